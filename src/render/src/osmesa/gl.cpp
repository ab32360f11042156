// Small GL helpers of the rasteriser (gl.hpp).
#include "gl.hpp"

#include <stdexcept>

namespace crumple::render::gl {

void checkFramebuffer(const char* what) {
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error(std::string("OsmesaRenderer: incomplete ") + what +
                             " framebuffer (status " + std::to_string(status) + ")");
}

void checkGl(const char* where) {
  const GLenum e = glGetError();
  if (e != GL_NO_ERROR)
    throw std::runtime_error(std::string("OsmesaRenderer: GL error ") + std::to_string(e) + " in " +
                             where);
}

std::array<float, 16> toGl(const Mat4& m) {
  std::array<float, 16> a{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      a[static_cast<std::size_t>(c * 4 + r)] = static_cast<float>(m(r, c));
  return a;
}

}  // namespace crumple::render::gl
