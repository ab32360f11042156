// The sheet's velocities a shot with a shutter caches (pipeline/src/
// frame_motion.hpp): each vertex's mean velocity over the frame, its
// position a frame earlier taken at the same pattern point on the previous
// frame's mesh, whatever that mesh was (remeshed, torn), on the vertex's
// own side of a tear.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/tear/cut.hpp"
#include "frame_motion.hpp"

namespace crumple::pipeline::detail {
namespace {

constexpr double kFrame = 1.0 / 24.0;  // s

cache::FrameRecord recordOf(const mesh::SheetMesh& m) {
  cache::FrameRecord f;
  f.pattern = m.pattern;
  f.triangles = m.triangles;
  f.positions = m.positions;
  return f;
}

// The sheet's pattern moved by an affine map: (u, v) -> a + U u + V v.
mesh::SheetMesh placed(mesh::SheetMesh m, const Vec3& a, const Vec3& u, const Vec3& v) {
  for (std::size_t i = 0; i < m.pattern.size(); ++i)
    m.positions[i] = a + u * m.pattern[i].x() + v * m.pattern[i].y();
  return m;
}

TEST(FrameVelocities, TheFirstFrameIsStill) {
  const mesh::SheetMesh m = mesh::makeRectangleSheet(0.1, 0.1, 0.02);
  const FrameVelocities velocities;
  for (const Vec3& v : velocities.of(recordOf(m), kFrame)) EXPECT_TRUE(v.isZero());
}

// An affine motion is linear on every triangle, so the velocity of every
// vertex of a new mesh is exact whatever the previous mesh was.
TEST(FrameVelocities, AcrossARemeshTheMaterialPointIsFollowed) {
  const mesh::SheetMesh coarse = placed(mesh::makeRectangleSheet(0.1, 0.1, 0.02), Vec3(0, 0.1, 0),
                                        Vec3(1, 0, 0), Vec3(0, 0, -1));
  // A frame later: moved, turned about y and sheared, on a finer mesh.
  const Vec3 a(0.01, 0.09, 0.002), u(0.995, 0.0, 0.0998), v(0.05, 0.01, -1.0);
  const mesh::SheetMesh fine = placed(mesh::makeRectangleSheet(0.1, 0.1, 0.013), a, u, v);
  ASSERT_NE(fine.vertexCount(), coarse.vertexCount());
  FrameVelocities velocities;
  velocities.remember(recordOf(coarse));
  const auto of = velocities.of(recordOf(fine), kFrame);
  ASSERT_EQ(of.size(), fine.vertexCount());
  for (std::size_t i = 0; i < of.size(); ++i) {
    const Vec2& p = fine.pattern[i];
    const Vec3 before = Vec3(0, 0.1, 0) + Vec3(1, 0, 0) * p.x() + Vec3(0, 0, -1) * p.y();
    EXPECT_NEAR((of[i] - (fine.positions[i] - before) / kFrame).norm(), 0.0, 1e-9) << i;
  }
}

// A sheet torn along a cut whose two lips share their pattern points: the
// right lip slides along +x, the left one stays. Each lip's vertices take
// their own side's motion (looking the twins up by their pattern point
// alone would give one lip the other's).
TEST(FrameVelocities, EachLipOfATearMovesWithItsOwnSide) {
  mesh::SheetMesh sheet = mesh::makeRectangleSheet(0.04, 0.04, 0.005);
  mesh::placePattern(sheet, Vec3::Zero(), Vec3::UnitX(), -Vec3::UnitZ());
  const int from = mesh::nearestPatternVertex(sheet, Vec2(0.02, 0.0));
  const Vec2 start = sheet.pattern[static_cast<std::size_t>(from)];
  const tear::CutResult cut = tear::cutAlong(sheet, from, Vec2(0.0213, 0.026));
  ASSERT_GT(cut.twins.size(), 3u);
  const Vec2 tip = sheet.pattern[static_cast<std::size_t>(cut.tip)];
  const Vec2 along = (tip - start).normalized();
  std::vector<char> right(sheet.vertexCount(), 0);
  for (std::size_t v = 0; v < sheet.vertexCount(); ++v) {
    const Vec2 d = sheet.pattern[v] - start;
    right[v] = along.x() * d.y() - along.y() * d.x() < -1e-12;
  }
  for (std::size_t i = 0; i + 1 < cut.chain.size(); ++i)
    right[static_cast<std::size_t>(cut.chain[i])] = 1;
  for (const int t : cut.twins) right[static_cast<std::size_t>(t)] = 0;
  // The right lip opened by `shift` behind the tip, fading to 0 ahead of it.
  const auto opened = [&](double shift) {
    mesh::SheetMesh m = sheet;
    for (std::size_t v = 0; v < m.vertexCount(); ++v) {
      const double g = std::clamp((tip.y() - 0.002 - m.pattern[v].y()) / 0.006, 0.0, 1.0);
      if (right[v]) m.positions[v].x() += shift * g;
    }
    return m;
  };
  const mesh::SheetMesh before = opened(0.002), after = opened(0.004);
  FrameVelocities velocities;
  velocities.remember(recordOf(before));
  const auto of = velocities.of(recordOf(after), kFrame);
  int lipVertices = 0;
  for (std::size_t v = 0; v < of.size(); ++v) {
    const Vec3 expected = (after.positions[v] - before.positions[v]) / kFrame;
    EXPECT_NEAR((of[v] - expected).norm(), 0.0, 1e-9) << "vertex " << v;
  }
  for (std::size_t i = 0; i + 1 < cut.chain.size(); ++i) {
    const auto r = static_cast<std::size_t>(cut.chain[i]);
    const auto l = static_cast<std::size_t>(cut.twins[i]);
    if (sheet.pattern[r] != sheet.pattern[l] || after.positions[r] == before.positions[r]) continue;
    ++lipVertices;
    EXPECT_GT(of[r].x(), 1e-3) << "the right lip slides";
    EXPECT_LT(of[l].norm(), 1e-12) << "the left lip stays";
  }
  EXPECT_GT(lipVertices, 2);
}

}  // namespace
}  // namespace crumple::pipeline::detail
