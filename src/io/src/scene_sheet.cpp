// The scene file's [sheet] (a rectangle, an outline or a pattern mesh of
// the animation file) and [paper] (the preset, sim::Material, and the look).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "crumple/core/error.hpp"
#include "scene_parser.hpp"

namespace crumple::io::detail {

namespace fs = std::filesystem;

namespace {

constexpr double kMaxSheetSide = 100.0;  // m
constexpr double kMaxSheetVertices = 1'000'000;

}  // namespace

void SceneParser::parseSheet(const toml::table& table) {
  const TableReader r(table, "sheet", file_);
  r.allowOnly(
      {"width", "height", "pattern_mesh", "outline", "max_edge", "origin", "u_axis", "v_axis"});
  SheetSpec& s = spec_.sheet;
  const bool rect = r.has("width") || r.has("height");
  if (r.has("outline") && (rect || r.has("pattern_mesh")))
    r.fail("outline", "give one of width/height, pattern_mesh or outline");
  if (r.has("outline")) {
    s.kind = SheetSpec::Kind::Outline;
    s.outline = parseOutline(r);
    Vec2 hi = s.outline.front();
    for (const Vec2& q : s.outline) hi = hi.cwiseMax(q);
    s.width = hi.x();
    s.height = hi.y();
    if (auto o = r.vec3("origin")) s.origin = *o * mpu();
    if (auto u = r.vec3("u_axis")) s.uAxis = r.requireDirection("u_axis", *u);
    if (auto v = r.vec3("v_axis")) s.vAxis = r.requireDirection("v_axis", *v);
    if (std::abs(s.uAxis.dot(s.vAxis)) > 1e-6)
      r.fail(r.has("v_axis") ? "v_axis" : "u_axis", "u_axis and v_axis must be perpendicular");
  } else if (r.has("pattern_mesh")) {
    if (rect) {
      r.fail(r.has("width") ? "width" : "height",
             "give either width/height or pattern_mesh, not both");
    }
    s.kind = SheetSpec::Kind::PatternMesh;
    s.patternMesh = *r.string("pattern_mesh");
    s.patternMeshLine = r.lineOf("pattern_mesh");
    if (s.patternMesh.empty()) r.fail("pattern_mesh", "must not be empty");
    if (spec_.animationFile.empty()) {
      r.fail("pattern_mesh", "needs an animation file ([scene] animation) holding the mesh");
    }
    for (const char* key : {"origin", "u_axis", "v_axis"}) {
      if (r.has(key)) {
        r.fail(key, "only for a width/height rectangle (a pattern mesh is placed by its file)");
      }
    }
  } else {
    s.kind = SheetSpec::Kind::Rectangle;
    const std::optional<double> w = r.number("width");
    if (!w) r.missing("width");
    const std::optional<double> h = r.number("height");
    if (!h) r.missing("height");
    s.width = r.requirePositive("width", *w) * mpu();
    s.height = r.requirePositive("height", *h) * mpu();
    if (auto o = r.vec3("origin")) s.origin = *o * mpu();
    if (auto u = r.vec3("u_axis")) s.uAxis = r.requireDirection("u_axis", *u);
    if (auto v = r.vec3("v_axis")) s.vAxis = r.requireDirection("v_axis", *v);
    if (std::abs(s.uAxis.dot(s.vAxis)) > 1e-6) {
      r.fail(r.has("v_axis") ? "v_axis" : "u_axis", "u_axis and v_axis must be perpendicular");
    }
  }
  if (auto e = r.number("max_edge")) {
    s.maxEdge = r.requirePositive("max_edge", *e) * mpu();
    if (s.kind == SheetSpec::Kind::Rectangle && s.maxEdge > std::max(s.width, s.height)) {
      r.fail("max_edge", "is larger than the sheet itself");
    }
  }
  if (s.kind != SheetSpec::Kind::PatternMesh) checkSheetSize(r, s);
}

// A sheet the mesh and the models can hold (docs/RELIABILITY.md): no side
// over kMaxSheetSide, and about area / (0.87 max_edge^2) vertices (the
// triangular lattice of mesh::makeRectangleSheet) within kMaxSheetVertices.
void SceneParser::checkSheetSize(const TableReader& r, const SheetSpec& s) const {
  const char* side = r.has("outline") ? "outline" : s.width >= s.height ? "width" : "height";
  if (std::max(s.width, s.height) > kMaxSheetSide)
    r.fail(side, formatNumber(std::max(s.width, s.height) / mpu()) +
                     " is not a sheet of paper (at most " + formatNumber(kMaxSheetSide / mpu()) +
                     " in the scene's units)");
  const double edge = s.maxEdge > 0.0 ? s.maxEdge : std::min(s.width, s.height) / 16.0;
  const double vertices = s.width * s.height / (0.866 * edge * edge);
  if (vertices > kMaxSheetVertices)
    r.fail(r.has("max_edge") ? "max_edge" : side,
           "the sheet would have about " + formatNumber(std::round(vertices)) +
               " vertices, more than " + formatNumber(kMaxSheetVertices) +
               " (raise max_edge or use a smaller sheet)");
}

// [sheet] outline = [[u, v], ...]: at least 3 points, none negative, a
// simple polygon (no two edges cross or touch but neighbours at their
// shared point); returned counter-clockwise, scaled to m.
std::vector<Vec2> SceneParser::parseOutline(const TableReader& r) const {
  const toml::array* arr = r.find("outline")->as_array();
  const std::string expected = "expected an array of [u, v] points";
  if (!arr) r.fail("outline", expected);
  std::vector<Vec2> pts;
  for (const toml::node& n : *arr) {
    const toml::array* p = n.as_array();
    if (!p || p->size() != 2) r.fail("outline", expected);
    Vec2 q;
    for (int k = 0; k < 2; ++k) {
      const toml::node& c = *p->get(static_cast<std::size_t>(k));
      if (auto i = c.as_integer()) {
        q[k] = static_cast<double>(i->get());
      } else if (auto d = c.as_floating_point()) {
        q[k] = d->get();
      } else {
        r.fail("outline", expected);
      }
    }
    if (!std::isfinite(q.x()) || !std::isfinite(q.y()) || q.minCoeff() < 0.0)
      r.fail("outline", "point " + std::to_string(pts.size()) +
                            " must be finite and not negative (the pattern starts at [0, 0])");
    pts.push_back(q * mpu());
  }
  if (pts.size() < 3) r.fail("outline", "needs at least 3 points");
  double area = 0.0;
  const std::size_t n = pts.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = pts[i];
    const Vec2& b = pts[(i + 1) % n];
    area += a.x() * b.y() - a.y() * b.x();
  }
  if (std::abs(area) < 1e-12) r.fail("outline", "encloses no area");
  if (area < 0.0) std::reverse(pts.begin(), pts.end());
  const auto cross = [](const Vec2& u, const Vec2& v) { return u.x() * v.y() - u.y() * v.x(); };
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const bool neighbours = j == i + 1 || (i == 0 && j == n - 1);
      const Vec2 &a = pts[i], &b = pts[(i + 1) % n], &c = pts[j], &d = pts[(j + 1) % n];
      const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
      const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
      const bool crosses = ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0.0 &&
                           d2 != 0.0 && d3 != 0.0 && d4 != 0.0;
      if (crosses || (!neighbours && (a == c || a == d || b == c || b == d)))
        r.fail("outline", "edges " + std::to_string(i) + " and " + std::to_string(j) +
                              " cross or touch: the outline must be a simple polygon");
    }
  return pts;
}

std::vector<std::string> SceneParser::availablePresets() const {
  std::set<std::string> names;
  for (const std::string& dir : paperPresetDirs()) {
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      if (it->path().extension() == ".toml") names.insert(it->path().stem().string());
    }
  }
  return {names.begin(), names.end()};
}

// Resolve a preset name; `fail` reports a problem at the right place.
template <class Fail>
PaperPreset SceneParser::findPreset(const std::string& name, Fail&& fail) const {
  if (name.empty() || name.find_first_of("/\\") != std::string::npos || name == "." ||
      name == "..") {
    fail("must be a preset name such as 'office-70gsm', not a path");
  }
  std::string looked;
  for (const std::string& dir : paperPresetDirs()) {
    const fs::path p = fs::path(dir) / (name + ".toml");
    std::error_code ec;
    if (fs::is_regular_file(p, ec)) return loadPaperPreset(p.string());
    looked += (looked.empty() ? "" : ", ") + dir;
  }
  std::string known;
  for (const std::string& n : availablePresets()) known += (known.empty() ? "" : ", ") + n;
  fail("unknown paper preset '" + name +
       "' (looked in: " + (looked.empty() ? std::string("no directory") : looked) +
       "; available: " + (known.empty() ? std::string("none") : known) + ")");
  return {};
}

void SceneParser::parsePaper(const toml::table* table) {
  if (!table) {
    spec_.paper = findPreset(spec_.paperPreset, [&](const std::string& problem) {
      throw InputError(file_, "'paper.preset': " + problem);
    });
    return;
  }
  const TableReader r(*table, "paper", file_);
  r.allowOnly({"preset", "front_color", "back_color", "texture", "texture_size", "transmittance",
               "crease_deg"});
  if (auto preset = r.string("preset")) spec_.paperPreset = *preset;
  spec_.paper =
      findPreset(spec_.paperPreset, [&](const std::string& problem) { r.fail("preset", problem); });
  if (auto c = r.vec3("front_color")) spec_.paper.frontColor = r.requireColor("front_color", *c, 1);
  if (auto c = r.vec3("back_color")) spec_.paper.backColor = r.requireColor("back_color", *c, 1);
  PaperLookSpec& look = spec_.look;
  if (auto t = r.string("texture")) {
    if (t->empty()) r.fail("texture", "must not be empty");
    look.texture = resolvePath(*t);
    look.textureLine = r.lineOf("texture");
    std::error_code ec;
    if (checkFiles_ && !fs::is_regular_file(look.texture, ec))
      r.fail("texture", "no such file: " + look.texture);
  }
  if (auto ts = r.vec2("texture_size")) {
    if (!(ts->x() > 0.0 && ts->y() > 0.0)) r.fail("texture_size", "both sides must be > 0");
    look.textureSize = *ts * mpu();
  }
  if (auto t = r.number("transmittance")) {
    if (!(*t >= 0.0 && *t < 1.0))
      r.fail("transmittance", "must be in [0, 1) (got " + formatNumber(*t) + ")");
    look.transmittance = *t;
  }
  if (auto c = r.number("crease_deg")) {
    if (!(*c > 0.0 && *c <= 180.0))
      r.fail("crease_deg", "must be in (0, 180] degrees (got " + formatNumber(*c) + ")");
    look.creaseAngle = *c * kPi / 180.0;
  }
}

}  // namespace crumple::io::detail
