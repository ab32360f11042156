#pragma once
// Private to the path tracer: the integrator, tracing the image's tiles
// against a frame's Embree scene (integrator.cpp).
#include <embree3/rtcore.h>

#include <atomic>
#include <cstdint>

#include "crumple/core/image.hpp"
#include "crumple/render/aov.hpp"
#include "crumple/render/embree_renderer.hpp"
#include "frame_data.hpp"

namespace crumple::render::pt {

// Renders the tiles handed out by `next` (kTileSize squares, row by row) into
// `out`, and settings.aovs into `aovs` (makeAovImage's channels) when it is
// not null; returns the number of dropped non-finite samples. Several
// workers may share `next`, `out` and `aovs`: each pixel is written by one
// tile only.
std::uint64_t renderTiles(const FrameData& f, RTCScene scene, const PathTraceSettings& settings,
                          std::atomic<int>& next, ImageRGBAF& out, AovImage* aovs);

// The shading point of a camera or bounce ray's hit (ray direction dir,
// unit) at shutter time `time` (motion blur; still meshes ignore it):
// normals flipped to the side the ray came from, that side's albedo.
Surface makeSurface(const FrameData& f, const RTCRayHit& rh, V3 dir, float time);

}  // namespace crumple::render::pt
