// The motion sub-blocks (docs/PCACHE.md SHTR, VELO, PRPV): a shot's shutter
// and its frames' velocities read back as written (velocities rounded to
// float), and a malformed or mismatched block is an error naming the file,
// the frame and the block: truncated, trailing bytes, a second block, a
// non-finite or huge value, a count that does not match the frame, a frame
// of a shot with a shutter without its velocities.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_look.hpp"
#include "crumple/cache/pcache_motion.hpp"
#include "crumple/core/error.hpp"
#include "frame_refusal.hpp"
#include "temp_dir.hpp"

namespace crumple::cache {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

CacheHeader makeHeader(bool shutter) {
  CacheHeader h;
  h.frameStart = 1;
  h.frameEnd = 2;
  h.sheetWidth = 0.1;
  h.sheetHeight = 0.1;
  if (shutter) h.extensions = {encodeShutter({-0.25, 0.25})};
  return h;
}

// Two triangles, their velocities and one mesh prop's motion and its derivative.
FrameRecord makeFrame() {
  FrameRecord f;
  f.frame = 1;
  f.time = 1.0 / 24.0;
  f.pattern = {Vec2(0, 0), Vec2(0.1, 0), Vec2(0.1, 0.1), Vec2(0, 0.1)};
  f.triangles = {{0, 1, 2}, {0, 2, 3}};
  f.regionOfTriangle = {0, 0};
  f.regionTypes = {0};
  for (const Vec2& p : f.pattern) f.positions.push_back(Vec3(p.x(), 0.0, -p.y()));
  f.camera.position = Vec3(0, 1, 0);
  const std::vector<Vec3> v = {Vec3(1, 0, 0), Vec3(0.1, -2.5, 0), Vec3::Zero(), Vec3(0, 0, 1e-3)};
  Mat4 derivative = Mat4::Zero();
  derivative(0, 3) = 1.0;  // moving along +x at 1 m/s
  f.extensions = {encodePropMotions({Mat4::Identity()}), encodeVelocities(v),
                  encodePropVelocities({derivative})};
  return f;
}

// A block with the given tag and bytes.
ExtensionBlock raw(const std::array<char, 4>& tag, std::vector<std::uint8_t> bytes) {
  return {tag, std::move(bytes)};
}
std::vector<std::uint8_t> f32Bytes(const std::vector<float>& values) {
  std::vector<std::uint8_t> out;
  for (const float v : values) {
    std::uint8_t b[4];
    std::memcpy(b, &v, 4);  // the test host is little-endian, as the format
    out.insert(out.end(), b, b + 4);
  }
  return out;
}
std::vector<std::uint8_t> velocityBlock(std::uint32_t count, const std::vector<float>& values) {
  std::vector<std::uint8_t> out = {
      static_cast<std::uint8_t>(count), static_cast<std::uint8_t>(count >> 8),
      static_cast<std::uint8_t>(count >> 16), static_cast<std::uint8_t>(count >> 24)};
  const auto body = f32Bytes(values);
  out.insert(out.end(), body.begin(), body.end());
  return out;
}

class PcacheMotionTest : public test::TempDirTest {
 protected:
  std::string write(const CacheHeader& h, const FrameRecord& f) {
    const std::string path = file("m.pcache");
    CacheWriter w(path, h);  // the writer does not check: a hostile file is easy to make
    w.append(f);
    w.close();
    return path;
  }
};

TEST_F(PcacheMotionTest, ShutterVelocitiesAndPropDerivativesRoundTrip) {
  const FrameRecord written = makeFrame();
  const CacheReader r(write(makeHeader(true), written));
  EXPECT_EQ(decodeShutter(r.header().extensions), (Shutter{-0.25, 0.25}));
  const FrameRecord f = r.readFrame(0);
  const auto v = decodeVelocities(f.extensions);
  ASSERT_TRUE(v.has_value());
  ASSERT_EQ(v->size(), 4u);
  EXPECT_EQ((*v)[1], Vec3(0.1f, -2.5f, 0.0f)) << "float32, rounded once";
  EXPECT_EQ((*v)[3].z(), static_cast<double>(1e-3f));
  const auto d = decodePropVelocities(f.extensions);
  ASSERT_TRUE(d.has_value());
  ASSERT_EQ(d->size(), 1u);
  EXPECT_EQ((*d)[0](0, 3), 1.0);
  EXPECT_TRUE(r.verifyAll().empty());
  // 12 bytes a vertex (and the count) for VELO; 16 doubles a prop for PRPV.
  EXPECT_EQ(encodeVelocities(std::vector<Vec3>(100, Vec3::Zero())).data.size(), 4u + 1200u);
  EXPECT_EQ(encodePropVelocities({Mat4::Zero()}).data.size(), 4u + 128u);
  // A cache without a shutter has none of it.
  EXPECT_FALSE(decodeShutter({}).has_value());
  EXPECT_FALSE(decodeVelocities({}).has_value());
  EXPECT_FALSE(decodePropVelocities({}).has_value());
}

TEST_F(PcacheMotionTest, TheEncodersRefuseWhatTheReaderWould) {
  EXPECT_THROW((void)encodeShutter({0.25, -0.25}), std::invalid_argument);
  EXPECT_THROW((void)encodeShutter({0.0, 0.0}), std::invalid_argument) << "closed: no block";
  EXPECT_THROW((void)encodeShutter({-1.5, 0.0}), std::invalid_argument);
  EXPECT_THROW((void)encodeVelocities({Vec3(kNaN, 0, 0)}), std::invalid_argument);
  EXPECT_THROW((void)encodeVelocities({Vec3(0, 2e9, 0)}), std::invalid_argument);
  Mat4 bad = Mat4::Zero();
  bad(2, 1) = kNaN;
  EXPECT_THROW((void)encodePropVelocities({bad}), std::invalid_argument);
}

TEST_F(PcacheMotionTest, AMalformedOrMismatchedFrameBlockNamesFileFrameAndBlock) {
  struct Bad {
    const char* name;
    const char* block;  // what the message must name
    std::function<void(FrameRecord&)> damage;
  };
  const auto replace = [](FrameRecord& f, const std::array<char, 4>& tag, ExtensionBlock b) {
    for (auto& e : f.extensions)
      if (e.tag == tag) e = std::move(b);
  };
  const std::vector<Bad> cases = {
      {"a velocity short", "VELO sub-block",
       [&](FrameRecord& f) {
         replace(f, kVelocitiesTag, raw(kVelocitiesTag, velocityBlock(4, std::vector<float>(11))));
       }},
      {"trailing bytes", "VELO sub-block",
       [&](FrameRecord& f) {
         replace(f, kVelocitiesTag, raw(kVelocitiesTag, velocityBlock(4, std::vector<float>(13))));
       }},
      {"count beyond the block", "VELO sub-block",
       [&](FrameRecord& f) {
         replace(f, kVelocitiesTag,
                 raw(kVelocitiesTag, velocityBlock(0x40000000u, std::vector<float>(12))));
       }},
      {"NaN velocity", "VELO sub-block",
       [&](FrameRecord& f) {
         std::vector<float> v(12, 0.0f);
         v[7] = std::numeric_limits<float>::quiet_NaN();
         replace(f, kVelocitiesTag, raw(kVelocitiesTag, velocityBlock(4, v)));
       }},
      {"infinite velocity", "VELO sub-block",
       [&](FrameRecord& f) {
         std::vector<float> v(12, 0.0f);
         v[0] = -std::numeric_limits<float>::infinity();
         replace(f, kVelocitiesTag, raw(kVelocitiesTag, velocityBlock(4, v)));
       }},
      {"velocity of 3e38 m/s", "VELO sub-block",
       [&](FrameRecord& f) {
         std::vector<float> v(12, 0.0f);
         v[11] = 3e38f;
         replace(f, kVelocitiesTag, raw(kVelocitiesTag, velocityBlock(4, v)));
       }},
      {"fewer velocities than vertices", "VELO sub-block: 3 velocities for 4 vertices",
       [&](FrameRecord& f) {
         replace(f, kVelocitiesTag, encodeVelocities(std::vector<Vec3>(3, Vec3::Zero())));
       }},
      {"more velocities than vertices", "VELO sub-block: 5 velocities for 4 vertices",
       [&](FrameRecord& f) {
         replace(f, kVelocitiesTag, encodeVelocities(std::vector<Vec3>(5, Vec3::Zero())));
       }},
      {"two VELO blocks", "more than once",
       [&](FrameRecord& f) {
         f.extensions.push_back(encodeVelocities(std::vector<Vec3>(4, Vec3::Zero())));
       }},
      {"no VELO with a shutter", "VELO sub-block: missing",
       [&](FrameRecord& f) {
         std::erase_if(f.extensions,
                       [](const ExtensionBlock& b) { return b.tag == kVelocitiesTag; });
       }},
      {"NaN prop derivative", "PRPV sub-block",
       [&](FrameRecord& f) {
         Mat4 d = Mat4::Zero();
         d(3, 3) = kNaN;
         ExtensionBlock b = encodePropVelocities({Mat4::Zero()});
         std::memcpy(b.data.data() + 4 + 8 * 15, &d(3, 3), 8);
         replace(f, kPropVelocitiesTag, std::move(b));
       }},
      {"truncated prop derivative", "PRPV sub-block",
       [&](FrameRecord& f) {
         ExtensionBlock b = encodePropVelocities({Mat4::Zero()});
         b.data.resize(b.data.size() - 8);
         replace(f, kPropVelocitiesTag, std::move(b));
       }},
      {"a derivative per prop", "PRPV sub-block: 2 prop velocities for 1 prop motions",
       [&](FrameRecord& f) {
         replace(f, kPropVelocitiesTag, encodePropVelocities({Mat4::Zero(), Mat4::Zero()}));
       }},
      {"no PRPV with a shutter and props", "PRPV sub-block: missing",
       [&](FrameRecord& f) {
         std::erase_if(f.extensions,
                       [](const ExtensionBlock& b) { return b.tag == kPropVelocitiesTag; });
       }},
  };
  for (const Bad& c : cases) {
    SCOPED_TRACE(c.name);
    FrameRecord f = makeFrame();
    c.damage(f);
    test::expectFirstFrameRefused(write(makeHeader(true), f), c.block);
  }
}

// Without a shutter in the header a frame needs no velocities; any it has
// are still checked against the frame.
TEST_F(PcacheMotionTest, WithoutAShutterVelocitiesAreOptionalButChecked) {
  FrameRecord f = makeFrame();
  f.extensions = {};
  EXPECT_NO_THROW((void)CacheReader(write(makeHeader(false), f)).readFrame(0));
  f.extensions = {encodeVelocities(std::vector<Vec3>(2, Vec3::Zero()))};
  EXPECT_THROW((void)CacheReader(write(makeHeader(false), f)).readFrame(0), CorruptDataError);
}

TEST_F(PcacheMotionTest, AMalformedShutterIsAnInputErrorOnOpening) {
  const auto shutterBytes = [](double open, double close) {
    std::vector<std::uint8_t> b(16);
    std::memcpy(b.data(), &open, 8);
    std::memcpy(b.data() + 8, &close, 8);
    return b;
  };
  const std::vector<std::pair<const char*, std::vector<ExtensionBlock>>> cases = {
      {"closes before it opens", {raw(kShutterTag, shutterBytes(0.25, -0.25))}},
      {"empty", {raw(kShutterTag, shutterBytes(0.0, 0.0))}},
      {"NaN", {raw(kShutterTag, shutterBytes(kNaN, 0.25))}},
      {"beyond a frame", {raw(kShutterTag, shutterBytes(-2.0, 0.25))}},
      {"truncated", {raw(kShutterTag, std::vector<std::uint8_t>(12))}},
      {"trailing bytes", {raw(kShutterTag, std::vector<std::uint8_t>(20))}},
      {"twice", {encodeShutter({-0.25, 0.25}), encodeShutter({-0.25, 0.25})}},
  };
  for (const auto& [what, blocks] : cases) {
    SCOPED_TRACE(what);
    CacheHeader h = makeHeader(false);
    h.extensions = blocks;
    FrameRecord f = makeFrame();
    const std::string path = write(h, f);
    try {
      const CacheReader r(path);
      ADD_FAILURE() << "opened";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path + ": damaged cache header: pcache SHTR sub-block"),
                std::string::npos)
          << message;
    }
  }
}

}  // namespace
}  // namespace crumple::cache
