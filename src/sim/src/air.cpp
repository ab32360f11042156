// Air on the sheet (sim/air.hpp; docs/AIR.md): the per-triangle
// quasi-steady forces of Andersen, Pesavento & Wang 2005 (J. Fluid Mech.
// 541, 65-90, eqs. (5.1)-(5.5)), their implicit and explicit parts.
#include "crumple/sim/air.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "air_shelter.hpp"
#include "crumple/sim/colliders.hpp"
#include "crumple/sim/self_contact.hpp"

namespace crumple::sim {

namespace {

// Below this relative speed (m/s) the angle of attack is undefined and the
// lift terms vanish.
constexpr double kStill = 1e-9;
// Sheltering runs when the sheet's normals spread more than this from their
// mean (rad, 60 degrees: ContactOptions::foldSpread's default).
constexpr double kShelterSpread = 1.0471975511965976;

// The connected pieces of the sheet: which one each triangle is in, and
// each one's chord, twice its pattern area over its perimeter (a strip's
// width, a disc's radius, half a square's side).
struct Pieces {
  std::vector<int> of;        // per triangle
  std::vector<double> chord;  // per piece
  // The pieces' mass as the sheet lumps it: every vertex's share of its
  // triangles' pattern areas (a third of each), the piece it is in (-1 in
  // none), and a vertex of each piece that the sums are taken about.
  std::vector<double> vertexArea;
  std::vector<int> vertexPiece;
  std::vector<int> reference;
};

Pieces findPieces(const std::vector<std::array<int, 3>>& triangles,
                  const std::vector<Vec2>& pattern, std::size_t vertexCount) {
  std::vector<std::size_t> parent(vertexCount);
  std::iota(parent.begin(), parent.end(), std::size_t{0});
  const auto find = [&parent](std::size_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (const auto& t : triangles)
    for (int k = 1; k < 3; ++k) {
      const std::size_t a = find(static_cast<std::size_t>(t[0]));
      const std::size_t b = find(static_cast<std::size_t>(t[static_cast<std::size_t>(k)]));
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  std::vector<double> area(vertexCount, 0.0), perimeter(vertexCount, 0.0);
  // Boundary edges: used by one triangle (counted with a sorted edge list).
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * triangles.size());
  for (const auto& t : triangles) {
    const Vec2 e1 =
        pattern[static_cast<std::size_t>(t[1])] - pattern[static_cast<std::size_t>(t[0])];
    const Vec2 e2 =
        pattern[static_cast<std::size_t>(t[2])] - pattern[static_cast<std::size_t>(t[0])];
    area[find(static_cast<std::size_t>(t[0]))] += 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    for (int k = 0; k < 3; ++k) {
      const int a = t[static_cast<std::size_t>(k)], b = t[static_cast<std::size_t>((k + 1) % 3)];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) {
      const auto a = static_cast<std::size_t>(edges[i].first);
      const auto b = static_cast<std::size_t>(edges[i].second);
      perimeter[find(a)] += (pattern[a] - pattern[b]).norm();
    }
    i = j;
  }
  Pieces pieces;
  std::vector<int> index(vertexCount, -1);
  for (const auto& t : triangles) {
    const std::size_t root = find(static_cast<std::size_t>(t[0]));
    if (index[root] < 0) {
      index[root] = static_cast<int>(pieces.chord.size());
      pieces.chord.push_back(perimeter[root] > 0.0 ? 2.0 * area[root] / perimeter[root]
                                                   : std::sqrt(area[root]));
    }
    pieces.of.push_back(index[root]);
  }
  pieces.vertexArea.assign(vertexCount, 0.0);
  pieces.vertexPiece.assign(vertexCount, -1);
  pieces.reference.assign(pieces.chord.size(), -1);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    const Vec2 e1 =
        pattern[static_cast<std::size_t>(tri[1])] - pattern[static_cast<std::size_t>(tri[0])];
    const Vec2 e2 =
        pattern[static_cast<std::size_t>(tri[2])] - pattern[static_cast<std::size_t>(tri[0])];
    const double third = std::abs(e1.x() * e2.y() - e1.y() * e2.x()) / 6.0;
    const int k = pieces.of[t];
    for (const int i : tri) {
      pieces.vertexArea[static_cast<std::size_t>(i)] += third;
      pieces.vertexPiece[static_cast<std::size_t>(i)] = k;
    }
    if (pieces.reference[static_cast<std::size_t>(k)] < 0)
      pieces.reference[static_cast<std::size_t>(k)] = tri[0];
  }
  return pieces;
}

// Every piece's motion as a rigid body at (x, v), its mass lumped on its
// vertices as the sheet's is: the centre's velocity and the spin that
// carries its angular momentum (I omega = L about the centre). The sums are
// taken about a vertex of the piece and moved to its centre (the parallel
// axis theorem), in one pass over the vertices.
void pieceMotion(const Pieces& pieces, const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                 std::vector<Vec3>& velocity, std::vector<Vec3>& spin) {
  const std::size_t np = pieces.chord.size();
  struct Sums {
    double mass = 0.0;
    Vec3 moment = Vec3::Zero(), momentum = Vec3::Zero(), angular = Vec3::Zero();
    Mat3 second = Mat3::Zero();  // sum of m r r^T
  };
  std::vector<Sums> sums(np);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const int k = pieces.vertexPiece[i];
    if (k < 0) continue;
    Sums& s = sums[static_cast<std::size_t>(k)];
    const double m = pieces.vertexArea[i];
    const Vec3 r =
        x[i] - x[static_cast<std::size_t>(pieces.reference[static_cast<std::size_t>(k)])];
    s.mass += m;
    s.moment += m * r;
    s.momentum += m * v[i];
    s.angular += m * r.cross(v[i]);
    s.second.noalias() += m * r * r.transpose();
  }
  velocity.assign(np, Vec3::Zero());
  spin.assign(np, Vec3::Zero());
  for (std::size_t k = 0; k < np; ++k) {
    const Sums& s = sums[k];
    if (!(s.mass > 0.0)) continue;
    const Vec3 centre = s.moment / s.mass;
    velocity[k] = s.momentum / s.mass;
    const Mat3 second = s.second - s.mass * centre * centre.transpose();
    const Mat3 inertia = second.trace() * Mat3::Identity() - second;
    const Vec3 momentum = s.angular - s.mass * centre.cross(velocity[k]);
    // A piece with no extent about an axis has no spin about it.
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(inertia);
    const double floor = 1e-9 * eig.eigenvalues().maxCoeff();
    Vec3 omega = Vec3::Zero();
    for (int i = 0; i < 3; ++i)
      if (eig.eigenvalues()(i) > floor)
        omega += eig.eigenvectors().col(i) *
                 (eig.eigenvectors().col(i).dot(momentum) / eig.eigenvalues()(i));
    spin[k] = omega;
  }
}

// 1/2 rho A C_D(alpha) times the exposure (kg/m) of a triangle moving at
// `relative` to the air (paper eq. (5.5)'s C_D(alpha)), given the cross
// product big = (p1 - p0) x (p2 - p0) of its corners' edges and twiceArea =
// |big|.
double dragOf(const AirParams& params, const Vec3& big, double twiceArea, const Vec3& relative,
              double exposure) {
  if (!(twiceArea > 0.0)) return 0.0;
  const double speed = relative.norm();
  const double sin2 = speed > kStill ? std::pow(relative.dot(big) / (twiceArea * speed), 2.0) : 1.0;
  const double cd = params.dragTangential + (params.dragNormal - params.dragTangential) * sin2;
  return 0.25 * params.density * twiceArea * cd * exposure;
}

}  // namespace

std::string airParamsProblem(const AirParams& p) {
  const auto finiteNonNegative = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (!(std::isfinite(p.density) && p.density > 0.0)) return "density must be positive";
  if (!finiteNonNegative(p.dragNormal) || !finiteNonNegative(p.dragTangential) ||
      !finiteNonNegative(p.translationalLift) || !finiteNonNegative(p.rotationalLift) ||
      !finiteNonNegative(p.addedMass))
    return "the coefficients must be finite and non-negative";
  for (const WindKey& k : p.wind)
    if (!std::isfinite(k.time) || !k.velocity.allFinite()) return "a wind key is not finite";
  const GustParams& g = p.gusts;
  if (!finiteNonNegative(g.speed) || !(g.lengthScale > 0.0) || !std::isfinite(g.lengthScale) ||
      !(g.timeScale > 0.0) || !std::isfinite(g.timeScale) || g.modes < 0)
    return "gusts need a finite speed >= 0, positive length and time scales and modes >= 0";
  return {};
}

namespace {

// The implicit energy's Hessian with respect to the centroid, at relative
// velocity u (|u| = speed).
Mat3 centroidHessianAt(const AirTriangleFrame& f, double h, const Vec3& u, double speed) {
  Mat3 hc = (f.addedMass / (h * h)) * f.normal * f.normal.transpose();
  if (speed > 0.0) hc += (f.drag / h) * (speed * Mat3::Identity() + u * u.transpose() / speed);
  return hc;
}

}  // namespace

double airTriangleEnergy(const AirTriangleFrame& f, double h, const Vec3& x0, const Vec3& x1,
                         const Vec3& x2, Vec9* gradient, Mat9* hessian, Mat3* centroidHessian) {
  const Vec3 c = (x0 + x1 + x2) / 3.0;
  const Vec3 u = (c - f.centroidStart) / h - f.wind;
  const double speed = u.norm();
  const double d = f.normal.dot(c - f.inertiaTarget);
  const double h2 = h * h;
  // paper eq. (5.5)'s drag as a convex potential in u; added mass as inertia.
  const double energy = h * f.drag / 3.0 * speed * speed * speed + 0.5 * f.addedMass * d * d / h2;
  if (gradient) {
    const Vec3 gc = f.drag * speed * u + (f.addedMass * d / h2) * f.normal;
    for (int a = 0; a < 3; ++a) gradient->segment<3>(3 * a) = gc / 3.0;
  }
  if (hessian || centroidHessian) {
    const Mat3 hc = centroidHessianAt(f, h, u, speed);
    if (centroidHessian) *centroidHessian = hc;
    if (hessian)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) hessian->block<3, 3>(3 * a, 3 * b) = hc / 9.0;
  }
  return energy;
}

std::array<Vec3, 3> airExplicitForces(const AirParams& p, const AirExplicitInput& in,
                                      std::array<Vec3, 3>* circulation) {
  std::array<Vec3, 3> out{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  if (circulation) *circulation = out;
  const Vec3 e1 = in.x[1] - in.x[0], e2 = in.x[2] - in.x[0];
  const Vec3 big = e1.cross(e2);
  const double twiceArea = big.norm();
  if (!(twiceArea > 0.0)) return out;
  const Vec3 n = big / twiceArea;
  const double area = 0.5 * twiceArea;
  const double rho = p.density * in.exposure;  // the flow's forces
  Vec3 total = Vec3::Zero();
  // Translational circulation: lift -rho C_T (u.n)(|u|^2 n - (u.n) u)/|u|
  // per unit area, perpendicular to u, u the piece's velocity relative to
  // the wind here (eq. (5.4)'s C_T term).
  const Vec3 uc = in.pieceVelocity - in.wind;
  const double ucSpeed = uc.norm();
  if (ucSpeed > kStill) {
    const double ucn = uc.dot(n);
    total -=
        (rho * p.translationalLift * area * ucn / ucSpeed) * (ucSpeed * ucSpeed * n - ucn * uc);
  }
  // Rotational circulation: 1/2 rho C_R chord (omega x u) per unit area,
  // omega the part of the piece's spin that turns this face (eq. (5.4)'s C_R
  // term).
  const Vec3 turning = in.pieceSpin - in.pieceSpin.dot(n) * n;
  total += (0.5 * rho * p.rotationalLift * in.chord * area) * turning.cross(uc);
  if (circulation) circulation->fill(total / 3.0);
  // Added mass m: the air's momentum m (u.n) n changes with the normal, and
  // a changing wind carries m along (d/dt of dT/dv, T = 1/2 m (u.n)^2).
  const double m = p.density * in.openness * p.addedMass * in.chord * area;
  if (m == 0.0) {  // no added mass (openness 0: the circulation alone)
    for (Vec3& f : out) f = total / 3.0;
    return out;
  }
  const Vec3 u = (in.v[0] + in.v[1] + in.v[2]) / 3.0 - in.wind;
  const double un = u.dot(n);
  const Vec3 ut = u - un * n;
  // The normal's rate: the tangential part of d(e1 x e2)/dt over |e1 x e2|.
  const Vec3 bigRate = (in.v[1] - in.v[0]).cross(e2) + e1.cross(in.v[2] - in.v[0]);
  const Vec3 nRate = (bigRate - bigRate.dot(n) * n) / twiceArea;
  total -= m * (u.dot(nRate) * n + un * nRate);
  total += m * in.windRate.dot(n) * n;
  for (Vec3& f : out) f = total / 3.0;
  // dT/dx through the normal: the Munk moment, m (u.n) (dn/dx_a)^T u.
  const Vec3 f1 = (m * un / twiceArea) * e2.cross(ut);
  const Vec3 f2 = (m * un / twiceArea) * ut.cross(e1);
  out[0] -= f1 + f2;
  out[1] += f1;
  out[2] += f2;
  return out;
}

struct AirModel::Impl {
  AirParams params;
  WindField wind;
  std::vector<std::array<int, 3>> triangles;
  Pieces pieces;
  std::size_t vertexCount = 0;
  double h = 0.0;
  std::vector<AirTriangleFrame> frames;
  std::vector<Vec3> forces, startForces, startLift;
  std::vector<Vec3> windRate;  // per triangle, over the step
  std::vector<double> exposure, openness;
  ShelterCaster shelter;

  Impl(const AirParams& p, const std::vector<std::array<int, 3>>& tris,
       const std::vector<Vec2>& pattern, std::size_t nv)
      : params(p),
        wind(p),
        triangles(tris),
        pieces(findPieces(tris, pattern, nv)),
        vertexCount(nv) {}
  double chordOf(std::size_t t) const {
    return pieces.chord[static_cast<std::size_t>(pieces.of[t])];
  }
  // The explicit forces at (x, v) with this step's wind, exposure and
  // openness into `all`, and the circulation's lift alone (openness 0 drops
  // the added mass's forces) into `lift`, each when given (per vertex,
  // summed over its triangles in triangle order).
  void explicitAt(const std::vector<Vec3>& x, const std::vector<Vec3>& v, std::vector<Vec3>* all,
                  std::vector<Vec3>* lift) const;
};

void AirModel::Impl::explicitAt(const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                                std::vector<Vec3>* all, std::vector<Vec3>* lift) const {
  for (std::vector<Vec3>* out : {all, lift})
    if (out) out->assign(vertexCount, Vec3::Zero());
  std::vector<Vec3> pieceVelocity, pieceSpin;
  pieceMotion(pieces, x, v, pieceVelocity, pieceSpin);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    AirExplicitInput in;
    for (std::size_t a = 0; a < 3; ++a) {
      in.x[a] = x[static_cast<std::size_t>(tri[a])];
      in.v[a] = v[static_cast<std::size_t>(tri[a])];
    }
    const auto piece = static_cast<std::size_t>(pieces.of[t]);
    in.wind = frames[t].wind;
    in.windRate = windRate[t];
    in.chord = chordOf(t);
    in.pieceVelocity = pieceVelocity[piece];
    in.pieceSpin = pieceSpin[piece];
    in.exposure = exposure[t];
    // One evaluation gives both: the lift is its circulation's part.
    in.openness = all ? openness[t] : 0.0;
    std::array<Vec3, 3> circulation;
    const auto fs = airExplicitForces(params, in, lift ? &circulation : nullptr);
    for (std::size_t a = 0; a < 3; ++a) {
      const auto i = static_cast<std::size_t>(tri[a]);
      if (all) (*all)[i] += fs[a];
      if (lift) (*lift)[i] += circulation[a];
    }
  }
}

AirModel::AirModel(const AirParams& params, const std::vector<std::array<int, 3>>& triangles,
                   const std::vector<Vec2>& pattern, std::size_t vertexCount)
    : impl_(std::make_unique<Impl>(params, triangles, pattern, vertexCount)) {}
AirModel::~AirModel() = default;
AirModel::AirModel(AirModel&&) noexcept = default;
AirModel& AirModel::operator=(AirModel&&) noexcept = default;

void AirModel::beginStep(const std::vector<Vec3>& x, const std::vector<Vec3>& v, double t0,
                         double t1, const ColliderSet* colliders) {
  Impl& m = *impl_;
  const AirParams& p = m.params;
  m.h = t1 - t0;
  const std::size_t nt = m.triangles.size();
  m.frames.assign(nt, AirTriangleFrame{});
  m.exposure.assign(nt, 1.0);
  m.openness.assign(nt, 1.0);
  std::vector<Vec3> centroid(nt), relative(nt), windEnd, windStart;
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& tri = m.triangles[t];
    centroid[t] = (x[static_cast<std::size_t>(tri[0])] + x[static_cast<std::size_t>(tri[1])] +
                   x[static_cast<std::size_t>(tri[2])]) /
                  3.0;
  }
  m.wind.sampleStep(centroid, t0, t1, windStart, windEnd);
  // A wall within a chord of some centroid is within the centroids'
  // bounding sphere's radius plus the longest chord of its centre: one query
  // tells whether any triangle's can find one (the same answers, fewer
  // queries for a sheet in the air).
  bool nearWall = false;
  if (colliders != nullptr && colliders->size() > 0 && nt > 0) {
    Vec3 centre = Vec3::Zero();
    for (const Vec3& c : centroid) centre += c;
    centre /= static_cast<double>(nt);
    double radius = 0.0;
    for (const Vec3& c : centroid) radius = std::max(radius, (c - centre).norm());
    const double chord = *std::max_element(m.pieces.chord.begin(), m.pieces.chord.end());
    nearWall = colliders->nearest(centre, (radius + chord) * (1.0 + 1e-9)).has_value();
  }
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& tri = m.triangles[t];
    const Vec3& c = centroid[t];
    const Vec3 vbar = (v[static_cast<std::size_t>(tri[0])] + v[static_cast<std::size_t>(tri[1])] +
                       v[static_cast<std::size_t>(tri[2])]) /
                      3.0;
    if (nearWall) {
      // No flow through a wall: the wind's normal part fades to nothing at it.
      const double reach = m.chordOf(t);
      if (const auto wall = colliders->nearest(c, reach)) {
        const double fade = 1.0 - std::clamp(wall->distance / reach, 0.0, 1.0);
        for (Vec3* w : {&windEnd[t], &windStart[t]})
          *w -= fade * w->dot(wall->normal) * wall->normal;
      }
    }
    relative[t] = vbar - windEnd[t];
  }
  // Only a folded sheet has parts that can stand in each other's air (the
  // self-contact gate, sim/self_contact.hpp): a flat or gently curved one
  // casts no rays.
  if (p.shelter && sheetIsFolded(m.triangles, x, kShelterSpread)) {
    m.shelter.build(x, m.triangles);
    for (std::size_t t = 0; t < nt; ++t) {
      const double reach = m.chordOf(t);
      // The flow reaches the face from where the face moves to: upwind.
      if (const double speed = relative[t].norm(); speed > kStill)
        m.exposure[t] = std::clamp(
            m.shelter.hitDistance(t, centroid[t], relative[t] / speed, reach) / reach, 0.0, 1.0);
      // The air it pushes aside is on both its sides: how open each is.
      const auto& tri = m.triangles[t];
      const Vec3 big =
          (x[static_cast<std::size_t>(tri[1])] - x[static_cast<std::size_t>(tri[0])])
              .cross(x[static_cast<std::size_t>(tri[2])] - x[static_cast<std::size_t>(tri[0])]);
      if (const double twiceArea = big.norm(); twiceArea > 0.0) {
        const Vec3 n = big / twiceArea;
        double open = 0.0;
        for (const double d : m.shelter.lineHits(t, centroid[t], n, reach))
          open += std::clamp(d / reach, 0.0, 1.0);
        m.openness[t] = 0.5 * open;
      }
    }
  }
  m.windRate.resize(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& tri = m.triangles[t];
    const std::array<Vec3, 3> corners{x[static_cast<std::size_t>(tri[0])],
                                      x[static_cast<std::size_t>(tri[1])],
                                      x[static_cast<std::size_t>(tri[2])]};
    const Vec3 big = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
    const double twiceArea = big.norm();
    AirTriangleFrame& f = m.frames[t];
    f.centroidStart = centroid[t];
    f.inertiaTarget = centroid[t] + m.h * (relative[t] + windEnd[t]);
    f.wind = windEnd[t];
    m.windRate[t] = (windEnd[t] - windStart[t]) / m.h;
    if (!(twiceArea > 0.0)) continue;
    f.normal = big / twiceArea;
    f.drag = dragOf(p, big, twiceArea, relative[t], m.exposure[t]);
    f.addedMass = p.density * p.addedMass * m.chordOf(t) * 0.5 * twiceArea * m.openness[t];
  }
  m.explicitAt(x, v, &m.startForces, &m.startLift);
  m.forces = m.startForces;
}

std::vector<Vec3> AirModel::correctStep(const std::vector<Vec3>& x1, const std::vector<Vec3>& v1) {
  Impl& m = *impl_;
  std::vector<Vec3> change;
  m.explicitAt(x1, v1, nullptr, &change);
  for (std::size_t i = 0; i < m.vertexCount; ++i) {
    change[i] = 0.5 * (change[i] - m.startLift[i]);
    m.forces[i] = m.startForces[i] + change[i];
  }
  // The drag's angle of attack likewise: C_D the mean of the start's and
  // the end's (a turning face's drag would lag its turning by half a step).
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto& tri = m.triangles[t];
    std::array<Vec3, 3> p, w;
    for (std::size_t a = 0; a < 3; ++a) {
      p[a] = x1[static_cast<std::size_t>(tri[a])];
      w[a] = v1[static_cast<std::size_t>(tri[a])];
    }
    AirTriangleFrame& f = m.frames[t];
    const Vec3 u = (w[0] + w[1] + w[2]) / 3.0 - f.wind;
    const Vec3 big = (p[1] - p[0]).cross(p[2] - p[0]);
    const double drag = 0.5 * (f.drag + dragOf(m.params, big, big.norm(), u, m.exposure[t]));
    const Vec3 dragChange = (f.drag - drag) * u.norm() * u / 3.0;
    for (std::size_t a = 0; a < 3; ++a) change[static_cast<std::size_t>(tri[a])] += dragChange;
    f.drag = drag;
  }
  return change;
}

const std::vector<AirTriangleFrame>& AirModel::frames() const { return impl_->frames; }
const std::vector<Vec3>& AirModel::explicitForces() const { return impl_->forces; }
const std::vector<double>& AirModel::exposure() const { return impl_->exposure; }
const std::vector<double>& AirModel::openness() const { return impl_->openness; }
double AirModel::chord(std::size_t triangle) const { return impl_->chordOf(triangle); }

}  // namespace crumple::sim
