// The sound database's loader: a small database built from
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
#include "sound_db_fixture.hpp"

using namespace crumple;
using namespace crumple::sound;
namespace fs = std::filesystem;

namespace {

using namespace crumple::testing;  // the shared helpers (test_util.hpp)
using Scratch = DatabaseScratch;

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
