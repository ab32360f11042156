#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "crumple/core/index.hpp"

using namespace crumple;

namespace {

template <class T>
concept Convertible = requires(T t) {
  idx(t);
};

// idx takes signed ids and counts only: an unsigned value needs no
// conversion and a floating-point one is not an index.
static_assert(Convertible<int>);
static_assert(Convertible<std::int64_t>);
static_assert(Convertible<std::ptrdiff_t>);
static_assert(!Convertible<std::size_t>);
static_assert(!Convertible<unsigned>);
static_assert(!Convertible<double>);
static_assert(idx(0) == 0 && idx(7) == 7);

}  // namespace

TEST(Index, IdxIsTheSizeTOfANonNegativeId) {
  const std::vector<int> v{10, 11, 12};
  const int id = 2;
  EXPECT_EQ(idx(id), std::size_t{2});
  EXPECT_EQ(v[idx(id)], 12);
  EXPECT_EQ(idx(std::int64_t{1} << 40), std::size_t{1} << 40);
  std::vector<double> sized;
  sized.resize(idx(id + 3));
  EXPECT_EQ(sized.size(), 5u);
}

TEST(Index, InRangeRejectsNegativeAndPastTheEndIds) {
  const std::vector<int> v{1, 2, 3};
  EXPECT_TRUE(inRange(v, 0));
  EXPECT_TRUE(inRange(v, 2));
  EXPECT_FALSE(inRange(v, 3));
  EXPECT_FALSE(inRange(v, -1));
  EXPECT_FALSE(inRange(std::vector<int>{}, 0));
  const std::array<char, 2> a{};
  EXPECT_TRUE(inRange(a, 1));
  EXPECT_FALSE(inRange(a, 2));
  EXPECT_FALSE(inRange(a, std::int64_t{-5}));
}

#ifndef NDEBUG
TEST(IndexDeathTest, IdxAssertsOnANegativeIdInDebugBuilds) {
  EXPECT_DEATH((void)idx(-1), "negative id");
}
#endif
