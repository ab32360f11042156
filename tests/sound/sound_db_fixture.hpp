#pragma once
// A small sound database the sound tests write (tests/sound): clips and
// spectra they generate, and its index.toml.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "crumple/sound/wav.hpp"
#include "scratch.hpp"

namespace crumple::testing {

namespace fs = std::filesystem;
using sound::Audio;
using sound::SampleFormat;
using sound::writeWav;

// A scratch folder with the database's two subfolders.
struct DatabaseScratch : SoundScratch {
  DatabaseScratch() {
    fs::create_directories(dir / "crumpling");
    fs::create_directories(dir / "friction");
  }
};

// A decaying sine clip of `hz` (mono).
inline void writeClip(const fs::path& path, double hz, int rate = 48000, int channels = 1) {
  Audio a;
  a.sampleRate = rate;
  a.channels.assign(static_cast<std::size_t>(channels), std::vector<float>(960));
  for (auto& c : a.channels)
    for (std::size_t i = 0; i < c.size(); ++i) {
      const double t = static_cast<double>(i) / rate;
      c[i] = static_cast<float>(0.5 * std::exp(-t / 0.005) *
                                std::sin(2.0 * std::numbers::pi * hz * t));
    }
  writeWav(path, a, SampleFormat::Float32);
}

// A spectrum of `bins` powers peaking at bin `peak`.
inline void writeSpectrum(const fs::path& path, std::size_t bins, std::size_t peak) {
  std::ofstream out(path);
  out << "# a test spectrum\n";
  for (std::size_t k = 0; k < bins; ++k)
    out << 1.0 / (1.0 + std::pow((static_cast<double>(k) - peak) / 4.0, 2.0)) << "\n";
}

// The test database: M = 64 (33 bins); cells (0, 0), (2.5, 5), (10, 10)
// with clips and spectra, (20, 0.5) with clips only.
inline void writeDatabase(const fs::path& dir, const std::string& extra = "") {
  writeClip(dir / "crumpling/c0.wav", 4000.0);
  writeClip(dir / "crumpling/a0.wav", 1000.0);
  writeClip(dir / "crumpling/a1.wav", 1100.0);
  writeClip(dir / "crumpling/b0.wav", 300.0);
  writeClip(dir / "crumpling/d0.wav", 150.0);
  writeSpectrum(dir / "friction/c0.txt", 33, 30);
  writeSpectrum(dir / "friction/a0.txt", 33, 20);
  writeSpectrum(dir / "friction/b0.txt", 33, 8);
  std::ofstream index(dir / "index.toml");
  index << "[database]\nformat = \"crumple-sound-db\"\nversion = 1\nsample_rate = 48000\n"
           "fft_size = 64\n\n"
           "[[cell]]\nl_r_cm = 0.0\nl_c_cm = 0.0\ncrumpling = [\"crumpling/c0.wav\"]\n"
           "friction = [\"friction/c0.txt\"]\n\n"
           "[[cell]]\nl_r_cm = 2.5\nl_c_cm = 5.0\n"
           "crumpling = [\"crumpling/a0.wav\", \"crumpling/a1.wav\"]\n"
           "friction = [\"friction/a0.txt\"]\n\n"
           "[[cell]]\nl_r_cm = 10.0\nl_c_cm = 10.0\ncrumpling = [\"crumpling/b0.wav\"]\n"
           "friction = [\"friction/b0.txt\"]\n\n"
           "[[cell]]\nl_r_cm = 20.0\nl_c_cm = 0.5\ncrumpling = [\"crumpling/d0.wav\"]\n"
        << extra;
}

}  // namespace crumple::testing
