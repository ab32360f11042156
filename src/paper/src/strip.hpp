#pragma once
// Internal to src/paper (not installed): the imaginary rulings of paper
// Appendices A-B (thesis 2.4.3) as a pencil of chords of a flat region F in
// the pattern, the border they meet, and F remeshed into the flat parts
// outside the strip and a curved region of the strip's chords.
#include <string>

#include "crumple/paper/geometric_mesh.hpp"
#include "crumple/paper/geometric_step.hpp"
#include "crumple/paper/params.hpp"
#include "region_tools.hpp"

namespace crumple::paper::detail {

// A pencil of chords: parallel to `dir` (apex < 0) or through vertex `apex`.
// A chord is identified by its parameter: the signed offset n.x (parallel)
// or the angle from `dir` around the apex (conical).
struct Pencil {
  int apex = -1;
  Vec2 origin =
      Vec2::Zero();          // a point of chord 0 (the compressed triangle's centroid) or the apex
  Vec2 dir = Vec2::UnitX();  // direction of chord 0
};

// Where the walk from the compressed triangle meets F's border (Appendix A,
// Fig. 6 b-d): dS (free), another flat region, a curved region, or nothing
// usable; the loop edge crossed and the point.
struct Border {
  enum class Kind { Free, FlatFlat, Curved, None } kind = Kind::None;
  int loopEdge = -1;
  Vec2 hit = Vec2::Zero();
};

// Appendix A: walks from the compressed triangle's centroid along +-dir to
// the region's border and classifies it (Fig. 6 b-d).
Border findBorder(const GeometricMesh& g, const Loop& loop, const Vec2& origin, const Vec2& dir,
                  double tol);

// Whether F was remeshed; else why not (for the developer trace).
struct StripResult {
  bool done = false;
  std::string note;
};

// Appendix B: remeshes region F into the flat parts outside the strip and a
// curved region of the strip's chords.
StripResult remeshStrip(GeometricMesh& g, int region, const Pencil& pencil,
                        const CrumpleParams& params, const BoundaryPosition& boundary);

}  // namespace crumple::paper::detail
