#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numeric>
#include <set>
#include <string>
#include <vector>

#include "crumple/core/crc32.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/parallel.hpp"
#include "crumple/core/progress.hpp"
#include "crumple/core/rng.hpp"
#include "crumple/core/state_io.hpp"
#include "crumple/core/units.hpp"

using namespace crumple;

TEST(Crc32, MatchesTheStandardCheckValue) {
  const char* s = "123456789";
  EXPECT_EQ(crc32(s, std::strlen(s)), 0xCBF43926U);
  // Incremental use gives the same value.
  EXPECT_EQ(crc32(s + 4, 5, crc32(s, 4)), 0xCBF43926U);
  EXPECT_EQ(crc32(nullptr, 0), 0U);
}

TEST(CounterRng, IsAPureFunctionOfItsKey) {
  const CounterRng a(42, 7, RngPurpose::SingularityPlacement);
  const CounterRng b(42, 7, RngPurpose::SingularityPlacement);
  for (std::uint64_t i = 0; i < 100; ++i) EXPECT_EQ(a.bits(i), b.bits(i));
  // Any part of the key changes the stream.
  EXPECT_NE(a.bits(0), CounterRng(43, 7, RngPurpose::SingularityPlacement).bits(0));
  EXPECT_NE(a.bits(0), CounterRng(42, 8, RngPurpose::SingularityPlacement).bits(0));
  EXPECT_NE(a.bits(0), CounterRng(42, 7, RngPurpose::FiberTexture).bits(0));
}

TEST(CounterRng, UniformIsInRangeWithPlausibleMean) {
  const CounterRng r(1, 0, RngPurpose::Generic);
  double sum = 0.0;
  std::set<std::uint64_t> distinct;
  constexpr int n = 100000;
  for (int i = 0; i < n; ++i) {
    const double u = r.uniform(static_cast<std::uint64_t>(i));
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    distinct.insert(r.bits(static_cast<std::uint64_t>(i)));
  }
  EXPECT_NEAR(sum / n, 0.5, 0.005);
  EXPECT_EQ(distinct.size(), static_cast<std::size_t>(n));
}

TEST(Units, KnownAndUnknown) {
  EXPECT_DOUBLE_EQ(*metresPerUnit("cm"), 0.01);
  EXPECT_DOUBLE_EQ(*metresPerUnit("m"), 1.0);
  EXPECT_DOUBLE_EQ(*metresPerUnit("mm"), 0.001);
  EXPECT_DOUBLE_EQ(*metresPerUnit("in"), 0.0254);
  EXPECT_FALSE(metresPerUnit("furlong").has_value());
}

TEST(ParallelFor, CoversEveryIndexOnceForAnyThreadCount) {
  for (int threads : {1, 2, 3, 8}) {
    setThreadCount(threads);
    std::vector<int> hits(10007, 0);
    parallelFor(
        hits.size(),
        [&](std::size_t b, std::size_t e) {
          for (std::size_t i = b; i < e; ++i) ++hits[i];
        },
        16);
    for (int h : hits) ASSERT_EQ(h, 1) << "threads " << threads;
  }
  setThreadCount(1);
}

TEST(ParallelFor, RethrowsAWorkerException) {
  setThreadCount(2);
  EXPECT_THROW(parallelFor(
                   1000,
                   [](std::size_t b, std::size_t) {
                     if (b > 0) throw std::runtime_error("boom");
                   },
                   10),
               std::runtime_error);
  setThreadCount(1);
}

// Progress lines: "PROGRESS <percent>" per step when not a terminal, and
// nothing at all with no stream (a quiet run, ShotOptions::log = nullptr).
TEST(Progress, WritesOneLinePerStepOrNothingWithoutAStream) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    crumple::Progress p("work", 4, f, 0);
    for (long i = 1; i <= 4; ++i) p.update(i);
    p.finish();
  }
  std::rewind(f);
  std::string text;
  for (int c; (c = std::fgetc(f)) != EOF;) text.push_back(static_cast<char>(c));
  std::fclose(f);
  EXPECT_EQ(text, "PROGRESS 25\nPROGRESS 50\nPROGRESS 75\nPROGRESS 100\n");
  crumple::Progress quiet("work", 4, nullptr, -1);
  EXPECT_FALSE(quiet.interactive());
  quiet.update(2);  // no stream: nothing to write to, and no crash
  quiet.finish();
}

// The checkpoint's byte layer: everything written reads back bit
// for bit; a wrong section, a short state or a huge count is refused.
TEST(StateIo, RoundTripsAndRefusesDamage) {
  StateWriter w;
  w.tag("TEST");
  w.u8(7);
  w.i32(-5);
  w.i64(-1234567890123);
  w.f64(-0.0);
  w.f64(std::numeric_limits<double>::denorm_min());
  w.boolean(true);
  w.str("frame \xff");
  w.vec3s({Vec3(1, 2, 3), Vec3(-1, 0.5, 1e300)});
  w.f64s({0.1, 0.2});
  w.i32s({1, -2, 3});
  w.bytes({1, 0, 1});
  w.triangles({{0, 1, 2}});
  StateReader r(w.data(), "t");
  r.tag("TEST");
  EXPECT_EQ(r.u8(), 7);
  EXPECT_EQ(r.i32(), -5);
  EXPECT_EQ(r.i64(), -1234567890123);
  EXPECT_TRUE(std::signbit(r.f64()));
  EXPECT_EQ(r.f64(), std::numeric_limits<double>::denorm_min());
  EXPECT_TRUE(r.boolean());
  EXPECT_EQ(r.str(), "frame \xff");
  const auto v = r.vec3s();
  ASSERT_EQ(v.size(), 2u);
  EXPECT_EQ(v[1].z(), 1e300);
  EXPECT_EQ(r.f64s(), (std::vector<double>{0.1, 0.2}));
  EXPECT_EQ(r.i32s(), (std::vector<int>{1, -2, 3}));
  EXPECT_EQ(r.bytes(), (std::vector<char>{1, 0, 1}));
  EXPECT_EQ(r.triangles().at(0)[2], 2);
  EXPECT_TRUE(r.atEnd());
  EXPECT_THROW(r.u8(), CorruptDataError);  // past the end
  StateReader wrong(w.data(), "t");
  EXPECT_THROW(wrong.tag("ELAS"), CorruptDataError);
  StateWriter huge;
  huge.u64(std::uint64_t{1} << 60);
  StateReader h(huge.data(), "t");
  EXPECT_THROW((void)h.f64s(), CorruptDataError);
}

// A checkpoint's points and vectors are finite: a NaN position is damage
// (exit 2 on resume), not a state to simulate from.
TEST(StateIo, ANonFinitePointIsDamage) {
  StateWriter w;
  w.vec3(Vec3(0.0, std::numeric_limits<double>::quiet_NaN(), 0.0));
  w.vec2s({Vec2(1.0, 2.0), Vec2(std::numeric_limits<double>::infinity(), 0.0)});
  StateReader r(w.data(), "t");
  EXPECT_THROW((void)r.vec3(), CorruptDataError);
  EXPECT_THROW((void)r.vec2s(), CorruptDataError);
}
