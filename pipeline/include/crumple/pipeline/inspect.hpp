#pragma once
// Per-frame measures of a cached shot (`crumple inspect`): sizes, edge strain
// against the pattern (c_mean and n_comp as in paper Table IV), sharpest
// fold between adjacent triangles, handle error.
#include <string>
#include <vector>

#include "crumple/exporters/pcache.hpp"

namespace crumple::pipeline {

struct FrameMetrics {
  int frame = 0;
  double time = 0.0;
  std::size_t vertices = 0;
  std::size_t triangles = 0;
  double cMean = 0.0;        // mean |l - L| / L over edges (paper Table IV, c_mean)
  double nComp = 0.0;        // share of edges with (L - l) / L > 1% (paper Table IV, n_comp)
  double maxStrain = 0.0;    // max |l - L| / L over edges
  double maxDihedral = 0.0;  // largest angle (rad) between the normals of adjacent triangles
  double handleError = 0.0;  // max distance between a held vertex and its track (m)
  std::size_t singularVertices = 0;
  std::size_t junctionVertices = 0;
  std::size_t tears = 0;
};

FrameMetrics measureFrame(const cache::FrameRecord& frame);

// The `inspect --json` object: {"format_version", "fps", "frame_count",
// "frames": [...]} -- later features extend it but never rename a key.
std::string inspectJson(const cache::CacheReader& reader);
// The human-readable table.
std::string inspectText(const cache::CacheReader& reader);

}  // namespace crumple::pipeline
