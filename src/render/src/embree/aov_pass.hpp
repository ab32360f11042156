#pragma once
// Private to the path tracer: the AOVs (crumple/render/aov.hpp) of the
// camera rays' first hits, summed pixel by pixel beside the beauty.
#include <embree3/rtcore.h>

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/render/aov.hpp"
#include "frame_data.hpp"

namespace crumple::render::pt {

// Per sheet triangle, the region AOV's label: 0 when the sheet's regions are
// not modelled (RenderScene::modelledRegions: the elastic model) or missing,
// else 2 in a curved region, 1 in a flat one.
std::vector<std::uint8_t> sheetTriangleRegions(const mesh::SheetMesh& sheet, bool modelled);

// Per sheet triangle, which of its corners are singular (sharp) vertices: bit
// k for corner k. A hit whose barycentric weight of such a corner is at least
// kSingularNeighbourhood is in the singular neighbourhood (the region AOV's
// third label): the part of each triangle around the vertex within half the
// way to the opposite edge.
std::vector<std::uint8_t> singularCorners(const mesh::SheetMesh& sheet,
                                          const std::vector<int>& sharpVertices);
inline constexpr float kSingularNeighbourhood = 0.5f;

// Per sheet triangle, the handle-id AOV's label: 1 + the index of the handle
// whose vertex is nearest the triangle's centroid in the pattern (ties to the
// lower index); 0 when no handle holds a vertex (index -1: released).
std::vector<std::uint16_t> nearestHandles(const mesh::SheetMesh& sheet,
                                          const std::vector<int>& handleVertices);

// `aovs`' channels at width x height, every pixel at its no-hit value (depth
// kAovFarDepth, everything else 0).
AovImage makeAovImage(const std::vector<Aov>& aovs, int width, int height);

// One pixel's AOVs over its camera rays (one per worker, reused).
class AovPixel {
 public:
  explicit AovPixel(const FrameData& f) : f_(f) {}

  void reset();
  // A camera ray that hit rh, at shading point s (makeSurface).
  void add(const RTCRayHit& rh, const Surface& s);
  // The pixel's values over `spp` camera rays into out's channels (in
  // makeAovImage's order for `aovs`).
  void store(const std::vector<Aov>& aovs, std::size_t pixel, int spp, AovImage& out) const;

 private:
  // The most frequent id of a pixel's hits (ties to the smaller id).
  static float majority(const std::vector<std::pair<float, int>>& counts);
  static void count(std::vector<std::pair<float, int>>& counts, float id);

  const FrameData& f_;
  int hits_ = 0;
  float nearest_ = kAovFarDepth;
  double normal_[3] = {0.0, 0.0, 0.0};
  double albedo_[3] = {0.0, 0.0, 0.0};
  double position_[3] = {0.0, 0.0, 0.0};
  int region_[3] = {0, 0, 0};  // hits on flat, curved, singular-neighbourhood paper
  std::vector<std::pair<float, int>> objects_;
  std::vector<std::pair<float, int>> handles_;
};

}  // namespace crumple::render::pt
