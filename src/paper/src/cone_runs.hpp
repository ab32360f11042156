#pragma once
// Internal to src/paper (not installed): the runs of rulings of a curved
// region refitted as generalized cones (paper Sec. 6.2 last paragraphs,
// Fig. 15; thesis 2.5.2, Fig. 2.19), used by refitCurvedRegion.
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "crumple/core/geometry2d.hpp"
#include "crumple/paper/boundary_curve.hpp"
#include "crumple/paper/cone_fit.hpp"
#include "crumple/paper/geometric_mesh.hpp"

namespace crumple::paper::cones {

// Outline parameter s taken modulo the perimeter into [0, perimeter).
inline double wrapPositive(double s, double perimeter) {
  double w = std::fmod(s, perimeter);
  if (w < 0.0) w += perimeter;
  if (w >= perimeter) w = 0.0;
  return w;
}

// One boundary chain of a run of rulings: a piece of dS parametrized by
// t in [0, length], t = sigma (s - s0) modulo the perimeter.
struct Chain {
  const GeometricMesh* g = nullptr;
  double perimeter = 0.0;
  double s0 = 0.0;
  int sigma = 1;
  double length = 0.0;
  std::vector<double> knots;  // 0, corners strictly inside, length

  double sAt(double t) const { return wrapPositive(s0 + sigma * t, perimeter); }
  double tOf(double s) const { return wrapPositive(sigma * (s - s0), perimeter); }
  Vec2 point(double t) const { return outlinePoint(*g, sAt(t)); }

  // The intersection of the line o + mu dir with the chain within [lo, hi]
  // closest to `guess`.
  std::optional<double> hit(const Vec2& o, const Vec2& dir, double lo, double hi, double guess,
                            double eps) const {
    std::optional<double> best;
    for (std::size_t k = 0; k + 1 < knots.size(); ++k) {
      const double t0 = knots[k];
      const double t1 = knots[k + 1];
      if (t1 < lo - eps || t0 > hi + eps || t1 - t0 <= 0.0) continue;
      const Vec2 p = point(t0);
      const Vec2 e = point(t1) - p;
      const double denom = cross2(e, dir);
      if (std::abs(denom) <= 1e-14 * e.norm() * dir.norm()) continue;  // parallel
      const double lambda = cross2(o - p, dir) / denom;
      const double t = t0 + lambda * (t1 - t0);
      if (t < std::max(t0, lo) - eps || t > std::min(t1, hi) + eps) continue;
      const double clamped = std::clamp(t, lo, hi);
      if (!best || std::abs(clamped - guess) < std::abs(*best - guess)) best = clamped;
    }
    return best;
  }
};

// A pencil of pattern lines: through a point (cone apex) or parallel
// (apex at infinity).
struct Pencil {
  bool atInfinity = false;
  Vec2 point = Vec2::Zero();
  Vec2 direction = Vec2::UnitY();

  // Direction of the line of the pencil through p (nullopt when p is the apex).
  std::optional<Vec2> through(const Vec2& p, double eps) const {
    if (atInfinity) return direction;
    const Vec2 d = p - point;
    if (d.norm() <= eps) return std::nullopt;
    return d;
  }
};

// A ruling in chain coordinates: t[c] on chain c, v[c] the S_G vertex when
// the endpoint is an existing vertex (-1: to be created).
struct ChainRuling {
  std::array<double, 2> t{0.0, 0.0};
  std::array<int, 2> v{-1, -1};
};

struct FixedPoint {
  double t = 0.0;
  int v = -1;
};

struct RunResult {
  std::vector<ChainRuling> rulings;  // replaces the run, borders included
  std::array<Chain, 2> chains;
  std::vector<ConeSegment> segments;
  std::vector<PatternApex> apices;
  int junctionCones = 0;
  int sharedRulings = 0;
  int keptJunctions = 0;
};

// A junction between two cones of a run (or at a run's end): L ends the
// cone before, R starts the cone after (paper Fig. 15 last row).
struct Junction {
  ChainRuling left, right;
  bool fan = false;
  int fanChain = 0;
  bool shared = false;
};

// The data of the region the runs need.
struct RegionContext {
  GeometricMesh* g = nullptr;
  std::vector<Ruling> rulings;  // oriented: a on side 0
  double perimeter = 0.0;
  double spacing = 0.0;  // 1 / rho_bound
  double tolerance = 0.0;
  double paperLength = 0.0;
  std::vector<double> cornerS;
  std::vector<char> fixedVertex;   // never moves (handle, singular, corner, used by another region)
  std::vector<Vec3> rulingNormal;  // per region ruling
};

// Outline parameter of a boundary vertex (paper Sec. 6.2: the boundary
// curve is parametrized along dS).
double vertexS(const GeometricMesh& g, int v);

// Normal of the polygon between rulings r0 and r1 (a0, a1, b1, b0), oriented
// like a counter-clockwise face (faceNormal's convention).
Vec3 polygonNormal(const GeometricMesh& g, const Ruling& r0, const Ruling& r1);

class RunRefitter {
 public:
  RunRefitter(const RegionContext& ctx, int first, int last)
      : ctx_(ctx), first_(first), last_(last) {}

  // Returns the reason when the run cannot be refitted.
  std::string run(RunResult& out);

 private:
  std::string buildChains();
  std::string fanRun(int apexChain);
  std::string coneRun();
  // thesis 2.5.2 / paper Fig. 15 last row: rulings of a junction cone from
  // the point t on chain c to the other chain over [lo, hi] (exclusive).
  void fanInterior(int c, double t, int v, double lo, double hi,
                   std::vector<ChainRuling>& out) const;
  // paper Sec. 6.2: rulings of cone `pencil` strictly between s and e.
  std::string coneInterior(const Pencil& pencil, const ChainRuling& s, const ChainRuling& e,
                           std::vector<ChainRuling>& out) const;
  Junction resolveJunction(int J, bool degraded, const std::vector<ConeSegment>& segments,
                           const std::vector<Pencil>& pencils) const;
  std::optional<double> pencilHit(const Pencil& pencil, int c, double t, double lo, double hi,
                                  double guess) const;
  ChainRuling original(int k) const;  // run-local index k

  const RegionContext& ctx_;
  int first_;
  int last_;
  std::array<Chain, 2> chains_;
  std::array<std::vector<FixedPoint>, 2> fixed_;  // fixed vertices strictly inside each chain
  std::vector<std::array<double, 2>> t_;  // chain coordinates of the original rulings (run-local)
  RunResult* out_ = nullptr;
  double eps_ = 0.0;
};

}  // namespace crumple::paper::cones
