#include "crumple/sound/database.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#include "crumple/core/error.hpp"
#include "crumple/sound/wav.hpp"

namespace crumple::sound {

namespace {

namespace fs = std::filesystem;

constexpr const char* kFormat = "crumple-sound-db";
constexpr long kVersion = 1;

long lineOf(const toml::node& n) { return static_cast<long>(n.source().begin.line); }

std::vector<float> readSpectrum(const fs::path& path, std::size_t bins) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "cannot read the friction spectrum");
  std::vector<float> out;
  std::string line;
  long number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    double value = 0.0;
    std::string rest;
    if (!(fields >> value) || (fields >> rest) || !std::isfinite(value) || value < 0.0)
      throw InputError(path.string() + ":" + std::to_string(number),
                       "a spectrum line holds one finite, non-negative power");
    out.push_back(static_cast<float>(value));
  }
  if (out.size() != bins)
    throw InputError(path.string(), "the spectrum has " + std::to_string(out.size()) +
                                        " bins, the database's fft_size needs " +
                                        std::to_string(bins));
  return out;
}

}  // namespace

SoundDatabase SoundDatabase::load(const fs::path& dir) {
  const fs::path indexPath = dir / "index.toml";
  const std::string index = indexPath.string();
  toml::table root;
  try {
    root = toml::parse_file(index);
  } catch (const toml::parse_error& e) {
    throw InputError(index + ":" + std::to_string(e.source().begin.line),
                     std::string(e.description()));
  }
  const toml::table* db = root["database"].as_table();
  if (db == nullptr) throw InputError(index, "missing [database]");
  const auto format = (*db)["format"].value<std::string>();
  if (!format || *format != kFormat)
    throw InputError(index, "[database] format must be \"" + std::string(kFormat) + "\"");
  const auto version = (*db)["version"].value<long>();
  if (!version || *version != kVersion)
    throw InputError(index, "[database] version " +
                                (version ? std::to_string(*version) : std::string("missing")) +
                                " is not supported (1)");
  SoundDatabase out;
  const auto rate = (*db)["sample_rate"].value<long>();
  if (!rate || !supportedSampleRate(static_cast<int>(*rate)))
    throw InputError(index, "[database] sample_rate must be 48000 or 44100");
  out.rate_ = static_cast<int>(*rate);
  const auto fft = (*db)["fft_size"].value<long>();
  if (!fft || *fft < 64 || *fft > (1L << 20) || (*fft & (*fft - 1)) != 0)
    throw InputError(index, "[database] fft_size must be a power of two >= 64");
  out.fft_ = static_cast<int>(*fft);
  const std::size_t bins = static_cast<std::size_t>(out.fft_ / 2 + 1);

  const toml::array* cells = root["cell"].as_array();
  if (cells == nullptr) throw InputError(index, "no [[cell]]");
  for (const toml::node& node : *cells) {
    const toml::table* cell = node.as_table();
    const std::string at = index + ":" + std::to_string(lineOf(node));
    if (cell == nullptr) throw InputError(at, "a [[cell]] must be a table");
    const auto lr = (*cell)["l_r_cm"].value<double>();
    const auto lc = (*cell)["l_c_cm"].value<double>();
    if (!lr || !lc || !(*lr >= 0.0) || !(*lc >= 0.0) || !std::isfinite(*lr) || !std::isfinite(*lc))
      throw InputError(at, "a cell needs l_r_cm and l_c_cm, finite and >= 0");
    SoundCell c;
    c.ruling = 0.01 * *lr;
    c.border = 0.01 * *lc;
    for (const SoundCell& other : out.cells_)
      if (other.ruling == c.ruling && other.border == c.border)
        throw InputError(at, "the cell (" + std::to_string(*lr) + ", " + std::to_string(*lc) +
                                 ") cm is listed twice");
    const auto files = [&](const char* key) {
      std::vector<fs::path> paths;
      const toml::node_view<const toml::node> v = (*cell)[key];
      if (!v) return paths;
      const toml::array* list = v.as_array();
      if (list == nullptr) throw InputError(at, std::string(key) + " must be a list of paths");
      for (const toml::node& p : *list) {
        const auto s = p.value<std::string>();
        if (!s || s->empty()) throw InputError(at, std::string(key) + " must be a list of paths");
        paths.push_back(dir / *s);
      }
      return paths;
    };
    for (const fs::path& p : files("crumpling")) {
      Audio a;
      try {
        a = readWav(p);
      } catch (const std::runtime_error& e) {
        throw InputError(e.what());
      }
      if (a.channels.size() != 1) throw InputError(p.string(), "a crumpling clip must be mono");
      if (a.sampleRate != out.rate_)
        throw InputError(p.string(), "the clip is at " + std::to_string(a.sampleRate) +
                                         " Hz, the database at " + std::to_string(out.rate_));
      if (a.sampleCount() == 0) throw InputError(p.string(), "an empty clip");
      c.clips.push_back(std::move(a.channels.front()));
    }
    for (const fs::path& p : files("friction")) c.spectra.push_back(readSpectrum(p, bins));
    out.cells_.push_back(std::move(c));
  }
  if (!std::any_of(out.cells_.begin(), out.cells_.end(),
                   [](const SoundCell& c) { return c.constrained(); }))
    throw InputError(index, "no constrained cell (l_r_cm = 0, l_c_cm = 0)");
  if (out.cells_.size() < 2) throw InputError(index, "no cell besides the constrained one");
  return out;
}

const SoundCell* SoundDatabase::nearest(double ruling, double border, bool clips) const {
  const SoundCell* best = nullptr;
  double bestDistance = std::numeric_limits<double>::infinity();
  for (const SoundCell& c : cells_) {
    if (clips ? c.clips.empty() : c.spectra.empty()) continue;
    if (border == 0.0) {
      if (c.constrained()) return &c;
      continue;
    }
    if (c.constrained()) continue;
    const double d = std::hypot(c.ruling - ruling, c.border - border);
    if (d < bestDistance) {
      bestDistance = d;
      best = &c;
    }
  }
  return best;
}

const SoundCell* SoundDatabase::crumplingCell(double ruling, double border) const {
  return nearest(ruling, border, true);
}

const SoundCell* SoundDatabase::frictionCell(double ruling, double border) const {
  return nearest(ruling, border, false);
}

namespace {

// Band-limited resampling: a Blackman-windowed sinc of kTaps zero crossings
// either side, its cutoff at the lower of the two Nyquist frequencies.
std::vector<float> resampleClip(const std::vector<float>& in, int from, int to) {
  constexpr int kTaps = 24;
  const double step = static_cast<double>(from) / to;  // input samples per output sample
  const double cutoff = std::min(1.0, 1.0 / step);     // of the input's Nyquist
  const auto n = static_cast<std::int64_t>(std::ceil(static_cast<double>(in.size()) / step));
  std::vector<float> out(static_cast<std::size_t>(n));
  const double reach = kTaps / cutoff;
  for (std::int64_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * step;
    const auto j0 = static_cast<std::int64_t>(std::ceil(t - reach));
    const auto j1 = static_cast<std::int64_t>(std::floor(t + reach));
    double sum = 0.0;
    for (std::int64_t j = std::max<std::int64_t>(0, j0);
         j <= std::min<std::int64_t>(static_cast<std::int64_t>(in.size()) - 1, j1); ++j) {
      const double x = (t - static_cast<double>(j)) * cutoff;
      const double sinc = x == 0.0 ? 1.0 : std::sin(std::numbers::pi * x) / (std::numbers::pi * x);
      const double u = (t - static_cast<double>(j)) / reach;  // in [-1, 1]
      const double window =
          0.42 + 0.5 * std::cos(std::numbers::pi * u) + 0.08 * std::cos(2.0 * std::numbers::pi * u);
      sum += in[static_cast<std::size_t>(j)] * cutoff * sinc * window;
    }
    out[static_cast<std::size_t>(i)] = static_cast<float>(sum);
  }
  return out;
}

// A power spectrum's bins at another rate: bin k of the new one at
// frequency k to / M, read from the old one by linear interpolation (zero
// above its Nyquist frequency).
std::vector<float> respectrum(const std::vector<float>& in, int from, int to) {
  const std::size_t bins = in.size();
  std::vector<float> out(bins, 0.0f);
  for (std::size_t k = 0; k < bins; ++k) {
    const double at = static_cast<double>(k) * to / from;  // in the old bins
    const auto k0 = static_cast<std::size_t>(std::floor(at));
    if (k0 + 1 >= bins) {
      if (k0 + 1 == bins) out[k] = in[k0];
      continue;
    }
    const double w = at - static_cast<double>(k0);
    out[k] = static_cast<float>((1.0 - w) * in[k0] + w * in[k0 + 1]);
  }
  return out;
}

}  // namespace

SoundDatabase SoundDatabase::resampledTo(int rate) const {
  if (!supportedSampleRate(rate))
    throw std::invalid_argument("SoundDatabase::resampledTo: " + std::to_string(rate) +
                                " Hz is not a supported rate");
  if (rate == rate_) return *this;
  SoundDatabase out = *this;
  out.rate_ = rate;
  for (auto& cell : out.cells_) {
    for (auto& clip : cell.clips) clip = resampleClip(clip, rate_, rate);
    for (auto& spectrum : cell.spectra) spectrum = respectrum(spectrum, rate_, rate);
  }
  return out;
}

}  // namespace crumple::sound
