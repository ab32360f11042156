// The reader's checks of decoded data (docs/PCACHE.md "What the reader
// checks"): a CRC-valid cache with a hostile index or a non-finite real is an
// error naming the file, the frame and the block, never data handed out.
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/error.hpp"
#include "frame_refusal.hpp"
#include "temp_dir.hpp"

namespace crumple::cache {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

CacheHeader makeHeader() {
  CacheHeader h;
  h.fps = 24.0;
  h.frameStart = 1;
  h.frameEnd = 24;
  h.sheetWidth = 0.2;
  h.sheetHeight = 0.2;
  h.paperThickness = 1e-4;
  h.handleNames = {"a", "b"};
  return h;
}

// A square of four triangles around a centre vertex, in two regions, with
// every structure field filled.
FrameRecord makeFrame() {
  FrameRecord f;
  f.frame = 1;
  f.time = 1.0 / 24.0;
  f.pattern = {Vec2(0, 0), Vec2(0.2, 0), Vec2(0.2, 0.2), Vec2(0, 0.2), Vec2(0.1, 0.1)};
  f.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  f.regionOfTriangle = {0, 1, 1, 0};
  f.regionTypes = {0, 1};
  for (const Vec2& p : f.pattern) f.positions.push_back(Vec3(p.x(), p.y(), 0.0));
  f.singularVertices = {4};
  f.junctionVertices = {1};
  f.rulings = {{4, 2}};
  f.handleVertices = {0, -1};
  f.handleTargets = {Vec3::Zero(), Vec3(1, 2, 3)};
  f.camera.position = Vec3(0, 0, 1);
  f.camera.yfov = 0.7;
  return f;
}

class PcacheChecksTest : public test::TempDirTest {
 protected:
  std::string write(const CacheHeader& h, const FrameRecord& f) {
    const std::string path = file("c.pcache");
    CacheWriter w(path, h);  // the writer does not check: a hostile file is easy to make
    w.append(f);
    w.close();
    return path;
  }
};

TEST_F(PcacheChecksTest, AValidFrameReads) {
  const CacheReader r(write(makeHeader(), makeFrame()));
  EXPECT_EQ(r.readFrame(0).positions.size(), 5u);
  EXPECT_TRUE(r.verifyAll().empty());
}

struct BadFrame {
  const char* name;
  const char* block;  // what the message must name
  std::function<void(FrameRecord&)> damage;
};

TEST_F(PcacheChecksTest, EveryIndexAndRealOfAFrameIsChecked) {
  const std::vector<BadFrame> cases = {
      {"triangle index -5", "topology: triangle 0", [](FrameRecord& f) { f.triangles[0][0] = -5; }},
      {"triangle index 999999", "topology: triangle 1",
       [](FrameRecord& f) { f.triangles[1][2] = 999999; }},
      {"triangle index = vertex count", "topology: triangle 2",
       [](FrameRecord& f) { f.triangles[2][1] = 5; }},
      {"repeated vertex", "repeats a vertex",
       [](FrameRecord& f) {
         f.triangles[3] = {3, 3, 4};
       }},
      {"region id out of range", "is in region 2",
       [](FrameRecord& f) { f.regionOfTriangle[0] = 2; }},
      {"negative region id", "is in region -1", [](FrameRecord& f) { f.regionOfTriangle[1] = -1; }},
      {"region count", "region ids for", [](FrameRecord& f) { f.regionOfTriangle.pop_back(); }},
      {"region type", "has type 7", [](FrameRecord& f) { f.regionTypes[1] = 7; }},
      {"pattern count", "pattern points for", [](FrameRecord& f) { f.pattern.pop_back(); }},
      {"NaN pattern", "pattern point 2", [](FrameRecord& f) { f.pattern[2].x() = kNaN; }},
      {"NaN position", "positions: vertex 3", [](FrameRecord& f) { f.positions[3].z() = kNaN; }},
      {"infinite position", "positions: vertex 0",
       [](FrameRecord& f) { f.positions[0].y() = kInf; }},
      {"position at 1e300 m", "positions: vertex 1",
       [](FrameRecord& f) { f.positions[1].x() = 1e300; }},
      {"pattern point at -1e10 m", "pattern point 4",
       [](FrameRecord& f) { f.pattern[4].y() = -1e10; }},
      {"singular vertex 1e7", "singular vertex 0",
       [](FrameRecord& f) { f.singularVertices = {10000000}; }},
      {"junction vertex -1", "junction vertex 0",
       [](FrameRecord& f) { f.junctionVertices = {-1}; }},
      {"ruling end", "ruling 0", [](FrameRecord& f) { f.rulings[0][1] = 5; }},
      {"handle vertex 1e7", "handles: handle 0",
       [](FrameRecord& f) { f.handleVertices[0] = 10000000; }},
      {"handle vertex -2", "handles: handle 1", [](FrameRecord& f) { f.handleVertices[1] = -2; }},
      {"handle count", "vertices for", [](FrameRecord& f) { f.handleTargets.pop_back(); }},
      {"more handles than names", "the header names",
       [](FrameRecord& f) {
         f.handleVertices.push_back(1);
         f.handleTargets.push_back(Vec3::Zero());
       }},
      {"NaN handle target", "handles: target 1",
       [](FrameRecord& f) { f.handleTargets[1].x() = kNaN; }},
      {"NaN time", "time", [](FrameRecord& f) { f.time = kNaN; }},
      {"NaN camera", "camera", [](FrameRecord& f) { f.camera.position.x() = kNaN; }},
      {"zero rotation", "camera", [](FrameRecord& f) { f.camera.rotation = Quat(0, 0, 0, 0); }},
      {"field of view pi", "camera", [](FrameRecord& f) { f.camera.yfov = 3.2; }},
  };
  for (const BadFrame& c : cases) {
    SCOPED_TRACE(c.name);
    FrameRecord f = makeFrame();
    c.damage(f);
    test::expectFirstFrameRefused(write(makeHeader(), f), c.block);
  }
}

// A frame without topology of its own is checked with the topology it
// carries: its positions must still match the vertex count.
TEST_F(PcacheChecksTest, AFrameIsCheckedAgainstTheTopologyItCarries) {
  const std::string path = file("carried.pcache");
  {
    CacheWriter w(path, makeHeader());
    FrameRecord f = makeFrame();
    w.append(f);
    f.frame = 2;
    f.positions.pop_back();  // 4 positions for the 5 vertices of frame 1's topology
    w.append(f);
    w.close();
  }
  const CacheReader r(path);
  EXPECT_NO_THROW((void)r.readFrame(0));
  EXPECT_THROW((void)r.readFrame(1), CorruptDataError);
}

TEST_F(PcacheChecksTest, AnImpossibleHeaderIsAnInputErrorOnOpening) {
  const std::vector<std::pair<const char*, std::function<void(CacheHeader&)>>> cases = {
      {"fps", [](CacheHeader& h) { h.fps = kNaN; }},
      {"fps", [](CacheHeader& h) { h.fps = 0.0; }},
      {"fps", [](CacheHeader& h) { h.fps = -24.0; }},
      {"planned frames", [](CacheHeader& h) { h.frameEnd = 0; }},
      {"substeps", [](CacheHeader& h) { h.substeps = 0; }},
      {"sheet width", [](CacheHeader& h) { h.sheetWidth = kInf; }},
      {"paper thickness", [](CacheHeader& h) { h.paperThickness = -1.0; }},
  };
  for (const auto& [what, damage] : cases) {
    SCOPED_TRACE(what);
    CacheHeader h = makeHeader();
    damage(h);
    const std::string path = write(h, makeFrame());
    try {
      const CacheReader r(path);
      ADD_FAILURE() << "opened";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + ": damaged cache header: " + what),
                std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace crumple::cache
