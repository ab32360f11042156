// The scene file parser (docs/SCENE.md is the schema).
#include "crumple/io/scene.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <numbers>
#include <optional>
#include <set>
#include <string_view>
#include <utility>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/core/units.hpp"
#include "crumple/io/animation.hpp"
#include "toml_reader.hpp"

namespace crumple::io {

namespace fs = std::filesystem;
using detail::formatNumber;
using detail::TableReader;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxSubsteps = 1024;
// The OSMesa preview's limits on Debian 12's Mesa 22.3 (llvmpipe): a side up
// to GL_MAX_RENDERBUFFER_SIZE, and its 4-sample colour buffer within 2 GiB
// (measured: 11584 x 11584 renders, 11600 x 11600 and 16384 x 16384 give an
// incomplete framebuffer; docs/RELIABILITY.md).
constexpr std::int64_t kMaxResolution = 16384;
constexpr std::int64_t kMaxPixels = std::int64_t{1} << 27;
constexpr double kMaxSheetSide = 100.0;  // m
constexpr double kMaxSheetVertices = 1'000'000;
// Upper limits of the hybrid parameters: far beyond any useful value, they
// catch numbers written in another unit (per m instead of per cm, ...).
constexpr double kMaxRhoBoundPerCm = 100.0;   // 0.1 mm between boundary samples
constexpr double kMaxRhoIntPerCm2 = 10000.0;  // 0.1 mm between interior samples
constexpr double kMaxSigmaCm = 100.0;
constexpr std::int64_t kMaxIsometryIterations = 100000;
// Coulomb coefficient of the built-in [friction] entries "default" and "paper".
constexpr double kDefaultFriction = 0.3;

// A [friction] material name: non-empty, only a-z, 0-9, _ and -.
bool isMaterialName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char ch) {
    return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_' || ch == '-';
  });
}

std::string notMaterialName(const std::string& name) {
  return "'" + name + "' is not a material name (use only a-z, 0-9, _ and -)";
}

class SceneParser {
 public:
  SceneParser(std::string_view text, const std::string& file, const std::string& baseDir,
              bool checkFiles)
      : file_(file),
        baseDir_(baseDir),
        checkFiles_(checkFiles),
        root_(detail::parseToml(text, file)) {
    spec_.file = file;
    spec_.dir = baseDir;
    spec_.sourceText = std::string(text);
  }

  SceneSpec parse() {
    const TableReader root(root_, "", file_);
    root.allowOnly({"scene", "sheet", "paper", "handles", "camera", "lights", "environment",
                    "ground", "props", "colliders", "friction", "contact", "tear", "sound",
                    "output", "sim", "model"});
    // [scene] first: its `units` scales every length that follows.
    parseScene(root.subTable("scene"));
    const toml::table* sheet = root.subTable("sheet");
    if (!sheet) throw InputError(file_, "'sheet': missing required table [sheet]");
    parseSheet(*sheet);
    parsePaper(root.subTable("paper"));
    parseHandles(root);
    parseCamera(root.subTable("camera"));
    parseLights(root);
    parseEnvironment(root.subTable("environment"));
    parseGround(root.subTable("ground"));
    parseProps(root);
    // [friction] before the colliders that look their material up in it (toml++
    // parses the whole file first, so [friction] may follow [[colliders]]).
    parseFriction(root.subTable("friction"));
    parseColliders(root);
    parseContact(root.subTable("contact"));
    parseTear(root.subTable("tear"));
    parseSound(root.subTable("sound"));
    parseOutput(root.subTable("output"));
    parseSim(root.subTable("sim"));
    parseModel(root.subTable("model"));
    return std::move(spec_);
  }

 private:
  double mpu() const { return spec_.metresPerUnit; }

  std::string defaultName() const {
    std::error_code ec;
    fs::path p = fs::absolute(baseDir_.empty() ? fs::path(".") : fs::path(baseDir_), ec);
    p = p.lexically_normal();
    std::string name = p.filename().string();
    if (name.empty()) name = p.parent_path().filename().string();
    return name.empty() ? std::string("scene") : name;
  }

  void parseScene(const toml::table* table) {
    spec_.name = defaultName();
    if (!table) return;
    const TableReader r(*table, "scene", file_);
    r.allowOnly(
        {"name", "units", "fps", "frames", "substeps", "seed", "animation", "frame_budget_s"});
    if (auto budget = r.number("frame_budget_s")) {
      if (!(*budget >= 0.0) || *budget > 1e6)
        r.fail("frame_budget_s", "must be in [0, 1e6] seconds (0: the cost guard is off)");
      spec_.frameBudget = *budget;
    }
    if (auto name = r.string("name")) {
      if (name->empty()) r.fail("name", "must not be empty");
      // It names the default output folder out/<name>/: one plain folder name.
      if (*name == "." || *name == ".." || name->find_first_of("/\\") != std::string::npos ||
          std::any_of(name->begin(), name->end(),
                      [](char c) { return static_cast<unsigned char>(c) < 0x20; }))
        r.fail(
            "name",
            "'" + *name + "' is not a folder name (no '/', '\\', control characters, '.' or '..')");
      spec_.name = *name;
    }
    if (auto units = r.string("units")) {
      const std::optional<double> m = metresPerUnit(*units);
      if (!m) r.fail("units", "unknown unit '" + *units + "' (expected one of: m, cm, mm, in)");
      spec_.metresPerUnit = *m;
    }
    if (auto fps = r.number("fps")) {
      spec_.fps = r.requirePositive("fps", *fps);
      if (spec_.fps > 10000.0) r.fail("fps", "must be <= 10000 (got " + formatNumber(*fps) + ")");
    }
    if (auto frames = r.intPair("frames")) {
      const auto [a, b] = *frames;
      constexpr std::int64_t lim = 100000000;
      if (a < -lim || a > lim || b < -lim || b > lim) {
        r.fail("frames", "frame numbers must be within +-" + std::to_string(lim));
      }
      if (a > b) {
        r.fail("frames",
               "first frame " + std::to_string(a) + " is after last frame " + std::to_string(b));
      }
      spec_.frameStart = static_cast<int>(a);
      spec_.frameEnd = static_cast<int>(b);
    }
    if (auto s = r.integer("substeps")) {
      if (*s < 1 || *s > kMaxSubsteps) {
        r.fail("substeps", "must be in [1, " + std::to_string(kMaxSubsteps) + "] (got " +
                               std::to_string(*s) + ")");
      }
      spec_.substeps = static_cast<int>(*s);
    }
    if (auto seed = r.integer("seed")) {
      if (*seed < 0) r.fail("seed", "must be >= 0 (got " + std::to_string(*seed) + ")");
      spec_.seed = static_cast<std::uint64_t>(*seed);
    }
    if (auto anim = r.string("animation")) {
      if (anim->empty()) r.fail("animation", "must not be empty");
      fs::path p(*anim);
      std::string ext = p.extension().string();
      for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (ext != ".gltf" && ext != ".glb" && ext != ".fbx" && ext != ".dae")
        r.fail("animation", "'" + *anim + "' is not a .gltf, .glb, .fbx or .dae file");
      if (p.is_relative()) p = fs::path(baseDir_.empty() ? "." : baseDir_) / p;
      p = p.lexically_normal();
      std::error_code ec;
      if (checkFiles_ && !fs::is_regular_file(p, ec))
        r.fail("animation", "no such file: " + p.string());
      spec_.animationFile = p.string();
    }
  }

  void parseSheet(const toml::table& table) {
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
  void checkSheetSize(const TableReader& r, const SheetSpec& s) const {
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
  std::vector<Vec2> parseOutline(const TableReader& r) const {
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

  std::vector<std::string> availablePresets() const {
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
  PaperPreset findPreset(const std::string& name, Fail&& fail) const {
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

  void parsePaper(const toml::table* table) {
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
    spec_.paper = findPreset(spec_.paperPreset,
                             [&](const std::string& problem) { r.fail("preset", problem); });
    if (auto c = r.vec3("front_color"))
      spec_.paper.frontColor = r.requireColor("front_color", *c, 1);
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

  // A path relative to the scene's folder.
  std::string resolvePath(const std::string& path) const {
    fs::path p(path);
    if (p.is_relative()) p = fs::path(baseDir_.empty() ? "." : baseDir_) / p;
    return p.lexically_normal().string();
  }

  void parseHandles(const TableReader& root) {
    const toml::array* handles = root.tableArray("handles");
    if (!handles) return;
    std::set<std::string> names;
    for (std::size_t i = 0; i < handles->size(); ++i) {
      const TableReader r(*handles->get(i)->as_table(), "handles[" + std::to_string(i) + "]",
                          file_);
      r.allowOnly({"name", "node", "pattern", "tangent_control", "tangent_vertices", "patch_radius",
                   "release_time"});
      HandleSpec h;
      const std::optional<std::string> node = r.string("node");
      if (!node) r.missing("node");
      if (node->empty()) r.fail("node", "must not be empty");
      if (spec_.animationFile.empty()) {
        r.fail("node",
               "handles need an animation file ([scene] animation) holding node '" + *node + "'");
      }
      h.node = *node;
      h.nodeLine = r.lineOf("node");
      h.name = r.string("name").value_or(h.node);
      if (h.name.empty()) r.fail("name", "must not be empty");
      if (!names.insert(h.name).second) {
        r.fail(r.has("name") ? "name" : "node", "duplicate handle name '" + h.name + "'");
      }
      if (auto p = r.vec2("pattern")) {
        const Vec2 q = *p * mpu();
        const SheetSpec& s = spec_.sheet;
        if (s.kind != SheetSpec::Kind::PatternMesh) {  // inside the (bounding) rectangle
          const double tol = 1e-9 * std::max(s.width, s.height);
          if (q.x() < -tol || q.x() > s.width + tol || q.y() < -tol || q.y() > s.height + tol) {
            r.fail("pattern", "point [" + formatNumber((*p).x()) + ", " + formatNumber((*p).y()) +
                                  "] is outside the sheet [0, " + formatNumber(s.width / mpu()) +
                                  "] x [0, " + formatNumber(s.height / mpu()) + "]");
          }
        }
        h.patternPoint = q;
        h.patternLine = r.lineOf("pattern");
      }
      h.tangentControl = r.boolean("tangent_control").value_or(false);
      if (auto n = r.integer("tangent_vertices")) {
        if (!(*n == 0 || (*n >= 2 && *n <= 4))) {
          r.fail("tangent_vertices",
                 "must be 0 (automatic) or 2, 3 or 4 (got " + std::to_string(*n) + ")");
        }
        if (*n != 0 && !h.tangentControl) {
          r.fail("tangent_vertices", "needs tangent_control = true");
        }
        h.tangentVertices = static_cast<int>(*n);
      }
      if (auto radius = r.number("patch_radius")) {
        if (!h.tangentControl) r.fail("patch_radius", "needs tangent_control = true");
        if (h.tangentVertices != 0)
          r.fail("patch_radius", "a handle holds a patch or tangent_vertices, not both");
        const SheetSpec& s = spec_.sheet;
        const double most = 0.25 * std::min(s.width, s.height);
        if (!(*radius > 0.0) || !(*radius * mpu() <= most))
          r.fail("patch_radius", "must be above 0 and at most a quarter of the sheet's side (" +
                                     formatNumber(most / mpu()) + "; got " + formatNumber(*radius) +
                                     ")");
        h.patchRadius = *radius * mpu();
      }
      if (auto t = r.number("release_time")) {
        h.releaseTime = r.requireNonNegative("release_time", *t);
      }
      spec_.handles.push_back(std::move(h));
    }
  }

  void parseCamera(const toml::table* table) {
    if (!table) return;
    const TableReader r(*table, "camera", file_);
    r.allowOnly({"node", "position", "look_at", "up", "fov_deg", "focal_mm", "sensor_mm",
                 "resolution", "f_stop", "focus_distance"});
    CameraSpec& c = spec_.camera;
    if (auto res = r.intPair("resolution")) {
      for (std::int64_t v : *res) {
        if (v < 1 || v > kMaxResolution) {
          r.fail("resolution", "width and height must be in [1, " + std::to_string(kMaxResolution) +
                                   "] (got " + std::to_string(v) + ")");
        }
      }
      if ((*res)[0] * (*res)[1] > kMaxPixels)
        r.fail("resolution", std::to_string((*res)[0] * (*res)[1]) + " pixels, more than the " +
                                 std::to_string(kMaxPixels) +
                                 " the renderers can draw (11584 x 11584)");
      c.width = static_cast<int>((*res)[0]);
      c.height = static_cast<int>((*res)[1]);
    }
    if (auto node = r.string("node")) {
      if (node->empty()) r.fail("node", "must not be empty");
      if (spec_.animationFile.empty()) {
        r.fail("node", "a camera node needs an animation file ([scene] animation)");
      }
      for (const char* key : {"position", "look_at", "up"}) {
        if (r.has(key)) r.fail(key, "give either node or position/look_at/up, not both");
      }
      c.node = *node;
      c.nodeLine = r.lineOf("node");
    } else {
      if (auto p = r.vec3("position")) c.position = *p * mpu();
      if (auto l = r.vec3("look_at")) c.lookAt = *l * mpu();
      if (auto u = r.vec3("up")) c.up = r.requireDirection("up", *u);
      const Vec3 view = c.lookAt - c.position;
      if (view.norm() < 1e-12) {
        r.fail(r.has("look_at") ? "look_at" : "position", "look_at must differ from position");
      }
      if (view.normalized().cross(c.up).norm() < 1e-6) {
        r.fail(r.has("up") ? "up" : "look_at", "up must not be parallel to the view direction");
      }
    }
    if (r.has("fov_deg") && r.has("focal_mm")) {
      r.fail("focal_mm", "give either fov_deg or focal_mm, not both");
    }
    if (r.has("sensor_mm") && !r.has("focal_mm")) r.fail("sensor_mm", "needs focal_mm");
    if (auto fov = r.number("fov_deg")) {
      if (!(*fov > 0.0 && *fov < 180.0)) {
        r.fail("fov_deg", "must be in (0, 180) degrees (got " + formatNumber(*fov) + ")");
      }
      c.yfov = *fov * kPi / 180.0;
      c.fovExplicit = true;
    }
    if (auto focal = r.number("focal_mm")) {
      const double f = r.requirePositive("focal_mm", *focal);
      const double sensor =
          r.has("sensor_mm") ? r.requirePositive("sensor_mm", *r.number("sensor_mm")) : 36.0;
      // sensor_mm is the sensor width; the vertical extent follows the aspect.
      const double aspect = static_cast<double>(c.width) / static_cast<double>(c.height);
      c.yfov = 2.0 * std::atan(sensor / aspect / (2.0 * f));
      c.sensorWidth = sensor * 1e-3;
      c.fovExplicit = true;
    }
    if (auto n = r.number("f_stop")) c.fStop = r.requirePositive("f_stop", *n);
    if (auto d = r.number("focus_distance")) {
      if (!(c.fStop > 0.0)) r.fail("focus_distance", "needs f_stop (depth of field)");
      c.focusDistance = r.requirePositive("focus_distance", *d) * mpu();
    }
  }

  void parseLights(const TableReader& root) {
    const toml::array* lights = root.tableArray("lights");
    if (!lights) {
      LightSpec key;
      key.name = "key";
      key.direction = Vec3(-0.4, -1.0, -0.3).normalized();
      key.shadow = true;
      LightSpec fill;
      fill.name = "fill";
      fill.direction = Vec3(0.6, -0.5, 0.4).normalized();
      fill.intensity = 0.35;
      fill.shadow = false;
      spec_.lights = {key, fill};
      return;
    }
    std::set<std::string> names;
    for (std::size_t i = 0; i < lights->size(); ++i) {
      const TableReader r(*lights->get(i)->as_table(), "lights[" + std::to_string(i) + "]", file_);
      r.allowOnly({"name", "type", "direction", "position", "color", "intensity", "shadow",
                   "angle_deg", "size"});
      LightSpec l;
      l.name = r.string("name").value_or("light" + std::to_string(i));
      if (l.name.empty()) r.fail("name", "must not be empty");
      if (!names.insert(l.name).second) r.fail("name", "duplicate light name '" + l.name + "'");
      const std::string type = r.string("type").value_or("directional");
      if (type == "directional" || type == "sun") {
        l.kind = LightSpec::Kind::Directional;
        if (r.has("position")) r.fail("position", "only for point and area lights");
        if (r.has("size")) r.fail("size", "only for area lights (type = \"area\")");
        l.direction = l.direction.normalized();
        if (auto d = r.vec3("direction")) l.direction = r.requireDirection("direction", *d);
        // A sun is a directional light with the sun's disc (0.53 degrees) by default.
        double angleDeg = type == "sun" ? 0.53 : 0.0;
        if (auto a = r.number("angle_deg")) {
          if (!(*a >= 0.0 && *a < 90.0))
            r.fail("angle_deg", "must be in [0, 90) degrees (got " + formatNumber(*a) + ")");
          angleDeg = *a;
        }
        l.angle = angleDeg * kPi / 180.0;
      } else if (type == "point" || type == "area") {
        l.kind = type == "point" ? LightSpec::Kind::Point : LightSpec::Kind::Area;
        if (r.has("angle_deg")) r.fail("angle_deg", "only for directional and sun lights");
        const std::optional<Vec3> p = r.vec3("position");
        if (!p) r.missing("position");
        l.position = *p * mpu();
        if (type == "point") {
          if (r.has("direction")) r.fail("direction", "only for directional, sun and area lights");
          if (r.has("size")) r.fail("size", "only for area lights (type = \"area\")");
        } else {
          const std::optional<Vec3> d = r.vec3("direction");
          if (!d) r.missing("direction");
          l.direction = r.requireDirection("direction", *d);
          if (auto sz = r.vec2("size")) {
            if (!(sz->x() > 0.0 && sz->y() > 0.0)) r.fail("size", "both sides must be > 0");
            l.size = *sz * mpu();
          }
        }
      } else {
        r.fail("type",
               "unknown light type '" + type + "' (expected directional, sun, point or area)");
      }
      if (auto c = r.vec3("color")) l.color = r.requireColor("color", *c, 1.0);
      if (auto v = r.number("intensity")) l.intensity = r.requireNonNegative("intensity", *v);
      l.shadow = r.boolean("shadow").value_or(false);
      spec_.lights.push_back(std::move(l));
    }
  }

  void parseEnvironment(const toml::table* table) {
    if (!table) return;
    const TableReader r(*table, "environment", file_);
    r.allowOnly({"color", "intensity"});
    if (auto c = r.vec3("color")) spec_.environment.color = r.requireColor("color", *c, 1.0);
    if (auto v = r.number("intensity"))
      spec_.environment.intensity = r.requireNonNegative("intensity", *v);
  }

  void parseProps(const TableReader& root) {
    const toml::array* props = root.tableArray("props");
    if (!props) return;
    std::set<std::string> names;
    for (std::size_t i = 0; i < props->size(); ++i) {
      const TableReader r(*props->get(i)->as_table(), "props[" + std::to_string(i) + "]", file_);
      r.allowOnly({"name", "node", "shape", "size", "position", "color"});
      PropSpec p;
      const std::string shape = r.string("shape").value_or(r.has("node") ? "mesh" : "box");
      if (shape == "mesh") {
        const std::optional<std::string> node = r.string("node");
        if (!node) r.missing("node");
        if (node->empty()) r.fail("node", "must not be empty");
        if (spec_.animationFile.empty())
          r.fail("node", "a mesh prop needs an animation file ([scene] animation)");
        for (const char* key : {"size", "position"})
          if (r.has(key)) r.fail(key, "only for shape = \"box\" (a mesh prop moves with its node)");
        p.node = *node;
        p.nodeLine = r.lineOf("node");
      } else if (shape == "box") {
        if (r.has("node")) r.fail("node", "a box has no node (use shape = \"mesh\")");
        const std::optional<Vec3> sz = r.vec3("size");
        if (!sz) r.missing("size");
        if (!(sz->minCoeff() > 0.0)) r.fail("size", "every side must be > 0");
        p.boxSize = *sz * mpu();
        if (auto pos = r.vec3("position")) p.position = *pos * mpu();
      } else {
        r.fail("shape", "unknown shape '" + shape + "' (expected box or mesh)");
      }
      p.name = r.string("name").value_or(p.node.empty() ? "prop" + std::to_string(i) : p.node);
      if (p.name.empty()) r.fail("name", "must not be empty");
      if (!names.insert(p.name).second) r.fail("name", "duplicate prop name '" + p.name + "'");
      if (auto c = r.vec3("color")) p.color = r.requireColor("color", *c, 1.0);
      spec_.props.push_back(std::move(p));
    }
  }

  void parseColliders(const TableReader& root) {
    const toml::array* colliders = root.tableArray("colliders");
    if (!colliders) return;
    std::set<std::string> names;
    for (std::size_t i = 0; i < colliders->size(); ++i) {
      const TableReader r(*colliders->get(i)->as_table(), "colliders[" + std::to_string(i) + "]",
                          file_);
      r.allowOnly(
          {"name", "type", "position", "normal", "size", "radius", "node", "material", "friction"});
      ColliderSpec c;
      const std::optional<std::string> type = r.string("type");
      if (!type) r.missing("type");
      const auto only = [&](const char* key, const char* types) {
        if (r.has(key)) r.fail(key, std::string("only for ") + types);
      };
      // A box or sphere may follow any node (position is then its offset).
      const auto followNode = [&](const std::string& what) {
        const std::optional<std::string> node = r.string("node");
        if (!node) return;
        if (node->empty()) r.fail("node", "must not be empty");
        if (spec_.animationFile.empty()) {
          r.fail("node",
                 "a " + what + " following a node needs an animation file ([scene] animation)");
        }
        c.node = *node;
        c.nodeLine = r.lineOf("node");
      };
      if (auto p = r.vec3("position")) c.position = *p * mpu();
      if (*type == "plane") {
        c.kind = ColliderSpec::Kind::Plane;
        if (auto n = r.vec3("normal")) c.normal = r.requireDirection("normal", *n);
        only("size", "boxes");
        only("radius", "spheres");
        only("node", "meshes, boxes and spheres");
      } else if (*type == "box") {
        c.kind = ColliderSpec::Kind::Box;
        const std::optional<Vec3> sz = r.vec3("size");
        if (!sz) r.missing("size");
        if (!(sz->minCoeff() > 0.0)) r.fail("size", "every side must be > 0");
        c.size = *sz * mpu();
        only("normal", "planes");
        only("radius", "spheres");
        followNode("box");
      } else if (*type == "sphere") {
        c.kind = ColliderSpec::Kind::Sphere;
        const std::optional<double> rad = r.number("radius");
        if (!rad) r.missing("radius");
        c.radius = r.requirePositive("radius", *rad) * mpu();
        only("normal", "planes");
        only("size", "boxes");
        followNode("sphere");
      } else if (*type == "mesh") {
        c.kind = ColliderSpec::Kind::Mesh;
        const std::optional<std::string> node = r.string("node");
        if (!node) r.missing("node");
        if (node->empty()) r.fail("node", "must not be empty");
        if (spec_.animationFile.empty())
          r.fail("node", "a mesh collider needs an animation file ([scene] animation)");
        c.node = *node;
        c.nodeLine = r.lineOf("node");
        only("position", "planes, boxes and spheres (a mesh moves with its node)");
        only("normal", "planes");
        only("size", "boxes");
        only("radius", "spheres");
      } else {
        r.fail("type",
               "unknown collider type '" + *type + "' (expected plane, box, sphere or mesh)");
      }
      // Friction: an explicit `friction` wins, else the material's [friction]
      // entry, else [friction] default.
      const std::optional<std::string> material = r.string("material");
      if (material && !isMaterialName(*material)) r.fail("material", notMaterialName(*material));
      if (auto mu = r.number("friction")) {
        c.friction = r.requireNonNegative("friction", *mu);
        c.material = material.value_or("custom");
      } else if (material) {
        const auto it = spec_.friction.find(*material);
        if (it == spec_.friction.end()) {
          std::string known;
          for (const auto& entry : spec_.friction)
            known += (known.empty() ? "" : ", ") + entry.first;
          r.fail("material", "material '" + *material +
                                 "' has no coefficient: add it to [friction] (known: " + known +
                                 ")");
        }
        c.friction = it->second;
        c.material = *material;
      } else {
        c.friction = spec_.friction.at("default");
        c.material = "default";
      }
      c.name = r.string("name").value_or(c.node.empty() ? "collider" + std::to_string(i) : c.node);
      if (c.name.empty()) r.fail("name", "must not be empty");
      if (!names.insert(c.name).second) r.fail("name", "duplicate collider name '" + c.name + "'");
      spec_.colliders.push_back(std::move(c));
    }
  }

  // [friction]: material name = Coulomb coefficient of paper on it, on top of
  // the built-in default and paper (paper on paper).
  void parseFriction(const toml::table* table) {
    spec_.friction = {{"default", kDefaultFriction}, {"paper", kDefaultFriction}};
    if (!table) return;
    const TableReader r(*table, "friction", file_);
    // Report the first bad entry in file order (toml++ sorts keys).
    std::vector<std::pair<long, std::string>> keys;
    for (auto&& [k, v] : *table)
      keys.emplace_back(static_cast<long>(k.source().begin.line), std::string(k.str()));
    std::sort(keys.begin(), keys.end());
    for (const auto& [line, name] : keys) {
      if (!isMaterialName(name)) r.fail(name, notMaterialName(name));
      spec_.friction[name] = r.requireNonNegative(name, *r.number(name));
    }
  }

  // [contact] self = true | false | "auto".
  void parseContact(const toml::table* table) {
    if (!table) return;
    const TableReader r(*table, "contact", file_);
    r.allowOnly({"self"});
    const toml::node* self = r.find("self");
    if (!self) return;
    const std::string expected = "expected true, false or \"auto\"";
    if (auto b = self->as_boolean()) {
      spec_.contact.self = b->get() ? ContactSpec::Self::On : ContactSpec::Self::Off;
    } else if (auto str = self->as_string()) {
      if (str->get() != "auto") r.fail("self", expected + " (got \"" + str->get() + "\")");
      spec_.contact.self = ContactSpec::Self::Auto;
    } else {
      r.fail("self", expected + ", got " + detail::typeName(*self));
    }
  }

  // [tear]: the table's presence enables tearing (enabled = false keeps it off).
  void parseTear(const toml::table* table) {
    if (!table) return;
    const TableReader r(*table, "tear", file_);
    r.allowOnly({"enabled", "resistance", "tip_damage", "speed_m", "texel_mm", "fiber_size_mm",
                 "fiber_octaves", "fiber_anisotropy", "fiber_direction", "detail_blend",
                 "stress_width_mm", "inward_angle_deg", "eps_a", "max_new_per_frame"});
    spec_.tearEnabled = r.boolean("enabled").value_or(true);
    tear::TearingParams& t = spec_.tearing;
    if (auto v = r.number("resistance"))
      t.griffith.resistance = r.requireNonNegative("resistance", *v);
    if (auto v = r.number("tip_damage")) {
      if (!(*v >= 0.0 && *v <= 1.0)) r.fail("tip_damage", "must be in [0, 1]");
      t.griffith.tipDamage = *v;
    }
    if (auto v = r.number("speed_m")) t.griffith.speed = r.requirePositive("speed_m", *v);
    if (auto v = r.number("texel_mm")) {
      t.fibers.texelSize = r.requirePositive("texel_mm", *v) * 1e-3;
      if (t.fibers.texelSize < 2e-5) r.fail("texel_mm", "must be at least 0.02 mm");
    }
    if (auto v = r.number("fiber_size_mm"))
      t.fibers.featureSize = r.requirePositive("fiber_size_mm", *v) * 1e-3;
    if (auto v = r.integer("fiber_octaves")) {
      if (*v < 1 || *v > 12) r.fail("fiber_octaves", "must be in [1, 12]");
      t.fibers.octaves = static_cast<int>(*v);
    }
    if (auto v = r.number("fiber_anisotropy")) {
      if (!(*v >= 1.0)) r.fail("fiber_anisotropy", "must be >= 1 (1 = isotropic)");
      t.fibers.anisotropy = *v;
    }
    if (auto v = r.vec2("fiber_direction")) {
      if (!(v->norm() > 0.0)) r.fail("fiber_direction", "must not be zero");
      t.fibers.fiberDirection = v->normalized();
    }
    if (auto v = r.number("detail_blend")) {
      if (!(*v >= 0.0 && *v <= 1.0)) r.fail("detail_blend", "must be in [0, 1]");
      t.detail.blend = *v;
    }
    if (auto v = r.number("stress_width_mm"))
      t.detail.stressWidth = r.requirePositive("stress_width_mm", *v) * 1e-3;
    if (auto v = r.number("inward_angle_deg")) {
      if (!(*v >= 0.0 && *v < 180.0)) r.fail("inward_angle_deg", "must be in [0, 180)");
      t.griffith.minInwardAngle = *v * std::numbers::pi / 180.0;
    }
    if (auto v = r.number("eps_a")) {
      if (!(*v >= 0.0 && *v < std::numbers::pi)) r.fail("eps_a", "must be in [0, pi) (rad)");
      t.branchAngle = *v;
    }
    if (auto v = r.integer("max_new_per_frame")) {
      if (*v < 0 || *v > 100) r.fail("max_new_per_frame", "must be in [0, 100]");
      t.maxNewTearsPerFrame = static_cast<int>(*v);
    }
  }

  // [sound]: the table's presence enables the sound events and the soundtrack.
  void parseSound(const toml::table* table) {
    if (!table) return;
    const TableReader r(*table, "sound", file_);
    r.allowOnly({"enabled", "grid_mm", "curvature_threshold", "a_max", "free_border_radius_cm",
                 "min_slide_mm_s", "listener", "database", "channels", "sample_rate", "format"});
    spec_.soundEnabled = r.boolean("enabled").value_or(true);
    sound::EventParams& s = spec_.soundEvents;
    if (auto v = r.number("grid_mm")) {
      s.gridSpacing = r.requirePositive("grid_mm", *v) * 1e-3;
      if (s.gridSpacing < 1e-4) r.fail("grid_mm", "must be at least 0.1 mm");
    }
    if (auto v = r.number("curvature_threshold"))
      s.curvatureThreshold = r.requirePositive("curvature_threshold", *v);
    if (auto v = r.number("a_max")) {
      if (!(*v > 0.0 && *v < std::numbers::pi)) r.fail("a_max", "must be in (0, pi) (rad)");
      s.maxDihedral = *v;
    }
    if (auto v = r.number("free_border_radius_cm"))
      s.freeBorderRadius = r.requirePositive("free_border_radius_cm", *v) * 1e-2;
    if (auto v = r.number("min_slide_mm_s"))
      s.minSlideSpeed = r.requireNonNegative("min_slide_mm_s", *v) * 1e-3;
    SoundtrackSpec& out = spec_.soundtrack;
    if (auto v = r.vec3("listener")) out.listener = *v * mpu();
    if (auto d = r.string("database")) {
      out.databaseLine = r.lineOf("database");
      out.database = resolvePath(*d);
    }
    if (auto v = r.integer("channels")) {
      if (*v != 1 && *v != 2) r.fail("channels", "must be 1 (mono) or 2 (stereo)");
      out.channels = static_cast<int>(*v);
    }
    if (auto v = r.integer("sample_rate")) {
      if (*v != 48000 && *v != 44100) r.fail("sample_rate", "must be 48000 or 44100");
      out.sampleRate = static_cast<int>(*v);
    }
    if (auto f = r.string("format")) {
      if (*f != "pcm24" && *f != "float") r.fail("format", "must be \"pcm24\" or \"float\"");
      out.floatSamples = *f == "float";
    }
  }

  void parseGround(const toml::table* table) {
    if (!table) return;
    const TableReader r(*table, "ground", file_);
    r.allowOnly({"enabled", "height", "size", "color"});
    GroundSpec& g = spec_.ground;
    g.enabled = r.boolean("enabled").value_or(true);  // the table's presence enables it
    if (auto h = r.number("height")) g.height = *h * mpu();
    if (auto s = r.number("size")) g.size = r.requirePositive("size", *s) * mpu();
    if (auto c = r.vec3("color")) g.color = r.requireColor("color", *c, 1.0);
  }

  void parseOutput(const toml::table* table) {
    if (!table) return;
    const TableReader r(*table, "output", file_);
    r.allowOnly({"dir", "frames"});
    if (auto d = r.string("dir")) spec_.output.dir = *d;
    if (auto f = r.boolean("frames")) spec_.output.frames = *f;
  }

  void parseSim(const toml::table* table) {
    if (!table) return;
    const TableReader r(*table, "sim", file_);
    r.allowOnly({"gravity", "mass_damping", "stiffness_damping", "max_newton_iterations"});
    sim::SimParams& s = spec_.sim;
    if (auto g = r.vec3("gravity")) {
      if (g->norm() > 1000.0)
        r.fail("gravity", "is implausibly large (m/s^2, not scaled by units)");
      s.gravity = *g;
    }
    if (auto a = r.number("mass_damping")) s.massDamping = r.requireNonNegative("mass_damping", *a);
    if (auto b = r.number("stiffness_damping")) {
      s.stiffnessDamping = r.requireNonNegative("stiffness_damping", *b);
    }
    if (auto n = r.integer("max_newton_iterations")) {
      if (*n < 1 || *n > 1000) {
        r.fail("max_newton_iterations", "must be in [1, 1000] (got " + std::to_string(*n) + ")");
      }
      s.maxNewtonIterations = static_cast<int>(*n);
    }
  }

  // [model]: which sheet model runs, and the hybrid model's parameters (paper
  // Table VI). The parameters have fixed units (their names say which),
  // whatever [scene] units says.
  void parseModel(const toml::table* table) {
    if (!table) return;
    const TableReader r(*table, "model", file_);
    static constexpr std::string_view kHybridKeys[] = {"rho_bound_per_cm",
                                                       "rho_int_per_cm2",
                                                       "theta0",
                                                       "theta_low",
                                                       "theta_high",
                                                       "eps_blaschke",
                                                       "eps_c",
                                                       "sigma_cm",
                                                       "theta_rest",
                                                       "damage",
                                                       "isometry_iterations",
                                                       "isometry_length_sweeps",
                                                       "isometry_length_tolerance",
                                                       "max_singular_per_frame",
                                                       "remesh_cooldown",
                                                       "max_edge_strain",
                                                       "lag_catch_up_speed"};
    std::vector<std::string_view> allowed = {"type"};
    allowed.insert(allowed.end(), std::begin(kHybridKeys), std::end(kHybridKeys));
    r.allowOnly(allowed);
    ModelSpec& m = spec_.model;
    m.typeLine = r.lineOf("type");
    const std::string type = r.string("type").value_or("elastic");
    if (type == "elastic") {
      m.type = ModelSpec::Type::Elastic;
      // A hybrid parameter under the elastic model is a mistake, not a no-op:
      // report the first one in file order.
      std::string_view first;
      long firstLine = 0;
      for (std::string_view key : kHybridKeys) {
        if (r.has(key) && (first.empty() || r.lineOf(key) < firstLine)) {
          first = key;
          firstLine = r.lineOf(key);
        }
      }
      if (!first.empty()) {
        r.fail(first, "only for type = \"hybrid\" (the elastic model has no such parameter)");
      }
      return;
    }
    if (type != "hybrid") {
      r.fail("type", "unknown model '" + type + "' (expected one of: elastic, hybrid)");
    }
    m.type = ModelSpec::Type::Hybrid;
    paper::CrumpleParams& h = spec_.crumpling;
    // value in (lo, hi), or [lo, hi) when loClosed; hiText names hi in the message.
    auto inRange = [&](std::string_view key, double v, double lo, double hi, bool loClosed,
                       const std::string& hiText = {}) {
      if (!((loClosed ? v >= lo : v > lo) && v < hi)) {
        r.fail(key, "must be in " + std::string(loClosed ? "[" : "(") + formatNumber(lo) + ", " +
                        (hiText.empty() ? formatNumber(hi) : hiText) + ") (got " + formatNumber(v) +
                        ")");
      }
      return v;
    };
    constexpr double kHalfPi = kPi / 2.0;
    const std::string halfPi = "pi/2";
    if (auto v = r.number("rho_bound_per_cm")) {
      h.rhoBound = inRange("rho_bound_per_cm", *v, 0.0, kMaxRhoBoundPerCm, false) * 100.0;
    }
    if (auto v = r.number("rho_int_per_cm2")) {
      h.rhoInt = inRange("rho_int_per_cm2", *v, 0.0, kMaxRhoIntPerCm2, false) * 1.0e4;
    }
    if (auto v = r.number("theta0")) {
      h.theta0 = inRange("theta0", *v, 0.0, kHalfPi, false, halfPi);
      // The hysteresis thresholds follow theta0 unless given (Table VI).
      h.thetaLow = h.theta0 / 10.0;
      h.thetaHigh = h.theta0;
    }
    if (auto v = r.number("theta_low")) {
      h.thetaLow = inRange("theta_low", *v, 0.0, kHalfPi, false, halfPi);
    }
    if (auto v = r.number("theta_high")) {
      h.thetaHigh = inRange("theta_high", *v, 0.0, kHalfPi, false, halfPi);
    }
    if (!(h.thetaLow < h.thetaHigh)) {
      const char* key = r.has("theta_low") ? "theta_low" : "theta_high";
      r.fail(key, "theta_low must be < theta_high (got theta_low = " + formatNumber(h.thetaLow) +
                      ", theta_high = " + formatNumber(h.thetaHigh) + ")");
    }
    if (auto v = r.number("eps_blaschke")) {
      h.epsBlaschke = inRange("eps_blaschke", *v, 0.0, 1.0, false);
    }
    if (auto v = r.number("eps_c")) h.epsC = inRange("eps_c", *v, 0.0, 0.5, false);
    if (auto v = r.number("sigma_cm")) {
      h.sigma = inRange("sigma_cm", *v, 0.0, kMaxSigmaCm, false) * 0.01;
    }
    if (auto v = r.number("theta_rest"))
      h.thetaRest = inRange("theta_rest", *v, 0.0, kPi, true, "pi");
    if (auto v = r.number("damage")) h.damage = r.requireNonNegative("damage", *v);
    if (auto n = r.integer("isometry_iterations")) {
      if (*n < 1 || *n > kMaxIsometryIterations) {
        r.fail("isometry_iterations", "must be in [1, " + std::to_string(kMaxIsometryIterations) +
                                          "] (got " + std::to_string(*n) + ")");
      }
      h.isometryIterations = static_cast<int>(*n);
    }
    // The isometry's Gauss-Seidel length sweeps after Phase II and their
    // early-exit tolerance (isometry.hpp deviation 7); 0 sweeps keeps the
    // paper's projection alone.
    if (auto n = r.integer("isometry_length_sweeps")) {
      if (*n < 0 || *n > kMaxIsometryIterations) {
        r.fail("isometry_length_sweeps", "must be in [0, " +
                                             std::to_string(kMaxIsometryIterations) + "] (got " +
                                             std::to_string(*n) + ")");
      }
      h.isometryLengthSweeps = static_cast<int>(*n);
    }
    if (auto v = r.number("isometry_length_tolerance")) {
      h.isometryLengthTolerance = inRange("isometry_length_tolerance", *v, 0.0, 0.1, false);
    }
    // How fast the sheet may crumple: new singular vertices per frame, and
    // animation steps a remeshed region waits before it is remeshed again.
    const auto count = [&](std::string_view key, long hi) -> std::optional<int> {
      const auto n = r.integer(key);
      if (!n) return std::nullopt;
      if (*n < 0 || *n > hi) {
        r.fail(key, "must be in [0, " + std::to_string(hi) + "] (got " + std::to_string(*n) + ")");
      }
      return static_cast<int>(*n);
    };
    if (auto n = count("max_singular_per_frame", 1000)) h.maxSingularPerFrame = *n;
    if (auto n = count("remesh_cooldown", 1000)) h.remeshCooldown = *n;
    // Paper stays paper: S_P's edge-strain bound after every animation step
    // (0 turns the strain limit off).
    if (auto v = r.number("max_edge_strain"))
      h.maxEdgeStrain = inRange("max_edge_strain", *v, 0.0, 0.5, true);
    // How fast a handle the bound left behind comes back (m/s; 0: at once).
    if (auto v = r.number("lag_catch_up_speed"))
      h.lagCatchUpSpeed = inRange("lag_catch_up_speed", *v, 0.0, 100.0, true);
  }

  std::string file_;
  std::string baseDir_;
  bool checkFiles_ = true;
  toml::table root_;
  SceneSpec spec_;
};

}  // namespace

std::string resolveScenePath(const std::string& sceneOrFolder) {
  std::error_code ec;
  fs::path p(sceneOrFolder);
  if (fs::is_directory(p, ec)) p /= "scene.toml";
  if (!fs::exists(p, ec)) throw InputError(p.string(), "no such file");
  if (!fs::is_regular_file(p, ec)) throw InputError(p.string(), "not a regular file");
  return p.string();
}

void checkAnimationNodes(const SceneSpec& scene, const AnimationScene& animation) {
  // Re-throw the animation's error at the scene line that named the node.
  auto check = [&](long line, const std::string& key, auto&& probe) {
    try {
      probe();
    } catch (const InputError& e) {
      throw InputError(scene.file, line, key, e.what());
    }
  };
  for (std::size_t i = 0; i < scene.handles.size(); ++i) {
    const HandleSpec& h = scene.handles[i];
    check(h.nodeLine, "handles[" + std::to_string(i) + "].node",
          [&] { (void)animation.worldPose(h.node, 0.0); });
  }
  if (!scene.camera.node.empty()) {
    check(scene.camera.nodeLine, "camera.node", [&] {
      if (!animation.camera(scene.camera.node, 0.0)) {
        throw InputError(animation.file(), "node '" + scene.camera.node + "' holds no camera");
      }
    });
  }
  if (scene.sheet.kind == SheetSpec::Kind::PatternMesh) {
    check(scene.sheet.patternMeshLine, "sheet.pattern_mesh", [&] {
      const std::optional<ImportedMesh> m = animation.mesh(scene.sheet.patternMesh);
      if (!m || m->triangles.empty()) {
        throw InputError(animation.file(),
                         "node '" + scene.sheet.patternMesh + "' holds no triangle mesh");
      }
    });
  }
  for (std::size_t i = 0; i < scene.colliders.size(); ++i) {
    const ColliderSpec& c = scene.colliders[i];
    if (c.node.empty()) continue;
    check(c.nodeLine, "colliders[" + std::to_string(i) + "].node", [&] {
      if (c.kind != ColliderSpec::Kind::Mesh) {
        // A box or sphere follows the node's transform: any node will do.
        (void)animation.worldPose(c.node, 0.0);
        return;
      }
      const std::optional<ImportedMesh> m = animation.mesh(c.node);
      if (!m || m->triangles.empty())
        throw InputError(animation.file(), "node '" + c.node + "' holds no triangle mesh");
    });
  }
  for (std::size_t i = 0; i < scene.props.size(); ++i) {
    const PropSpec& p = scene.props[i];
    if (p.node.empty()) continue;
    check(p.nodeLine, "props[" + std::to_string(i) + "].node", [&] {
      const std::optional<ImportedMesh> m = animation.mesh(p.node);
      if (!m || m->triangles.empty())
        throw InputError(animation.file(), "node '" + p.node + "' holds no triangle mesh");
    });
  }
}

SceneSpec loadScene(const std::string& path) {
  const std::string file = resolveScenePath(path);
  const std::string text = detail::readTextFile(file);
  std::string dir = fs::path(file).parent_path().string();
  if (dir.empty()) dir = ".";
  return parseScene(text, file, dir);
}

SceneSpec parseScene(std::string_view text, const std::string& sourceName,
                     const std::string& baseDir, bool checkFiles) {
  return SceneParser(text, sourceName, baseDir, checkFiles).parse();
}

}  // namespace crumple::io
