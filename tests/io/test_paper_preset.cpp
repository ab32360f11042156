// Paper presets: the shipped files are valid and consistent; bad preset files
// get the scene file's error style; $CRUMPLE_ASSETS is searched first.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "crumple/core/error.hpp"
#include "crumple/io/scene.hpp"

namespace crumple::io {
namespace {

namespace fs = std::filesystem;
const std::string kAssets = CRUMPLE_SOURCE_ASSETS;
const std::string kData = CRUMPLE_IO_TEST_DATA;

// A scratch folder removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    path_ = fs::temp_directory_path() /
            ("crumple_io_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter_++));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = path_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p) << text;
    return p.string();
  }
  std::string path() const { return path_.string(); }

 private:
  static inline int counter_ = 0;
  fs::path path_;
};

const char* kGood = R"(name = "test-paper"
grammage = 0.080
thickness = 1.0e-4
density = 800
youngs_modulus = 4.0e9
poisson_ratio = 0.3
)";

TEST(PaperPreset, ShippedPresetsAreConsistent) {
  for (const char* name : {"office-70gsm", "office-90gsm"}) {
    const std::string file = kAssets + "/papers/" + name + ".toml";
    const PaperPreset p = loadPaperPreset(file);
    EXPECT_EQ(p.material.name, name);
    EXPECT_EQ(p.file, file);
    EXPECT_NEAR(p.material.density, p.grammage / p.material.thickness, 0.01 * p.material.density);
    EXPECT_GT(p.material.youngsModulus, 1e9);
    EXPECT_LT(p.material.youngsModulus, 1e10);
    EXPECT_GE(p.material.poissonRatio, 0.2);
    EXPECT_LE(p.material.poissonRatio, 0.3);
    EXPECT_GT(p.material.thickness, 5e-5);
    EXPECT_LT(p.material.thickness, 2e-4);
    // Every number in the file carries a "# source:" comment.
    std::ifstream in(file);
    std::string line, text;
    int sources = 0;
    while (std::getline(in, line)) sources += line.rfind("# source:", 0) == 0;
    EXPECT_GE(sources, 6) << file;
  }
  const PaperPreset p70 = loadPaperPreset(kAssets + "/papers/office-70gsm.toml");
  EXPECT_NEAR(p70.grammage, 0.070, 1e-12);
  const PaperPreset p90 = loadPaperPreset(kAssets + "/papers/office-90gsm.toml");
  EXPECT_NEAR(p90.grammage, 0.090, 1e-12);
  EXPECT_GT(p90.material.thickness, p70.material.thickness);
}

TEST(PaperPreset, GoodFile) {
  TempDir dir;
  const PaperPreset p = loadPaperPreset(dir.write("test-paper.toml", kGood));
  EXPECT_DOUBLE_EQ(p.grammage, 0.080);
  EXPECT_DOUBLE_EQ(p.material.thickness, 1.0e-4);
  EXPECT_DOUBLE_EQ(p.material.density, 800.0);
  EXPECT_DOUBLE_EQ(p.material.youngsModulus, 4.0e9);
  EXPECT_DOUBLE_EQ(p.material.poissonRatio, 0.3);
}

void expectPresetError(const std::string& text, long line, const std::string& key,
                       const std::string& fragment,
                       const std::string& fileName = "test-paper.toml") {
  TempDir dir;
  const std::string file = dir.write(fileName, text);
  try {
    loadPaperPreset(file);
    ADD_FAILURE() << "expected InputError for\n" << text;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    const std::string prefix = file + ":" + std::to_string(line) + ": '" + key + "': ";
    EXPECT_EQ(msg.rfind(prefix, 0), 0u) << msg << "\nexpected prefix " << prefix;
    EXPECT_NE(msg.find(fragment), std::string::npos) << msg;
  }
}

TEST(PaperPreset, Errors) {
  std::string t = kGood;
  expectPresetError(t + "stiffness = 3\n", 7, "stiffness", "unknown key");
  expectPresetError(std::string(kGood).replace(t.find("0.080"), 5, "80"), 2, "grammage",
                    "80 g/m^2 is 0.080");
  expectPresetError(std::string(kGood).replace(t.find("800"), 3, "900"), 4, "density",
                    "grammage / thickness = 800");
  expectPresetError(std::string(kGood).replace(t.find("0.3\n"), 3, "0.6"), 6, "poisson_ratio",
                    "[0, 0.5)");
  expectPresetError(std::string(kGood).replace(t.find("4.0e9"), 5, "4.0"), 5, "youngs_modulus",
                    "4 GPa is 4.0e9");
  expectPresetError(std::string(kGood).replace(t.find("1.0e-4"), 6, "\"0.1\""), 3, "thickness",
                    "expected a number");
  expectPresetError(std::string(kGood).erase(t.find("youngs_modulus"), 23), 1, "youngs_modulus",
                    "missing required key");
  expectPresetError(kGood, 1, "name", "does not match its file name", "other.toml");
}

TEST(PaperPreset, EnvironmentDirectoryComesFirst) {
  TempDir dir;
  dir.write("papers/test-paper.toml", kGood);
  ASSERT_EQ(::setenv("CRUMPLE_ASSETS", dir.path().c_str(), 1), 0);
  const std::vector<std::string> dirs = paperPresetDirs();
  ASSERT_EQ(dirs.size(), 2u);
  EXPECT_EQ(dirs[0], dir.path() + "/papers");
  EXPECT_EQ(dirs[1], kAssets + "/papers");
  const SceneSpec s = parseScene(
      "[sheet]\nwidth = 1\nheight = 1\n[paper]\npreset = \"test-paper\"\n", "t.toml", kData);
  EXPECT_EQ(s.paper.material.name, "test-paper");
  EXPECT_DOUBLE_EQ(s.paper.grammage, 0.080);
  // Shipped presets are still found in the source tree.
  EXPECT_EQ(parseScene("[sheet]\nwidth = 1\nheight = 1\n", "t.toml", kData).paper.material.name,
            "office-70gsm");
  ::unsetenv("CRUMPLE_ASSETS");
  EXPECT_EQ(paperPresetDirs().size(), 1u);
}

TEST(PaperPreset, ErrorsInAPresetNameThePresetFile) {
  TempDir dir;
  dir.write("papers/bad.toml", "grammage = 0.08\n");
  ASSERT_EQ(::setenv("CRUMPLE_ASSETS", dir.path().c_str(), 1), 0);
  try {
    parseScene("[sheet]\nwidth = 1\nheight = 1\n[paper]\npreset = \"bad\"\n", "t.toml", kData);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.path() + "/papers/bad.toml"), std::string::npos)
        << e.what();
  }
  ::unsetenv("CRUMPLE_ASSETS");
}

}  // namespace
}  // namespace crumple::io
