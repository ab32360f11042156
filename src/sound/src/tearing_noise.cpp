#include "crumple/sound/tearing_noise.hpp"

#include <cmath>
#include <stdexcept>

#include "crumple/core/rng.hpp"

namespace crumple::sound {

TearingNoise::TearingNoise(std::uint64_t seed, int tear, const TearingNoiseParams& params)
    : seed_(seed), tear_(tear), params_(params) {
  if (!(params.alpha >= 1.0) || !std::isfinite(params.alpha))
    throw std::invalid_argument("TearingNoise: alpha must be finite and >= 1");
  if (!(params.referenceSpeed > 0.0) || !std::isfinite(params.referenceSpeed))
    throw std::invalid_argument("TearingNoise: the reference speed must be finite and > 0");
  if (!(params.gain >= 0.0) || !std::isfinite(params.gain))
    throw std::invalid_argument("TearingNoise: the gain must be finite and >= 0");
}

// Thesis 4.4.1: white noise times r^alpha, per sample.
double TearingNoise::crackle(std::int64_t j) const {
  const CounterRng rng(seed_, tear_, RngPurpose::SoundVariant);
  const auto k = static_cast<std::uint64_t>(j);
  const double n = 2.0 * rng.uniform(2 * k) - 1.0;
  const double r = rng.uniform(2 * k + 1);
  return n * std::pow(r, params_.alpha);
}

void TearingNoise::add(std::int64_t start, std::span<const double> speeds,
                       std::vector<float>& out) {
  if (start < 0 || (next_ >= 0 && start != next_))
    throw std::invalid_argument("TearingNoise: samples must follow each other");
  const std::size_t end = static_cast<std::size_t>(start) + speeds.size();
  if (out.size() < end) out.resize(end, 0.0f);
  for (std::size_t k = 0; k < speeds.size(); ++k) {
    const double v = speeds[k];
    if (!(v >= 0.0) || !std::isfinite(v))
      throw std::invalid_argument("TearingNoise: a negative or non-finite speed");
    const double ratio = v / params_.referenceSpeed;
    if (ratio > 0.0) {
      const double floor = std::floor(position_);
      const auto j = static_cast<std::int64_t>(floor);
      const double u = position_ - floor;
      // Between two independent crackle samples the blend keeps the noise's
      // power (a plain lerp would lose up to half of it at u = 1/2, so a
      // slower tear would also sound quieter than its amplitude says).
      const double c =
          ((1.0 - u) * crackle(j) + u * crackle(j + 1)) / std::sqrt((1.0 - u) * (1.0 - u) + u * u);
      out[static_cast<std::size_t>(start) + k] += static_cast<float>(params_.gain * ratio * c);
    }
    position_ += ratio;
  }
  next_ = static_cast<std::int64_t>(end);
}

}  // namespace crumple::sound
