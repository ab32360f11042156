#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/crc32.hpp"
#include "crumple/core/error.hpp"
#include "temp_dir.hpp"

namespace crumple::cache {
namespace {

using test::readBytes;
using test::writeBytes;

constexpr int kFrames = 6;
constexpr int kFirstFrame = 10;     // frame numbers 10..15, so indices and numbers differ
constexpr int kTopologyChange = 3;  // index of the frame where the topology changes
constexpr std::uint64_t kChunkPrefix = 16;

bool sameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

template <typename VecT>
void expectSameVectors(const std::vector<VecT>& a, const std::vector<VecT>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (Eigen::Index k = 0; k < a[i].size(); ++k)
      EXPECT_TRUE(sameBits(a[i][k], b[i][k])) << what << "[" << i << "][" << k << "]";
}

void expectSameHeader(const CacheHeader& a, const CacheHeader& b) {
  EXPECT_EQ(a.formatVersion, b.formatVersion);
  EXPECT_TRUE(sameBits(a.fps, b.fps));
  EXPECT_EQ(a.frameStart, b.frameStart);
  EXPECT_EQ(a.frameEnd, b.frameEnd);
  EXPECT_EQ(a.substeps, b.substeps);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.sceneName, b.sceneName);
  EXPECT_EQ(a.sceneFile, b.sceneFile);
  EXPECT_EQ(a.sceneText, b.sceneText);
  EXPECT_TRUE(sameBits(a.sheetWidth, b.sheetWidth));
  EXPECT_TRUE(sameBits(a.sheetHeight, b.sheetHeight));
  EXPECT_EQ(a.paperName, b.paperName);
  EXPECT_TRUE(sameBits(a.paperThickness, b.paperThickness));
  EXPECT_EQ(a.handleNames, b.handleNames);
  EXPECT_EQ(a.extensions, b.extensions);
}

void expectSameFrame(const FrameRecord& a, const FrameRecord& b) {
  SCOPED_TRACE("frame " + std::to_string(a.frame));
  EXPECT_EQ(a.frame, b.frame);
  EXPECT_TRUE(sameBits(a.time, b.time));
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.regionOfTriangle, b.regionOfTriangle);
  EXPECT_EQ(a.regionTypes, b.regionTypes);
  expectSameVectors(a.pattern, b.pattern, "pattern");
  expectSameVectors(a.positions, b.positions, "positions");
  EXPECT_EQ(a.singularVertices, b.singularVertices);
  EXPECT_EQ(a.junctionVertices, b.junctionVertices);
  EXPECT_EQ(a.rulings, b.rulings);
  EXPECT_EQ(a.tearCount, b.tearCount);
  EXPECT_EQ(a.handleVertices, b.handleVertices);
  expectSameVectors(a.handleTargets, b.handleTargets, "handleTargets");
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(sameBits(a.camera.position[k], b.camera.position[k]));
  EXPECT_TRUE(sameBits(a.camera.rotation.w(), b.camera.rotation.w()));
  EXPECT_TRUE(sameBits(a.camera.rotation.x(), b.camera.rotation.x()));
  EXPECT_TRUE(sameBits(a.camera.rotation.y(), b.camera.rotation.y()));
  EXPECT_TRUE(sameBits(a.camera.rotation.z(), b.camera.rotation.z()));
  EXPECT_TRUE(sameBits(a.camera.yfov, b.camera.yfov));
  EXPECT_EQ(a.extensions, b.extensions);
}

CacheHeader makeHeader() {
  CacheHeader h;
  h.fps = 29.97;
  h.frameStart = kFirstFrame;
  h.frameEnd = 40;
  h.substeps = 8;
  h.seed = 0xDEADBEEFCAFEF00DULL;
  h.sceneName = "crumple test";
  h.sceneFile = "/tmp/scenes/test.toml";
  h.sceneText = std::string("[sheet]\nwidth = 0.21\n\0binary\xff tail", 32);
  h.sheetWidth = 0.21;
  h.sheetHeight = 0.297;
  h.paperName = "copy paper 80 gsm";
  h.paperThickness = 1.0e-4;
  h.handleNames = {"left hand", "", "right hand"};
  return h;
}

// Frame index k. Topology A before kTopologyChange, B (one more vertex and
// triangle, other regions) from it on; positions include awkward doubles.
FrameRecord makeFrame(int k) {
  FrameRecord f;
  f.frame = kFirstFrame + k;
  f.time = k / 29.97;
  const bool b = k >= kTopologyChange;
  f.pattern = {Vec2(0, 0), Vec2(0.21, 0), Vec2(0.21, 0.297), Vec2(0, 0.297)};
  f.triangles = {{0, 1, 2}, {0, 2, 3}};
  f.regionOfTriangle = {0, 0};
  f.regionTypes = {0};
  if (b) {
    f.pattern.push_back(Vec2(0.105, 0.1485));
    f.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
    f.regionOfTriangle = {0, 1, 1, 0};
    f.regionTypes = {0, 1};
  }
  for (std::size_t v = 0; v < f.pattern.size(); ++v)
    f.positions.push_back(Vec3(f.pattern[v].x(), f.pattern[v].y(), 0.1 * k + 1e-17 * v));
  // The reader's bound on coordinates (1e9 m) is inclusive.
  f.positions[0] = Vec3(-0.0, std::numeric_limits<double>::denorm_min(), 1e9);
  f.positions[1].z() = std::numbers::pi * k;
  if (k % 2 == 1) {
    f.singularVertices = {1, 3};
    f.junctionVertices = {2};
    f.rulings = {{0, 2}, {1, 3}};
  }
  f.tearCount = static_cast<std::uint32_t>(k / 2);
  f.handleVertices = {0, -1, 3};
  f.handleTargets = {Vec3(0.0, 0.0, 0.01 * k), Vec3::Zero(), Vec3(0.21, 0.297, -0.02 * k)};
  f.camera.position = Vec3(0.1, -0.5, 0.4 + k);
  f.camera.rotation = Quat(Eigen::AngleAxisd(0.3 * k + 0.1, Vec3(1, 2, 3).normalized()));
  f.camera.yfov = 0.6981317007977318;
  return f;
}

// Writes the standard test cache and returns the file size after each
// append: sizes[k] is where frame index k's chunk starts, sizes[k + 1] where
// it ends.
std::vector<std::uint64_t> writeCache(const std::string& path, bool close = true) {
  std::vector<std::uint64_t> sizes;
  CacheWriter w(path, makeHeader());
  sizes.push_back(std::filesystem::file_size(path));
  for (int k = 0; k < kFrames; ++k) {
    w.append(makeFrame(k));
    sizes.push_back(std::filesystem::file_size(path));  // append() flushes
  }
  EXPECT_EQ(w.framesWritten(), static_cast<std::size_t>(kFrames));
  if (close) w.close();
  return sizes;
}

std::vector<std::uint8_t> truncated(std::vector<std::uint8_t> bytes, std::uint64_t size) {
  bytes.resize(size);
  return bytes;
}

void flipByte(const std::string& path, std::uint64_t offset) {
  auto bytes = readBytes(path);
  ASSERT_LT(offset, bytes.size());
  bytes[offset] ^= 0x5A;
  writeBytes(path, bytes);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

class PcacheTest : public test::TempDirTest {};

TEST_F(PcacheTest, RoundTripIsExactAndRewriteIsByteIdentical) {
  const std::string path = file("shot.pcache");
  writeCache(path);
  CacheReader r(path);
  EXPECT_FALSE(r.recovered());
  EXPECT_TRUE(r.issues().empty());
  EXPECT_EQ(r.path(), path);
  expectSameHeader(r.header(), makeHeader());
  ASSERT_EQ(r.frameCount(), static_cast<std::size_t>(kFrames));
  for (int k = 0; k < kFrames; ++k) {
    EXPECT_EQ(r.frameNumber(k), kFirstFrame + k);
    expectSameFrame(r.readFrame(k), makeFrame(k));
  }
  EXPECT_TRUE(r.verifyAll().empty());

  // Write again from what was read: byte-identical.
  const std::string copy = file("copy.pcache");
  {
    CacheWriter w(copy, r.header());
    for (std::size_t k = 0; k < r.frameCount(); ++k) w.append(r.readFrame(k));
    w.close();
  }
  EXPECT_EQ(readBytes(copy), readBytes(path));
}

TEST_F(PcacheTest, IdenticalInputGivesIdenticalBytes) {
  writeCache(file("a.pcache"));
  writeCache(file("b.pcache"));
  EXPECT_EQ(readBytes(file("a.pcache")), readBytes(file("b.pcache")));
}

TEST_F(PcacheTest, TopologyIsStoredOnlyWhenItChanges) {
  const std::string path = file("shot.pcache");
  const auto sizes = writeCache(path);
  CacheReader r(path);
  const std::vector<std::size_t> sources = {0, 0, 0, 3, 3, 3};
  for (std::size_t k = 0; k < sources.size(); ++k) EXPECT_EQ(r.topologySource(k), sources[k]);
  // A frame chunk without topology is smaller than its topology-carrying
  // predecessor with the same vertex count.
  EXPECT_LT(sizes[2] - sizes[1], sizes[1] - sizes[0]);
  EXPECT_LT(sizes[5] - sizes[4], sizes[4] - sizes[3]);
  // Out-of-order reads still carry the right topology forward.
  for (int k : {5, 1, 4, 0, 2, 3, 5}) expectSameFrame(r.readFrame(k), makeFrame(k));
}

TEST_F(PcacheTest, TruncationInsideTheFourthFrameRecoversThreeFrames) {
  const std::string path = file("shot.pcache");
  const auto sizes = writeCache(path);
  const auto bytes = readBytes(path);
  const std::uint64_t start = sizes[3];
  const std::uint64_t end = sizes[4];
  ASSERT_GT(end - start, kChunkPrefix + 8);
  for (std::uint64_t cut : {start + 1, start + 4, start + 10, start + kChunkPrefix,
                            start + kChunkPrefix + 1, (start + end) / 2, end - 4, end - 1}) {
    SCOPED_TRACE("cut at byte " + std::to_string(cut));
    const std::string cutPath = file("cut.pcache");
    writeBytes(cutPath, truncated(bytes, cut));
    CacheReader r(cutPath);
    EXPECT_TRUE(r.recovered());
    ASSERT_EQ(r.frameCount(), 3u);
    ASSERT_EQ(r.issues().size(), 1u);
    EXPECT_EQ(r.issues()[0].frameIndex, 3);
    EXPECT_TRUE(contains(r.issues()[0].message, "no footer")) << r.issues()[0].message;
    EXPECT_TRUE(contains(r.issues()[0].message, "recovered 3 complete frames"))
        << r.issues()[0].message;
    EXPECT_TRUE(
        contains(r.issues()[0].message, "frame index 3 truncated at byte " + std::to_string(cut)))
        << r.issues()[0].message;
    for (int k = 0; k < 3; ++k) expectSameFrame(r.readFrame(k), makeFrame(k));
    EXPECT_TRUE(r.verifyAll().empty());
  }
  // Cut exactly between chunks: nothing is truncated, three frames remain.
  const std::string cutPath = file("cut.pcache");
  writeBytes(cutPath, truncated(bytes, start));
  CacheReader r(cutPath);
  EXPECT_TRUE(r.recovered());
  EXPECT_EQ(r.frameCount(), 3u);
  ASSERT_EQ(r.issues().size(), 1u);
  EXPECT_EQ(r.issues()[0].frameIndex, -1);
}

TEST_F(PcacheTest, WriterDestroyedWithoutCloseLeavesRecoverableFrames) {
  const std::string path = file("crashed.pcache");
  writeCache(path, /*close=*/false);
  CacheReader r(path);
  EXPECT_TRUE(r.recovered());
  ASSERT_EQ(r.frameCount(), static_cast<std::size_t>(kFrames));
  ASSERT_EQ(r.issues().size(), 1u);
  EXPECT_TRUE(contains(r.issues()[0].message, "no footer")) << r.issues()[0].message;
  expectSameHeader(r.header(), makeHeader());
  for (int k = 0; k < kFrames; ++k) {
    EXPECT_EQ(r.topologySource(k), k < kTopologyChange ? 0u : 3u);
    expectSameFrame(r.readFrame(k), makeFrame(k));
  }
}

// Checkpoint and resume: a cache cut anywhere after frame k (a
// killed run: later frames, a torn chunk, or a finished file's footer) and
// resumed from k frames, then given the same frames, is byte for byte the
// uninterrupted cache; the topology shared across the cut is stored once.
TEST_F(PcacheTest, AResumedWriterWritesTheUninterruptedBytes) {
  const std::string whole = file("whole.pcache");
  const auto sizes = writeCache(whole);
  const auto reference = readBytes(whole);
  for (const int keep : {0, 2, 4}) {  // 4: after the topology changed at frame 3
    for (const bool torn : {false, true}) {
      const std::string path = file("resumed.pcache");
      writeCache(path, /*close=*/false);
      if (torn)  // killed in the middle of the chunk after the kept ones
        writeBytes(path, truncated(readBytes(path), sizes[static_cast<std::size_t>(keep) + 1] - 7));
      const auto w = CacheWriter::resume(path, makeHeader(), static_cast<std::size_t>(keep));
      EXPECT_EQ(w->framesWritten(), static_cast<std::size_t>(keep));
      for (int k = keep; k < kFrames; ++k) w->append(makeFrame(k));
      w->close();
      EXPECT_EQ(readBytes(path), reference) << "kept " << keep << (torn ? ", torn" : "");
    }
  }
  // A finished cache resumed: its footer goes too.
  const std::string done = file("done.pcache");
  writeCache(done);
  const auto w = CacheWriter::resume(done, makeHeader(), kFrames - 1);
  w->append(makeFrame(kFrames - 1));
  w->close();
  EXPECT_EQ(readBytes(done), reference);
  // Another shot's header, or more frames than it holds: refused.
  CacheHeader other = makeHeader();
  other.seed += 1;
  EXPECT_THROW(CacheWriter::resume(done, other, 2), InputError);
  EXPECT_THROW(CacheWriter::resume(done, makeHeader(), kFrames + 1), InputError);
}

TEST_F(PcacheTest, DamagedFooterOrTrailerFallsBackToScanning) {
  const std::string path = file("shot.pcache");
  const auto sizes = writeCache(path);
  const auto bytes = readBytes(path);
  const std::uint64_t footer = sizes.back();
  struct Case {
    const char* name;
    std::vector<std::uint8_t> bytes;
  };
  std::vector<Case> cases;
  cases.push_back({"trailer cut", truncated(bytes, bytes.size() - 5)});
  cases.push_back({"footer cut", truncated(bytes, footer + 7)});
  auto flipped = bytes;
  flipped[footer + kChunkPrefix + 6] ^= 0x01;  // inside the frame table
  cases.push_back({"footer CRC", flipped});
  flipped = bytes;
  flipped[bytes.size() - 16] ^= 0x01;  // footer offset in the trailer
  cases.push_back({"trailer offset", flipped});
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string damaged = file("damaged.pcache");
    writeBytes(damaged, c.bytes);
    CacheReader r(damaged);
    EXPECT_TRUE(r.recovered());
    EXPECT_EQ(r.frameCount(), static_cast<std::size_t>(kFrames));
    ASSERT_EQ(r.issues().size(), 1u);
    EXPECT_TRUE(contains(r.issues()[0].message, "recovered 6 complete frames"))
        << r.issues()[0].message;
    expectSameFrame(r.readFrame(kFrames - 1), makeFrame(kFrames - 1));
  }
}

TEST_F(PcacheTest, FlippedByteInAFrameIsReportedWithItsFrameNumber) {
  const std::string path = file("shot.pcache");
  const auto sizes = writeCache(path);
  flipByte(path, sizes[2] + kChunkPrefix + 30);  // payload of frame index 2 = frame 12
  CacheReader r(path);  // the footer is intact: frames are not checked on opening
  EXPECT_FALSE(r.recovered());
  ASSERT_EQ(r.frameCount(), static_cast<std::size_t>(kFrames));
  try {
    r.readFrame(2);
    FAIL() << "no CorruptDataError";
  } catch (const CorruptDataError& e) {
    EXPECT_TRUE(contains(e.what(), "frame 12")) << e.what();
    EXPECT_TRUE(contains(e.what(), "CRC")) << e.what();
    EXPECT_TRUE(contains(e.what(), path)) << e.what();
  }
  for (int k : {0, 1, 3, 4, 5}) expectSameFrame(r.readFrame(k), makeFrame(k));
  const auto issues = r.verifyAll();
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].frameIndex, 2);
  EXPECT_EQ(issues[0].frame, 12);
  EXPECT_TRUE(contains(issues[0].message, "frame 12")) << issues[0].message;
  EXPECT_TRUE(contains(issues[0].message, "CRC")) << issues[0].message;
}

TEST_F(PcacheTest, DamagedTopologyFrameFailsTheFramesThatShareIt) {
  const std::string path = file("shot.pcache");
  const auto sizes = writeCache(path);
  flipByte(path, sizes[3] + kChunkPrefix + 20);  // frame 13 holds the topology of 13..15
  CacheReader r(path);
  expectSameFrame(r.readFrame(2), makeFrame(2));
  try {
    r.readFrame(4);
    FAIL() << "no CorruptDataError";
  } catch (const CorruptDataError& e) {
    EXPECT_TRUE(contains(e.what(), "frame 13")) << e.what();
    EXPECT_TRUE(contains(e.what(), "CRC")) << e.what();
  }
  // Frame 13's chunk, and frames 14 and 15, whose topology it holds.
  const auto issues = r.verifyAll();
  ASSERT_EQ(issues.size(), 3u);
  EXPECT_EQ(issues[0].frame, 13);
  EXPECT_TRUE(contains(issues[0].message, "CRC")) << issues[0].message;
  EXPECT_TRUE(contains(issues[1].message, "its topology is unreadable")) << issues[1].message;
}

TEST_F(PcacheTest, FlippedByteWithoutFooterStopsRecoveryBeforeIt) {
  const std::string path = file("crashed.pcache");
  const auto sizes = writeCache(path, /*close=*/false);
  flipByte(path, sizes[2] + kChunkPrefix + 30);
  CacheReader r(path);
  EXPECT_TRUE(r.recovered());
  ASSERT_EQ(r.frameCount(), 2u);
  ASSERT_EQ(r.issues().size(), 1u);
  EXPECT_EQ(r.issues()[0].frameIndex, 2);
  EXPECT_TRUE(contains(r.issues()[0].message, "CRC")) << r.issues()[0].message;
  for (int k = 0; k < 2; ++k) expectSameFrame(r.readFrame(k), makeFrame(k));
}

TEST_F(PcacheTest, DamagedHeaderIsAnInputErrorNamingTheFile) {
  const std::string path = file("shot.pcache");
  const auto sizes = writeCache(path);
  const auto bytes = readBytes(path);
  for (std::uint64_t offset : {std::uint64_t{0}, std::uint64_t{8}, std::uint64_t{8 + 20},
                               std::uint64_t{8 + kChunkPrefix + 40}, sizes[0] - 1}) {
    SCOPED_TRACE("flipped byte " + std::to_string(offset));
    auto damaged = bytes;
    damaged[offset] ^= 0x10;
    writeBytes(path, damaged);
    try {
      CacheReader r(path);
      FAIL() << "no InputError";
    } catch (const InputError& e) {
      EXPECT_TRUE(contains(e.what(), path)) << e.what();
    }
  }
  writeBytes(path, truncated(bytes, sizes[0] - 3));
  EXPECT_THROW(CacheReader{path}, InputError);
  writeBytes(path, {});
  EXPECT_THROW(CacheReader{path}, InputError);
}

TEST_F(PcacheTest, MissingFileIsAnInputError) {
  const std::string path = file("nope.pcache");
  try {
    CacheReader r(path);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_TRUE(contains(e.what(), path)) << e.what();
  }
  EXPECT_THROW(CacheReader{dir().string()}, InputError);
}

TEST_F(PcacheTest, ExtensionSubBlocksAreSkippedAndKept) {
  const std::string path = file("ext.pcache");
  CacheHeader h = makeHeader();
  h.extensions = {{{'N', 'O', 'T', 'E'}, {1, 2, 3}}};
  FrameRecord f0 = makeFrame(0);
  f0.extensions = {{{'S', 'N', 'D', ' '}, {0xFF, 0x00, 0x7F, 0x80, 0x01}},
                   {{'T', 'E', 'A', 'R'}, {}},
                   {{'\0', '\x01', '\xfe', '\xff'}, std::vector<std::uint8_t>(1000, 0xAB)}};
  FrameRecord f1 = makeFrame(1);
  {
    CacheWriter w(path, h);
    w.append(f0);
    w.append(f1);
    w.close();
  }
  CacheReader r(path);
  expectSameHeader(r.header(), h);
  ASSERT_EQ(r.frameCount(), 2u);
  expectSameFrame(r.readFrame(0), f0);  // fields around the sub-blocks are intact
  expectSameFrame(r.readFrame(1), f1);
  EXPECT_TRUE(r.verifyAll().empty());
}

// A chunk type from a later format revision between two frames: a scanning
// reader skips it.
TEST_F(PcacheTest, UnknownChunkTypesAreSkippedWhenScanning) {
  const std::string path = file("crashed.pcache");
  const auto sizes = writeCache(path, /*close=*/false);
  auto bytes = readBytes(path);
  std::vector<std::uint8_t> chunk = {'X', 'T', 'R', 'A', 1, 0, 0, 0, 3, 0,
                                     0,   0,   0,   0,   0, 0, 7, 8, 9};
  const std::uint32_t crc = crumple::crc32(chunk.data(), chunk.size());
  for (int k = 0; k < 4; ++k) chunk.push_back(static_cast<std::uint8_t>(crc >> (8 * k)));
  bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(sizes[2]), chunk.begin(), chunk.end());
  writeBytes(path, bytes);
  CacheReader r(path);
  EXPECT_TRUE(r.recovered());
  ASSERT_EQ(r.frameCount(), static_cast<std::size_t>(kFrames));
  for (int k = 0; k < kFrames; ++k) expectSameFrame(r.readFrame(k), makeFrame(k));
}

TEST_F(PcacheTest, EmptyCacheRoundTrips) {
  const std::string path = file("empty.pcache");
  {
    CacheWriter w(path, makeHeader());
    w.close();
    w.close();  // a second close does nothing
  }
  CacheReader r(path);
  EXPECT_FALSE(r.recovered());
  EXPECT_EQ(r.frameCount(), 0u);
  EXPECT_THROW(r.readFrame(0), std::out_of_range);
}

TEST_F(PcacheTest, WriterMisuseIsRejected) {
  const std::string path = file("misuse.pcache");
  CacheWriter w(path, makeHeader());
  w.append(makeFrame(1));
  EXPECT_THROW(w.append(makeFrame(1)), std::invalid_argument);
  EXPECT_THROW(w.append(makeFrame(0)), std::invalid_argument);
  w.append(makeFrame(2));
  w.close();
  EXPECT_THROW(w.append(makeFrame(3)), std::logic_error);
  CacheReader r(path);
  EXPECT_EQ(r.frameCount(), 2u);
}

TEST_F(PcacheTest, WriterThatCannotCreateTheFileThrowsInputError) {
  const std::string path = file("missing/folder/shot.pcache");
  try {
    CacheWriter w(path, makeHeader());
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_TRUE(contains(e.what(), path + ": cannot create cache: ")) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST_F(PcacheTest, ReaderMovesAndReadsConcurrently) {
  const std::string path = file("shot.pcache");
  writeCache(path);
  CacheReader a(path);
  CacheReader b = std::move(a);
  ASSERT_EQ(b.frameCount(), static_cast<std::size_t>(kFrames));
  std::vector<std::thread> threads;
  std::vector<int> failures(4, 0);
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int rep = 0; rep < 5; ++rep)
        for (int k = 0; k < kFrames; ++k) {
          const FrameRecord f = b.readFrame((k + t) % kFrames);
          if (f.triangles != makeFrame((k + t) % kFrames).triangles) ++failures[t];
        }
    });
  for (auto& th : threads) th.join();
  for (int t = 0; t < 4; ++t) EXPECT_EQ(failures[t], 0);
}

}  // namespace
}  // namespace crumple::cache
