// Paper presets (assets/papers/<name>.toml): raw physical numbers in SI,
// read into sim::Material.
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "crumple/core/error.hpp"
#include "crumple/io/scene.hpp"
#include "toml_reader.hpp"

#ifndef CRUMPLE_SOURCE_ASSETS
#define CRUMPLE_SOURCE_ASSETS ""
#endif

namespace crumple::io {

using detail::formatNumber;
using detail::TableReader;

namespace {

// Plausibility ranges: wide enough for tissue to board, narrow enough to catch
// a value written in the wrong unit (g/m^2 for kg/m^2, mm for m, GPa for Pa).
struct Range {
  double lo, hi;
  const char* hint;
};
constexpr Range kGrammage{0.005, 2.0, "kg/m^2; 80 g/m^2 is 0.080"};
constexpr Range kThickness{5e-6, 5e-3, "m; 0.1 mm is 1.0e-4"};
constexpr Range kDensity{100.0, 2000.0, "kg/m^3"};
constexpr Range kYoungs{1e7, 1e11, "Pa; 4 GPa is 4.0e9"};

double readInRange(const TableReader& r, std::string_view key, const Range& range) {
  const std::optional<double> v = r.number(key);
  if (!v) r.missing(key);
  if (!(*v >= range.lo && *v <= range.hi)) {
    r.fail(key, "must be in [" + formatNumber(range.lo) + ", " + formatNumber(range.hi) + "] (" +
                    range.hint + "), got " + formatNumber(*v));
  }
  return *v;
}

}  // namespace

PaperPreset loadPaperPreset(const std::string& path) {
  const std::string text = detail::readTextFile(path);
  const toml::table root = detail::parseToml(text, path);
  const TableReader r(root, "", path);
  r.allowOnly({"name", "description", "grammage", "thickness", "density", "youngs_modulus",
               "poisson_ratio", "front_color", "back_color"});

  PaperPreset p;
  sim::Material& m = p.material;
  p.file = path;
  const std::string stem = std::filesystem::path(path).stem().string();
  m.name = r.string("name").value_or(stem);
  if (r.has("name") && m.name != stem) {
    r.fail("name", "preset name '" + m.name + "' does not match its file name '" + stem + ".toml'");
  }
  (void)r.string("description");

  p.grammage = readInRange(r, "grammage", kGrammage);
  m.thickness = readInRange(r, "thickness", kThickness);
  m.density = readInRange(r, "density", kDensity);
  const double derived = p.grammage / m.thickness;
  if (std::abs(m.density - derived) > 0.01 * derived) {
    r.fail("density", "must equal grammage / thickness = " + formatNumber(derived) +
                          " kg/m^3 within 1% (got " + formatNumber(m.density) + ")");
  }
  m.youngsModulus = readInRange(r, "youngs_modulus", kYoungs);
  const std::optional<double> nu = r.number("poisson_ratio");
  if (!nu) r.missing("poisson_ratio");
  if (!(*nu >= 0.0 && *nu < 0.5)) {
    r.fail("poisson_ratio", "must be in [0, 0.5) (got " + formatNumber(*nu) + ")");
  }
  m.poissonRatio = *nu;
  if (auto c = r.vec3("front_color")) p.frontColor = r.requireColor("front_color", *c, 1.0);
  if (auto c = r.vec3("back_color")) p.backColor = r.requireColor("back_color", *c, 1.0);
  return p;
}

std::vector<std::string> paperPresetDirs() {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("CRUMPLE_ASSETS"); env && *env) {
    dirs.push_back((std::filesystem::path(env) / "papers").string());
  }
  const std::string source = CRUMPLE_SOURCE_ASSETS;
  if (!source.empty()) dirs.push_back(source + "/papers");
  return dirs;
}

}  // namespace crumple::io
