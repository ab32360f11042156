// The scene file parser (docs/SCENE.md is the schema): the order of the
// tables, [scene] and [output], and the public entry points (scene.hpp).
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>

#include "crumple/core/error.hpp"
#include "crumple/core/units.hpp"
#include "crumple/io/animation.hpp"
#include "scene_parser.hpp"

namespace crumple::io::detail {

namespace fs = std::filesystem;

namespace {

constexpr int kMaxSubsteps = 1024;

}  // namespace

SceneParser::SceneParser(std::string_view text, const std::string& file, const std::string& baseDir,
                         bool checkFiles)
    : file_(file),
      baseDir_(baseDir),
      checkFiles_(checkFiles),
      root_(detail::parseToml(text, file)) {
  spec_.file = file;
  spec_.dir = baseDir;
  spec_.sourceText = std::string(text);
}

SceneSpec SceneParser::parse() {
  const TableReader root(root_, "", file_);
  root.allowOnly({"scene", "sheet", "paper", "handles", "camera", "lights", "environment", "ground",
                  "props", "colliders", "friction", "contact", "tear", "sound", "output", "sim",
                  "model", "air"});
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
  // After [sim], whose struct holds the air.
  parseAir(root.subTable("air"));
  parseModel(root.subTable("model"));
  return std::move(spec_);
}

std::string SceneParser::defaultName() const {
  std::error_code ec;
  fs::path p = fs::absolute(baseDir_.empty() ? fs::path(".") : fs::path(baseDir_), ec);
  p = p.lexically_normal();
  std::string name = p.filename().string();
  if (name.empty()) name = p.parent_path().filename().string();
  return name.empty() ? std::string("scene") : name;
}

// A path relative to the scene's folder.
std::string SceneParser::resolvePath(const std::string& path) const {
  fs::path p(path);
  if (p.is_relative()) p = fs::path(baseDir_.empty() ? "." : baseDir_) / p;
  return p.lexically_normal().string();
}

void SceneParser::parseScene(const toml::table* table) {
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
      r.fail("name", "'" + *name +
                         "' is not a folder name (no '/', '\\', control characters, '.' or '..')");
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

void SceneParser::parseOutput(const toml::table* table) {
  if (!table) return;
  const TableReader r(*table, "output", file_);
  r.allowOnly({"dir", "frames"});
  if (auto d = r.string("dir")) spec_.output.dir = *d;
  if (auto f = r.boolean("frames")) spec_.output.frames = *f;
}

}  // namespace crumple::io::detail

namespace crumple::io {

namespace fs = std::filesystem;

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
  const fs::path parent = fs::path(file).parent_path();
  return parseScene(text, file, parent.empty() ? std::string(".") : parent.string());
}

SceneSpec parseScene(std::string_view text, const std::string& sourceName,
                     const std::string& baseDir, bool checkFiles) {
  return detail::SceneParser(text, sourceName, baseDir, checkFiles).parse();
}

}  // namespace crumple::io
