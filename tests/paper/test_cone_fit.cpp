// Fitting generalized cones (paper Sec. 6.2, eq. (2), Figs. 14-15; thesis
// 2.5.2, Algorithms 2-3): the Blaschke apex fit, the segmentation, the apex
// in the pattern and the remeshing of a curved region of S_G.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/paper/boundary_curve.hpp"
#include "crumple/paper/cone_fit.hpp"
#include "crumple/paper/geometric_mesh.hpp"

using crumple::Vec2;
using crumple::Vec3;
using namespace crumple::paper;

namespace {

std::string sci(double v) {
  std::ostringstream out;
  out.precision(3);
  out << std::scientific << v;
  return out.str();
}

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Distance from point q to the line through p0, p1 (pattern).
double lineDistance(const Vec2& q, const Vec2& p0, const Vec2& p1) {
  return std::abs(cross2(p1 - p0, q - p0)) / (p1 - p0).norm();
}

double angleBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
}

// A circular cone developed from the pattern: pattern apex `apex2`, 3D
// apex (apex2.x, apex2.y, 0), half-angle with sin = sinAlpha. The pattern
// ray from apex2 in direction `ref` maps to the 3D ray in direction
// (ref, 0), the tangent plane along it is z = 0 and the cone bends towards
// +z; the development is isometric, so that pattern ray stays where it is.
struct DevelopedCone {
  Vec2 apex2;
  double sinAlpha;
  Vec2 ref = Vec2::UnitY();

  Vec3 apex3() const { return {apex2.x(), apex2.y(), 0.0}; }
  // Generator direction at cone angle psi.
  Vec3 generator(double psi) const {
    const double ca = std::sqrt(1.0 - sinAlpha * sinAlpha);
    const Vec3 g0(ref.x(), ref.y(), 0.0);
    const Vec3 et(-ref.y(), ref.x(), 0.0);  // image of the pattern direction perp(ref)
    const Vec3 axis = ca * g0 + sinAlpha * Vec3::UnitZ();
    const Vec3 er = sinAlpha * g0 - ca * Vec3::UnitZ();
    return ca * axis + sinAlpha * (std::cos(psi) * er + std::sin(psi) * et);
  }
  double psi(const Vec2& p) const {
    const Vec2 d = p - apex2;
    return std::atan2(ref.x() * d.y() - ref.y() * d.x(), ref.dot(d)) / sinAlpha;
  }
  Vec3 embed(const Vec2& p) const { return apex3() + (p - apex2).norm() * generator(psi(p)); }
  // Tangent plane along the generator at psi.
  RulingPlane plane(double psi) const {
    const double h = 1e-6;
    const Vec3 n = generator(psi).cross(generator(psi + h) - generator(psi - h)).normalized();
    return {n, -n.dot(apex3()), generator(psi)};
  }
};

// ---------------------------------------------------------------------------
// The hand-built S_G of a 10 cm square sheet: flat | curved quad strip | flat.
// The strip's rulings are the vertical segments x = xs[k] from the bottom
// side (y = 0) to the top side (y = 0.1); the flat regions are two triangles
// each. Every vertex is placed in 3D by `embed`.
struct StripSheet {
  GeometricMesh g;
  int curved = 1;
  std::vector<int> bottom, top;  // strip vertices per ruling
};

StripSheet makeStrip(const std::vector<double>& xs, const std::function<Vec3(const Vec2&)>& embed) {
  StripSheet s;
  GeometricMesh& g = s.g;
  g.outline = {Vec2(0, 0), Vec2(0.1, 0), Vec2(0.1, 0.1), Vec2(0, 0.1)};
  const auto add = [&](const Vec2& p, int segment, bool corner) {
    GeometricVertex v;
    v.pattern = p;
    v.position = embed(p);
    v.onBoundary = true;
    v.corner = corner;
    v.outlineSegment = segment;
    return addVertex(g, v);
  };
  const int c0 = add(Vec2(0, 0), 0, true);
  const int c1 = add(Vec2(0.1, 0), 1, true);
  const int c2 = add(Vec2(0.1, 0.1), 2, true);
  const int c3 = add(Vec2(0, 0.1), 3, true);
  for (double x : xs) {
    s.bottom.push_back(add(Vec2(x, 0.0), 0, false));
    s.top.push_back(add(Vec2(x, 0.1), 2, false));
  }
  g.regions.resize(3);
  g.regions[0].type = crumple::mesh::RegionType::Flat;
  g.regions[1].type = crumple::mesh::RegionType::Curved;
  g.regions[2].type = crumple::mesh::RegionType::Flat;
  const auto tri = [&](int a, int b, int c, int region) {
    GeometricFace f;
    f.v = {a, b, c, -1};
    f.region = region;
    g.faces.push_back(f);
  };
  tri(c0, s.bottom.front(), s.top.front(), 0);
  tri(c0, s.top.front(), c3, 0);
  tri(s.bottom.back(), c1, c2, 2);
  tri(s.bottom.back(), c2, s.top.back(), 2);
  for (std::size_t k = 0; k < xs.size(); ++k)
    g.regions[1].rulings.push_back({s.bottom[k], s.top[k]});
  rebuildCurvedFaces(g, 1);
  return s;
}

// The 3D outline of the sheet under `embed`, sampled every 0.5 mm (what
// S_P's boundary would give with a fine sampling), corners as breaks.
BoundaryCurve outlineCurve(const GeometricMesh& g, const std::function<Vec3(const Vec2&)>& embed) {
  const double perimeter = outlinePerimeter(g);
  std::vector<BoundarySample> samples;
  const int n = 800;
  for (int k = 0; k < n; ++k) {
    const double s = perimeter * k / n;
    samples.push_back({s, embed(outlinePoint(g, s))});
  }
  return BoundaryCurve(samples, perimeter, outlineCornerParameters(g));
}

// Developability of a curved region: the largest out-of-plane offset of a
// quad's fourth vertex from the plane of the other three (0 when every quad
// is planar, i.e. its rulings are generators of a developable surface).
double maxQuadTwist(const GeometricMesh& g, int region) {
  double worst = 0.0;
  for (const GeometricFace& f : g.faces) {
    if (f.region != region || f.size() != 4) continue;
    const auto P = [&](int k) -> const Vec3& {
      return g.vertices[static_cast<std::size_t>(f.v[k])].position;
    };
    const Vec3 n = (P(1) - P(0)).cross(P(3) - P(0)).normalized();
    worst = std::max(worst, std::abs(n.dot(P(2) - P(0))));
  }
  return worst;
}

double curvedArea(const GeometricMesh& g, int region) {
  double area = 0.0;
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    if (g.faces[f].region == region) area += patternArea(g, static_cast<int>(f));
  }
  return area;
}

const Vec2& pat(const GeometricMesh& g, int v) {
  return g.vertices[static_cast<std::size_t>(v)].pattern;
}
const Vec3& pos(const GeometricMesh& g, int v) {
  return g.vertices[static_cast<std::size_t>(v)].position;
}

// Tangent planes of a (generalized) cylinder of axis d.
std::vector<RulingPlane> cylinderPlanes(const Vec3& d, const std::function<Vec2(double)>& section,
                                        int n, std::vector<Vec3>* mids = nullptr) {
  const Vec3 e1 = d.unitOrthogonal();
  const Vec3 e2 = d.cross(e1);
  const Vec3 origin(0.3, -0.2, 0.1);
  std::vector<RulingPlane> planes;
  for (int k = 0; k < n; ++k) {
    const double t = 1.2 * k / (n - 1);
    const double h = 1e-6;
    const Vec2 c = section(t);
    const Vec2 tan2 = (section(t + h) - section(t - h)) / (2 * h);
    const Vec3 p = origin + c.x() * e1 + c.y() * e2;
    const Vec3 tangent = tan2.x() * e1 + tan2.y() * e2;
    const Vec3 normal = d.cross(tangent).normalized();
    planes.push_back({normal, -normal.dot(p), d});
    if (mids) mids->push_back(p + 0.05 * d);
  }
  return planes;
}

}  // namespace

// ---------------------------------------------------------------------------
// (a) cylinder: the apex is at infinity along the axis.

TEST(ConeFit, CylinderHasApexAtInfinityAlongItsAxis) {
  const Vec3 axis = Vec3(0.2, 1.0, -0.3).normalized();
  // A circular cylinder and a generalized one (parabolic cross-section): any
  // cylinder is a cone with apex at infinity.
  const std::vector<std::function<Vec2(double)>> sections{
      [](double t) { return Vec2(0.05 * std::cos(t), 0.05 * std::sin(t)); },
      [](double t) { return Vec2(0.04 * t, 0.03 * t * t); }};
  for (const auto& section : sections) {
    std::vector<Vec3> mids;
    const std::vector<RulingPlane> planes = cylinderPlanes(axis, section, 12, &mids);
    FitFrame frame;
    for (const Vec3& m : mids) frame.centre += m / 12.0;
    frame.length = 0.1;
    const ApexFit fit = fitApex(planes, frame);
    EXPECT_TRUE(fit.atInfinity);
    EXPECT_FALSE(fit.degenerate);
    const double angle = angleBetween(fit.direction, axis);
    RecordProperty("cylinder_axis_angle_rad", sci(angle));
    EXPECT_LT(angle, 1e-6);
    EXPECT_LT(fit.rms, 1e-9);
    const auto segments = segmentRulings(planes, 0.0005, frame);
    ASSERT_EQ(segments.size(), 1u);
    EXPECT_TRUE(segments[0].fit.atInfinity);
  }
}

TEST(ConeFit, RefitOfExactCylinderStripKeepsRulingsParallelToTheAxis) {
  // The strip x in [3, 7] cm bent around an axis parallel to y (radius 5 cm),
  // the flat parts tangent to it.
  const double r = 0.05;
  const auto embed = [r](const Vec2& p) -> Vec3 {
    const double x = std::clamp(p.x(), 0.03, 0.07) - 0.03;
    const double th = x / r;
    Vec3 q(0.03 + r * std::sin(th), p.y(), r * (1.0 - std::cos(th)));
    if (p.x() < 0.03) q.x() = p.x();
    if (p.x() > 0.07) q += (p.x() - 0.07) * Vec3(std::cos(th), 0.0, std::sin(th));
    return q;
  };
  StripSheet sheet = makeStrip({0.03, 0.04, 0.05, 0.06, 0.07}, embed);
  GeometricMesh& g = sheet.g;
  ASSERT_EQ(validate(g), "");
  const Ruling first = g.regions[1].rulings.front();
  const Ruling last = g.regions[1].rulings.back();
  const BoundaryCurve curve = outlineCurve(g, embed);
  const CrumpleParams params;
  const ConeRefitResult res = refitCurvedRegion(g, 1, curve, params, 0.1);
  ASSERT_TRUE(res.changed) << res.skipped;
  EXPECT_EQ(res.segmentCount, 1);
  ASSERT_EQ(res.segments.size(), 1u);
  EXPECT_TRUE(res.segments[0].fit.atInfinity);
  EXPECT_LT(angleBetween(res.segments[0].fit.direction, Vec3::UnitY()), 1e-6);
  EXPECT_TRUE(res.apices[0].atInfinity);
  EXPECT_EQ(res.junctionCones, 0);  // both borders are shared with the cylinder
  const std::vector<Ruling>& rulings = g.regions[1].rulings;
  EXPECT_EQ(rulings.front().a, first.a);
  EXPECT_EQ(rulings.front().b, first.b);
  EXPECT_EQ(rulings.back().a, last.a);
  EXPECT_EQ(rulings.back().b, last.b);
  // 4 cm at <= 1/rho_bound = 8.33 mm: 5 gaps, 6 rulings.
  EXPECT_EQ(rulings.size(), 6u);
  double worstPattern = 0.0;
  double worst3d = 0.0;
  for (const Ruling& ru : rulings) {
    const Vec2 d2 = pat(g, ru.b) - pat(g, ru.a);
    worstPattern = std::max(worstPattern, std::atan2(std::abs(d2.x()), std::abs(d2.y())));
    worst3d = std::max(worst3d, angleBetween(pos(g, ru.b) - pos(g, ru.a), Vec3::UnitY()));
  }
  RecordProperty("pattern_angle_rad", sci(worstPattern));
  RecordProperty("angle_3d_rad", sci(worst3d));
  EXPECT_LT(worstPattern, 1e-6);
  EXPECT_LT(worst3d, 1e-6);  // new endpoints from the boundary curve
  compact(g);                // the replaced interior vertices go
  EXPECT_EQ(validate(g), "");
}

// ---------------------------------------------------------------------------
// (b) a cone with its apex outside the sheet.

TEST(ConeFit, ConeApexIsFoundAndMappedIntoThePattern) {
  const DevelopedCone cone{Vec2(0.05, -0.25), 0.3};
  // Generators through the bottom side of a 10 cm sheet, x in [2, 8] cm.
  std::vector<RulingPlane> planes;
  std::vector<RulingGeometry> geometry;
  FitFrame frame;
  const int n = 10;
  for (int k = 0; k < n; ++k) {
    const Vec2 foot(0.02 + 0.06 * k / (n - 1), 0.0);
    const Vec2 dir = (foot - cone.apex2).normalized();
    const Vec2 a2 = foot;
    const Vec2 b2 = foot + 0.1 / dir.y() * dir;  // up to y = 0.1
    const RulingPlane p = cone.plane(cone.psi(foot));
    planes.push_back(p);
    geometry.push_back({cone.embed(a2), cone.embed(b2), a2, b2, p.normal});
    frame.centre += 0.5 * (cone.embed(a2) + cone.embed(b2)) / n;
  }
  frame.length = 0.1;
  const ApexFit fit = fitApex(planes, frame);
  ASSERT_FALSE(fit.atInfinity);
  const double apexError = (fit.apex - cone.apex3()).norm();
  RecordProperty("apex_error_m", sci(apexError));
  EXPECT_LT(apexError, 1e-6);
  EXPECT_LT(fit.rms, 1e-9);
  const auto segments = segmentRulings(planes, 0.0005, frame);
  ASSERT_EQ(segments.size(), 1u);
  EXPECT_EQ(segments[0].first, 0);
  EXPECT_EQ(segments[0].last, n - 1);
  const PatternApex pa = patternApex(segments[0], geometry);
  EXPECT_FALSE(pa.atInfinity);
  const double patternError = (pa.point - cone.apex2).norm();
  RecordProperty("pattern_apex_error_m", sci(patternError));
  EXPECT_LT(patternError, 1e-6);
  // The mapping itself is exact for the true apex on any ruling.
  for (const RulingGeometry& r : geometry)
    EXPECT_LT((apexInPattern(cone.apex3(), r) - cone.apex2).norm(), 1e-12);
}

TEST(ConeFit, ApexInPatternUsesTheCoordinateAlongTheRuling) {
  // A ruling stretched in the pattern: only its direction matters, t is
  // the signed 3D distance along the ruling.
  RulingGeometry r;
  r.a3 = Vec3(1, 1, 1);
  r.b3 = Vec3(1, 1, 3);  // length 2, along z
  r.a2 = Vec2(0.5, 0.0);
  r.b2 = Vec2(0.5, 5.0);  // pattern direction +y
  EXPECT_LT((apexInPattern(Vec3(4, 1, -2), r) - Vec2(0.5, -3.0)).norm(), 1e-15);
  EXPECT_LT((apexInPattern(Vec3(1, 7, 2.5), r) - Vec2(0.5, 1.5)).norm(), 1e-15);
  // Directions: rotating by +phi about the normal rotates by +phi in the pattern.
  r.normal = Vec3(-1, 0, 0);  // (u, n x u) = (z, y)
  const double phi = 0.3;
  const Vec3 d = std::cos(phi) * Vec3::UnitZ() + std::sin(phi) * Vec3::UnitY() + 0.2 * r.normal;
  const Vec2 e = directionInPattern(d, r);
  EXPECT_LT((e - Vec2(-std::sin(phi), std::cos(phi))).norm(), 1e-12);
}

// ---------------------------------------------------------------------------
// (c) two cones of very different apices.

TEST(ConeFit, TwoConesAreSplitAtTheRightRuling) {
  // Apex A below the sheet, apex B to its left with rulings across A's,
  // both strongly bent (sin alpha = 0.9) so their tangent planes differ.
  // The end-dropping of the paper is greedy and any three planes meet in a
  // point, so other layouts may leave a short run of two or three rulings
  // at the transition; this one splits cleanly.
  const DevelopedCone coneA{Vec2(0.03, -0.2), 0.9};
  const DevelopedCone coneB{Vec2(-0.2, 0.05), 0.9, Vec2::UnitX()};
  std::vector<RulingPlane> planes;
  FitFrame frame;
  for (int k = 0; k < 10; ++k) planes.push_back(coneA.plane(-1.3 + 0.12 * k));
  for (int k = 0; k < 10; ++k) planes.push_back(coneB.plane(0.6 + 0.12 * k));
  frame.centre = Vec3(0.05, 0.05, 0.0);
  frame.length = 1.0;  // 10 L_paper, as refitCurvedRegion
  const double tol = 0.005 * 0.1;
  const auto segments = segmentRulings(planes, tol, frame);
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_EQ(segments[0].first, 0);
  EXPECT_EQ(segments[0].last, 9);
  EXPECT_EQ(segments[1].first, 10);
  EXPECT_EQ(segments[1].last, 19);
  EXPECT_LT((segments[0].fit.apex - coneA.apex3()).norm(), 1e-6);
  EXPECT_LT((segments[1].fit.apex - coneB.apex3()).norm(), 1e-6);
  EXPECT_LE(segments[0].fit.maxDistance, tol);
  EXPECT_LE(segments[1].fit.maxDistance, tol);

  // Thesis Algorithm 3 index lists: neighbouring segments share a ruling,
  // so a short bridge (any three planes meet) joins the two cones; no longer
  // segment mixes them.
  const auto shared = segmentRulings(planes, tol, frame, true);
  ASSERT_GE(shared.size(), 2u);
  EXPECT_EQ(shared.front().first, 0);
  EXPECT_EQ(shared.back().last, 19);
  for (std::size_t k = 0; k < shared.size(); ++k) {
    if (k > 0) {
      EXPECT_EQ(shared[k].first, shared[k - 1].last);
    }
    EXPECT_LE(shared[k].fit.maxDistance, tol);
    if (shared[k].last - shared[k].first >= 3) {
      EXPECT_TRUE(shared[k].last <= 9 || shared[k].first >= 10)
          << shared[k].first << "-" << shared[k].last;
    }
  }
}

TEST(ConeFit, SegmentationCoversEverythingAndRespectsTheTolerance) {
  // A twisted ribbon: the tangent planes drift along a non-developable
  // surface, so the segmentation has to cut several times.
  std::vector<RulingPlane> planes;
  for (int k = 0; k < 40; ++k) {
    const double t = 0.05 * k;
    const Vec3 n = Vec3(std::sin(t), std::cos(t) * std::cos(2 * t), std::sin(2 * t)).normalized();
    const Vec3 p(0.003 * k, 0.01 * std::sin(3 * t), 0.0);
    planes.push_back({n, -n.dot(p)});
  }
  FitFrame frame;
  frame.centre = Vec3(0.06, 0.0, 0.0);
  frame.length = 0.05;
  for (double tol : {1e-5, 1e-4, 1e-3}) {
    const auto segments = segmentRulings(planes, tol, frame);
    ASSERT_FALSE(segments.empty());
    EXPECT_EQ(segments.front().first, 0);
    EXPECT_EQ(segments.back().last, 39);
    for (std::size_t k = 0; k < segments.size(); ++k) {
      if (k > 0) {
        EXPECT_EQ(segments[k].first, segments[k - 1].last + 1);
      }
      EXPECT_LE(segments[k].fit.maxDistance, tol);
    }
  }
}

TEST(ConeFit, ErrorIsThePlaneDistanceScaledByTheFrame) {
  // Four planes through a = (3, 0, 0) cm, one of them moved by 1 mm; the
  // contributions follow e_i = (L u_i . X)^2 = d_i^2 L^2 / (L^2 + |a - c|^2).
  const Vec3 a(0.03, 0.0, 0.0);
  std::vector<RulingPlane> planes;
  for (const Vec3& n : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 1).normalized()}) {
    planes.push_back({n, -n.dot(a)});
  }
  FitFrame frame;
  frame.length = 0.1;
  const ApexFit exact = fitApex(planes, frame);
  EXPECT_LT((exact.apex - a).norm(), 1e-12);
  EXPECT_LT(exact.rms, 1e-12);
  planes[3].w -= 0.001;
  const ApexFit fit = fitApex(planes, frame);
  ASSERT_FALSE(fit.atInfinity);
  const double L = frame.length;
  const double scale = L * L / (L * L + fit.apex.squaredNorm());
  double sum = 0.0;
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const double d = planes[i].normal.dot(fit.apex) + planes[i].w;
    EXPECT_NEAR(fit.contributions[i], d * d * scale, 1e-15);
    sum += fit.contributions[i];
  }
  EXPECT_NEAR(fit.sumSquares, sum, 1e-18);
  EXPECT_NEAR(fit.rms, std::sqrt(sum / 4.0), 1e-15);
  EXPECT_GT(fit.rms, 1e-4);  // ~ 1 mm / 4 spread over four planes
}

TEST(ConeFit, DegenerateFitsPutTheApexAtInfinity) {
  // Two planes: the apex is anywhere on their intersection line; we take
  // the point at infinity of that line.
  const Vec3 n0 = Vec3(0, 0.1, 1).normalized();
  const Vec3 n1 = Vec3(0, -0.1, 1).normalized();
  const std::vector<RulingPlane> two{{n0, 0.01, Vec3::UnitX()}, {n1, 0.02, Vec3::UnitX()}};
  const ApexFit fit2 = fitApex(two);
  EXPECT_TRUE(fit2.degenerate);
  EXPECT_TRUE(fit2.atInfinity);
  EXPECT_LT(angleBetween(fit2.direction, n0.cross(n1)), 1e-12);
  EXPECT_GT(fit2.direction.x(), 0.0);  // the ruling direction's sign
  EXPECT_LT(fit2.rms, 1e-12);
  // One plane: the ruling direction projected into it.
  const std::vector<RulingPlane> one{{Vec3::UnitZ(), -0.5, Vec3(1, 0, 0.2).normalized()}};
  const ApexFit fit1 = fitApex(one);
  EXPECT_TRUE(fit1.atInfinity);
  EXPECT_LT(angleBetween(fit1.direction, Vec3::UnitX()), 1e-12);
  // A flat strip (all planes equal): also the mean ruling direction.
  const std::vector<RulingPlane> flat(
      5, RulingPlane{Vec3::UnitZ(), 0.0, Vec3(0.1, 1, 0).normalized()});
  const ApexFit fitFlat = fitApex(flat);
  EXPECT_TRUE(fitFlat.atInfinity);
  EXPECT_LT(angleBetween(fitFlat.direction, Vec3(0.1, 1, 0)), 1e-12);
}

TEST(ConeFit, RejectsBadInput) {
  EXPECT_THROW(fitApex({}), std::invalid_argument);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<RulingPlane> bad{{Vec3(nan, 0, 1), 0.0}};
  EXPECT_THROW(fitApex(bad), crumple::NumericalError);
  const std::vector<RulingPlane> zero{{Vec3::Zero(), 0.0}};
  EXPECT_THROW(fitApex(zero), crumple::NumericalError);
  const std::vector<RulingPlane> ok{{Vec3::UnitZ(), 0.0}};
  FitFrame frame;
  frame.length = 0.0;
  EXPECT_THROW(fitApex(ok, frame), std::invalid_argument);
  EXPECT_THROW(segmentRulings(ok, -1.0), std::invalid_argument);
  RulingGeometry r;  // zero length
  EXPECT_THROW(apexInPattern(Vec3::Zero(), r), crumple::NumericalError);
}

// ---------------------------------------------------------------------------
// (d) refitCurvedRegion on the hand-built sheet: the strip is a slightly
// conical surface but its rulings are parallel in the pattern.

namespace {

struct ConicalStripCase {
  DevelopedCone cone{Vec2(0.05, -0.3), 0.25};
  StripSheet sheet;
  BoundaryCurve curve{{{0.0, Vec3::Zero()}}, 1.0};
  ConicalStripCase() {
    const auto embed = [this](const Vec2& p) { return cone.embed(p); };
    sheet = makeStrip({0.03, 0.04, 0.05, 0.06, 0.07}, embed);
    curve = outlineCurve(sheet.g, embed);
  }
};

}  // namespace

TEST(ConeFit, RefitMakesParallelRulingsConvergeToTheApex) {
  ConicalStripCase c;
  GeometricMesh& g = c.sheet.g;
  ASSERT_EQ(validate(g), "");
  const double areaBefore = curvedArea(g, 1);
  const double twistBefore = maxQuadTwist(g, 1);
  const Ruling first = g.regions[1].rulings.front();
  const Ruling last = g.regions[1].rulings.back();
  const CrumpleParams params;
  const ConeRefitResult res = refitCurvedRegion(g, 1, c.curve, params, 0.1);
  ASSERT_TRUE(res.changed) << res.skipped;
  ASSERT_EQ(res.segmentCount, 1);
  const ApexFit& fit = res.segments[0].fit;
  ASSERT_FALSE(fit.atInfinity);
  RecordProperty("fit_rms_m", sci(fit.rms));
  RecordProperty("apex_3d_error_m", sci((fit.apex - c.cone.apex3()).norm()));
  EXPECT_LT((fit.apex - c.cone.apex3()).norm(), 0.01);  // chords, not generators: approximate
  const Vec2 apex = res.apices[0].point;
  RecordProperty("pattern_apex_error_m", sci((apex - c.cone.apex2).norm()));
  EXPECT_LT((apex - c.cone.apex2).norm(), 0.01);
  EXPECT_EQ(res.junctionCones, 2);  // a fan at each border

  const std::vector<Ruling>& rulings = g.regions[1].rulings;
  EXPECT_EQ(rulings.front().a, first.a);
  EXPECT_EQ(rulings.front().b, first.b);
  EXPECT_EQ(rulings.back().a, last.a);
  EXPECT_EQ(rulings.back().b, last.b);
  // Every other ruling passes through the pattern apex, or belongs to a
  // junction fan (shares an endpoint with a border ruling).
  int throughApex = 0;
  int fan = 0;
  double worst = 0.0;
  for (std::size_t k = 1; k + 1 < rulings.size(); ++k) {
    const Ruling& r = rulings[k];
    const double d = lineDistance(apex, pat(g, r.a), pat(g, r.b));
    const bool sharesBorder = r.a == first.a || r.b == first.b || r.a == last.a || r.b == last.b;
    if (d <= 1e-9) {
      ++throughApex;
      worst = std::max(worst, d);
    } else {
      EXPECT_TRUE(sharesBorder) << "ruling " << k << " misses the apex by " << d;
      ++fan;
    }
  }
  RecordProperty("rulings_through_apex", throughApex);
  RecordProperty("worst_apex_distance_m", sci(worst));
  EXPECT_GE(throughApex, 4);
  // Spacing along both sides <= 1 / rho_bound, and consecutive ends either
  // one vertex (a fan) or at least half of it apart (no sliver cells).
  for (std::size_t k = 1; k < rulings.size(); ++k) {
    for (const auto& [x, y] :
         {std::pair{rulings[k - 1].a, rulings[k].a}, std::pair{rulings[k - 1].b, rulings[k].b}}) {
      const double gap = (pat(g, x) - pat(g, y)).norm();
      EXPECT_LE(gap, 1.0 / params.rhoBound + 1e-12) << "rulings " << k - 1 << ", " << k;
      if (x != y) {
        EXPECT_GE(gap, 0.5 / params.rhoBound - 1e-12) << "rulings " << k - 1 << ", " << k;
      }
    }
  }
  // New vertices lie on the 3D boundary curve, on the outline.
  for (const Ruling& r : rulings) {
    for (int v : {r.a, r.b}) {
      const GeometricVertex& gv = g.vertices[static_cast<std::size_t>(v)];
      ASSERT_TRUE(gv.onBoundary);
      const double s = outlineParameter(g, gv.pattern, gv.outlineSegment);
      EXPECT_LT((gv.position - c.curve.evaluate(s)).norm(), 1e-7);
    }
  }
  EXPECT_NEAR(curvedArea(g, 1), areaBefore, 1e-15);
  // Vertical chords of a cone are twisted quads; rulings through the apex
  // are (nearly) generators.
  const double twistAfter = maxQuadTwist(g, 1);
  RecordProperty("twist_before_m", sci(twistBefore));
  RecordProperty("twist_after_m", sci(twistAfter));
  EXPECT_LT(twistAfter, 0.1 * twistBefore);
  compact(g);
  EXPECT_EQ(validate(g), "");
  EXPECT_NEAR(outlineArea(g), 0.01, 1e-15);
}

TEST(ConeFit, RefitKeepsFixedVerticesAsRulingEndpoints) {
  ConicalStripCase c;
  GeometricMesh& g = c.sheet.g;
  // A handle pins the top end of the middle ruling, a singular vertex the
  // bottom end of the second one.
  const int handle = c.sheet.top[2];
  const int singular = c.sheet.bottom[1];
  g.vertices[static_cast<std::size_t>(handle)].handle = true;
  g.vertices[static_cast<std::size_t>(singular)].singular = true;
  const Vec2 handlePattern = pat(g, handle);
  const Vec3 handlePosition = pos(g, handle);
  const ConeRefitResult res = refitCurvedRegion(g, 1, c.curve, CrumpleParams{}, 0.1);
  ASSERT_TRUE(res.changed) << res.skipped;
  bool handleUsed = false;
  bool singularUsed = false;
  for (const Ruling& r : g.regions[1].rulings) {
    handleUsed |= r.a == handle || r.b == handle;
    singularUsed |= r.a == singular || r.b == singular;
  }
  EXPECT_TRUE(handleUsed);
  EXPECT_TRUE(singularUsed);
  EXPECT_EQ(pat(g, handle), handlePattern);
  EXPECT_EQ(pos(g, handle), handlePosition);
  const std::vector<int> map = compact(g);
  EXPECT_EQ(validate(g), "");
  EXPECT_TRUE(g.vertices[static_cast<std::size_t>(map[static_cast<std::size_t>(handle)])].handle);
}

TEST(ConeFit, RefitKeepsRulingsWithAnEndpointOffTheOutline) {
  // As if the first ruling started at an interior (singular) point: it and
  // its face are kept, the run of the other rulings is refitted.
  ConicalStripCase c;
  GeometricMesh& g = c.sheet.g;
  g.vertices[static_cast<std::size_t>(c.sheet.bottom[0])].onBoundary = false;
  const std::vector<Ruling> before = g.regions[1].rulings;
  const ConeRefitResult res = refitCurvedRegion(g, 1, c.curve, CrumpleParams{}, 0.1);
  ASSERT_TRUE(res.changed) << res.skipped;
  const std::vector<Ruling>& after = g.regions[1].rulings;
  ASSERT_GE(after.size(), 3u);
  EXPECT_EQ(after[0].a, before[0].a);
  EXPECT_EQ(after[0].b, before[0].b);
  EXPECT_EQ(after[1].a, before[1].a);  // the border of the refitted run
  EXPECT_EQ(after[1].b, before[1].b);
  EXPECT_EQ(after.back().a, before.back().a);
  EXPECT_EQ(after.back().b, before.back().b);
  double area = 0.0;
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    const double a = patternArea(g, static_cast<int>(f));
    EXPECT_GT(a, 0.0);
    area += a;
  }
  EXPECT_NEAR(area, 0.01, 1e-15);
}

TEST(ConeFit, RefitIsStableWhenRepeated) {
  ConicalStripCase c;
  GeometricMesh& g = c.sheet.g;
  const CrumpleParams params;
  ASSERT_TRUE(refitCurvedRegion(g, 1, c.curve, params, 0.1).changed);
  compact(g);
  const std::size_t rulingsOnce = g.regions[1].rulings.size();
  const ConeRefitResult again = refitCurvedRegion(g, 1, c.curve, params, 0.1);
  ASSERT_TRUE(again.changed) << again.skipped;
  compact(g);
  EXPECT_EQ(validate(g), "");
  EXPECT_EQ(again.segmentCount, 1);
  EXPECT_NEAR(static_cast<double>(g.regions[1].rulings.size()), static_cast<double>(rulingsOnce),
              2.0);
}

// Two cones joined on the generator x = 5 cm of a strip: left of it a cone
// with pattern apex (5, -15) cm below the sheet, right of it one with apex
// (5, 30) cm above it.
struct TwoCones {
  DevelopedCone left{Vec2(0.05, -0.15), 0.3};
  DevelopedCone right{Vec2(0.05, 0.3), 0.3, -Vec2::UnitY()};
  Vec3 embed(const Vec2& p) const { return p.x() <= 0.05 ? left.embed(p) : right.embed(p); }
  // The strip's ruling positions, x from 2 to 8 cm every 5 mm.
  std::vector<double> rulingXs() const {
    std::vector<double> xs;
    for (int k = 0; k <= 12; ++k) xs.push_back(0.02 + 0.005 * k);
    return xs;
  }
};

TEST(ConeFit, RefitOfTwoConesJoinedOnAGeneratorMeshesEachCone) {
  // Left of x = 5 cm the strip is a cone with pattern apex (5, -15) cm below
  // the sheet, right of it one with apex (5, 30) cm above it; both contain
  // the vertical generator x = 5 cm with the same tangent plane (C1,
  // developable).
  const TwoCones cones;
  const DevelopedCone& left = cones.left;
  const DevelopedCone& right = cones.right;
  const auto embed = [&](const Vec2& p) { return cones.embed(p); };
  StripSheet sheet = makeStrip(cones.rulingXs(), embed);
  GeometricMesh& g = sheet.g;
  ASSERT_EQ(validate(g), "");
  const BoundaryCurve curve = outlineCurve(g, embed);
  // eps_blaschke = 0.1 mm: near the C1 join the two cones differ by less
  // than the default 0.5 mm, which then lets a ruling or two of one cone into
  // the other (see the next test).
  CrumpleParams params;
  params.epsBlaschke = 0.001;
  const double twistBefore = maxQuadTwist(g, 1);
  ConeRefitResult res = refitCurvedRegion(g, 1, curve, params, 0.1);
  ASSERT_TRUE(res.changed) << res.skipped;
  compact(g);
  ASSERT_EQ(validate(g), "");
  const double twistOnce = maxQuadTwist(g, 1);
  RecordProperty("twist_before_m", sci(twistBefore));
  RecordProperty("twist_after_one_refit_m", sci(twistOnce));
  // Two cones, split where they join: rulings 0-6 (x <= 5 cm) and 7-12.
  ASSERT_EQ(res.segmentCount, 2);
  EXPECT_EQ(res.segments[0].last, 6);
  EXPECT_EQ(res.segments[1].first, 7);
  ASSERT_FALSE(res.apices[0].atInfinity);
  ASSERT_FALSE(res.apices[1].atInfinity);
  RecordProperty("left_pattern_apex_error_m", sci((res.apices[0].point - left.apex2).norm()));
  RecordProperty("right_pattern_apex_error_m", sci((res.apices[1].point - right.apex2).norm()));
  EXPECT_LT((res.apices[0].point - left.apex2).norm(), 0.01);
  EXPECT_LT((res.apices[1].point - right.apex2).norm(), 0.01);
  EXPECT_LT(twistOnce, 0.05 * twistBefore);  // the quads are (nearly) planar now
  // Every remeshed ruling goes through one of the pattern apices or is part
  // of a junction fan (shares a vertex with a neighbour ruling).
  const auto checkRulings = [&](const ConeRefitResult& r) {
    const std::vector<Ruling>& rulings = g.regions[1].rulings;
    for (std::size_t k = 1; k + 1 < rulings.size(); ++k) {
      const Ruling& ru = rulings[k];
      double best = std::numeric_limits<double>::infinity();
      for (const PatternApex& pa : r.apices) {
        const Vec2 d = (pat(g, ru.b) - pat(g, ru.a)).normalized();
        best = std::min(best, pa.atInfinity ? std::abs(cross2(d, pa.direction))
                                            : lineDistance(pa.point, pat(g, ru.a), pat(g, ru.b)));
      }
      const bool fan = ru.a == rulings[k - 1].a || ru.b == rulings[k - 1].b ||
                       ru.a == rulings[k + 1].a || ru.b == rulings[k + 1].b;
      EXPECT_TRUE(best <= 1e-9 || fan) << "ruling " << k << " misses every apex by " << best;
    }
  };
  checkRulings(res);

  // Refitting again (as every step does) converges: the rulings become the
  // generators and the apices the true ones. The junction fans at the
  // borders show up as two-ruling segments of their own.
  double twist = twistOnce;
  for (int iteration = 0; iteration < 4; ++iteration) {
    res = refitCurvedRegion(g, 1, curve, params, 0.1);
    ASSERT_TRUE(res.changed) << res.skipped;
    checkRulings(res);
    compact(g);
    ASSERT_EQ(validate(g), "");
    const double now = maxQuadTwist(g, 1);
    EXPECT_LT(now, twist);
    twist = now;
  }
  RecordProperty("twist_after_five_refits_m", sci(twist));
  EXPECT_LT(twist, 1e-6);
  std::vector<Vec2> apices;
  for (std::size_t k = 0; k < res.segments.size(); ++k) {
    if (res.segments[k].last - res.segments[k].first >= 2) apices.push_back(res.apices[k].point);
  }
  ASSERT_EQ(apices.size(), 2u);
  EXPECT_LT((apices[0] - left.apex2).norm(), 1e-3);
  EXPECT_LT((apices[1] - right.apex2).norm(), 1e-3);
}

TEST(ConeFit, RefitOfTwoConesWithTheDefaultToleranceStaysValid) {
  const TwoCones cones;
  const auto embed = [&](const Vec2& p) { return cones.embed(p); };
  StripSheet sheet = makeStrip(cones.rulingXs(), embed);
  GeometricMesh& g = sheet.g;
  const BoundaryCurve curve = outlineCurve(g, embed);
  const double twistBefore = maxQuadTwist(g, 1);
  double worst = 0.0;
  int kept = 0;
  for (int iteration = 0; iteration < 5; ++iteration) {
    const ConeRefitResult res = refitCurvedRegion(g, 1, curve, CrumpleParams{}, 0.1);
    ASSERT_TRUE(res.changed) << res.skipped;
    EXPECT_GE(res.segmentCount, 2);
    kept += res.keptJunctions;
    compact(g);
    ASSERT_EQ(validate(g), "");
    worst = std::max(worst, maxQuadTwist(g, 1));
  }
  RecordProperty("twist_before_m", sci(twistBefore));
  RecordProperty("worst_twist_over_five_refits_m", sci(worst));
  RecordProperty("junctions_kept_as_original", kept);
  EXPECT_LT(worst, twistBefore);
}

TEST(ConeFit, RefitSkipsRegionsWithAnApexAndRejectsFlatOnes) {
  ConicalStripCase c;
  GeometricMesh& g = c.sheet.g;
  EXPECT_THROW(refitCurvedRegion(g, 0, c.curve, CrumpleParams{}, 0.1), std::invalid_argument);
  EXPECT_THROW(refitCurvedRegion(g, 7, c.curve, CrumpleParams{}, 0.1), std::out_of_range);
  EXPECT_THROW(refitCurvedRegion(g, 1, c.curve, CrumpleParams{}, 0.0), std::invalid_argument);
  g.regions[1].apex = c.sheet.bottom[0];
  const std::size_t faces = g.faces.size();
  const ConeRefitResult res = refitCurvedRegion(g, 1, c.curve, CrumpleParams{}, 0.1);
  EXPECT_FALSE(res.changed);
  EXPECT_FALSE(res.skipped.empty());
  EXPECT_EQ(g.faces.size(), faces);
}

// A sharp cone (apex 1.5 cm below the sheet): spaced at 1/rho_bound on the
// far border, its rulings crowd the near one. Consecutive ruling ends are
// one vertex or at least half the spacing apart (the refit thins them):
// ends a millimetre apart made sliver cells that stalled the elastic solve.
TEST(ConeFit, RefitOfASharpConeKeepsRulingEndsApart) {
  const DevelopedCone cone{Vec2(0.05, -0.015), 0.25};
  const auto embed = [&](const Vec2& p) { return cone.embed(p); };
  StripSheet sheet = makeStrip({0.02, 0.035, 0.05, 0.065, 0.08}, embed);
  GeometricMesh& g = sheet.g;
  const BoundaryCurve curve = outlineCurve(g, embed);
  ASSERT_EQ(validate(g), "");
  const CrumpleParams params;
  const ConeRefitResult res = refitCurvedRegion(g, 1, curve, params, 0.1);
  ASSERT_TRUE(res.changed) << res.skipped;
  const std::vector<Ruling>& rulings = g.regions[1].rulings;
  ASSERT_GE(rulings.size(), 5u);
  for (std::size_t k = 1; k < rulings.size(); ++k) {
    for (const auto& [x, y] :
         {std::pair{rulings[k - 1].a, rulings[k].a}, std::pair{rulings[k - 1].b, rulings[k].b}}) {
      if (x == y) continue;
      EXPECT_GE((pat(g, x) - pat(g, y)).norm(), 0.5 / params.rhoBound - 1e-12)
          << "rulings " << k - 1 << ", " << k;
    }
  }
  RecordProperty("rulings", static_cast<int>(rulings.size()));
  compact(g);  // may move the regions: `rulings` is not used after this
  EXPECT_EQ(validate(g), "");
}

// A ruling is a straight segment of the surface: on an exact cylinder strip
// no ruling is shorter in space than in the pattern; bending the sheet across
// one ruling (its top end pulled 1 mm towards its bottom end) compresses it
// by 1 %, which worstRulingCompression reports; stretching reports nothing.
TEST(ConeFit, WorstRulingCompressionSeesARulingCutAcrossTheBending) {
  const double r = 0.05;
  const auto embed = [r](const Vec2& p) -> Vec3 {
    const double th = p.x() / r;
    return {r * std::sin(th), p.y(), r * (1.0 - std::cos(th))};
  };
  StripSheet sheet = makeStrip({0.03, 0.04, 0.05, 0.06, 0.07}, embed);
  GeometricMesh& g = sheet.g;
  ASSERT_EQ(validate(g), "");
  EXPECT_LT(worstRulingCompression(g, sheet.curved), 1e-12);
  g.vertices[static_cast<std::size_t>(sheet.top[2])].position -= Vec3(0.0, 0.001, 0.0);
  EXPECT_NEAR(worstRulingCompression(g, sheet.curved), 0.01, 1e-12);
  g.vertices[static_cast<std::size_t>(sheet.top[2])].position += Vec3(0.0, 0.002, 0.0);
  EXPECT_LT(worstRulingCompression(g, sheet.curved), 1e-12);  // stretched, not compressed
  EXPECT_THROW(worstRulingCompression(g, 7), std::out_of_range);
}
