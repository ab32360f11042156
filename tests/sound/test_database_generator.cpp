// The generated default sound database (docs/SOUND.md "The
// default database"): the shipped assets/sound/default loads, has the
// thesis' grid, and is byte for byte what make_sound_db makes; clacs are
// short and flaps long; friction spectra move up as the resonator shrinks;
// the constrained friction is flatter and quieter; all of it repeatable.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "crumple/sound/database.hpp"
#include "crumple/sound/database_generator.hpp"
#include "scratch.hpp"

using namespace crumple;
using namespace crumple::sound;
namespace fs = std::filesystem;

namespace {

const fs::path kShipped = fs::path(CRUMPLE_SOURCE_DIR) / "assets" / "sound" / "default";

// The database is loaded once: 249 clips and 165 spectra.
const SoundDatabase& shipped() {
  static const SoundDatabase db = SoundDatabase::load(kShipped);
  return db;
}

const std::vector<double>& gridCm() {
  static const std::vector<double> grid = DatabaseModel{}.gridCm;
  return grid;
}

// The time (s) the clip's energy envelope (5 ms windows) takes from its peak
// to fall 40 dB below it for good.
double decayTime(const std::vector<float>& clip, int rate) {
  const std::size_t w = static_cast<std::size_t>(rate / 200);
  std::vector<double> prefix(clip.size() + 1, 0.0);
  for (std::size_t i = 0; i < clip.size(); ++i)
    prefix[i + 1] = prefix[i] + static_cast<double>(clip[i]) * clip[i];
  std::vector<double> e(clip.size());
  for (std::size_t i = 0; i < clip.size(); ++i)
    e[i] = prefix[std::min(clip.size(), i + w / 2 + 1)] - prefix[i >= w / 2 ? i - w / 2 : 0];
  const auto peak = std::max_element(e.begin(), e.end());
  std::size_t last = clip.size() - 1;
  while (last > 0 && e[last] < 1e-4 * *peak) --last;
  return static_cast<double>(last - static_cast<std::size_t>(peak - e.begin())) / rate;
}

double centroid(const std::vector<float>& p, double binHz) {
  double num = 0.0;
  double den = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    num += k * binHz * p[k];
    den += p[k];
  }
  return num / den;
}

// Geometric over arithmetic mean of bins 1 .. M/2 (1: white).
double flatness(const std::vector<float>& p) {
  double logs = 0.0;
  double sum = 0.0;
  for (std::size_t k = 1; k < p.size(); ++k) {
    logs += std::log(static_cast<double>(p[k]));
    sum += p[k];
  }
  const double n = static_cast<double>(p.size() - 1);
  return std::exp(logs / n) / (sum / n);
}

double totalPower(const std::vector<float>& p) {
  double s = 0.0;
  for (const float v : p) s += v;
  return s;
}

const SoundCell& cellAt(double lrCm, double lcCm) {
  const SoundCell* c = shipped().crumplingCell(0.01 * lrCm, 0.01 * lcCm);
  EXPECT_NE(c, nullptr);
  EXPECT_NEAR(c->ruling, 0.01 * lrCm, 1e-12);
  EXPECT_NEAR(c->border, 0.01 * lcCm, 1e-12);
  return *c;
}

const SoundCell& constrainedCell() { return *shipped().crumplingCell(0.1, 0.0); }

std::vector<fs::path> filesUnder(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out.push_back(fs::relative(e.path(), dir));
  std::sort(out.begin(), out.end());
  return out;
}

std::string bytesOf(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

}  // namespace

TEST(DefaultSoundDatabase, LoadsWithTheThesisGridAndVariants) {
  const SoundDatabase& db = shipped();
  EXPECT_EQ(db.sampleRate(), 48000);
  EXPECT_EQ(db.fftSize(), 2048);
  ASSERT_EQ(db.cells().size(), 82u);
  const SoundCell& first = db.cells().front();
  EXPECT_TRUE(first.constrained());
  EXPECT_EQ(first.clips.size(), 6u);
  EXPECT_EQ(first.spectra.size(), 3u);
  const std::vector<double> grid = {2.5, 5.0, 7.5, 10.0, 12.5, 15.0, 20.0, 25.0, 30.0};
  std::size_t i = 1;
  for (const double lr : grid)
    for (const double lc : grid) {
      const SoundCell& c = db.cells()[i++];
      EXPECT_DOUBLE_EQ(c.ruling, 0.01 * lr);
      EXPECT_DOUBLE_EQ(c.border, 0.01 * lc);
      EXPECT_EQ(c.clips.size(), 3u) << lr << " x " << lc;
      EXPECT_EQ(c.spectra.size(), 2u) << lr << " x " << lc;
      for (const auto& s : c.spectra) EXPECT_EQ(s.size(), 1025u);
    }
}

TEST(DefaultSoundDatabase, IsByteForByteWhatTheGeneratorWrites) {
  const crumple::testing::SoundScratch s;
  generateDatabase(s.dir);
  const std::vector<fs::path> made = filesUnder(s.dir);
  const std::vector<fs::path> ship = filesUnder(kShipped);
  ASSERT_EQ(made.size(), 1u + 249u + 165u);
  ASSERT_EQ(made, ship)
      << "the shipped files are not the generator's: run scripts/make-sound-db.sh";
  for (const fs::path& p : made)
    EXPECT_TRUE(bytesOf(s.dir / p) == bytesOf(kShipped / p))
        << p << " differs from the generator's: run scripts/make-sound-db.sh";
  const std::uint64_t size = [&] {
    std::uint64_t n = 0;
    for (const fs::path& p : ship) n += fs::file_size(kShipped / p);
    return n;
  }();
  EXPECT_LT(size, 8u << 20) << "the default database should stay under 8 MiB";
}

TEST(DefaultSoundDatabase, ClipsAreAsStoredAndAsTheFunctionsGiveThem) {
  const DatabaseModel model;
  EXPECT_EQ(constrainedCell().clips[4], crumplingClip(model, 0.0, 0.0, 4));
  const SoundCell& c = cellAt(12.5, 20.0);
  EXPECT_EQ(c.clips[2], crumplingClip(model, 0.125, 0.2, 2));
  EXPECT_EQ(c.spectra[1], frictionSpectrum(model, 0.125, 0.2, 1));
  EXPECT_EQ(constrainedCell().spectra[2], frictionSpectrum(model, 0.0, 0.0, 2));
}

TEST(DatabaseGenerator, ClacsDieWithinMillisecondsFlapsRingForHundreds) {
  const int rate = shipped().sampleRate();
  for (const auto& clip : constrainedCell().clips) {
    const double t = decayTime(clip, rate);
    EXPECT_LT(t, 0.020) << "clac";
    EXPECT_GT(t, 0.003) << "clac";
  }
  for (const SoundCell& c : shipped().cells()) {
    if (c.constrained()) continue;
    for (const auto& clip : c.clips) {
      const double t = decayTime(clip, rate);
      EXPECT_GT(t, 0.100) << "flap " << c.ruling << " x " << c.border;
      EXPECT_LT(t, 0.600) << "flap " << c.ruling << " x " << c.border;
    }
  }
}

TEST(DatabaseGenerator, BiggerFlapsRingLonger) {
  // A sheet at least twice as big both ways rings longer (the mean of a
  // cell's variants: one variant's decay also depends on where the snap
  // struck and on how its lowest modes beat).
  const int rate = shipped().sampleRate();
  const std::vector<double>& grid = gridCm();
  std::map<std::pair<double, double>, double> decay;
  for (const double lr : grid)
    for (const double lc : grid) {
      const SoundCell& c = cellAt(lr, lc);
      double sum = 0.0;
      for (const auto& clip : c.clips) sum += decayTime(clip, rate);
      decay[{lr, lc}] = sum / static_cast<double>(c.clips.size());
    }
  int pairs = 0;
  for (const auto& [small, t] : decay)
    for (const auto& [big, u] : decay)
      if (big.first >= 2.0 * small.first && big.second >= 2.0 * small.second) {
        ++pairs;
        EXPECT_GT(u, 1.05 * t) << big.first << " x " << big.second << " against " << small.first
                               << " x " << small.second;
      }
  EXPECT_EQ(pairs, 576);
  const double largest = decay[{30.0, 30.0}];
  const double smallest = decay[{2.5, 2.5}];
  EXPECT_GT(largest, 1.8 * smallest);
}

TEST(DatabaseGenerator, FrictionCentroidFallsAsTheResonatorGrows) {
  const double binHz = 48000.0 / 2048.0;
  const std::vector<double>& grid = gridCm();
  for (std::size_t v = 0; v < 2; ++v)
    for (std::size_t i = 0; i < grid.size(); ++i)
      for (std::size_t j = 0; j + 1 < grid.size(); ++j) {
        // l_r grows at fixed l_c = grid[i], and l_c grows at fixed l_r = grid[i].
        EXPECT_LT(centroid(cellAt(grid[j + 1], grid[i]).spectra[v], binHz),
                  centroid(cellAt(grid[j], grid[i]).spectra[v], binHz))
            << "l_r " << grid[j] << " -> " << grid[j + 1] << " at l_c " << grid[i];
        EXPECT_LT(centroid(cellAt(grid[i], grid[j + 1]).spectra[v], binHz),
                  centroid(cellAt(grid[i], grid[j]).spectra[v], binHz))
            << "l_c " << grid[j] << " -> " << grid[j + 1] << " at l_r " << grid[i];
      }
}

TEST(DatabaseGenerator, ConstrainedFrictionIsFlatterAndQuieter) {
  double flattest = 0.0;
  double loudest = 0.0;
  for (const auto& p : constrainedCell().spectra) {
    flattest = std::max(flattest, flatness(p));
    loudest = std::max(loudest, totalPower(p));
    EXPECT_GT(flatness(p), 0.8) << "close to white";
  }
  double constrainedLeastFlat = 1.0;
  for (const auto& p : constrainedCell().spectra)
    constrainedLeastFlat = std::min(constrainedLeastFlat, flatness(p));
  for (const SoundCell& c : shipped().cells()) {
    if (c.constrained()) continue;
    for (const auto& p : c.spectra) {
      EXPECT_LT(flatness(p), constrainedLeastFlat) << c.ruling << " x " << c.border;
      EXPECT_GT(totalPower(p), loudest) << c.ruling << " x " << c.border;
    }
  }
}

TEST(DatabaseGenerator, ClacsAndFlapsAreEquallyLoud) {
  // Every clip: RMS 0.05 over its first 100 ms (within the 16-bit steps),
  // and no sample at full scale.
  const DatabaseModel model;
  const auto window = static_cast<std::size_t>(model.loudnessWindow * model.sampleRate);
  for (const SoundCell& c : shipped().cells())
    for (const auto& clip : c.clips) {
      double energy = 0.0;
      float peak = 0.0f;
      for (std::size_t i = 0; i < clip.size(); ++i) {
        if (i < window) energy += static_cast<double>(clip[i]) * clip[i];
        peak = std::max(peak, std::abs(clip[i]));
      }
      EXPECT_NEAR(std::sqrt(energy / static_cast<double>(window)), model.clipRms, 1e-3);
      EXPECT_LT(peak, 0.99f);
    }
}

TEST(DatabaseGenerator, IsRepeatableAndItsVariantsDiffer) {
  const DatabaseModel model;
  const auto flap = crumplingClip(model, 0.075, 0.15, 1);
  EXPECT_EQ(flap, crumplingClip(model, 0.075, 0.15, 1));
  EXPECT_NE(flap, crumplingClip(model, 0.075, 0.15, 0));
  const auto clac = crumplingClip(model, 0.0, 0.0, 3);
  EXPECT_EQ(clac, crumplingClip(model, 0.0, 0.0, 3));
  EXPECT_NE(clac, crumplingClip(model, 0.0, 0.0, 2));
  const auto spectrum = frictionSpectrum(model, 0.2, 0.05, 1);
  EXPECT_EQ(spectrum, frictionSpectrum(model, 0.2, 0.05, 1));
  const auto other = frictionSpectrum(model, 0.2, 0.05, 0);
  EXPECT_NE(spectrum, other);
  // ... slightly: the centroids of two variants within 3 %.
  const double binHz = 48000.0 / 2048.0;
  EXPECT_NEAR(centroid(spectrum, binHz) / centroid(other, binHz), 1.0, 0.03);
  // Another seed, another database.
  DatabaseModel reseeded;
  reseeded.seed += 1;
  EXPECT_NE(flap, crumplingClip(reseeded, 0.075, 0.15, 1));
}

TEST(DatabaseGenerator, RefusesABadModelOrCell) {
  DatabaseModel bad;
  bad.fftSize = 1000;
  EXPECT_THROW(crumplingClip(bad, 0.1, 0.1, 0), std::invalid_argument);
  bad = {};
  bad.gridCm = {5.0, 2.5};
  EXPECT_THROW(frictionSpectrum(bad, 0.1, 0.1, 0), std::invalid_argument);
  const DatabaseModel model;
  EXPECT_THROW(crumplingClip(model, -0.1, 0.1, 0), std::invalid_argument);
  EXPECT_THROW(frictionSpectrum(model, 0.0, 0.1, 0), std::invalid_argument);
  EXPECT_THROW(crumplingClip(model, 0.1, 0.1, -1), std::invalid_argument);
}

TEST(MakeSoundDb, HelpUsageAndANonEmptyFolder) {
  const crumple::testing::SoundScratch s;
  const std::string tool = MAKE_SOUND_DB;
  const auto run = [](const std::string& command) {
    const int status = std::system((command + " >/dev/null 2>&1").c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  EXPECT_EQ(run(tool + " --help"), 0);
  EXPECT_EQ(run(tool), 2);
  EXPECT_EQ(run(tool + " --frobnicate " + s.dir.string()), 2);
  EXPECT_EQ(run(tool + " " + s.dir.string() + " " + s.dir.string()), 2);
  std::ofstream(s.dir / "keep.txt") << "mine";
  EXPECT_EQ(run(tool + " " + s.dir.string()), 2) << "a non-empty folder needs --force";
  EXPECT_FALSE(fs::exists(s.dir / "index.toml"));
  std::ofstream(s.dir / "a-file") << "x";
  EXPECT_EQ(run(tool + " " + (s.dir / "a-file").string()), 2) << "not a folder";
  fs::create_directories(s.dir / "crumpling");
  std::ofstream(s.dir / "crumpling" / "stale.wav") << "old";
  EXPECT_EQ(run(tool + " --force " + s.dir.string()), 0);
  EXPECT_TRUE(fs::exists(s.dir / "keep.txt"));
  EXPECT_FALSE(fs::exists(s.dir / "crumpling" / "stale.wav"));
  EXPECT_EQ(SoundDatabase::load(s.dir).cells().size(), 82u);
}

// The figures docs/SOUND.md quotes ("The default database"), printed.
TEST(DatabaseGenerator, Figures) {
  const int rate = shipped().sampleRate();
  const double binHz = 48000.0 / 2048.0;
  // Per kind (0 clac, 1 flap): decay T40, length and peak, least and most.
  double lo[2][3] = {{1e9, 1e9, 1e9}, {1e9, 1e9, 1e9}};
  double hi[2][3] = {};
  for (const SoundCell& c : shipped().cells())
    for (const auto& clip : c.clips) {
      float peak = 0.0f;
      for (const float x : clip) peak = std::max(peak, std::abs(x));
      const double v[3] = {1e3 * decayTime(clip, rate), 1e3 * clip.size() / rate, peak};
      const int kind = c.constrained() ? 0 : 1;
      for (int i = 0; i < 3; ++i) {
        lo[kind][i] = std::min(lo[kind][i], v[i]);
        hi[kind][i] = std::max(hi[kind][i], v[i]);
      }
    }
  for (int kind = 0; kind < 2; ++kind)
    std::printf("%s: T40 %.1f .. %.1f ms, length %.0f .. %.0f ms, peak %.3f .. %.3f\n",
                kind == 0 ? "clac" : "flap", lo[kind][0], hi[kind][0], lo[kind][1], hi[kind][1],
                lo[kind][2], hi[kind][2]);
  const auto row = [&](const char* name, const SoundCell& c) {
    double t = 0.0;
    for (const auto& clip : c.clips) t += decayTime(clip, rate);
    double cen = 0.0, fl = 0.0, pw = 0.0;
    for (const auto& p : c.spectra) {
      cen += centroid(p, binHz);
      fl += flatness(p);
      pw += totalPower(p);
    }
    const double n = static_cast<double>(c.spectra.size());
    const double m = static_cast<double>(c.clips.size());
    std::printf("%-22s T40 %6.1f ms  centroid %7.0f Hz  flatness %.3f  noise RMS %.4f\n", name,
                1e3 * t / m, cen / n, fl / n, std::sqrt(2.0 * pw / n) / 2048.0);
  };
  row("constrained", constrainedCell());
  row("2.5 x 2.5 cm", cellAt(2.5, 2.5));
  row("10 x 15 cm (A6-like)", cellAt(10.0, 15.0));
  row("15 x 20 cm (A5-like)", cellAt(15.0, 20.0));
  row("20 x 30 cm (A4-like)", cellAt(20.0, 30.0));
  row("30 x 30 cm", cellAt(30.0, 30.0));
  std::uint64_t size = 0;
  for (const auto& e : fs::recursive_directory_iterator(kShipped))
    if (e.is_regular_file()) size += e.file_size();
  std::printf("assets/sound/default: %.2f MB\n", static_cast<double>(size) / 1e6);
}
