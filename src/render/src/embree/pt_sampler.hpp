#pragma once
// Owen-scrambled Sobol sample points for the path tracer (Burley 2020,
// "Practical Hash-based Owen Scrambling"): every pair of dimensions is a 2-D
// Sobol (0,2)-sequence, Owen-scrambled with a hash-based nested uniform
// scramble and read at an Owen-shuffled sample index, both keyed by a
// per-pixel, per-pair seed, so that consecutive pairs are decorrelated while
// each stays stratified. Every value is a pure function of (pixel key, sample
// index, pair): the image does not depend on the order of evaluation.
#include <array>
#include <cstddef>
#include <cstdint>

#include "crumple/core/rng.hpp"

namespace crumple::render::pt {

// Reverses the 32 bits of x.
inline std::uint32_t reverseBits(std::uint32_t x) {
  x = __builtin_bswap32(x);
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  return ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
}

// Laine-Karras style hash in which every bit depends only on the bits below
// it (Vegdahl's improved constants): an Owen scramble of the reversed bits.
inline std::uint32_t laineKarrasPermutation(std::uint32_t x, std::uint32_t seed) {
  x ^= x * 0x3d20adeau;
  x += seed;
  x *= (seed >> 16) | 1u;
  x ^= x * 0x05526c56u;
  x ^= x * 0x53a22864u;
  return x;
}

// Nested uniform (Owen) scramble of a 32-bit binary fraction.
inline std::uint32_t nestedUniformScramble(std::uint32_t x, std::uint32_t seed) {
  return reverseBits(laineKarrasPermutation(reverseBits(x), seed));
}

// Sobol dimension 1 (the Pascal matrix: v_0 = 2^31, v_k = v_{k-1} ^ (v_{k-1} >> 1)),
// bit-reversed, applied to each byte of an index: the XOR of the reversed v_k
// of its set bits (bit reversal is linear over XOR).
inline constexpr std::array<std::array<std::uint32_t, 256>, 4> kSobolDim1ReversedBytes = [] {
  std::array<std::uint32_t, 32> v{};
  v[0] = 0x80000000u;
  for (std::size_t k = 1; k < 32; ++k) v[k] = v[k - 1] ^ (v[k - 1] >> 1);
  for (std::uint32_t& x : v) {
    std::uint32_t r = 0;
    for (int b = 0; b < 32; ++b)
      if ((x >> b) & 1u) r |= 1u << (31 - b);
    x = r;
  }
  std::array<std::array<std::uint32_t, 256>, 4> t{};
  for (std::size_t b = 0; b < 4; ++b)
    for (std::uint32_t x = 0; x < 256; ++x) {
      std::uint32_t r = 0;
      for (std::size_t j = 0; j < 8; ++j)
        if ((x >> j) & 1u) r ^= v[8 * b + j];
      t[b][x] = r;
    }
  return t;
}();

// reverseBits(Sobol dimension 1 of index); dimension 0 is reverseBits(index).
inline std::uint32_t sobolDim1Reversed(std::uint32_t index) {
  return kSobolDim1ReversedBytes[0][index & 0xFFu] ^
         kSobolDim1ReversedBytes[1][(index >> 8) & 0xFFu] ^
         kSobolDim1ReversedBytes[2][(index >> 16) & 0xFFu] ^
         kSobolDim1ReversedBytes[3][index >> 24];
}

// A 32-bit integer hash (lowbias32, Wellons).
inline std::uint32_t hash32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

struct Sample2 {
  float x, y;  // in [0, 1)
};

// Point `index` of the shuffled, Owen-scrambled 2-D Sobol sequence of `seed`:
// nestedUniformScramble(sobol_d(nestedUniformScramble(index, seed)), seed_d)
// with the reversals that cancel left out.
inline Sample2 owenSobol2(std::uint32_t index, std::uint32_t seed) {
  const std::uint32_t i = nestedUniformScramble(index, seed);
  const std::uint32_t x = reverseBits(laineKarrasPermutation(i, hash32(seed ^ 0xa511e9b3u)));
  const std::uint32_t y =
      reverseBits(laineKarrasPermutation(sobolDim1Reversed(i), hash32(seed ^ 0x63d83595u)));
  return {static_cast<float>(x >> 8) * 0x1p-24f, static_cast<float>(y >> 8) * 0x1p-24f};
}

// The sample points of one camera sample of one pixel, by dimension pair.
struct PixelSampler {
  std::uint64_t pixelKey;  // hash of (seed, frame, pixel)
  std::uint32_t index;     // sample number within the pixel

  // The 2-D point of dimension pair `pair`.
  Sample2 get(std::uint32_t pair) const {
    const auto lo = static_cast<std::uint32_t>(pixelKey),
               hi = static_cast<std::uint32_t>(pixelKey >> 32);
    return owenSobol2(index, hash32(lo ^ hash32(hi + 0x9E3779B9u * (pair + 1u))));
  }
};

}  // namespace crumple::render::pt
