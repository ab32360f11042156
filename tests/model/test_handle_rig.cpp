// HandleRig::rebindTangents: after the hybrid model rebuilds its mesh, the
// tangent-plane pins hold the pattern's shape around the handle, rigidly
// turned (Kabsch) to fit where the sheet is now.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "../pipeline/test_util.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/model/handle_rig.hpp"
#include "crumple/sim/elastic_sheet.hpp"

using namespace crumple;
using namespace crumple::testing;

namespace {

// One tangent-controlled handle on an interior vertex of a 10 x 10 cm
// criss-cross sheet (2.5 cm cells), held by node "A", which moves and turns
// between t = 0 and t = 1 s so that the node's frame at the rebind time is
// neither the identity nor the bind-time frame.
struct RigFixture {
  TempDir tmp;
  io::SceneSpec spec;
  io::AnimationScene anim;
  mesh::SheetMesh sheet;
  int handleVertex = -1;

  static io::AnimationScene loadAnimation(const TempDir& dir) {
    const Quat q0(Eigen::AngleAxisd(0.9, Vec3(0.3, -0.5, 0.8).normalized()));
    const Quat q1(Eigen::AngleAxisd(-0.4, Vec3(-0.7, 0.2, 0.4).normalized()));
    auto f = [](double v) { return static_cast<float>(v); };
    GltfTrack a{"A",
                {0.0f, 1.0f},
                {{0.01f, 0.20f, -0.03f}, {0.04f, 0.17f, 0.02f}},
                {{f(q0.x()), f(q0.y()), f(q0.z()), f(q0.w())},
                 {f(q1.x()), f(q1.y()), f(q1.z()), f(q1.w())}}};
    writeFile(dir / "anim.gltf", makeGltf({a}));
    return io::AnimationScene::load((dir / "anim.gltf").string());
  }

  RigFixture() : anim(loadAnimation(tmp)), sheet(mesh::makeRectangleSheet(0.1, 0.1, 0.025)) {
    spec.file = (tmp / "scene.toml").string();
    io::HandleSpec h;
    h.name = "hold";
    h.node = "A";
    h.patternPoint = Vec2(0.025, 0.05);
    h.tangentControl = true;
    spec.handles.push_back(h);
    handleVertex = mesh::nearestPatternVertex(sheet, *h.patternPoint);
  }

  // The pattern offset of vertex n from the handle vertex, in the plane z = 0.
  Vec3 flat(int n) const {
    const Vec2 d = sheet.pattern[static_cast<std::size_t>(n)] -
                   sheet.pattern[static_cast<std::size_t>(handleVertex)];
    return {d.x(), d.y(), 0.0};
  }

  // Every vertex at centre + shape * (its pattern offset from the handle).
  void place(const Vec3& centre, const Mat3& shape) {
    for (std::size_t n = 0; n < sheet.vertexCount(); ++n)
      sheet.positions[n] = centre + shape * flat(static_cast<int>(n));
  }
};

}  // namespace

TEST(HandleRig, RebindKeepsThePatternDistancesOfAStretchedNeighbourhood) {
  RigFixture f;
  // Bind on a neighbourhood compressed to 0.8 (so offsets kept from the bind
  // would be 0.8x the pattern), then rebind at t = 0.5 s on one stretched to
  // 1.1x around the handle and tilted: offsets copied from the current
  // positions would be 1.1x the pattern.
  f.place(f.anim.worldPose("A", 0.0).position, 0.8 * Mat3::Identity());
  model::HandleRig rig(f.spec, &f.anim, f.sheet, 0.0);
  ASSERT_EQ(rig.handles().size(), 1u);
  const double t = 0.5;
  const Vec3 node = rig.target(0, t);
  const Mat3 tilt = Eigen::AngleAxisd(0.3, Vec3(1.0, 2.0, -0.5).normalized()).toRotationMatrix();
  f.place(node, 1.1 * tilt);
  rig.rebindTangents(f.sheet, t);

  std::vector<sim::Pin> pins;
  rig.pins(t, pins);
  ASSERT_EQ(pins.size(), 5u) << "an interior handle holds four tangent-plane vertices";
  EXPECT_EQ(pins[0].vertex, f.handleVertex);
  EXPECT_LT((pins[0].position - node).norm(), 1e-15);
  for (std::size_t k = 1; k < pins.size(); ++k) {
    // Handle to tangent pin: the pattern distance, not 1.1x (nor 0.8x) of it.
    const double pattern = f.flat(pins[k].vertex).norm();
    const double pinned = (pins[k].position - pins[0].position).norm();
    EXPECT_NEAR(pinned / pattern, 1.0, 1e-12) << "tangent vertex " << pins[k].vertex;
    // Tangent pin to tangent pin: the pattern distance too.
    for (std::size_t j = k + 1; j < pins.size(); ++j) {
      const double patternKJ = (f.flat(pins[k].vertex) - f.flat(pins[j].vertex)).norm();
      const double pinnedKJ = (pins[k].position - pins[j].position).norm();
      EXPECT_NEAR(pinnedKJ / patternKJ, 1.0, 1e-12)
          << "tangent vertices " << pins[k].vertex << ", " << pins[j].vertex;
    }
  }
}

TEST(HandleRig, RebindTurnsThePatternOntoTheCurrentTangentPlane) {
  RigFixture f;
  // Bind on the flat pattern, then turn the sheet 30 degrees about an axis
  // through the handle: the rebound pins follow the turned plane.
  f.place(f.anim.worldPose("A", 0.0).position, Mat3::Identity());
  model::HandleRig rig(f.spec, &f.anim, f.sheet, 0.0);
  ASSERT_EQ(rig.handles().size(), 1u);
  const double t = 0.5;
  const Vec3 node = rig.target(0, t);
  const Mat3 turn =
      Eigen::AngleAxisd(std::numbers::pi / 6, Vec3(0.4, -1.0, 0.7).normalized()).toRotationMatrix();
  f.place(node, turn);
  rig.rebindTangents(f.sheet, t);

  // Unstretched: every pin lands exactly on where its vertex is now.
  std::vector<sim::Pin> pins;
  rig.pins(t, pins);
  ASSERT_EQ(pins.size(), 5u) << "an interior handle holds four tangent-plane vertices";
  EXPECT_EQ(pins[0].vertex, f.handleVertex);
  for (const auto& pin : pins)
    EXPECT_LT((pin.position - f.sheet.positions[static_cast<std::size_t>(pin.vertex)]).norm(),
              1e-12)
        << "vertex " << pin.vertex;

  // Turned the same way and stretched 1.1x: the pins keep the turn but not
  // the stretch, the pattern turned 30 degrees about the handle.
  f.place(node, 1.1 * turn);
  rig.rebindTangents(f.sheet, t);
  rig.pins(t, pins);
  ASSERT_EQ(pins.size(), 5u);
  for (const auto& pin : pins)
    EXPECT_LT((pin.position - (node + turn * f.flat(pin.vertex))).norm(), 1e-12)
        << "vertex " << pin.vertex;
}

// A handle vertex that a tear or a remeshing left in no triangle has no
// tangent plane: no tangent vertices (it indexed an empty one-ring before).
TEST(HandleRig, AVertexInNoTriangleHasNoTangentNeighbours) {
  mesh::SheetMesh sheet;
  sheet.pattern = {{0.0, 0.0}, {0.01, 0.0}, {0.0, 0.01}, {0.05, 0.05}};
  sheet.positions = {{0.0, 0.0, 0.0}, {0.01, 0.0, 0.0}, {0.0, 0.01, 0.0}, {0.05, 0.05, 0.0}};
  sheet.triangles = {{0, 1, 2}};
  sheet.regionOfTriangle = {0};
  EXPECT_TRUE(model::tangentNeighbours(sheet, 3, 0).empty());
  EXPECT_EQ(model::tangentNeighbours(sheet, 0, 0).size(), 2u) << "a corner: 2";
}

// A finger that holds a patch ([[handles]] patch_radius) pins only its
// vertex; its six patch points (an interior handle) are grips at the patch
// radius around it in the pattern, drawn to where the node's motion and
// rotation carry them: at a later time the grip targets are the bind-time
// points turned by the node's rotation since then, about the moving node.
TEST(HandleRig, APatchPinsTheHandleAndGripsSixPointsThatTurnWithTheNode) {
  RigFixture f;
  f.spec.handles[0].patchRadius = 0.005;
  f.place(f.anim.worldPose("A", 0.0).position, Mat3::Identity());
  model::HandleRig rig(f.spec, &f.anim, f.sheet, 0.0);
  std::vector<sim::Pin> pins;
  rig.pins(0.0, pins);
  ASSERT_EQ(pins.size(), 1u) << "the patch replaces the tangent-plane vertices";
  EXPECT_EQ(pins[0].vertex, f.handleVertex);
  std::vector<sim::Grip> grips;
  constexpr double kStiffness = 1234.0;
  rig.grips(0.0, kStiffness, grips);
  ASSERT_EQ(grips.size(), 6u) << "an interior handle's patch has all six directions";
  const Vec3 centre = f.sheet.positions[static_cast<std::size_t>(f.handleVertex)];
  for (const sim::Grip& g : grips) {
    EXPECT_EQ(g.anchor, f.handleVertex);
    EXPECT_EQ(g.stiffness, kStiffness);
    EXPECT_NEAR(g.weights.sum(), 1.0, 1e-12);
    EXPECT_GE(g.weights.minCoeff(), -1e-12);
    // At bind time each grip is where its point of the sheet is: at the
    // patch radius from the handle.
    const auto& T = f.sheet.triangles[static_cast<std::size_t>(g.triangle)];
    Vec3 x = Vec3::Zero();
    for (int c = 0; c < 3; ++c)
      x += g.weights(c) * f.sheet.positions[static_cast<std::size_t>(T[c])];
    EXPECT_LT((g.position - x).norm(), 1e-12);
    EXPECT_NEAR((g.position - centre).norm(), 0.005, 1e-12);
  }
  const double t = 0.7;
  std::vector<sim::Grip> later;
  rig.grips(t, kStiffness, later);
  ASSERT_EQ(later.size(), grips.size());
  const Quat turn =
      f.anim.worldPose("A", t).rotation * f.anim.worldPose("A", 0.0).rotation.conjugate();
  for (std::size_t k = 0; k < later.size(); ++k)
    EXPECT_LT((later[k].position - (rig.target(0, t) + turn * (grips[k].position - centre))).norm(),
              1e-12);
  // A corner's patch keeps the directions inside the sheet: 0 and 60 degrees.
  RigFixture corner;
  corner.spec.handles[0].patternPoint = Vec2(0.0, 0.0);
  corner.spec.handles[0].patchRadius = 0.005;
  corner.place(corner.anim.worldPose("A", 0.0).position, Mat3::Identity());
  model::HandleRig cornerRig(corner.spec, &corner.anim, corner.sheet, 0.0);
  cornerRig.grips(0.0, kStiffness, grips);
  EXPECT_EQ(grips.size(), 2u);
  // Without a patch radius there are no grips.
  RigFixture pinned;
  pinned.place(pinned.anim.worldPose("A", 0.0).position, Mat3::Identity());
  model::HandleRig pinnedRig(pinned.spec, &pinned.anim, pinned.sheet, 0.0);
  pinnedRig.grips(0.0, kStiffness, grips);
  EXPECT_TRUE(grips.empty());
}
