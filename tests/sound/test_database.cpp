// The sound database's loader (issue 7, item 3): a small database built from
// WAVs and spectra the test writes, read back, looked up; and every way an
// index or a file can be wrong, named.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "crumple/core/error.hpp"
#include "crumple/sound/database.hpp"
#include "crumple/sound/wav.hpp"
#include "scratch.hpp"

using namespace crumple;
using namespace crumple::sound;
namespace fs = std::filesystem;

namespace {

// A scratch folder with the database's two subfolders.
struct Scratch : crumple::testing::SoundScratch {
  Scratch() {
    fs::create_directories(dir / "crumpling");
    fs::create_directories(dir / "friction");
  }
};

// Replaces the first `from` in DIR/index.toml by `to`.
void editIndex(const fs::path& dir, const std::string& from, const std::string& to) {
  std::string text;
  {
    std::ifstream in(dir / "index.toml");
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  text.replace(text.find(from), from.size(), to);
  std::ofstream(dir / "index.toml") << text;
}

// A decaying sine clip of `hz` (mono).
void writeClip(const fs::path& path, double hz, int rate = 48000, int channels = 1) {
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
void writeSpectrum(const fs::path& path, std::size_t bins, std::size_t peak) {
  std::ofstream out(path);
  out << "# a test spectrum\n";
  for (std::size_t k = 0; k < bins; ++k)
    out << 1.0 / (1.0 + std::pow((static_cast<double>(k) - peak) / 4.0, 2.0)) << "\n";
}

// The test database: M = 64 (33 bins); cells (0, 0), (2.5, 5), (10, 10)
// with clips and spectra, (20, 0.5) with clips only.
void writeDatabase(const fs::path& dir, const std::string& extra = "") {
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

// The message of the InputError `load` throws ("" when it does not).
std::string loadError(const fs::path& dir) {
  try {
    (void)SoundDatabase::load(dir);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SoundDatabase, LoadsCellsClipsAndSpectra) {
  const Scratch s;
  writeDatabase(s.dir);
  const SoundDatabase db = SoundDatabase::load(s.dir);
  EXPECT_EQ(db.sampleRate(), 48000);
  EXPECT_EQ(db.fftSize(), 64);
  ASSERT_EQ(db.cells().size(), 4u);
  EXPECT_TRUE(db.cells()[0].constrained());
  EXPECT_DOUBLE_EQ(db.cells()[1].ruling, 0.025);
  EXPECT_DOUBLE_EQ(db.cells()[1].border, 0.05);
  EXPECT_EQ(db.cells()[1].clips.size(), 2u);
  EXPECT_EQ(db.cells()[1].clips[0].size(), 960u);
  ASSERT_EQ(db.cells()[2].spectra.size(), 1u);
  ASSERT_EQ(db.cells()[2].spectra[0].size(), 33u);
  EXPECT_FLOAT_EQ(db.cells()[2].spectra[0][8], 1.0f);
  EXPECT_TRUE(db.cells()[3].spectra.empty());
}

// Thesis 4.3.3: l_c = 0 takes the constrained cell; otherwise the nearest
// cell in (l_r, l_c) that has what is asked for.
TEST(SoundDatabase, LooksUpTheNearestCell) {
  const Scratch s;
  writeDatabase(s.dir);
  const SoundDatabase db = SoundDatabase::load(s.dir);
  const auto& c = db.cells();
  EXPECT_EQ(db.crumplingCell(0.05, 0.0), &c[0]);
  EXPECT_EQ(db.frictionCell(0.30, 0.0), &c[0]);
  EXPECT_EQ(db.crumplingCell(0.03, 0.04), &c[1]);
  EXPECT_EQ(db.crumplingCell(0.09, 0.12), &c[2]);
  EXPECT_EQ(db.crumplingCell(0.19, 0.01), &c[3]);
  // (20, 0.5) has no spectra: friction falls to the nearest cell that has.
  EXPECT_EQ(db.frictionCell(0.19, 0.01), &c[2]);
}

TEST(SoundDatabase, NamesWhatIsWrong) {
  {
    const Scratch s;
    EXPECT_NE(loadError(s.dir).find("index.toml"), std::string::npos);
  }
  const auto expectError = [](const std::string& extra, const std::string& words,
                              const auto& change) {
    const Scratch s;
    writeDatabase(s.dir, extra);
    change(s.dir);
    const std::string e = loadError(s.dir);
    EXPECT_NE(e.find(words), std::string::npos) << "got: \"" << e << "\"";
  };
  const auto nothing = [](const fs::path&) {};
  expectError("[[cell]]\nl_r_cm = 2.5\nl_c_cm = 5.0\n", "listed twice", nothing);
  expectError("[[cell]]\nl_r_cm = -1.0\nl_c_cm = 5.0\n", ">= 0", nothing);
  expectError("[[cell]]\nl_r_cm = 1.0\nl_c_cm = 1.0\ncrumpling = [\"crumpling/none.wav\"]\n",
              "none.wav", nothing);
  expectError("[[cell]]\nl_r_cm = 1.0\nl_c_cm = 1.0\ncrumpling = [\"crumpling/st.wav\"]\n", "mono",
              [](const fs::path& d) { writeClip(d / "crumpling/st.wav", 500.0, 48000, 2); });
  expectError("[[cell]]\nl_r_cm = 1.0\nl_c_cm = 1.0\ncrumpling = [\"crumpling/r.wav\"]\n",
              "44100 Hz",
              [](const fs::path& d) { writeClip(d / "crumpling/r.wav", 500.0, 44100); });
  expectError("[[cell]]\nl_r_cm = 1.0\nl_c_cm = 1.0\nfriction = [\"friction/short.txt\"]\n",
              "32 bins", [](const fs::path& d) { writeSpectrum(d / "friction/short.txt", 32, 3); });
  expectError("[[cell]]\nl_r_cm = 1.0\nl_c_cm = 1.0\nfriction = [\"friction/neg.txt\"]\n",
              "neg.txt:3", [](const fs::path& d) {
                std::ofstream out(d / "friction/neg.txt");
                out << "# x\n1.0\n-2.0\n";
              });
  expectError("", "version 2",
              [](const fs::path& d) { editIndex(d, "version = 1", "version = 2"); });
  expectError("", "fft_size",
              [](const fs::path& d) { editIndex(d, "fft_size = 64", "fft_size = 100"); });
  expectError("", "constrained cell", [](const fs::path& d) {
    editIndex(d, "l_r_cm = 0.0\nl_c_cm = 0.0", "l_r_cm = 1.5\nl_c_cm = 0.5");
  });
}
