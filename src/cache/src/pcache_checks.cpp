// What a .pcache reader checks of decoded data before anyone uses it
// (docs/PCACHE.md "What the reader checks"): every index against the frame's
// own sizes and every real for finiteness, so that a CRC-valid but hostile
// file is an error naming its block, never undefined behaviour.
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_contacts.hpp"
#include "crumple/cache/pcache_look.hpp"
#include "crumple/cache/pcache_motion.hpp"
#include "crumple/core/error.hpp"

namespace crumple::cache {
namespace {

std::string num(std::size_t n) { return std::to_string(n); }

// The first index of `indices` outside [lowest, n), as a message, or "".
template <typename Range>
std::string indexProblem(const Range& indices, std::size_t n, int lowest, const char* what,
                         std::size_t record) {
  for (const int v : indices)
    if (v < lowest || (v >= 0 && static_cast<std::size_t>(v) >= n))
      return std::string(what) + " " + num(record) + " has vertex " + std::to_string(v) +
             " (the frame has " + num(n) + " vertices)";
  return {};
}

// Farther than any scene reaches; a bound on every coordinate keeps the
// tools' lengths, squares and bounding boxes finite (a CRC-valid frame with
// a vertex at 1e300 m crashed the self-penetration measure's AABB tree).
constexpr double kMaxCoordinate = 1e9;  // m

template <typename Vec>
bool inBounds(const Vec& p) {
  return p.allFinite() && p.cwiseAbs().maxCoeff() <= kMaxCoordinate;
}

template <typename Vec>
std::string firstNonFinite(const std::vector<Vec>& points, const char* what) {
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!inBounds(points[i]))
      return std::string(what) + " " + num(i) + " is not finite or beyond 1e9 m";
  return {};
}

std::string topologyProblem(const FrameRecord& f) {
  const std::size_t n = f.positions.size();
  if (f.pattern.size() != n)
    return "topology: " + num(f.pattern.size()) + " pattern points for " + num(n) + " vertices";
  if (f.regionOfTriangle.size() != f.triangles.size())
    return "topology: " + num(f.regionOfTriangle.size()) + " region ids for " +
           num(f.triangles.size()) + " triangles";
  for (std::size_t r = 0; r < f.regionTypes.size(); ++r)
    if (f.regionTypes[r] > 1)
      return "topology: region " + num(r) + " has type " + std::to_string(f.regionTypes[r]) +
             " (0 flat, 1 curved)";
  for (std::size_t t = 0; t < f.triangles.size(); ++t) {
    const auto& tri = f.triangles[t];
    if (auto p = indexProblem(tri, n, 0, "triangle", t); !p.empty()) return "topology: " + p;
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      return "topology: triangle " + num(t) + " repeats a vertex";
    const int region = f.regionOfTriangle[t];
    if (region < 0 || static_cast<std::size_t>(region) >= f.regionTypes.size())
      return "topology: triangle " + num(t) + " is in region " + std::to_string(region) + " of " +
             num(f.regionTypes.size());
  }
  if (auto p = firstNonFinite(f.pattern, "pattern point"); !p.empty()) return "topology: " + p;
  return {};
}

std::string structureProblem(const FrameRecord& f) {
  const std::size_t n = f.positions.size();
  for (std::size_t i = 0; i < f.singularVertices.size(); ++i)
    if (auto p = indexProblem(std::array{f.singularVertices[i]}, n, 0, "singular vertex", i);
        !p.empty())
      return "structure: " + p;
  for (std::size_t i = 0; i < f.junctionVertices.size(); ++i)
    if (auto p = indexProblem(std::array{f.junctionVertices[i]}, n, 0, "junction vertex", i);
        !p.empty())
      return "structure: " + p;
  for (std::size_t i = 0; i < f.rulings.size(); ++i)
    if (auto p = indexProblem(f.rulings[i], n, 0, "ruling", i); !p.empty())
      return "structure: " + p;
  return {};
}

std::string handleProblem(const FrameRecord& f, const CacheHeader& h) {
  const std::size_t n = f.positions.size();
  if (f.handleVertices.size() != f.handleTargets.size())
    return "handles: " + num(f.handleVertices.size()) + " vertices for " +
           num(f.handleTargets.size()) + " targets";
  if (f.handleVertices.size() > h.handleNames.size())
    return "handles: " + num(f.handleVertices.size()) + " handles, the header names " +
           num(h.handleNames.size());
  for (std::size_t i = 0; i < f.handleVertices.size(); ++i)  // -1: a released handle
    if (auto p = indexProblem(std::array{f.handleVertices[i]}, n, -1, "handle", i); !p.empty())
      return "handles: " + p;
  if (auto p = firstNonFinite(f.handleTargets, "target"); !p.empty()) return "handles: " + p;
  return {};
}

std::string contactProblem(const FrameRecord& f, const CacheHeader& h) {
  const auto contacts = decodeContacts(f.extensions);
  if (!contacts) return {};
  const auto colliders = decodeColliders(h.extensions);
  const std::size_t nColliders = colliders ? colliders->size() : 0;
  for (std::size_t i = 0; i < contacts->size(); ++i) {
    const ContactRecord& c = (*contacts)[i];
    if (static_cast<std::size_t>(c.vertex) >= f.positions.size())
      return "CONT sub-block: contact " + num(i) + " has vertex " + std::to_string(c.vertex) +
             " (the frame has " + num(f.positions.size()) + " vertices)";
    if (c.collider != kSelfContact && static_cast<std::size_t>(c.collider) >= nColliders)
      return "CONT sub-block: contact " + num(i) + " names collider " + std::to_string(c.collider) +
             " (the header lists " + num(nColliders) + ")";
  }
  return {};
}

// Sub-frame motion: a shot simulated for a shutter (SHTR) carries the
// sheet's velocities in every frame, one per vertex, and with mesh props
// their motions' derivatives, one per prop.
std::string motionProblem(const FrameRecord& f, const CacheHeader& h) {
  const bool shutter = decodeShutter(h.extensions).has_value();
  const auto velocities = decodeVelocities(f.extensions);
  if (shutter && !velocities) return "VELO sub-block: missing (the header has a shutter)";
  if (velocities && velocities->size() != f.positions.size())
    return "VELO sub-block: " + num(velocities->size()) + " velocities for " +
           num(f.positions.size()) + " vertices";
  const auto props = decodePropVelocities(f.extensions);
  if (!props && !shutter) return {};
  const auto motions = decodePropMotions(f.extensions);
  const std::size_t nMotions = motions ? motions->size() : 0;
  if (props && props->size() != nMotions)
    return "PRPV sub-block: " + num(props->size()) + " prop velocities for " + num(nMotions) +
           " prop motions";
  if (shutter && motions && !props) return "PRPV sub-block: missing (the header has a shutter)";
  return {};
}

}  // namespace

std::string validate(const CacheHeader& h) {
  if (!std::isfinite(h.fps) || h.fps <= 0.0)
    return "fps " + std::to_string(h.fps) + " is not a positive number";
  if (h.frameEnd < h.frameStart)
    return "planned frames " + std::to_string(h.frameStart) + "-" + std::to_string(h.frameEnd) +
           " end before they start";
  if (h.substeps < 1) return "substeps " + std::to_string(h.substeps) + " is below 1";
  for (const auto& [value, name] :
       {std::pair{h.sheetWidth, "sheet width"}, std::pair{h.sheetHeight, "sheet height"},
        std::pair{h.paperThickness, "paper thickness"}})
    if (!std::isfinite(value) || value < 0.0)
      return std::string(name) + " " + std::to_string(value) + " is not a length";
  try {
    (void)decodeShutter(h.extensions);
  } catch (const CorruptDataError& e) {
    return e.what();
  }
  return {};
}

std::string validate(const FrameRecord& f, const CacheHeader& h) {
  if (!std::isfinite(f.time)) return "time is not finite";
  if (auto p = topologyProblem(f); !p.empty()) return p;
  if (auto p = firstNonFinite(f.positions, "vertex"); !p.empty()) return "positions: " + p;
  if (auto p = structureProblem(f); !p.empty()) return p;
  if (auto p = handleProblem(f, h); !p.empty()) return p;
  const CameraRecord& c = f.camera;
  if (!inBounds(c.position) || !c.rotation.coeffs().allFinite() || !(c.rotation.norm() > 0.0) ||
      !std::isfinite(c.yfov) || c.yfov < 0.0 || c.yfov >= std::numbers::pi)
    return "camera: not a finite pose with a field of view in [0, pi)";
  try {
    if (auto p = contactProblem(f, h); !p.empty()) return p;
    return motionProblem(f, h);
  } catch (const CorruptDataError& e) {
    return e.what();
  }
}

}  // namespace crumple::cache
