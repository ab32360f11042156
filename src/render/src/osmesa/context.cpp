// The rasteriser's OSMesa context (context.hpp).
#include "context.hpp"

#include <cstdlib>
#include <mutex>
#include <stdexcept>

namespace crumple::render::gl {

// llvmpipe compiles shaders for the CPU it runs on; AVX, FMA and the vector
// width change floating-point results in the last bit. Pinning the feature set
// to SSE4.1 (no FMA, 128-bit vectors) makes images byte-identical across x86-64
// machines of the same Mesa/LLVM build. Mesa reads the variable once, when the
// first context of the process is created; a value the user set is kept.
void pinLlvmpipeCpuFeatures() {
  static std::once_flag once;
  std::call_once(once, [] { ::setenv("GALLIUM_OVERRIDE_CPU_CAPS", "sse4.1", 0); });
}

OsmesaContext::OsmesaContext() {
  // GL 3.3 core first, then a compatibility context of the same version.
  for (const int profile : {OSMESA_CORE_PROFILE, OSMESA_COMPAT_PROFILE}) {
    // clang-format off
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA,
                           OSMESA_DEPTH_BITS, 24,
                           OSMESA_STENCIL_BITS, 0,
                           OSMESA_ACCUM_BITS, 0,
                           OSMESA_PROFILE, profile,
                           OSMESA_CONTEXT_MAJOR_VERSION, 3,
                           OSMESA_CONTEXT_MINOR_VERSION, 3,
                           0};
    // clang-format on
    ctx_ = OSMesaCreateContextAttribs(attribs, nullptr);
    if (ctx_) break;
  }
  if (!ctx_) throw std::runtime_error("OsmesaRenderer: OSMesaCreateContextAttribs failed");
}

OsmesaContext::~OsmesaContext() {
  if (ctx_) OSMesaDestroyContext(ctx_);
}

CurrentContext::CurrentContext(const OsmesaContext& context, std::vector<std::uint8_t>& buffer,
                               int width, int height) {
  if (!OSMesaMakeCurrent(context.get(), buffer.data(), GL_UNSIGNED_BYTE, width, height))
    throw std::runtime_error("OsmesaRenderer: OSMesaMakeCurrent failed");
}

CurrentContext::~CurrentContext() { OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0); }

}  // namespace crumple::render::gl
