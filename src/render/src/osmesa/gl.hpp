#pragma once
// Private to the rasteriser: the GL headers (OSMesa's; link OSMesa only: with
// libGL linked too every GL call is a no-op), its limits, vertex layouts and
// small GL helpers.
#define GL_GLEXT_PROTOTYPES 1
// clang-format off
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>
// clang-format on

#include <array>
#include <string>

#include "crumple/core/types.hpp"

namespace crumple::render::gl {

constexpr int kMaxLights = 16;
// Shadow map side: the map is fitted to the casters, so 1024 texels give
// ~0.3 mm on an A4 sheet, finer than a pixel of a 1280 x 720 frame showing the
// sheet; images over 2048 pixels wide get 2048 (a 2048 map costs ~10 ms).
constexpr int kShadowMapSmall = 1024;
constexpr int kShadowMapLarge = 2048;
constexpr int kMaxSamples = 4;

// A vertex of the paper, a prop or the ground (three per triangle).
struct Vertex {
  float pos[3];
  float normal[3];
  float uv[2];
};

// A corner of a tear patch's triangle: a Vertex and its atlas coordinates.
struct PatchVertex {
  float pos[3];
  float normal[3];
  float uv[2];
  float maskUv[2];  // normalised atlas coordinates
};

// The texture unit of the tear atlas's mask.
constexpr int kMaskUnit = 3;

// Throws std::runtime_error unless the bound framebuffer is complete.
void checkFramebuffer(const char* what);

// Throws std::runtime_error naming GL's pending error, if any, and `where`.
void checkGl(const char* where);

// Column-major float copy of a double matrix for glUniformMatrix4fv.
std::array<float, 16> toGl(const Mat4& m);

}  // namespace crumple::render::gl
