# One call declares a module's library the house way (docs/ARCHITECTURE.md
# "Modules"): crumple_<name> with its alias crumple::<name>, the public
# headers in include/ (and the private ones in src/ when the folder has
# private headers), and its links.
#
#   crumple_module(<name> SOURCES <file>... [PUBLIC <target>...] [PRIVATE <target>...])
function(crumple_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  add_library(crumple_${name} ${ARG_SOURCES})
  add_library(crumple::${name} ALIAS crumple_${name})
  target_include_directories(crumple_${name} PUBLIC include)
  file(GLOB private_headers ${CMAKE_CURRENT_SOURCE_DIR}/src/*.hpp)
  if(private_headers)
    target_include_directories(crumple_${name} PRIVATE src)
  endif()
  target_link_libraries(crumple_${name} PUBLIC ${ARG_PUBLIC} PRIVATE ${ARG_PRIVATE})
endfunction()

# A module's parameters (docs/ARCHITECTURE.md "Parameters"): the header-only
# INTERFACE target crumple::<name>_params over params/include, so that io
# fills them without linking the module's code.
#
#   crumple_params(<name> [DEPENDS <target>...])
function(crumple_params name)
  cmake_parse_arguments(ARG "" "" "DEPENDS" ${ARGN})
  add_library(crumple_${name}_params INTERFACE)
  add_library(crumple::${name}_params ALIAS crumple_${name}_params)
  target_include_directories(crumple_${name}_params INTERFACE params/include)
  target_link_libraries(crumple_${name}_params INTERFACE ${ARG_DEPENDS})
endfunction()
