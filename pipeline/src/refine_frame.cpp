// Render-time refinement of a cached frame (refine.hpp).
#include <algorithm>
#include <charconv>

#include "crumple/cache/pcache_developable.hpp"
#include "crumple/cache/pcache_motion.hpp"
#include "crumple/cache/pcache_tear.hpp"
#include "crumple/core/error.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/refine.hpp"

namespace crumple::pipeline {

mesh::RefineOptions parseRefine(const std::string& text, const std::string& flag) {
  mesh::RefineOptions o;
  if (text == "auto") return o;
  if (text == "off") {
    o.mode = mesh::RefineMode::Off;
    return o;
  }
  int cells = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), cells);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || cells < 1 ||
      cells > o.maxCells)
    throw InputError(flag, "'" + text + "' is not auto, off or a count of sub-cells from 1 to " +
                               std::to_string(o.maxCells));
  o.mode = mesh::RefineMode::Fixed;
  o.cells = cells;
  return o;
}

std::string refineName(const mesh::RefineOptions& options) {
  switch (options.mode) {
    case mesh::RefineMode::Off:
      return "off";
    case mesh::RefineMode::Auto:
      return "auto";
    case mesh::RefineMode::Fixed:
      break;
  }
  return std::to_string(options.cells);
}

namespace {

// Motion blur (VELO) on the refined mesh: the source's vertices keep their
// velocities, a new vertex takes the velocity the source's triangle holding
// its pattern point interpolates there (the blur's motion is linear over the
// shutter anyway).
std::vector<Vec3> refinedVelocities(const mesh::SheetMesh& source, const std::vector<Vec3>& v,
                                    const std::vector<Vec2>& pattern, const std::string& name) {
  if (v.size() != source.vertexCount())
    throw CorruptDataError(name + ": VELO sub-block: " + std::to_string(v.size()) +
                           " velocities for " + std::to_string(source.vertexCount()) + " vertices");
  std::vector<Vec3> out = v;
  for (std::size_t i = v.size(); i < pattern.size(); ++i) {
    const mesh::PatternLocation at = mesh::locatePattern(source, pattern[i]);
    Vec3 w = Vec3::Zero();
    if (at.triangle >= 0) {
      const auto& tri = source.triangles[static_cast<std::size_t>(at.triangle)];
      for (int k = 0; k < 3; ++k)
        w += at.weights[k] * v[static_cast<std::size_t>(tri[static_cast<std::size_t>(k)])];
    } else {
      w = v[static_cast<std::size_t>(mesh::nearestPatternVertex(source, pattern[i]))];
    }
    out.push_back(w);
  }
  return out;
}

}  // namespace

std::optional<mesh::RefineStats> refineFrame(cache::FrameRecord& frame,
                                             const mesh::RefineOptions& options) {
  if (options.mode == mesh::RefineMode::Off) return std::nullopt;
  const std::string name = "frame " + std::to_string(frame.frame) + " of the cache";
  std::optional<mesh::DevelopableStructure> structure;
  std::optional<mesh::TearAtlas> tears;
  std::optional<std::vector<Vec3>> velocities;
  try {
    structure = cache::decodeDevelopable(frame);
    tears = cache::decodeTearAtlas(frame.extensions);
    velocities = cache::decodeVelocities(frame.extensions);
  } catch (const CorruptDataError& e) {
    throw CorruptDataError(name + ": " + e.what());
  }
  if (!structure || structure->regions.empty()) return std::nullopt;
  const mesh::SheetMesh sheet = sheetOfFrame(frame);
  if (const std::string problem = mesh::validate(*structure, sheet); !problem.empty())
    throw CorruptDataError(name + ": SGEO sub-block: " + problem);
  std::vector<int> pinned = frame.singularVertices;
  for (int v : frame.handleVertices)
    if (v >= 0) pinned.push_back(v);
  std::vector<int> locked;
  if (tears)
    for (const auto& patch : tears->patches) locked.push_back(patch.triangle);
  mesh::RefinedSheet refined = mesh::refineDevelopable(sheet, *structure, options, pinned, locked);
  if (refined.stats.refinedRuns == 0) return refined.stats;
  frame.pattern = std::move(refined.mesh.pattern);
  frame.positions = std::move(refined.mesh.positions);
  frame.triangles = std::move(refined.mesh.triangles);
  frame.regionOfTriangle = std::move(refined.mesh.regionOfTriangle);
  const auto replaceBlock = [&](const cache::ExtensionBlock& block) {
    for (auto& b : frame.extensions)
      if (b.tag == block.tag) b = block;
  };
  if (tears) replaceBlock(cache::encodeTearAtlas(mesh::remapTearAtlas(*tears, refined)));
  if (velocities)
    replaceBlock(
        cache::encodeVelocities(refinedVelocities(sheet, *velocities, frame.pattern, name)));
  return refined.stats;
}

}  // namespace crumple::pipeline
