// The scene's [air] (docs/AIR.md): every key reaches sim::AirParams, its
// absence means no air, and bad values get one clear error.
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/io/scene.hpp"
#include "scene_test.hpp"

namespace crumple::io {
namespace {

using testing::expectError;
using testing::parse;

const std::string kSheet = "[sheet]\nwidth = 21\nheight = 29.7\n";

}  // namespace

TEST(SceneAir, AbsentMeansNoAirAndTheMassDampingStays) {
  const SceneSpec s = parse(kSheet);
  EXPECT_FALSE(s.sim.air.has_value());
  EXPECT_EQ(s.sim.massDamping, sim::SimParams{}.massDamping);
  EXPECT_FALSE(parse(kSheet + "[air]\nenabled = false\n").sim.air.has_value());
}

TEST(SceneAir, TheTableAloneGivesStillAirWithTheDefaults) {
  const SceneSpec s = parse(kSheet + "[air]\n");
  ASSERT_TRUE(s.sim.air.has_value());
  EXPECT_EQ(*s.sim.air, sim::AirParams{});
  // The mass damping is [sim]'s own, with or without air.
  EXPECT_EQ(s.sim.massDamping, sim::SimParams{}.massDamping);
  EXPECT_EQ(parse(kSheet + "[air]\n[sim]\nmass_damping = 0\n").sim.massDamping, 0.0);
}

TEST(SceneAir, EveryKeyReachesAirParams) {
  using Set = std::function<void(sim::AirParams&)>;
  const std::vector<std::pair<std::string, Set>> cases = {
      {"density = 1.1", [](auto& p) { p.density = 1.1; }},
      {"wind = [1, 0, 0.5]",
       [](auto& p) {
         p.wind = {{0.0, Vec3(1, 0, 0.5)}};
       }},
      {"wind_keys = [[0, 0, 0, 0], [0.5, 2, 0, 0]]",
       [](auto& p) {
         p.wind = {{0.0, Vec3::Zero()}, {0.5, Vec3(2, 0, 0)}};
       }},
      {"gust_speed = 0.7", [](auto& p) { p.gusts.speed = 0.7; }},
      {"gust_length = 0.2", [](auto& p) { p.gusts.lengthScale = 0.2; }},
      {"gust_time = 2", [](auto& p) { p.gusts.timeScale = 2.0; }},
      {"gust_modes = 8", [](auto& p) { p.gusts.modes = 8; }},
      {"drag_normal = 2.0", [](auto& p) { p.dragNormal = 2.0; }},
      {"drag_tangential = 0.05", [](auto& p) { p.dragTangential = 0.05; }},
      {"lift_translational = 0", [](auto& p) { p.translationalLift = 0.0; }},
      {"lift_rotational = 1.5", [](auto& p) { p.rotationalLift = 1.5; }},
      {"added_mass = 0", [](auto& p) { p.addedMass = 0.0; }},
      {"shelter = false", [](auto& p) { p.shelter = false; }},
  };
  for (const auto& [line, set] : cases) {
    sim::AirParams want;
    set(want);
    const SceneSpec s = parse(kSheet + "[air]\n" + line + "\n");
    ASSERT_TRUE(s.sim.air.has_value()) << line;
    EXPECT_EQ(*s.sim.air, want) << line;
  }
}

TEST(SceneAir, BadValuesAreRejectedAtTheirLine) {
  const std::string head = kSheet + "[air]\n";  // [air] on line 4, its keys from 5
  expectError(head + "density = 0\n", 5, "air.density", {"must be in"});
  expectError(head + "wind = [200, 0, 0]\n", 5, "air.wind", {"implausibly fast"});
  expectError(head + "wind = [1, 0, 0]\nwind_keys = [[0, 1, 0, 0]]\n", 6, "air.wind_keys",
              {"not both"});
  expectError(head + "wind_keys = [[0, 1, 0, 0], [0, 2, 0, 0]]\n", 5, "air.wind_keys",
              {"times must increase"});
  expectError(head + "wind_keys = [[0, 1, 0]]\n", 5, "air.wind_keys", {"[time_s, vx, vy, vz]"});
  expectError(head + "wind_keys = []\n", 5, "air.wind_keys", {"non-empty"});
  expectError(head + "gust_modes = 0\n", 5, "air.gust_modes", {"must be in"});
  expectError(head + "drag_normal = -1\n", 5, "air.drag_normal", {"must be in"});
  expectError(head + "gust_length = 0\n", 5, "air.gust_length", {"must be in"});
  expectError(head + "breeze = 1\n", 5, "air.breeze");
}

}  // namespace crumple::io
