#include "crumple/sound/friction_synth.hpp"

#include <fftw3.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "crumple/core/rng.hpp"

namespace crumple::sound {

struct FrictionSynth::Impl {
  int m = 0;
  std::uint64_t seed = 0;
  double* time = nullptr;        // M real samples
  fftw_complex* freq = nullptr;  // M/2 + 1 bins
  fftw_plan plan = nullptr;
  std::vector<double> window;  // sine window: w^2 sums to 1 over a hop of M/2

  ~Impl() {
    if (plan != nullptr) fftw_destroy_plan(plan);
    fftw_free(time);
    fftw_free(freq);
  }
};

FrictionSynth::FrictionSynth(int fftSize, std::uint64_t seed) : impl_(std::make_unique<Impl>()) {
  if (fftSize < 64 || (fftSize & (fftSize - 1)) != 0)
    throw std::invalid_argument("FrictionSynth: fft size " + std::to_string(fftSize) +
                                " is not a power of two >= 64");
  Impl& s = *impl_;
  s.m = fftSize;
  s.seed = seed;
  s.time = fftw_alloc_real(static_cast<std::size_t>(fftSize));
  s.freq = fftw_alloc_complex(static_cast<std::size_t>(fftSize / 2 + 1));
  if (s.time == nullptr || s.freq == nullptr) throw std::bad_alloc();
  // FFTW_ESTIMATE: the same algorithm every run (MEASURE times candidates,
  // which could change the rounding between runs), and the arrays are left
  // alone while planning (../shared/DEPENDENCIES.md).
  s.plan = fftw_plan_dft_c2r_1d(fftSize, s.freq, s.time, FFTW_ESTIMATE);
  if (s.plan == nullptr) throw std::runtime_error("FrictionSynth: FFTW could not plan");
  s.window.resize(static_cast<std::size_t>(fftSize));
  for (int n = 0; n < fftSize; ++n)
    s.window[static_cast<std::size_t>(n)] = std::sin(std::numbers::pi * (n + 0.5) / fftSize);
}

FrictionSynth::~FrictionSynth() = default;
FrictionSynth::FrictionSynth(FrictionSynth&&) noexcept = default;
FrictionSynth& FrictionSynth::operator=(FrictionSynth&&) noexcept = default;

int FrictionSynth::fftSize() const { return impl_->m; }

// Thesis 4.3.3: the block's spectrum with random phases, c2r, windowed, added.
void FrictionSynth::addBlock(std::int64_t block, std::span<const float> power,
                             std::vector<float>& out, std::int64_t offset) {
  Impl& s = *impl_;
  const int m = s.m;
  const std::size_t bins = static_cast<std::size_t>(m / 2 + 1);
  if (power.size() != bins)
    throw std::invalid_argument("FrictionSynth: a spectrum of " + std::to_string(power.size()) +
                                " bins, M / 2 + 1 = " + std::to_string(bins) + " needed");
  if (block < 0 || offset < 0)
    throw std::invalid_argument("FrictionSynth: negative block or offset");
  const CounterRng rng(s.seed, block, RngPurpose::SoundVariant);
  for (std::size_t k = 0; k < bins; ++k) {
    const double p = power[k];
    if (!(p >= 0.0) || !std::isfinite(p))
      throw std::invalid_argument("FrictionSynth: a negative or non-finite power");
    const double amplitude = std::sqrt(p);
    // Bins 0 and M/2 are real in a real signal: a random sign.
    if (k == 0 || k + 1 == bins) {
      s.freq[k][0] = rng.uniform(k) < 0.5 ? -amplitude : amplitude;
      s.freq[k][1] = 0.0;
      continue;
    }
    const double phase = 2.0 * std::numbers::pi * rng.uniform(k);
    s.freq[k][0] = amplitude * std::cos(phase);
    s.freq[k][1] = amplitude * std::sin(phase);
  }
  fftw_execute(s.plan);  // unnormalised: divide by M
  const std::size_t start = static_cast<std::size_t>(offset + block * (m / 2));
  if (out.size() < start + static_cast<std::size_t>(m))
    out.resize(start + static_cast<std::size_t>(m), 0.0f);
  // Each frame is noise of variance sum_k |X_k|^2 / M^2 (the full
  // spectrum); where two frames overlap their windows' squares sum to one,
  // so the sum keeps that variance.
  const double scale = 1.0 / m;
  for (int n = 0; n < m; ++n)
    out[start + static_cast<std::size_t>(n)] +=
        static_cast<float>(scale * s.time[n] * s.window[static_cast<std::size_t>(n)]);
}

}  // namespace crumple::sound
