#pragma once
// Private to the rasteriser: the key light's shadow-map projection, fitted to
// what it shadows (shadow_map.cpp).
#include <cstddef>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/render/view.hpp"

namespace crumple::render::gl {

// The key light's view-projection and the world size of a shadow texel.
struct ShadowProjection {
  Mat4 lightViewProj = Mat4::Identity();
  double texelWorld = 0.0;  // m per texel (per metre of distance for a point light)
};

// Fits the shadow map of `key` (position relative to the render origin) of
// shadowSize^2 texels: `receivers` are the casters' vertices (the first
// casterCount: paper, props, tear patches) followed by the ground's corners.
// A directional light gets an orthographic map fitted in x/y to the casters
// and in depth to all receivers; a point or area light a perspective map
// from its position towards the casters' bounding sphere.
ShadowProjection fitShadowProjection(const Light& key, const std::vector<Vec3>& receivers,
                                     std::size_t casterCount, int shadowSize);

}  // namespace crumple::render::gl
