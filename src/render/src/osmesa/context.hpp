#pragma once
// Private to the rasteriser: the OSMesa context, owned, and bound to the
// calling thread for one scope.
#include <cstdint>
#include <vector>

#include "gl.hpp"

namespace crumple::render::gl {

// Pins llvmpipe's CPU features to SSE4.1 for the whole process, once, unless
// GALLIUM_OVERRIDE_CPU_CAPS is already set (osmesa_renderer.hpp).
void pinLlvmpipeCpuFeatures();

// Owns the OSMesa context (GL 3.3 core, else compatibility); every GL object
// lives and dies with it. Throws std::runtime_error when OSMesa cannot
// create one.
class OsmesaContext {
 public:
  OsmesaContext();
  ~OsmesaContext();
  OsmesaContext(const OsmesaContext&) = delete;
  OsmesaContext& operator=(const OsmesaContext&) = delete;
  // The context handle.
  OSMesaContext get() const { return ctx_; }

 private:
  OSMesaContext ctx_ = nullptr;
};

// Binds a context to the calling thread for one scope, then releases it, so
// a renderer may be used from different threads one after the other.
class CurrentContext {
 public:
  // Binds `context` with `buffer` (width * height RGBA bytes, outliving the
  // binding) as its default framebuffer. Throws std::runtime_error on failure.
  CurrentContext(const OsmesaContext& context, std::vector<std::uint8_t>& buffer, int width,
                 int height);
  ~CurrentContext();
  CurrentContext(const CurrentContext&) = delete;
  CurrentContext& operator=(const CurrentContext&) = delete;
};

}  // namespace crumple::render::gl
