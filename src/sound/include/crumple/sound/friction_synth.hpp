#pragma once
// Friction noise from power spectra (thesis 4.3.3): each
// block of M/2 samples sounds the power spectrum the friction events of that
// block ask for (the database's spectra, weighted), as noise of random
// phases made by an inverse FFT (FFTW c2r) and overlap-added by M/2 with a
// sine window, whose square sums to one over the overlaps: the noise's
// power stays continuous across blocks, with no click at the joins.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace crumple::sound {

class FrictionSynth {
 public:
  // `fftSize` M: a power of two >= 64 (the database's fft_size). The phases
  // of block b come from CounterRng(seed, b): the output depends on the
  // seed and the blocks only. Throws std::invalid_argument for a bad M.
  FrictionSynth(int fftSize, std::uint64_t seed);
  ~FrictionSynth();
  FrictionSynth(FrictionSynth&&) noexcept;
  FrictionSynth& operator=(FrictionSynth&&) noexcept;

  int fftSize() const;
  int hop() const { return fftSize() / 2; }

  // Adds block `block` (0, 1, ...) with power spectrum `power` (M/2 + 1
  // bins, non-negative) into `out` at sample block * hop + offset (out
  // grows as needed). A block's frame spans M samples from there: block b
  // and b + 1 overlap by M/2. For a spectrum held constant, the output's
  // variance is (P_0 + P_{M/2} + 2 sum_{0<k<M/2} P_k) / M^2 wherever two
  // blocks overlap. Throws std::invalid_argument for a spectrum of the
  // wrong length or a negative or non-finite power.
  void addBlock(std::int64_t block, std::span<const float> power, std::vector<float>& out,
                std::int64_t offset = 0);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crumple::sound
