#pragma once
// Private to the path tracer: the integrator, tracing the image's tiles
// against a frame's Embree scene (integrator.cpp).
#include <embree3/rtcore.h>

#include <atomic>
#include <cstdint>

#include "crumple/core/image.hpp"
#include "crumple/render/embree_renderer.hpp"
#include "frame_data.hpp"

namespace crumple::render::pt {

// Renders the tiles handed out by `next` (kTileSize squares, row by row) into
// `out`; returns the number of dropped non-finite samples. Several workers
// may share `next` and `out`: each pixel is written by one tile only.
std::uint64_t renderTiles(const FrameData& f, RTCScene scene, const PathTraceSettings& settings,
                          std::atomic<int>& next, ImageRGBAF& out);

}  // namespace crumple::render::pt
