// Collider proximity queries: analytic planes, boxes and
// spheres, FCL-backed meshes, animated poses.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <limits>

#include "crumple/core/rng.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/sim/colliders.hpp"
#include "crumple/sim/elastic_sheet.hpp"

namespace crumple::sim {
namespace {

Pose at(const Vec3& p, const Quat& q = Quat::Identity()) { return {p, q}; }

ColliderShape box(const Vec3& h) {
  ColliderShape s;
  s.kind = ColliderShape::Kind::Box;
  s.halfExtents = h;
  return s;
}

ColliderShape sphere(double r) {
  ColliderShape s;
  s.kind = ColliderShape::Kind::Sphere;
  s.radius = r;
  return s;
}

// A closed cube [-h, h]^3 as 12 outward-facing triangles.
ColliderShape cubeMesh(double h) {
  ColliderShape s;
  s.kind = ColliderShape::Kind::Mesh;
  for (int i = 0; i < 8; ++i)
    s.vertices.emplace_back((i & 1) ? h : -h, (i & 2) ? h : -h, (i & 4) ? h : -h);
  s.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                 {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return s;
}

TEST(Colliders, TiltedPlaneGivesSignedDistanceAndNormal) {
  ColliderSet set;
  const Quat tilt(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
  set.add("table", ColliderShape{}, at(Vec3(0, 1, 0), tilt));
  const Vec3 n = tilt * Vec3::UnitY();
  const Vec3 onPlane = Vec3(0, 1, 0) + tilt * Vec3(0.2, 0, 0.1);
  const Vec3 above = onPlane + 0.004 * n;
  const auto c = set.nearest(above, 0.01);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->distance, 0.004, 1e-12);
  EXPECT_TRUE(c->normal.isApprox(n, 1e-12));
  EXPECT_TRUE((c->point + 0.004 * n).isApprox(above, 1e-12));
  EXPECT_FALSE(set.nearest(onPlane + 0.02 * n, 0.01).has_value()) << "beyond the margin";
  const auto below = set.nearest(onPlane - 0.5 * n, 0.01);
  ASSERT_TRUE(below.has_value()) << "a half-space is solid all the way down";
  EXPECT_NEAR(below->distance, -0.5, 1e-12);
}

TEST(Colliders, BoxAndSphereInsideAndOutside) {
  ColliderSet set;
  set.add("box", box(Vec3(0.1, 0.2, 0.3)), at(Vec3(1, 0, 0)));
  set.add("ball", sphere(0.25), at(Vec3(-1, 0, 0)));
  // Outside the box near an edge: distance to the clamped point.
  auto c = set.nearest(Vec3(1.1 + 0.003, 0.2 + 0.004, 0.0), 0.01);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->collider, 0);
  EXPECT_NEAR(c->distance, 0.005, 1e-12);
  EXPECT_TRUE(c->normal.isApprox(Vec3(0.6, 0.8, 0.0), 1e-12));
  // Inside the box: the nearest face, negative distance.
  c = set.nearest(Vec3(1.09, 0.0, 0.0), 0.01);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->distance, -0.01, 1e-12);
  EXPECT_TRUE(c->normal.isApprox(Vec3::UnitX(), 1e-12));
  EXPECT_TRUE(c->point.isApprox(Vec3(1.1, 0.0, 0.0), 1e-12));
  // The sphere, and its pose moved by an animation.
  c = set.nearest(Vec3(-1, 0.255, 0), 0.01);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->collider, 1);
  EXPECT_NEAR(c->distance, 0.005, 1e-12);
  set.setPose(1, at(Vec3(-1, 0.5, 0)));
  EXPECT_NEAR(set.nearest(Vec3(-1, 0.755, 0), 0.01)->distance, 0.005, 1e-12);
  EXPECT_FALSE(set.nearest(Vec3(-1, -0.255, 0), 0.01).has_value()) << "the ball moved away";
  EXPECT_EQ(set.name(1), "ball");
}

TEST(Colliders, MeshMatchesTheAnalyticBoxNearItsSurface) {
  // The cube mesh against the analytic box of the same size, rotated and
  // moved: near the surface (within the margin) both give the same signed
  // distance and closest point (the FCL broad phase misses no triangle).
  const Quat q(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  const Pose pose = at(Vec3(0.3, -0.2, 0.5), q);
  ColliderSet mesh, analytic;
  mesh.add("cube", cubeMesh(0.1), pose);
  analytic.add("cube", box(Vec3::Constant(0.1)), pose);
  const CounterRng rng(1, 0, RngPurpose::Generic);
  int compared = 0;
  for (std::uint64_t i = 0; i < 400; ++i) {
    const Vec3 local(0.24 * rng.uniform(3 * i) - 0.12, 0.24 * rng.uniform(3 * i + 1) - 0.12,
                     0.24 * rng.uniform(3 * i + 2) - 0.12);
    const Vec3 p = pose.rotation * local + pose.position;
    const auto a = analytic.nearest(p, 0.02);
    const auto m = mesh.nearest(p, 0.02);
    if (!a) {
      EXPECT_FALSE(m.has_value()) << "point " << i << " is beyond the margin";
      continue;
    }
    if (std::abs(a->distance) > 0.019) continue;  // deep inside: meshes see the surface only
    ASSERT_TRUE(m.has_value()) << "point " << i;
    EXPECT_NEAR(m->distance, a->distance, 1e-9) << "point " << i;
    EXPECT_TRUE(m->point.isApprox(a->point, 1e-9)) << "point " << i;
    ++compared;
  }
  EXPECT_GT(compared, 50);
}

TEST(Colliders, ClosestPointOnTriangleRegions) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_TRUE(closestPointOnTriangle(Vec3(0.2, 0.2, 1), a, b, c).isApprox(Vec3(0.2, 0.2, 0)));
  EXPECT_TRUE(closestPointOnTriangle(Vec3(-1, -1, 0), a, b, c).isApprox(a));
  EXPECT_TRUE(closestPointOnTriangle(Vec3(2, -1, 0), a, b, c).isApprox(b));
  EXPECT_TRUE(closestPointOnTriangle(Vec3(0.5, -1, 0), a, b, c).isApprox(Vec3(0.5, 0, 0)));
  EXPECT_TRUE(closestPointOnTriangle(Vec3(1, 1, 0), a, b, c).isApprox(Vec3(0.5, 0.5, 0)));
}

TEST(Colliders, RejectsDegenerateShapes) {
  ColliderSet set;
  EXPECT_THROW(set.add("b", box(Vec3(0.1, 0.0, 0.1)), at(Vec3::Zero())), std::invalid_argument);
  EXPECT_THROW(set.add("s", sphere(-1.0), at(Vec3::Zero())), std::invalid_argument);
  ColliderShape m = cubeMesh(0.1);
  m.triangles.push_back({0, 1, 99});
  EXPECT_THROW(set.add("m", m, at(Vec3::Zero())), std::invalid_argument);
  EXPECT_THROW(set.add("p", ColliderShape{}, at(Vec3(std::nan(""), 0, 0))), std::invalid_argument);
  EXPECT_EQ(set.size(), 0u);
  EXPECT_THROW(set.setPose(0, at(Vec3::Zero())), std::out_of_range);
}

// --- contacts in the elastic step -----------------------------

// A 10 cm sheet lying flat at height y, front side up.
mesh::SheetMesh flatSheet(double y, double maxEdge = 0.02) {
  mesh::SheetMesh m = mesh::makeRectangleSheet(0.1, 0.1, maxEdge);
  mesh::placePattern(m, Vec3(-0.05, y, 0.05), Vec3::UnitX(), -Vec3::UnitZ());
  return m;
}

// Contacts with `set` at `distance`, no self-contact.
ContactOptions collide(const ColliderSet* set, double distance) {
  ContactOptions o;
  o.colliders = set;
  o.distance = distance;
  return o;
}

const PinFunction kNoPins = [](double, std::vector<Pin>& out) { out.clear(); };

// A 2 cm-meshed sheet colliding with `table`, the plane y = 0.
ElasticSheet sheetOverTable(const Material& paper, ColliderSet& table) {
  ElasticSheet sheet(flatSheet(0.02), paper, SimParams{});
  table.add("table", ColliderShape{}, at(Vec3::Zero()));
  sheet.setContacts(collide(&table, paper.thickness));
  return sheet;
}

TEST(Contacts, ASheetDroppedOnATableComesToRestOnIt) {
  const Material paper;
  ColliderSet table;
  ElasticSheet sheet = sheetOverTable(paper, table);
  const double dt = 1.0 / 96.0;
  double lowest = 1.0;
  for (int step = 0; step < 96; ++step) {  // 1 s: falls 2 cm in ~64 ms, then rests
    sheet.advance(step * dt, dt, kNoPins);
    for (const Vec3& x : sheet.positions()) lowest = std::min(lowest, x.y());
  }
  EXPECT_GE(lowest, 0.9 * paper.thickness) << "no vertex deeper than 10 % of the thickness";
  double highest = 0.0, speed = 0.0;
  for (const Vec3& x : sheet.positions()) highest = std::max(highest, x.y());
  for (const Vec3& v : sheet.velocities()) speed = std::max(speed, v.norm());
  EXPECT_LT(highest, 2.0 * paper.thickness) << "it lies flat on the table";
  EXPECT_LT(speed, 1e-3) << "at rest";
  EXPECT_GT(sheet.contactVertexSteps(), 0);
}

TEST(Contacts, ASheetDrapesOverASphereWithoutEnteringIt) {
  const Material paper;
  ElasticSheet sheet(flatSheet(0.031, 0.01), paper, SimParams{});
  ColliderSet ball;
  ball.add("ball", sphere(0.03), at(Vec3::Zero()));
  sheet.setContacts(collide(&ball, paper.thickness));
  const double dt = 1.0 / 384.0;
  double nearest = 1.0;
  for (int step = 0; step < 192; ++step) {  // 0.5 s
    sheet.advance(step * dt, dt, kNoPins);
    for (const Vec3& x : sheet.positions()) nearest = std::min(nearest, x.norm() - 0.03);
  }
  EXPECT_GE(nearest, 0.9 * paper.thickness);
  // It rests on the ball (touching it) and bends around it: the edges droop.
  double touch = 1.0, lowest = 1.0;
  for (const Vec3& x : sheet.positions()) {
    touch = std::min(touch, x.norm() - 0.03);
    lowest = std::min(lowest, x.y());
  }
  EXPECT_LT(touch, 2.0 * paper.thickness);
  EXPECT_LT(lowest, 0.031 - 0.002);
}

TEST(Contacts, WithoutCollidersTheSheetFallsThrough) {
  const Material paper;
  ColliderSet table;
  ElasticSheet sheet = sheetOverTable(paper, table);
  sheet.setContacts({});  // switched off again
  for (int step = 0; step < 48; ++step) sheet.advance(step / 96.0, 1.0 / 96.0, kNoPins);
  EXPECT_LT(sheet.positions()[0].y(), -0.1);
  EXPECT_EQ(sheet.contactVertexSteps(), 0);
  EXPECT_THROW(sheet.setContacts(collide(&table, 0.0)), std::invalid_argument);
}

// The centroid's travel over `seconds` of a sheet resting on a plane tilted
// by `slope` (rad) with friction `mu` (paper on it).
double slideOnSlope(double slope, double mu, double seconds) {
  const Material paper;
  const Quat tilt(Eigen::AngleAxisd(slope, Vec3::UnitZ()));
  mesh::SheetMesh m = flatSheet(paper.thickness);
  for (Vec3& x : m.positions) x = tilt * x;
  ElasticSheet sheet(m, paper, SimParams{});
  ColliderSet slopeSet;
  slopeSet.add("slope", ColliderShape{}, at(Vec3::Zero(), tilt), mu);
  sheet.setContacts(collide(&slopeSet, paper.thickness));
  const auto centroid = [&] {
    Vec3 c = Vec3::Zero();
    for (const Vec3& x : sheet.positions()) c += x;
    return Vec3(c / static_cast<double>(sheet.positions().size()));
  };
  const Vec3 start = centroid();
  const double dt = 1.0 / 96.0;
  double lowest = 1.0;
  for (int step = 0; step < static_cast<int>(seconds * 96.0); ++step) {
    sheet.advance(step * dt, dt, kNoPins);
    for (const Vec3& x : sheet.positions()) lowest = std::min(lowest, (tilt.conjugate() * x).y());
  }
  EXPECT_GE(lowest, 0.9 * paper.thickness) << "slope " << slope;
  return (centroid() - start).norm();
}

TEST(Contacts, FrictionHoldsASheetOnA10DegreeSlopeAndLetsItSlideOn30) {
  constexpr double kDeg = 3.14159265358979323846 / 180.0;
  const double held = slideOnSlope(10.0 * kDeg, 0.3, 1.0);
  const double slid = slideOnSlope(30.0 * kDeg, 0.3, 1.0);
  const double frictionless = slideOnSlope(10.0 * kDeg, 0.0, 1.0);
  std::cout << "[ measure ] travel in 1 s, mu 0.3: 10 deg " << held << " m, 30 deg " << slid
            << " m; mu 0, 10 deg: " << frictionless << " m\n";
  EXPECT_LT(held, 2e-3) << "tan 10 deg = 0.18 < 0.3: it stays";
  // Sliding with a = g (sin 30 - 0.3 cos 30) = 2.36 m/s^2: about 1.2 m in 1 s.
  EXPECT_GT(slid, 0.5);
  EXPECT_LT(slid, 1.6);
  // Without friction even 10 degrees slides: g sin 10 = 1.7 m/s^2.
  EXPECT_GT(frictionless, 0.4);
}

TEST(Contacts, AMovingPlateDragsTheSheetAlongByFriction) {
  // A sheet resting on a plate that slides along +X at 0.2 m/s: friction
  // relative to the plate's surface carries the sheet with it (mu 0.5); on
  // a frictionless plate the sheet stays where it was.
  const auto travel = [](double mu) {
    const Material paper;
    ElasticSheet sheet(flatSheet(paper.thickness), paper, SimParams{});
    ColliderSet plate;
    const int id = plate.add("plate", box(Vec3(0.5, 0.01, 0.5)), at(Vec3(0, -0.01, 0)), mu);
    ContactOptions options;
    options.colliders = &plate;
    options.distance = paper.thickness;
    options.moveColliders = [&plate, id](double t) {
      plate.setPose(id, at(Vec3(0.2 * t, -0.01, 0)));
    };
    sheet.setContacts(options);
    const double x0 = sheet.positions()[0].x();
    double lowest = 1.0;
    const double dt = 1.0 / 96.0;
    for (int step = 0; step < 48; ++step) {  // 0.5 s: the plate moves 10 cm
      sheet.advance(step * dt, dt, kNoPins);
      for (const Vec3& x : sheet.positions()) lowest = std::min(lowest, x.y());
    }
    EXPECT_GE(lowest, 0.9 * paper.thickness) << "mu " << mu;
    EXPECT_FALSE(sheet.contacts().empty()) << "it touches the plate";
    return sheet.positions()[0].x() - x0;
  };
  const double dragged = travel(0.5), left = travel(0.0);
  std::cout << "[ measure ] plate moved 0.1 m; sheet moved " << dragged << " m (mu 0.5), " << left
            << " m (mu 0)\n";
  EXPECT_GT(dragged, 0.09) << "carried with the plate (static friction)";
  EXPECT_LT(std::abs(left), 0.005) << "nothing drags a sheet on a frictionless plate";
}

TEST(Contacts, ContactSamplesReportTheSlidingSpeedAndTheWeight) {
  const Material paper;
  ElasticSheet sheet(flatSheet(paper.thickness), paper, SimParams{});
  sheet.setVelocities(std::vector<Vec3>(sheet.positions().size(), Vec3(0.5, 0, 0)));
  ColliderSet table;
  table.add("table", ColliderShape{}, at(Vec3::Zero()), 0.0);  // frictionless: keeps sliding
  sheet.setContacts(collide(&table, paper.thickness));
  for (int step = 0; step < 24; ++step) sheet.advance(step / 96.0, 1.0 / 96.0, kNoPins);
  const auto& contacts = sheet.contacts();
  ASSERT_EQ(contacts.size(), sheet.positions().size()) << "every vertex lies on the table";
  double force = 0.0;
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    EXPECT_EQ(contacts[i].vertex, static_cast<int>(i));
    EXPECT_EQ(contacts[i].collider, 0);
    // Mass damping (0.5/s) slows it: 0.5 exp(-0.5 * 0.25) = 0.44 m/s.
    EXPECT_NEAR(contacts[i].slideSpeed, 0.5 * std::exp(-0.5 * 0.25), 0.01);
    force += contacts[i].normalForce;
  }
  const double weight = paper.arealDensity() * 0.01 * 9.81;
  EXPECT_NEAR(force, weight, 0.05 * weight) << "the table carries the sheet's weight";
}

TEST(Contacts, ABallCannotPassBetweenTheVerticesOfACoarseSheet) {
  // A 10 cm sheet of four triangles falls onto a 1 cm ball under the middle
  // of one of them: no vertex ever comes near the ball, so vertex contacts
  // alone would let it through; the ball's centre is a probe the faces keep
  // their distance from, so the sheet lands on it.
  mesh::SheetMesh m = mesh::makeRectangleSheet(0.1, 0.1, 0.1);
  mesh::placePattern(m, Vec3(-0.05, 0.02, 0.05), Vec3::UnitX(), -Vec3::UnitZ());
  ASSERT_EQ(m.triangleCount(), 4u);
  const Material paper;
  ColliderSet set;
  const Vec3 centre(0.025, 0.0, 0.0);  // under the middle of the +X triangle
  set.add("ball", sphere(0.01), at(centre));
  ElasticSheet sheet(m, paper, SimParams{});
  sheet.setContacts(collide(&set, paper.thickness));
  double worst = 1.0, highest = -1.0;
  for (int step = 0; step < 24; ++step) {  // 0.25 s: lands at ~45 ms
    sheet.advance(step / 96.0, 1.0 / 96.0, kNoPins);
    const auto& x = sheet.positions();
    for (const auto& t : m.triangles) {
      const Vec3 q = closestPointOnTriangle(centre, x[static_cast<std::size_t>(t[0])],
                                            x[static_cast<std::size_t>(t[1])],
                                            x[static_cast<std::size_t>(t[2])]);
      worst = std::min(worst, (q - centre).norm() - 0.01);
    }
    for (const Vec3& p : x) highest = std::max(highest, p.y());
  }
  std::cout << "[ measure ] the sheet's faces came within " << worst / paper.thickness
            << " thicknesses of the ball\n";
  EXPECT_GE(worst, 0.9 * paper.thickness) << "the faces stay outside the ball";
  EXPECT_GT(highest, 0.005) << "the sheet rests on the ball instead of falling through";
}

}  // namespace
}  // namespace crumple::sim
