// The one byte codec (core/byte_io.hpp): the documented little-endian layout
// whatever the host, bounds-checked reads, and messages that name the
// source, the record and the field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include "crumple/core/byte_io.hpp"
#include "crumple/core/error.hpp"

namespace crumple {
namespace {

std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const CorruptDataError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ByteIo, WritesLittleEndianByteByByte) {
  Bytes b;
  ByteWriter w(b);
  w.u32(0x01020304u);
  w.i32(-2);
  w.u64(0x0102030405060708ull);
  w.f64(1.0);
  w.f32(-0.0f);
  w.tag({'A', 'B', 'C', 'D'});
  w.str32("hi", "text");
  w.boolean(true);
  const Bytes expected{0x04, 0x03, 0x02, 0x01,                          // u32
                       0xfe, 0xff, 0xff, 0xff,                          // i32 -2
                       0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01,  // u64
                       0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xf0, 0x3f,  // f64 1.0
                       0x00, 0x00, 0x00, 0x80,                          // f32 -0.0
                       'A',  'B',  'C',  'D',                           // tag
                       0x02, 0x00, 0x00, 0x00, 'h',  'i',               // str32
                       0x01};                                           // boolean
  EXPECT_EQ(b, expected);
}

TEST(ByteIo, ReadsBackWhatWasWrittenBitForBit) {
  Bytes b;
  ByteWriter w(b);
  w.u8(7);
  w.i32(std::numeric_limits<std::int32_t>::min());
  w.i64(-1234567890123);
  w.f64(-0.0);
  w.f64(std::numeric_limits<double>::denorm_min());
  w.f32(std::numeric_limits<float>::infinity());
  w.count64(3);
  w.str64("frame \xff");
  ByteReader r(b, {"t"});
  EXPECT_EQ(r.u8(), 7);
  EXPECT_EQ(r.i32(), std::numeric_limits<std::int32_t>::min());
  EXPECT_EQ(r.i64(), -1234567890123);
  EXPECT_TRUE(std::signbit(r.f64()));
  EXPECT_EQ(r.f64(), std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(r.f32(), std::numeric_limits<float>::infinity());
  EXPECT_EQ(r.count64(0), 3u);
  EXPECT_EQ(r.str64(), "frame \xff");
  EXPECT_TRUE(r.atEnd());
  EXPECT_NO_THROW(r.expectEnd());
}

TEST(ByteIo, EveryFailureNamesSourceRecordFieldAndOffset) {
  Bytes b;
  ByteWriter(b).u32(5);
  {
    ByteReader r(b, {"pcache TEST sub-block"});
    r.at("patch", 2);
    EXPECT_EQ(messageOf([&] { (void)r.u64("size"); }),
              "pcache TEST sub-block: patch 2: size truncated");
  }
  {
    ByteReader r(b, {"the checkpoint", true});
    EXPECT_EQ(messageOf([&] { (void)r.count32(1, "point count"); }),
              "the checkpoint: point count 5 runs past the end (0 bytes left) (at byte 4)");
  }
  {
    ByteReader r(b, {"s"});
    (void)r.u8();
    EXPECT_EQ(messageOf([&] { r.expectEnd(); }), "s: 3 trailing bytes");
  }
  {
    Bytes flag{2};
    ByteReader r(flag, {"s"});
    EXPECT_EQ(messageOf([&] { (void)r.boolean("closed"); }), "s: closed: a flag of 2");
  }
}

// A damaged count cannot ask for more items than the bytes left can hold,
// whatever the item size: no huge allocation from a flipped bit.
TEST(ByteIo, ACountLargerThanTheRestIsRefused) {
  Bytes b;
  ByteWriter w(b);
  w.u64(std::uint64_t{1} << 60);
  w.u32(0xffffffffu);
  ByteReader r(b, {"s"});
  EXPECT_THROW((void)r.count64(8), CorruptDataError);
  const Bytes tail(b.begin() + 8, b.end());
  ByteReader r32(tail, {"s"});
  EXPECT_THROW((void)r32.count32(1), CorruptDataError);
}

TEST(ByteIo, AThirtyTwoBitCountRefusesMoreThanItHolds) {
  Bytes b;
  ByteWriter w(b);
  EXPECT_THROW(w.count32(std::size_t{1} << 33, "points"), std::length_error);
  EXPECT_TRUE(b.empty());
}

}  // namespace
}  // namespace crumple
