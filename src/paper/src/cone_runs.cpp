// Runs of rulings of a curved region refitted as generalized cones (paper
// Sec. 6.2 last paragraphs, Fig. 15; thesis 2.5.2, Fig. 2.19).
#include "cone_runs.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "crumple/core/index.hpp"

namespace crumple::paper::cones {

namespace {

// Length scale L of the apex fit in refitCurvedRegion, in sheet sizes: an
// apex much closer than L is judged by its plane distances (paper eq. (2)),
// a much farther one by L times the angles (see cone_fit.hpp).
constexpr double kFarApex = 10.0;

// Samples strictly inside [lo, hi] of one chain with spacing <= h, uniform.
std::vector<double> uniformInterior(double lo, double hi, double h) {
  std::vector<double> out;
  const double len = hi - lo;
  if (!(len > h * (1.0 + 1e-9))) return out;
  const int m = static_cast<int>(std::ceil(len / h - 1e-9));
  for (int i = 1; i < m; ++i) out.push_back(lo + len * static_cast<double>(i) / m);
  return out;
}

// paper Sec. 6.2 (normals constant along a ruling): the tangent planes and
// geometry of rulings first..first + n - 1 and the apex fit's frame.
struct RunPlanes {
  std::vector<RulingPlane> planes;
  std::vector<RulingGeometry> geometry;
  FitFrame frame;
};
std::string runPlanes(const RegionContext& ctx, int first, int n, RunPlanes& out) {
  const GeometricMesh& g = *ctx.g;
  std::vector<RulingPlane>& planes = out.planes;
  std::vector<RulingGeometry>& geometry = out.geometry;
  FitFrame& frame = out.frame;
  planes.resize(idx(n));
  geometry.resize(idx(n));
  frame.centre = Vec3::Zero();
  double lengthSum = 0.0;
  for (int k = 0; k < n; ++k) {
    const Ruling& r = ctx.rulings[idx(first + k)];
    const GeometricVertex& va = g.vertices[idx(r.a)];
    const GeometricVertex& vb = g.vertices[idx(r.b)];
    const Vec3 normal = ctx.rulingNormal[idx(first + k)];
    const Vec3 mid = 0.5 * (va.position + vb.position);
    const Vec3 d = vb.position - va.position;
    if (!(d.norm() > 0.0) || !((vb.pattern - va.pattern).norm() > 0.0))
      return "a ruling has zero length";
    planes[idx(k)] = {normal, -normal.dot(mid), d.normalized()};
    geometry[idx(k)] = {va.position, vb.position, va.pattern, vb.pattern, normal};
    frame.centre += mid;
    lengthSum += d.norm();
  }
  frame.centre /= n;
  frame.length = kFarApex * ctx.paperLength;
  if (!(lengthSum > 0.0)) return "the rulings have zero length";
  return {};
}

}  // namespace

// Outline parameter of a boundary vertex (paper Sec. 6.2: the boundary
// curve is parametrized along dS).
double vertexS(const GeometricMesh& g, int v) {
  const GeometricVertex& gv = g.vertices[idx(v)];
  return wrapPositive(outlineParameter(g, gv.pattern, gv.outlineSegment), outlinePerimeter(g));
}

// Normal of the polygon between rulings r0 and r1 (a0, a1, b1, b0), oriented
// like a counter-clockwise face (faceNormal's convention).
Vec3 polygonNormal(const GeometricMesh& g, const Ruling& r0, const Ruling& r1) {
  std::array<int, 4> poly{r0.a, r1.a, r1.b, r0.b};
  std::vector<int> v;
  for (int id : poly) {
    if (!v.empty() && v.back() == id) continue;
    v.push_back(id);
  }
  if (v.size() > 1 && v.back() == v.front()) v.pop_back();
  if (v.size() < 3) return Vec3::Zero();
  const auto P = [&](std::size_t k) -> const Vec3& { return g.vertices[idx(v[k])].position; };
  const auto Q = [&](std::size_t k) -> const Vec2& { return g.vertices[idx(v[k])].pattern; };
  Vec3 n = v.size() == 3 ? Vec3((P(1) - P(0)).cross(P(2) - P(0)))
                         : Vec3((P(2) - P(0)).cross(P(3) - P(1)));
  double area = 0.0;
  for (std::size_t k = 0; k < v.size(); ++k) area += cross2(Q(k), Q((k + 1) % v.size()));
  if (area < 0.0) n = -n;
  const double len = n.norm();
  return len > 0.0 ? Vec3(n / len) : Vec3::Zero();
}

// The current (original) ruling k of the run in chain coordinates.
ChainRuling RunRefitter::original(int k) const {
  const Ruling& r = ctx_.rulings[idx(first_ + k)];
  ChainRuling out;
  out.t = t_[idx(k)];
  out.v = {r.a, r.b};
  return out;
}

// paper Fig. 15: the two boundary chains of dS the rulings of a run end on,
// with the chain coordinates of the current rulings and the fixed vertices.
std::string RunRefitter::buildChains() {
  const GeometricMesh& g = *ctx_.g;
  const int n = last_ - first_ + 1;
  t_.assign(idx(n), {0.0, 0.0});
  for (int c = 0; c < 2; ++c) {
    std::vector<int> verts;
    std::vector<double> s;
    for (int k = 0; k < n; ++k) {
      const Ruling& r = ctx_.rulings[idx(first_ + k)];
      verts.push_back(c == 0 ? r.a : r.b);
      s.push_back(vertexS(g, verts.back()));
    }
    // Direction along dS: the sum of the wrapped steps.
    double total = 0.0;
    for (int k = 0; k + 1 < n; ++k) {
      double d = wrapPositive(s[idx(k + 1)] - s[idx(k)], ctx_.perimeter);
      if (d > 0.5 * ctx_.perimeter) d -= ctx_.perimeter;
      total += d;
    }
    Chain& chain = chains_[idx(c)];
    chain.g = &g;
    chain.perimeter = ctx_.perimeter;
    chain.s0 = s.front();
    chain.sigma = total < 0.0 ? -1 : 1;
    double prev = 0.0;
    for (int k = 0; k < n; ++k) {
      double t = chain.tOf(s[idx(k)]);
      if (verts[idx(k)] == verts.front()) t = 0.0;
      // A vertex at the very start seen across the wrap.
      if (t > ctx_.perimeter - 1e-12 * ctx_.perimeter) t = 0.0;
      if (t < prev - 1e-12 * ctx_.perimeter)
        return "a boundary chain of the region is not monotone along dS";
      t = std::max(t, prev);
      t_[idx(k)][idx(c)] = t;
      prev = t;
    }
    chain.length = prev;
    chain.knots = {0.0};
    for (double sc : ctx_.cornerS) {
      const double tc = chain.tOf(sc);
      if (tc > 0.0 && tc < chain.length) chain.knots.push_back(tc);
    }
    std::sort(chain.knots.begin(), chain.knots.end());
    chain.knots.push_back(chain.length);
    // Fixed vertices strictly inside the chain.
    std::set<int> seen;
    for (int k = 1; k + 1 < n; ++k) {
      const int v = verts[idx(k)];
      if (v == verts.front() || v == verts.back() || !seen.insert(v).second) continue;
      if (ctx_.fixedVertex[idx(v)]) {
        fixed_[idx(c)].push_back({t_[idx(k)][idx(c)], v});
      }
    }
  }
  return {};
}

// paper Sec. 6.2: where the line of a cone's pencil through the point t of
// chain c meets the other chain (the resampled ruling endpoint).
std::optional<double> RunRefitter::pencilHit(const Pencil& pencil, int c, double t, double lo,
                                             double hi, double guess) const {
  const Chain& from = chains_[idx(c)];
  const Chain& to = chains_[idx(1 - c)];
  const Vec2 p = from.point(t);
  const std::optional<Vec2> dir = pencil.through(p, 1e-9 * ctx_.spacing);
  if (!dir) return std::nullopt;
  return to.hit(p, *dir, lo, hi, guess, eps_);
}

// paper Sec. 6.2 / Fig. 15 last row: the rulings of a junction cone, a fan
// from the point t of chain c over [lo, hi] of the other chain, spaced
// <= 1/rho_bound and through the fixed vertices there.
void RunRefitter::fanInterior(int c, double t, int v, double lo, double hi,
                              std::vector<ChainRuling>& out) const {
  const int o = 1 - c;
  std::vector<FixedPoint> stops{{lo, -1}};
  for (const FixedPoint& f : fixed_[idx(o)]) {
    if (f.t > lo + eps_ && f.t < hi - eps_) stops.push_back(f);
  }
  stops.push_back({hi, -1});
  for (std::size_t k = 0; k + 1 < stops.size(); ++k) {
    if (k > 0) {
      ChainRuling r;
      r.t[idx(c)] = t;
      r.v[idx(c)] = v;
      r.t[idx(o)] = stops[k].t;
      r.v[idx(o)] = stops[k].v;
      out.push_back(r);
    }
    for (double tt : uniformInterior(stops[k].t, stops[k + 1].t, ctx_.spacing)) {
      ChainRuling r;
      r.t[idx(c)] = t;
      r.v[idx(c)] = v;
      r.t[idx(o)] = tt;
      out.push_back(r);
    }
  }
}

// paper Sec. 6.2 / Fig. 15 second row: the rulings of a cone between its
// extreme rulings s and e, all through its pattern apex (thesis 2.5.2:
// density >= rho_bound on both chains, rulings added or removed).
std::string RunRefitter::coneInterior(const Pencil& pencil, const ChainRuling& s,
                                      const ChainRuling& e, std::vector<ChainRuling>& out) const {
  const double len0 = e.t[0] - s.t[0];
  const double len1 = e.t[1] - s.t[1];
  if (len0 <= eps_ && len1 <= eps_) return {};
  const int c = len0 >= len1 ? 0 : 1;  // driver: the longer side
  const int o = 1 - c;
  const auto cu = idx(c);
  const auto ou = idx(o);
  if ((o == 0 ? len0 : len1) <= eps_) {
    // The cone degenerates to a fan from a point of the other chain.
    fanInterior(o, s.t[ou], s.v[ou], s.t[cu], e.t[cu], out);
    return {};
  }
  const auto lerpOther = [&](double tc) {
    return s.t[ou] + (e.t[ou] - s.t[ou]) * (tc - s.t[cu]) / (e.t[cu] - s.t[cu]);
  };
  // Rulings through the fixed vertices inside the cone, aimed at its apex.
  std::vector<ChainRuling> stops{s};
  for (int side = 0; side < 2; ++side) {
    const auto su = idx(side);
    for (const FixedPoint& f : fixed_[su]) {
      if (!(f.t > s.t[su] + eps_ && f.t < e.t[su] - eps_)) continue;
      const double guess =
          side == c ? lerpOther(f.t)
                    : s.t[cu] + (e.t[cu] - s.t[cu]) * (f.t - s.t[su]) / (e.t[su] - s.t[su]);
      const std::optional<double> h = pencilHit(pencil, side, f.t, s.t[1 - su], e.t[1 - su], guess);
      if (!h)
        return "a fixed boundary vertex cannot be joined to its cone's apex inside the region";
      ChainRuling r;
      r.t[su] = f.t;
      r.v[su] = f.v;
      r.t[1 - su] = *h;
      stops.push_back(r);
    }
  }
  stops.push_back(e);
  std::sort(stops.begin() + 1, stops.end() - 1,
            [cu](const ChainRuling& a, const ChainRuling& b) { return a.t[cu] < b.t[cu]; });
  for (std::size_t k = 0; k + 1 < stops.size(); ++k) {
    if (stops[k + 1].t[ou] < stops[k].t[ou] - eps_ || stops[k + 1].t[cu] < stops[k].t[cu] - eps_) {
      return "the rulings through fixed boundary vertices cross";
    }
  }
  const double h = ctx_.spacing;
  for (std::size_t k = 0; k + 1 < stops.size(); ++k) {
    const ChainRuling& a = stops[k];
    const ChainRuling& b = stops[k + 1];
    if (k > 0) out.push_back(a);
    const double lc = b.t[cu] - a.t[cu];
    const double lo = b.t[ou] - a.t[ou];
    if (lc <= eps_) continue;
    int m = std::max(1, static_cast<int>(std::ceil(lc / h - 1e-9)));
    const int cap = 4 * static_cast<int>(std::ceil(std::max(lc, lo) / h)) + 16;
    std::vector<ChainRuling> best;
    for (; m <= cap; ++m) {
      std::vector<ChainRuling> samples;
      double prevO = a.t[ou];
      double maxGapO = 0.0;
      for (int i = 1; i < m; ++i) {
        const double tc = a.t[cu] + lc * static_cast<double>(i) / m;
        const double guess = a.t[ou] + lo * static_cast<double>(i) / m;
        const std::optional<double> to = pencilHit(pencil, c, tc, a.t[ou], b.t[ou], guess);
        if (!to || *to < prevO - eps_) continue;
        ChainRuling r;
        r.t[cu] = tc;
        r.t[ou] = std::max(*to, prevO);
        maxGapO = std::max(maxGapO, r.t[ou] - prevO);
        prevO = r.t[ou];
        samples.push_back(r);
      }
      maxGapO = std::max(maxGapO, b.t[ou] - prevO);
      best = std::move(samples);
      if (maxGapO <= h * (1.0 + 1e-9)) break;
    }
    out.insert(out.end(), best.begin(), best.end());
  }
  return {};
}

// thesis 2.5.2 (a region that is already one cone with its apex on dS):
// only the sampling of the other chain.
std::string RunRefitter::fanRun(int apexChain) {
  // All rulings of the run share one vertex of chain `apexChain`: already a
  // cone with its apex on dS; only the density along the other chain.
  const int n = last_ - first_ + 1;
  const ChainRuling s = original(0);
  const ChainRuling e = original(n - 1);
  const auto a = idx(apexChain);
  const int o = 1 - apexChain;
  std::vector<ChainRuling>& out = out_->rulings;
  out.push_back(s);
  fanInterior(apexChain, s.t[a], s.v[a], s.t[idx(o)], e.t[idx(o)], out);
  out.push_back(e);
  return {};
}

// paper Sec. 6.2 / Fig. 15 last row: junction J of a run (before the
// first cone, between cones, after the last one) joined on one ruling or
// as a fan from a point of dS; the original rulings when `degraded`.
Junction RunRefitter::resolveJunction(int J, bool degraded,
                                      const std::vector<ConeSegment>& segments,
                                      const std::vector<Pencil>& pencils) const {
  const int n = last_ - first_ + 1;
  const int nseg = static_cast<int>(segments.size());
  const int iL = J == 0 ? 0 : segments[idx(J - 1)].last;
  const int iR = J == nseg ? n - 1 : segments[idx(J)].first;
  Junction out;
  out.left = original(iL);
  out.right = original(iR);
  if (degraded) return out;
  const Pencil* pl = J == 0 ? nullptr : &pencils[idx(J - 1)];
  const Pencil* pr = J == nseg ? nullptr : &pencils[idx(J)];
  std::optional<Junction> best;
  double bestGap = 0.0;
  for (int which : {iL, iR}) {
    for (int c = 0; c < 2; ++c) {
      const auto cu = idx(c);
      const auto ou = idx(1 - c);
      const ChainRuling base = original(which);
      const double tb = base.t[cu];
      const Chain& other = chains_[ou];
      // The line of each side through b = (c, tb) and where it meets the other chain.
      const auto sideHit = [&](const Pencil* p, int k) -> std::optional<double> {
        if (p == nullptr) {
          const ChainRuling orig = original(k);
          if (std::abs(orig.t[cu] - tb) > eps_) return std::nullopt;  // b not on the kept ruling
          return orig.t[ou];
        }
        return pencilHit(*p, c, tb, 0.0, other.length, original(k).t[ou]);
      };
      const std::optional<double> hl = sideHit(pl, iL);
      const std::optional<double> hr = sideHit(pr, iR);
      if (!hl || !hr || *hl > *hr + eps_) continue;
      const double gap = std::max(0.0, *hr - *hl);
      if (best && gap >= bestGap) continue;
      Junction j;
      j.left.t[cu] = tb;
      j.left.v[cu] = base.v[cu];
      j.left.t[ou] = *hl;
      j.right = j.left;
      j.right.t[ou] = std::max(*hr, *hl);
      if (pl == nullptr) j.left = original(iL);
      if (pr == nullptr) j.right = original(iR);
      j.fanChain = c;
      j.shared = gap <= 1e-6 * ctx_.spacing;
      if (j.shared) {
        // One ruling joins both cones (a kept border when there is one).
        j.right = pl == nullptr ? j.left : (pr == nullptr ? j.right : j.left);
        j.left = j.right;
      }
      j.fan = !j.shared;
      best = j;
      bestGap = gap;
    }
  }
  return best ? *best : out;
}

// paper Sec. 6.2 / thesis 2.5.2, Fig. 2.19: planes, segmentation, apices,
// junction cones and the resampled cones of one run.
std::string RunRefitter::coneRun() {
  const int n = last_ - first_ + 1;
  // 1. Tangent plane per ruling (paper Sec. 6.2: normals constant along the ruling).
  RunPlanes fit;
  if (std::string why = runPlanes(ctx_, first_, n, fit); !why.empty()) return why;
  const std::vector<RulingPlane>& planes = fit.planes;
  const std::vector<RulingGeometry>& geometry = fit.geometry;
  const FitFrame& frame = fit.frame;

  // 2. paper Sec. 6.2 iterative segmentation (disjoint segments, paper text).
  out_->segments = segmentRulings(planes, ctx_.tolerance, frame, false);
  const std::vector<ConeSegment>& segments = out_->segments;
  const int nseg = static_cast<int>(segments.size());
  // 3. The apices in the pattern.
  std::vector<Pencil> pencils;
  for (const ConeSegment& seg : segments) {
    const PatternApex pa = patternApex(seg, geometry, ApexMapping::InTangentPlane);
    out_->apices.push_back(pa);
    Pencil p;
    p.atInfinity = pa.atInfinity;
    p.point = pa.point;
    p.direction = pa.direction;
    pencils.push_back(p);
  }

  // 4. Junctions J = 0..nseg: before the first cone, between cones, after
  // the last one (paper Fig. 15 last row). L[J] ends the cone before, R[J]
  // starts the cone after; the region's borders are kept.
  std::vector<char> degraded(idx(nseg + 1), 0);
  std::vector<Junction> junctions(idx(nseg + 1));
  for (bool again = true; again;) {
    again = false;
    for (int J = 0; J <= nseg; ++J)
      junctions[idx(J)] = resolveJunction(J, degraded[idx(J)], segments, pencils);
    for (int j = 0; j < nseg; ++j) {
      const ChainRuling& s = junctions[idx(j)].right;
      const ChainRuling& e = junctions[idx(j + 1)].left;
      if (s.t[0] <= e.t[0] + eps_ && s.t[1] <= e.t[1] + eps_) continue;
      // The cone between would be inverted: keep the original rulings at
      // both of its junctions (shared with the neighbouring cones).
      bool changedHere = false;
      for (int J : {j, j + 1}) {
        if (!degraded[idx(J)]) {
          degraded[idx(J)] = 1;
          changedHere = true;
        }
      }
      if (!changedHere) return "the original rulings are not ordered along the chains";
      again = true;
    }
  }

  for (char d : degraded) out_->keptJunctions += d ? 1 : 0;

  // 5. Assemble: L0 [fan] R0 [cone 0] L1 [fan] R1 ... L_n [fan] R_n.
  std::vector<ChainRuling>& out = out_->rulings;
  for (int J = 0; J <= nseg; ++J) {
    const Junction& junction = junctions[idx(J)];
    out.push_back(junction.left);
    if (junction.fan) {
      const auto cu = idx(junction.fanChain);
      const auto ou = 1 - cu;
      fanInterior(junction.fanChain, junction.left.t[cu], junction.left.v[cu], junction.left.t[ou],
                  junction.right.t[ou], out);
      ++out_->junctionCones;
    } else if (junction.shared && J > 0 && J < nseg) {
      ++out_->sharedRulings;
    }
    out.push_back(junction.right);
    if (J < nseg) {
      const std::string why =
          coneInterior(pencils[idx(J)], junction.right, junctions[idx(J + 1)].left, out);
      if (!why.empty()) return why;
    }
  }
  return {};
}

// paper Sec. 6.2: one run of rulings between two chains of dS, then the
// density (thesis 2.5.2: >= rho_bound) and consistency checks.
std::string RunRefitter::run(RunResult& out) {
  out_ = &out;
  eps_ = 1e-9 * ctx_.spacing;
  if (std::string why = buildChains(); !why.empty()) return why;
  out.chains = chains_;
  const bool zero0 = chains_[0].length <= eps_;
  const bool zero1 = chains_[1].length <= eps_;
  if (zero0 && zero1) return "all rulings of the region coincide";
  std::string why = zero0 ? fanRun(0) : zero1 ? fanRun(1) : coneRun();
  if (!why.empty()) return why;

  // Densify gaps wider than 1 / rho_bound on either chain (degraded gaps):
  // rulings interpolated along both chains.
  std::vector<ChainRuling> dense;
  for (std::size_t k = 0; k < out.rulings.size(); ++k) {
    if (k > 0) {
      const ChainRuling& a = out.rulings[k - 1];
      const ChainRuling& b = out.rulings[k];
      const double gap = std::max(b.t[0] - a.t[0], b.t[1] - a.t[1]);
      if (gap > ctx_.spacing * (1.0 + 1e-9)) {
        const int m = static_cast<int>(std::ceil(gap / ctx_.spacing - 1e-9));
        for (int i = 1; i < m; ++i) {
          const double f = static_cast<double>(i) / m;
          ChainRuling r;
          for (std::size_t c = 0; c < 2; ++c) {
            if (std::abs(b.t[c] - a.t[c]) <= eps_ && a.v[c] >= 0) {
              r.t[c] = a.t[c];
              r.v[c] = a.v[c];
            } else {
              r.t[c] = a.t[c] + f * (b.t[c] - a.t[c]);
            }
          }
          dense.push_back(r);
        }
      }
    }
    dense.push_back(out.rulings[k]);
  }

  // Snap new endpoints within a quarter of the spacing onto kept vertices of
  // the same chain, then drop repeated rulings and new rulings closer than
  // half the spacing to a neighbour on either chain: ends millimetres apart
  // make sliver triangles in S_P that stall the elastic solve.
  std::array<std::vector<FixedPoint>, 2> kept;
  for (const ChainRuling& r : dense) {
    for (std::size_t c = 0; c < 2; ++c) {
      if (r.v[c] >= 0) kept[c].push_back({r.t[c], r.v[c]});
    }
  }
  const double snap = 0.25 * ctx_.spacing;
  for (ChainRuling& r : dense) {
    for (std::size_t c = 0; c < 2; ++c) {
      if (r.v[c] >= 0) continue;
      const FixedPoint* nearest = nullptr;
      for (const FixedPoint& f : kept[c]) {
        if (std::abs(f.t - r.t[c]) <= snap &&
            (!nearest || std::abs(f.t - r.t[c]) < std::abs(nearest->t - r.t[c]))) {
          nearest = &f;
        }
      }
      if (nearest != nullptr) {
        r.t[c] = nearest->t;
        r.v[c] = nearest->v;
      }
    }
  }
  out.rulings.clear();
  for (const ChainRuling& r : dense) {
    if (!out.rulings.empty()) {
      const ChainRuling& p = out.rulings.back();
      if (std::abs(p.t[0] - r.t[0]) <= eps_ && std::abs(p.t[1] - r.t[1]) <= eps_) continue;
    }
    out.rulings.push_back(r);
  }
  {
    const double minGap = 0.5 * ctx_.spacing;
    // A ruling may go when each of its vertices is new or stays a ruling
    // end through a neighbour (the apex of a fan).
    const auto isNew = [&](std::size_t k) {
      const ChainRuling& r = out.rulings[k];
      for (std::size_t c = 0; c < 2; ++c) {
        if (r.v[c] < 0) continue;
        const bool shared = (k > 0 && out.rulings[k - 1].v[c] == r.v[c]) ||
                            (k + 1 < out.rulings.size() && out.rulings[k + 1].v[c] == r.v[c]);
        if (!shared) return false;
      }
      return true;
    };
    const auto spaced = [&](const ChainRuling& a, const ChainRuling& b) {
      for (std::size_t c = 0; c < 2; ++c) {
        const double gap = std::abs(b.t[c] - a.t[c]);
        if (gap > eps_ && gap < minGap) return false;
      }
      return true;
    };
    std::vector<ChainRuling> thinned;
    for (std::size_t k = 0; k < out.rulings.size(); ++k) {
      const ChainRuling& r = out.rulings[k];
      if (isNew(k) && k > 0 && k + 1 < out.rulings.size()) {
        std::size_t next = k + 1;  // the next ruling that will surely stay
        while (next + 1 < out.rulings.size() && isNew(next)) ++next;
        if (!spaced(thinned.back(), r) || !spaced(r, out.rulings[next])) continue;
      }
      thinned.push_back(r);
    }
    out.rulings = std::move(thinned);
  }
  // Order along both chains.
  for (std::size_t k = 1; k < out.rulings.size(); ++k) {
    for (std::size_t c = 0; c < 2; ++c) {
      if (out.rulings[k].t[c] < out.rulings[k - 1].t[c] - eps_)
        return "the refitted rulings would cross";
    }
  }
  // Every fixed vertex is still a ruling endpoint.
  for (std::size_t c = 0; c < 2; ++c) {
    for (const FixedPoint& f : fixed_[c]) {
      const bool found = std::any_of(out.rulings.begin(), out.rulings.end(),
                                     [&](const ChainRuling& r) { return r.v[c] == f.v; });
      if (!found) return "a fixed boundary vertex would no longer be a ruling endpoint";
    }
  }
  return {};
}

}  // namespace crumple::paper::cones
