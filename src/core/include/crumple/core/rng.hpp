#pragma once
// Counter-based deterministic RNG (docs/ARCHITECTURE.md "Invariants everyone keeps"): every random
// number is a pure function of (seed, frame, purpose, index), so results never depend on thread
// scheduling or on the order in which consumers draw.
#include <cstdint>

namespace crumple {

// What a random number is for; new purposes are appended, never renumbered.
enum class RngPurpose : std::uint32_t {
  Generic = 0,
  SingularityPlacement = 1,
  FiberTexture = 2,
  SoundVariant = 3,
  Jitter = 4,
  Gusts = 5,
};

class CounterRng {
 public:
  CounterRng(std::uint64_t seed, std::int64_t frame, RngPurpose purpose)
      : key_(mix(seed ^ mix(static_cast<std::uint64_t>(frame) * 0x9E3779B97F4A7C15ULL +
                            static_cast<std::uint64_t>(purpose)))) {}

  // The index-th 64-bit value of this stream.
  std::uint64_t bits(std::uint64_t index) const {
    return mix(key_ + mix(index + 0x632BE59BD9B4E019ULL));
  }
  // Uniform in [0, 1) with 53 random bits.
  double uniform(std::uint64_t index) const {
    return static_cast<double>(bits(index) >> 11) * 0x1.0p-53;
  }

  // SplitMix64 finaliser: a bijective 64-bit mixer.
  static std::uint64_t mix(std::uint64_t z) {
    z += 0x9E3779B97F4A7C15ULL;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }

 private:
  std::uint64_t key_;
};

}  // namespace crumple
