// The SNDS / SEVT sub-blocks (cache/pcache_sound.hpp, docs/PCACHE.md).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "crumple/cache/pcache_sound.hpp"
#include "crumple/core/error.hpp"

namespace crumple::cache {
namespace {

std::vector<sound::SoundEvent> someEvents() {
  sound::SoundEvent crumpling;
  crumpling.kind = sound::EventKind::Crumpling;
  crumpling.amplitude = 2.5e-3;
  crumpling.position = Vec3(0.1, -0.2, 1.0 / 3.0);
  crumpling.normal = Vec3(0.0, 0.0, 1.0);
  crumpling.resonators = {{0.1, 0.0, 0.01, Vec3(1, 2, 3), Vec3(0, 1, 0), 0.056},
                          {0.125, 0.3, 0.02, Vec3(-1, 0, 0.5), Vec3(1, 0, 0), 0.08}};
  sound::SoundEvent friction;
  friction.kind = sound::EventKind::Friction;
  friction.amplitude = 0.07;
  friction.resonators = {{0.05, 0.1, 0.004, Vec3::Zero(), Vec3::UnitY(), 0.035}};
  sound::SoundEvent tearing;
  tearing.kind = sound::EventKind::Tearing;
  tearing.tear = 7;
  tearing.amplitude = std::numeric_limits<double>::denorm_min();
  tearing.duration = 0.125;
  return {crumpling, friction, tearing};
}

TEST(PcacheSound, EventsAndSetupRoundTripBitForBit) {
  const auto events = someEvents();
  const ExtensionBlock block = encodeSoundEvents(events);
  EXPECT_EQ(block.tag, kSoundEventsTag);
  // count, then per event 1 + 4 + 8 * 8 bytes + a count and 80 bytes per resonator.
  EXPECT_EQ(block.data.size(), 4u + 3u * (1 + 4 + 64 + 4) + 3u * 80u);
  const auto back = decodeSoundEvents({block});
  ASSERT_TRUE(back);
  EXPECT_EQ(*back, events);
  EXPECT_FALSE(decodeSoundEvents({}));

  const SoundSetupRecord setup{0.01, 5.0, 0.5, 1.0, 0.01, 0.0125, 0.5};
  const ExtensionBlock s = encodeSoundSetup(setup);
  EXPECT_EQ(s.data.size(), 56u);
  EXPECT_EQ(decodeSoundSetup({s}), setup);
  EXPECT_FALSE(decodeSoundSetup({}));
}

TEST(PcacheSound, MalformedBlocksThrowNamingTheRecord) {
  ExtensionBlock block = encodeSoundEvents(someEvents());
  // Truncated, trailing bytes, a huge count, two blocks.
  ExtensionBlock cut = block;
  cut.data.resize(cut.data.size() - 3);
  EXPECT_THROW(decodeSoundEvents({cut}), CorruptDataError);
  ExtensionBlock longer = block;
  longer.data.push_back(0);
  EXPECT_THROW(decodeSoundEvents({longer}), CorruptDataError);
  ExtensionBlock huge = block;
  huge.data[3] = 0x7f;
  EXPECT_THROW(decodeSoundEvents({huge}), CorruptDataError);
  EXPECT_THROW(decodeSoundEvents({block, block}), CorruptDataError);
  // A kind of 3 in the first event.
  ExtensionBlock kind = block;
  kind.data[4] = 3;
  try {
    (void)decodeSoundEvents({kind});
    FAIL() << "kind 3 accepted";
  } catch (const CorruptDataError& e) {
    EXPECT_NE(std::string(e.what()).find("event 0"), std::string::npos) << e.what();
  }
  // A negative amplitude (the first event's, after kind and tear).
  ExtensionBlock negative = block;
  const auto bits = std::bit_cast<std::uint64_t>(-1.0);
  for (int k = 0; k < 8; ++k) negative.data[9 + k] = static_cast<std::uint8_t>(bits >> (8 * k));
  EXPECT_THROW(decodeSoundEvents({negative}), CorruptDataError);
  ExtensionBlock setup = encodeSoundSetup({0.01, 5.0, 0.5, 1.0, 0.01, 0.0125, 0.5});
  setup.data.resize(55);
  EXPECT_THROW(decodeSoundSetup({setup}), CorruptDataError);
}

TEST(PcacheSound, EncodersRejectWhatTheDecoderWould) {
  auto events = someEvents();
  events[0].kind = static_cast<sound::EventKind>(4);
  EXPECT_THROW(encodeSoundEvents(events), std::invalid_argument);
  events = someEvents();
  events[1].resonators.back().area = -1.0;
  try {
    encodeSoundEvents(events);
    FAIL() << "a negative resonator area was encoded";
  } catch (const std::invalid_argument& e) {
    // The event and its resonator are named.
    const std::string expected =
        "event 1: resonator " + std::to_string(events[1].resonators.size() - 1) + ": ";
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
  events = someEvents();
  events[2].position.x() = std::nan("");
  EXPECT_THROW(encodeSoundEvents(events), std::invalid_argument);
  events = someEvents();
  events[2].tear = -2;
  EXPECT_THROW(encodeSoundEvents(events), std::invalid_argument);
  events = someEvents();
  events[2].duration = -0.5;
  EXPECT_THROW(encodeSoundEvents(events), std::invalid_argument);
  EXPECT_THROW(encodeSoundSetup({0.0, 5.0, 0.5, 1.0, 0.01, 0.0125, 0.5}), std::invalid_argument);
}

}  // namespace
}  // namespace crumple::cache
