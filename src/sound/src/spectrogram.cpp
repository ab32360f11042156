#include "crumple/sound/spectrogram.hpp"

#include <fftw3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace crumple::sound {

std::vector<std::vector<float>> spectrogramLevels(const Audio& audio, const SpectrogramParams& p) {
  if (audio.channels.empty() || audio.sampleCount() == 0)
    throw std::invalid_argument("spectrogram: no samples");
  if (p.fftSize < 64 || (p.fftSize & (p.fftSize - 1)) != 0 || p.height < 8 ||
      p.pixelsPerSecond < 1 || p.maxWidth < 8)
    throw std::invalid_argument("spectrogram: bad parameters");
  const int m = p.fftSize;
  const auto n = static_cast<std::int64_t>(audio.sampleCount());
  const double seconds = static_cast<double>(n) / audio.sampleRate;
  const int width =
      std::clamp(static_cast<int>(std::ceil(seconds * p.pixelsPerSecond)), 1, p.maxWidth);
  const double hop = static_cast<double>(n) / width;
  std::vector<double> window(static_cast<std::size_t>(m));
  double windowPower = 0.0;
  for (int i = 0; i < m; ++i) {
    window[static_cast<std::size_t>(i)] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * i / m);
    windowPower += window[static_cast<std::size_t>(i)];
  }
  double* in = fftw_alloc_real(static_cast<std::size_t>(m));
  fftw_complex* out = fftw_alloc_complex(static_cast<std::size_t>(m / 2 + 1));
  if (in == nullptr || out == nullptr) {
    fftw_free(in);
    fftw_free(out);
    throw std::bad_alloc();
  }
  const fftw_plan plan = fftw_plan_dft_r2c_1d(m, in, out, FFTW_ESTIMATE);
  const int bins = m / 2;
  std::vector<std::vector<float>> levels(static_cast<std::size_t>(width),
                                         std::vector<float>(static_cast<std::size_t>(p.height)));
  std::vector<double> power(static_cast<std::size_t>(bins));
  // A sine of amplitude 1 puts (windowPower / 2)^2 into its bin.
  const double reference = 0.25 * windowPower * windowPower;
  for (int x = 0; x < width; ++x) {
    std::fill(power.begin(), power.end(), 0.0);
    const auto centre = static_cast<std::int64_t>((x + 0.5) * hop);
    for (const auto& channel : audio.channels) {
      for (int i = 0; i < m; ++i) {
        const std::int64_t s = centre - m / 2 + i;
        in[i] = s >= 0 && s < n
                    ? channel[static_cast<std::size_t>(s)] * window[static_cast<std::size_t>(i)]
                    : 0.0;
      }
      fftw_execute(plan);
      for (int k = 0; k < bins; ++k)
        power[static_cast<std::size_t>(k)] += (out[k][0] * out[k][0] + out[k][1] * out[k][1]) /
                                              static_cast<double>(audio.channels.size());
    }
    for (int y = 0; y < p.height; ++y) {
      const int k0 = y * bins / p.height, k1 = std::max(k0 + 1, (y + 1) * bins / p.height);
      double sum = 0.0;
      for (int k = k0; k < k1; ++k) sum += power[static_cast<std::size_t>(k)];
      const double mean = sum / (k1 - k0) / reference;
      levels[static_cast<std::size_t>(x)][static_cast<std::size_t>(y)] =
          static_cast<float>(std::max(p.floorDb, 10.0 * std::log10(std::max(mean, 1e-30))));
    }
  }
  fftw_destroy_plan(plan);
  fftw_free(in);
  fftw_free(out);
  return levels;
}

ImageRGBA8 spectrogram(const Audio& audio, const SpectrogramParams& p) {
  const auto levels = spectrogramLevels(audio, p);
  const int width = static_cast<int>(levels.size());
  ImageRGBA8 image(width, p.height);
  // Black, blue, red, yellow, white at 0, 1/4, 1/2, 3/4, 1 of the range.
  constexpr std::array<std::array<double, 3>, 5> stops{
      {{0, 0, 0}, {0.1, 0.1, 0.6}, {0.8, 0.1, 0.2}, {1.0, 0.8, 0.1}, {1, 1, 1}}};
  for (int x = 0; x < width; ++x)
    for (int y = 0; y < p.height; ++y) {
      const double u = std::clamp(
          1.0 - levels[static_cast<std::size_t>(x)][static_cast<std::size_t>(y)] / p.floorDb, 0.0,
          1.0);
      const double at = u * 4.0;
      const int i = std::min(3, static_cast<int>(at));
      const double w = at - i;
      std::uint8_t* px = image.at(x, p.height - 1 - y);
      for (int c = 0; c < 3; ++c)
        px[c] = static_cast<std::uint8_t>(std::lround(
            255.0 * ((1.0 - w) * stops[static_cast<std::size_t>(i)][static_cast<std::size_t>(c)] +
                     w * stops[static_cast<std::size_t>(i + 1)][static_cast<std::size_t>(c)])));
      px[3] = 255;
    }
  return image;
}

}  // namespace crumple::sound
