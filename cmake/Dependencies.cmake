# Every dependency is a Debian 12 package (see scripts/bootstrap.sh and
# ../shared/DEPENDENCIES.md). Nothing is downloaded at build time.
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(Eigen3 3.4 REQUIRED CONFIG)
find_package(assimp 5.2 REQUIRED CONFIG)
find_package(PNG REQUIRED)
find_package(ZLIB REQUIRED)  # FBX arrays (src/io/src/fbx_takes.cpp)
find_package(CLI11 REQUIRED CONFIG)
find_package(tomlplusplus REQUIRED CONFIG)  # target tomlplusplus::tomlplusplus
# CGAL 5.5 is header-only on Debian; CGAL::CGAL carries Boost's headers, GMP,
# MPFR and -frounding-math (needed by its filtered predicates). Link it
# PRIVATE: only src/mesh/src/delaunay.cpp includes CGAL.
set(CGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE TRUE)
find_package(CGAL 5.5 REQUIRED CONFIG)
# FCL 0.7 (collider BVHs; target `fcl`, no namespace). Its asserts are live:
# only proximity queries with a margin are used (../shared/DEPENDENCIES.md).
find_package(fcl 0.7 REQUIRED CONFIG)
# Embree 3 (the path tracer; target `embree`, header <embree3/rtcore.h>).
find_package(embree 3.13 REQUIRED CONFIG)
# OpenEXR 3.1 (linear frames; targets OpenEXR::OpenEXR).
find_package(OpenEXR 3.1 REQUIRED CONFIG)
# OSMesa only: linking libGL as well turns every GL call into a no-op.
pkg_check_modules(OSMESA REQUIRED IMPORTED_TARGET osmesa)
# libsndfile (the soundtrack's WAV files).
pkg_check_modules(SNDFILE REQUIRED IMPORTED_TARGET sndfile)
# FFTW 3 (the friction noise's inverse FFTs).
pkg_check_modules(FFTW3 REQUIRED IMPORTED_TARGET fftw3)

# CHOLMOD (SuiteSparse 5.12) ships neither a CMake config nor a .pc file.
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig REQUIRED)
if(NOT TARGET crumple::cholmod)
  add_library(crumple_cholmod INTERFACE)
  target_include_directories(crumple_cholmod SYSTEM INTERFACE ${CHOLMOD_INCLUDE_DIR})
  target_link_libraries(crumple_cholmod INTERFACE ${CHOLMOD_LIBRARY} ${SUITESPARSECONFIG_LIBRARY})
  add_library(crumple::cholmod ALIAS crumple_cholmod)
endif()

if(CRUMPLE_BUILD_TESTS)
  find_package(GTest REQUIRED CONFIG)
  include(GoogleTest)
endif()
if(CRUMPLE_BUILD_BENCH)
  find_package(benchmark REQUIRED CONFIG)
endif()
