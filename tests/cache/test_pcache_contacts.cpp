// The COLL / CONT sub-blocks (cache/pcache_contacts.hpp, docs/PCACHE.md).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_contacts.hpp"
#include "crumple/core/error.hpp"
#include "temp_dir.hpp"

namespace crumple::cache {
namespace {

using Bytes = std::vector<std::uint8_t>;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

std::vector<ColliderInfo> someColliders() {
  return {{"table", "oak", 0.3},
          {"", "", 0.0},  // empty strings, no friction
          {std::string("ball\0\xff", 6), "rubber \xc3\xa9", 1.0 / 3.0}};
}

std::vector<ContactRecord> someContacts() {
  return {{0, 0, 0.0f, 0.0f},
          {3, kSelfContact, 1.5f, 2.25f},
          {3, 2, std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::max()},
          {2147483647, 1, 0.1f, 1e-30f}};
}

// Contacts a four-vertex frame can hold (the reader checks vertices against it).
std::vector<ContactRecord> frameContacts() {
  auto contacts = someContacts();
  contacts.back().vertex = 2;
  return contacts;
}

bool sameBits(float a, float b) {
  return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
}

void expectSameContacts(const std::vector<ContactRecord>& a, const std::vector<ContactRecord>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i], b[i]) << "contact " << i;
    EXPECT_TRUE(sameBits(a[i].slideSpeed, b[i].slideSpeed)) << "contact " << i;
    EXPECT_TRUE(sameBits(a[i].normalForce, b[i].normalForce)) << "contact " << i;
  }
}

void setU32(Bytes& b, std::size_t at, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b.at(at + k) = static_cast<std::uint8_t>(v >> (8 * k));
}
void setF32(Bytes& b, std::size_t at, float v) { setU32(b, at, std::bit_cast<std::uint32_t>(v)); }
void setF64(Bytes& b, std::size_t at, double v) {
  const auto u = std::bit_cast<std::uint64_t>(v);
  for (int k = 0; k < 8; ++k) b.at(at + k) = static_cast<std::uint8_t>(u >> (8 * k));
}

CacheHeader makeHeader() {
  CacheHeader h;
  h.fps = 24.0;
  h.frameStart = 1;
  h.frameEnd = 3;
  h.sceneName = "contacts";
  h.sheetWidth = 0.2;
  h.sheetHeight = 0.3;
  return h;
}

FrameRecord makeFrame(int frame) {
  FrameRecord f;
  f.frame = frame;
  f.time = frame / 24.0;
  f.pattern = {Vec2(0, 0), Vec2(0.2, 0), Vec2(0.2, 0.3), Vec2(0, 0.3)};
  f.triangles = {{0, 1, 2}, {0, 2, 3}};
  f.regionOfTriangle = {0, 0};
  f.regionTypes = {0};
  for (const auto& p : f.pattern) f.positions.push_back(Vec3(p.x(), p.y(), 0.01 * frame));
  return f;
}

class PcacheContactsTest : public test::TempDirTest {};

// The bytes are the ones docs/PCACHE.md specifies, field by field.
TEST(PcacheContacts, EncodingFollowsTheDocumentedLayout) {
  const ExtensionBlock coll = encodeColliders({{"ab", "x", 0.5}});
  EXPECT_EQ(coll.tag, (std::array<char, 4>{'C', 'O', 'L', 'L'}));
  EXPECT_EQ(coll.data, (Bytes{1, 0, 0, 0,                           // n
                              2, 0, 0, 0, 'a', 'b',                 // str name
                              1, 0, 0, 0, 'x',                      // str material
                              0, 0, 0, 0, 0,   0,   0xE0, 0x3F}));  // f64 0.5
  const ExtensionBlock cont = encodeContacts({{7, kSelfContact, 1.5f, 2.0f}, {258, 1, 0, 0}});
  EXPECT_EQ(cont.tag, (std::array<char, 4>{'C', 'O', 'N', 'T'}));
  EXPECT_EQ(cont.data, (Bytes{2, 0, 0,    0,                             // n
                              7, 0, 0,    0,    0xFF, 0xFF, 0xFF, 0xFF,  // vertex, collider -1
                              0, 0, 0xC0, 0x3F, 0,    0,    0,    0x40,  // 1.5f, 2.0f
                              2, 1, 0,    0,    1,    0,    0,    0,     // 258, 1
                              0, 0, 0,    0,    0,    0,    0,    0}));
  EXPECT_EQ(encodeContacts({}).data, (Bytes{0, 0, 0, 0}));
  EXPECT_EQ(encodeColliders({}).data, (Bytes{0, 0, 0, 0}));
}

TEST_F(PcacheContactsTest, RoundTripThroughACacheFile) {
  const std::string path = file("contacts.pcache");
  CacheHeader h = makeHeader();
  h.extensions = {encodeColliders(someColliders())};
  FrameRecord f1 = makeFrame(1), f2 = makeFrame(2), f3 = makeFrame(3);
  f1.extensions = {encodeContacts(frameContacts())};
  f2.extensions = {encodeContacts({})};  // touched nothing, said so
  // f3: no CONT block at all.
  {
    CacheWriter w(path, h);
    w.append(f1);
    w.append(f2);
    w.append(f3);
    w.close();
  }
  const CacheReader r(path);
  ASSERT_FALSE(r.recovered());
  const auto colliders = decodeColliders(r.header().extensions);
  ASSERT_TRUE(colliders.has_value());
  EXPECT_EQ(*colliders, someColliders());
  ASSERT_EQ(r.frameCount(), 3u);
  const auto c1 = decodeContacts(r.readFrame(0).extensions);
  ASSERT_TRUE(c1.has_value());
  expectSameContacts(*c1, frameContacts());
  const auto c2 = decodeContacts(r.readFrame(1).extensions);
  ASSERT_TRUE(c2.has_value());
  EXPECT_TRUE(c2->empty());
  EXPECT_FALSE(decodeContacts(r.readFrame(2).extensions).has_value());
}

TEST_F(PcacheContactsTest, AbsentBlockIsNullopt) {
  EXPECT_FALSE(decodeColliders({}).has_value());
  EXPECT_FALSE(decodeContacts({}).has_value());
  // Other blocks, including each other's tag and near misses, are not theirs.
  const std::vector<ExtensionBlock> others = {{{'P', 'T', 'E', 'X'}, {1, 2, 3}},
                                              {{'c', 'o', 'l', 'l'}, {0xFF}},
                                              {{'C', 'O', 'N', ' '}, {0xFF}},
                                              encodeContacts(someContacts())};
  EXPECT_FALSE(decodeColliders(others).has_value());
  const std::vector<ExtensionBlock> headerOnly = {encodeColliders(someColliders()),
                                                  {{'c', 'o', 'n', 't'}, {0xFF}}};
  EXPECT_FALSE(decodeContacts(headerOnly).has_value());
  // An older cache: no extensions anywhere.
  const std::string path = file("plain.pcache");
  {
    CacheWriter w(path, makeHeader());
    w.append(makeFrame(1));
    w.close();
  }
  const CacheReader r(path);
  EXPECT_FALSE(decodeColliders(r.header().extensions).has_value());
  EXPECT_FALSE(decodeContacts(r.readFrame(0).extensions).has_value());
}

// decode(bytes) must throw CorruptDataError naming the block and `part`.
void expectCorrupt(const std::function<void()>& decode, const std::string& block,
                   const std::string& part, const std::string& label) {
  SCOPED_TRACE(label);
  try {
    decode();
    ADD_FAILURE() << "no CorruptDataError";
  } catch (const CorruptDataError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(block), std::string::npos) << what;
    EXPECT_NE(what.find(part), std::string::npos) << what;
  }
}

TEST(PcacheContacts, MalformedContactsThrow) {
  const Bytes good = encodeContacts(someContacts()).data;  // 4 records of 16 bytes after n
  ASSERT_EQ(good.size(), 4u + 4u * 16u);
  ASSERT_TRUE(decodeContacts({{kContactsTag, good}}).has_value());  // the baseline is fine
  const auto corrupt = [&](const std::string& label, const std::string& part,
                           const std::function<void(Bytes&)>& damage) {
    Bytes b = good;
    damage(b);
    expectCorrupt([&] { (void)decodeContacts({{kContactsTag, b}}); }, "CONT", part, label);
  };
  const std::size_t rec1 = 4 + 16;  // second record
  corrupt("empty", "truncated", [](Bytes& b) { b.clear(); });
  corrupt("count cut short", "truncated", [](Bytes& b) { b.resize(2); });
  corrupt("last record cut short", "runs past", [](Bytes& b) { b.pop_back(); });
  corrupt("trailing byte", "1 trailing bytes", [](Bytes& b) { b.push_back(0); });
  corrupt("trailing record", "16 trailing bytes", [](Bytes& b) { setU32(b, 0, 3); });
  corrupt("count past the end", "runs past", [](Bytes& b) { setU32(b, 0, 5); });
  corrupt("count -1", "4294967295", [](Bytes& b) { setU32(b, 0, 0xFFFFFFFFu); });
  corrupt("absurd count", "runs past", [](Bytes& b) { setU32(b, 0, 0x40000000u); });
  corrupt("negative vertex", "contact 1: vertex -1",
          [&](Bytes& b) { setU32(b, rec1, 0xFFFFFFFFu); });
  corrupt("collider -2", "contact 1: collider -2",
          [&](Bytes& b) { setU32(b, rec1 + 4, 0xFFFFFFFEu); });
  corrupt("NaN slide speed", "contact 1: slide speed",
          [&](Bytes& b) { setF32(b, rec1 + 8, kNaN); });
  corrupt("infinite slide speed", "slide speed inf", [&](Bytes& b) { setF32(b, rec1 + 8, kInf); });
  corrupt("negative slide speed", "slide speed -0.5",
          [&](Bytes& b) { setF32(b, rec1 + 8, -0.5f); });
  corrupt("NaN normal force", "normal force", [&](Bytes& b) { setF32(b, rec1 + 12, -kNaN); });
  corrupt("infinite normal force", "normal force", [&](Bytes& b) { setF32(b, rec1 + 12, kInf); });
  corrupt("negative normal force", "normal force -1",
          [&](Bytes& b) { setF32(b, rec1 + 12, -1.0f); });
  expectCorrupt(
      [&] {
        (void)decodeContacts({{kContactsTag, good}, {kContactsTag, good}});
      },
      "CONT", "more than once", "two CONT blocks");
}

TEST(PcacheContacts, MalformedCollidersThrow) {
  const Bytes good = encodeColliders({{"table", "oak", 0.3}, {"ball", "rubber", 0.8}}).data;
  ASSERT_TRUE(decodeColliders({{kCollidersTag, good}}).has_value());
  // Offsets in the second record: 4 (n) + 4+5 + 4+3 + 8 = 28.
  const std::size_t rec1 = 28;
  ASSERT_EQ(good.size(), rec1 + 4 + 4 + 4 + 6 + 8);
  const auto corrupt = [&](const std::string& label, const std::string& part,
                           const std::function<void(Bytes&)>& damage) {
    Bytes b = good;
    damage(b);
    expectCorrupt([&] { (void)decodeColliders({{kCollidersTag, b}}); }, "COLL", part, label);
  };
  corrupt("empty", "truncated", [](Bytes& b) { b.clear(); });
  corrupt("friction cut short", "collider 1: friction truncated", [](Bytes& b) { b.pop_back(); });
  corrupt("material cut short", "collider 1: material",
          [](Bytes& b) { b.resize(rec1 + 4 + 4 + 2); });
  corrupt("name length past the end", "collider 1: name 1000 runs past the end",
          [&](Bytes& b) { setU32(b, rec1, 1000); });
  corrupt("name length -1", "collider 0: name 4294967295 runs past the end",
          [&](Bytes& b) { setU32(b, 4, 0xFFFFFFFFu); });
  corrupt("trailing byte", "1 trailing bytes", [](Bytes& b) { b.push_back('!'); });
  corrupt("fewer colliders than stored", "trailing bytes", [](Bytes& b) { setU32(b, 0, 1); });
  corrupt("count past the end", "collider count 4 runs past", [](Bytes& b) { setU32(b, 0, 4); });
  corrupt("count -1", "4294967295", [](Bytes& b) { setU32(b, 0, 0xFFFFFFFFu); });
  corrupt("NaN friction", "collider 1: friction",
          [&](Bytes& b) { setF64(b, b.size() - 8, std::nan("")); });
  corrupt("infinite friction", "friction inf",
          [&](Bytes& b) { setF64(b, b.size() - 8, HUGE_VAL); });
  corrupt("negative friction", "friction -0.25", [&](Bytes& b) { setF64(b, b.size() - 8, -0.25); });
  expectCorrupt(
      [&] {
        (void)decodeColliders({{kCollidersTag, good}, {kCollidersTag, good}});
      },
      "COLL", "more than once", "two COLL blocks");
}

// The encoders refuse what the decoders would reject, so a producer bug shows
// where it happens and not in a later reader.
TEST(PcacheContacts, EncodersRejectInvalidRecords) {
  EXPECT_THROW(encodeContacts({{-1, 0, 0, 0}}), std::invalid_argument);
  EXPECT_THROW(encodeContacts({{0, -2, 0, 0}}), std::invalid_argument);
  EXPECT_THROW(encodeContacts({{0, 0, kNaN, 0}}), std::invalid_argument);
  EXPECT_THROW(encodeContacts({{0, 0, -1.0f, 0}}), std::invalid_argument);
  EXPECT_THROW(encodeContacts({{0, 0, 0, kInf}}), std::invalid_argument);
  EXPECT_THROW(encodeColliders({{"a", "b", std::nan("")}}), std::invalid_argument);
  EXPECT_THROW(encodeColliders({{"a", "b", -0.1}}), std::invalid_argument);
  EXPECT_NO_THROW(encodeContacts({{0, kSelfContact, 0, 0}}));
}

// COLL and CONT sit among other sub-blocks (the look data, unknown future
// blocks); the writer and reader keep them all verbatim and in order, and a
// read-then-rewrite copy of the cache is byte-identical.
TEST_F(PcacheContactsTest, BlocksAreKeptVerbatimAlongsideOthers) {
  const std::string path = file("mixed.pcache");
  CacheHeader h = makeHeader();
  h.extensions = {{{'P', 'T', 'E', 'X'}, Bytes(300, 0x89)},
                  encodeColliders(someColliders()),
                  {{'N', 'O', 'T', 'E'}, {}}};
  FrameRecord f1 = makeFrame(1), f2 = makeFrame(2);
  f1.extensions = {{{'P', 'R', 'P', 'M'}, Bytes(128, 0x3F)},
                   encodeContacts(frameContacts()),
                   {{'S', 'N', 'D', ' '}, {1, 2, 3}}};
  f2.extensions = {encodeContacts({{1, 0, 0.5f, 3.0f}}), {{'\0', '\1', '\2', '\3'}, {0}}};
  {
    CacheWriter w(path, h);
    w.append(f1);
    w.append(f2);
    w.close();
  }
  const CacheReader r(path);
  EXPECT_EQ(r.header().extensions, h.extensions);
  EXPECT_EQ(decodeColliders(r.header().extensions), someColliders());
  const FrameRecord g1 = r.readFrame(0), g2 = r.readFrame(1);
  EXPECT_EQ(g1.extensions, f1.extensions);
  EXPECT_EQ(g2.extensions, f2.extensions);
  expectSameContacts(*decodeContacts(g1.extensions), frameContacts());
  expectSameContacts(*decodeContacts(g2.extensions), {{1, 0, 0.5f, 3.0f}});
  EXPECT_TRUE(r.verifyAll().empty());

  const std::string copy = file("copy.pcache");
  {
    CacheWriter w(copy, r.header());
    w.append(g1);
    w.append(g2);
    w.close();
  }
  EXPECT_EQ(test::readBytes(copy), test::readBytes(path));
}

// A CRC-valid cache whose contacts name a vertex the frame does not have, or
// a collider the header does not list, is refused by the reader with the
// block named, before any tool indexes the frame's arrays with them.
TEST_F(PcacheContactsTest, TheReaderRefusesContactsOutsideTheFrame) {
  for (const ContactRecord bad : {ContactRecord{4, 0, 0.0f, 0.0f},     // 4 vertices: 0..3
                                  ContactRecord{1, 3, 0.0f, 0.0f}}) {  // 3 colliders
    const std::string path = file("bad.pcache");
    CacheHeader h = makeHeader();
    h.extensions = {encodeColliders(someColliders())};
    FrameRecord f = makeFrame(1);
    f.extensions = {encodeContacts({bad})};
    {
      CacheWriter w(path, h);
      w.append(f);
      w.close();
    }
    const CacheReader r(path);
    try {
      (void)r.readFrame(0);
      FAIL() << "contact " << bad.vertex << "/" << bad.collider << " was read";
    } catch (const CorruptDataError& e) {
      EXPECT_NE(std::string(e.what()).find("frame 1"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("CONT sub-block"), std::string::npos) << e.what();
    }
    ASSERT_EQ(r.verifyAll().size(), 1u);
  }
}

}  // namespace
}  // namespace crumple::cache
