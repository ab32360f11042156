// The scene file parser: values, unit conversion, and one clear error (file,
// line, key) for every bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"
#include "scene_test.hpp"

namespace crumple::io {
namespace {

using testing::expectError;
using testing::kData;
using testing::parse;
constexpr double kPi = 3.14159265358979323846;

const std::string kSheet = "[sheet]\nwidth = 21\nheight = 29.7\n";

TEST(Scene, FullSceneRoundTripsInCentimetres) {
  const std::string text = R"(# every key
[scene]
name = "drape"
units = "cm"
fps = 30
frames = [5, 60]
substeps = 8
seed = 42
animation = "anim.gltf"

[sheet]
width = 21
height = 29.7
max_edge = 1.5
origin = [1, 2, 3]
u_axis = [2, 0, 0]
v_axis = [0, 0, -1]

[paper]
preset = "office-90gsm"
front_color = [0.9, 0.8, 0.7]
back_color = [0.5, 0.5, 0.5]

[[handles]]
name = "left"
node = "Handle"
pattern = [0, 29.7]
tangent_control = true
tangent_vertices = 3
release_time = 1.5

[[handles]]
node = "Child"

[camera]
position = [0, 30, 60]
look_at = [0, 0, 0]
up = [0, 1, 0]
fov_deg = 50
resolution = [320, 240]

[[lights]]
name = "sun"
type = "directional"
direction = [0, -2, 0]
color = [1, 0.9, 0.8]
intensity = 2
shadow = true

[[lights]]
name = "bulb"
type = "point"
position = [10, 20, 30]

[ground]
height = -1
size = 200
color = [0.2, 0.3, 0.4]

[output]
dir = "out/custom"
frames = false

[sim]
gravity = [0, -1.62, 0]
mass_damping = 0.25
stiffness_damping = 0.001
max_newton_iterations = 12
)";
  const SceneSpec s = parse(text);
  EXPECT_EQ(s.file, "test.toml");
  EXPECT_EQ(s.dir, kData);
  EXPECT_EQ(s.sourceText, text);
  EXPECT_EQ(s.name, "drape");
  EXPECT_DOUBLE_EQ(s.metresPerUnit, 0.01);
  EXPECT_DOUBLE_EQ(s.fps, 30.0);
  EXPECT_EQ(s.frameStart, 5);
  EXPECT_EQ(s.frameEnd, 60);
  EXPECT_EQ(s.substeps, 8);
  EXPECT_EQ(s.seed, 42u);
  EXPECT_EQ(s.animationFile, kData + "/anim.gltf");
  EXPECT_DOUBLE_EQ(s.frameTime(48), 1.6);

  EXPECT_EQ(s.sheet.kind, SheetSpec::Kind::Rectangle);
  EXPECT_NEAR(s.sheet.width, 0.21, 1e-15);
  EXPECT_NEAR(s.sheet.height, 0.297, 1e-15);
  EXPECT_NEAR(s.sheet.maxEdge, 0.015, 1e-15);
  EXPECT_TRUE(s.sheet.origin.isApprox(Vec3(0.01, 0.02, 0.03)));
  EXPECT_TRUE(s.sheet.uAxis.isApprox(Vec3(1, 0, 0)));  // normalised, not scaled
  EXPECT_TRUE(s.sheet.vAxis.isApprox(Vec3(0, 0, -1)));

  EXPECT_EQ(s.paperPreset, "office-90gsm");
  EXPECT_EQ(s.paper.material.name, "office-90gsm");
  EXPECT_NEAR(s.paper.grammage, 0.090, 1e-12);
  EXPECT_TRUE(s.paper.frontColor.isApprox(Vec3(0.9, 0.8, 0.7)));
  EXPECT_TRUE(s.paper.backColor.isApprox(Vec3(0.5, 0.5, 0.5)));

  ASSERT_EQ(s.handles.size(), 2u);
  EXPECT_EQ(s.handles[0].name, "left");
  EXPECT_EQ(s.handles[0].node, "Handle");
  ASSERT_TRUE(s.handles[0].patternPoint.has_value());
  EXPECT_TRUE(s.handles[0].patternPoint->isApprox(Vec2(0, 0.297)));
  EXPECT_TRUE(s.handles[0].tangentControl);
  EXPECT_EQ(s.handles[0].tangentVertices, 3);
  ASSERT_TRUE(s.handles[0].releaseTime.has_value());
  EXPECT_DOUBLE_EQ(*s.handles[0].releaseTime, 1.5);  // seconds, not scaled
  EXPECT_EQ(s.handles[1].name, "Child");             // defaults to the node
  EXPECT_FALSE(s.handles[1].patternPoint.has_value());
  EXPECT_FALSE(s.handles[1].tangentControl);
  EXPECT_FALSE(s.handles[1].releaseTime.has_value());

  EXPECT_TRUE(s.camera.node.empty());
  EXPECT_TRUE(s.camera.position.isApprox(Vec3(0, 0.3, 0.6)));
  EXPECT_TRUE(s.camera.lookAt.isZero());
  EXPECT_NEAR(s.camera.yfov, 50.0 * kPi / 180.0, 1e-15);
  EXPECT_TRUE(s.camera.fovExplicit);
  EXPECT_EQ(s.camera.width, 320);
  EXPECT_EQ(s.camera.height, 240);

  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].name, "sun");
  EXPECT_EQ(s.lights[0].kind, LightSpec::Kind::Directional);
  EXPECT_TRUE(s.lights[0].direction.isApprox(Vec3(0, -1, 0)));
  EXPECT_TRUE(s.lights[0].color.isApprox(Vec3(1, 0.9, 0.8)));
  EXPECT_DOUBLE_EQ(s.lights[0].intensity, 2.0);
  EXPECT_TRUE(s.lights[0].shadow);
  EXPECT_EQ(s.lights[1].kind, LightSpec::Kind::Point);
  EXPECT_TRUE(s.lights[1].position.isApprox(Vec3(0.1, 0.2, 0.3)));
  EXPECT_FALSE(s.lights[1].shadow);

  EXPECT_TRUE(s.ground.enabled);  // the table's presence enables it
  EXPECT_NEAR(s.ground.height, -0.01, 1e-15);
  EXPECT_NEAR(s.ground.size, 2.0, 1e-15);
  EXPECT_TRUE(s.ground.color.isApprox(Vec3(0.2, 0.3, 0.4)));

  EXPECT_EQ(s.output.dir, "out/custom");
  EXPECT_FALSE(s.output.frames);

  EXPECT_TRUE(s.sim.gravity.isApprox(Vec3(0, -1.62, 0)));  // m/s^2, never scaled by units
  EXPECT_DOUBLE_EQ(s.sim.massDamping, 0.25);
  EXPECT_DOUBLE_EQ(s.sim.stiffnessDamping, 0.001);
  EXPECT_EQ(s.sim.maxNewtonIterations, 12);
}

TEST(Scene, Defaults) {
  const SceneSpec s = parse("[sheet]\nwidth = 0.2\nheight = 0.3\n");
  EXPECT_EQ(s.name, std::filesystem::path(kData).filename().string());  // folder name
  EXPECT_DOUBLE_EQ(s.metresPerUnit, 1.0);
  EXPECT_DOUBLE_EQ(s.sheet.width, 0.2);
  EXPECT_DOUBLE_EQ(s.sheet.maxEdge, 0.0);
  EXPECT_DOUBLE_EQ(s.fps, 24.0);
  EXPECT_EQ(s.frameStart, 1);
  EXPECT_EQ(s.frameEnd, 48);
  EXPECT_EQ(s.substeps, 4);
  EXPECT_TRUE(s.animationFile.empty());
  EXPECT_EQ(s.paper.material.name, "office-70gsm");
  EXPECT_TRUE(s.handles.empty());
  EXPECT_FALSE(s.camera.fovExplicit);
  EXPECT_FALSE(s.ground.enabled);
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].name, "key");
  EXPECT_TRUE(s.lights[0].shadow);
  EXPECT_DOUBLE_EQ(s.lights[0].intensity, 1.0);
  EXPECT_NEAR(s.lights[0].direction.norm(), 1.0, 1e-12);
  EXPECT_EQ(s.lights[1].name, "fill");
  EXPECT_FALSE(s.lights[1].shadow);
  EXPECT_DOUBLE_EQ(s.lights[1].intensity, 0.35);
}

TEST(Scene, OtherUnits) {
  const SceneSpec mm = parse("[scene]\nunits = \"mm\"\n[sheet]\nwidth = 210\nheight = 297\n");
  EXPECT_NEAR(mm.sheet.width, 0.21, 1e-15);
  const SceneSpec in = parse("[scene]\nunits = \"in\"\n[sheet]\nwidth = 8.5\nheight = 11\n");
  EXPECT_NEAR(in.sheet.width, 0.2159, 1e-15);
  EXPECT_NEAR(in.sheet.height, 0.2794, 1e-15);
}

TEST(Scene, CameraFromFocalLength) {
  const SceneSpec s =
      parse(kSheet + "[camera]\nfocal_mm = 50\nsensor_mm = 36\nresolution = [600, 400]\n");
  // Sensor width 36 mm, aspect 1.5: sensor height 24 mm.
  EXPECT_NEAR(s.camera.yfov, 2.0 * std::atan(12.0 / 50.0), 1e-15);
  const SceneSpec d = parse(kSheet + "[camera]\nfocal_mm = 35\nresolution = [600, 400]\n");
  EXPECT_NEAR(d.camera.yfov, 2.0 * std::atan(12.0 / 35.0), 1e-15);  // default sensor 36 mm
}

TEST(Scene, CameraNodeAndPatternMesh) {
  const SceneSpec s = parse(
      "[scene]\nanimation = \"anim.glb\"\n[sheet]\npattern_mesh = \"Sheet\"\nmax_edge = 0.01\n"
      "[camera]\nnode = \"Camera\"\n");
  EXPECT_EQ(s.sheet.kind, SheetSpec::Kind::PatternMesh);
  EXPECT_EQ(s.sheet.patternMesh, "Sheet");
  EXPECT_EQ(s.camera.node, "Camera");
  EXPECT_FALSE(s.camera.fovExplicit);
}

TEST(Scene, LoadFromFolder) {
  const std::string folder = kData + "/drape";
  EXPECT_EQ(resolveScenePath(folder), folder + "/scene.toml");
  EXPECT_EQ(resolveScenePath(folder + "/scene.toml"), folder + "/scene.toml");
  const SceneSpec s = loadScene(folder);
  EXPECT_EQ(s.name, "drape");
  EXPECT_EQ(s.file, folder + "/scene.toml");
  EXPECT_EQ(s.dir, folder);
  EXPECT_EQ(s.animationFile, kData + "/anim.gltf");  // ../ resolved against the scene folder
  std::ifstream in(folder + "/scene.toml");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(s.sourceText, text);
  ASSERT_EQ(s.handles.size(), 1u);
  EXPECT_TRUE(s.handles[0].patternPoint->isApprox(Vec2(0, 0.297)));
}

TEST(Scene, MissingSceneFile) {
  try {
    resolveScenePath(kData + "/nowhere");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), kData + "/nowhere: no such file");
  }
  try {
    loadScene(kData);  // a folder without scene.toml
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), kData + "/scene.toml: no such file");
  }
}

// ---- One error per bad input ---------------------------------------------------

TEST(SceneErrors, TomlSyntax) {
  try {
    parse("[scene]\nfps = 24\nname = \"unterminated\n");
    FAIL();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("test.toml:3:", 0), 0u) << msg;
    EXPECT_NE(msg.find("TOML syntax error"), std::string::npos) << msg;
  }
}

TEST(SceneErrors, UnknownTableAndKeys) {
  expectError(kSheet + "[extras]\nx = 1\n", 4, "extras", {"unknown key"});
  expectError("[scene]\nfps = 24\nbogus = 3\n" + kSheet, 3, "scene.bogus",
              {"unknown key", "expected one of", "fps"});
  expectError(kSheet + "colour = 3\n", 4, "sheet.colour", {"unknown key"});
  expectError(kSheet + "[[handles]]\nnode = \"Handle\"\nwhatever = 1\n", 6, "handles[0].whatever",
              {"unknown key"});
  expectError(kSheet + "[camera]\n[camera.lens]\nf = 1\n", 5, "camera.lens", {"unknown key"});
  expectError(kSheet + "[sim]\ngravity = [0, -9.8, 0]\nsolver = \"cg\"\n", 6, "sim.solver");
}

TEST(SceneErrors, WrongTypes) {
  expectError("[scene]\nfps = \"24\"\n" + kSheet, 2, "scene.fps", {"expected a number", "string"});
  expectError("[scene]\nsubsteps = 2.5\n" + kSheet, 2, "scene.substeps", {"expected an integer"});
  expectError("[scene]\nframes = [1.0, 2]\n" + kSheet, 2, "scene.frames", {"two integers"});
  expectError(kSheet + "origin = [1, 2]\n", 4, "sheet.origin", {"3 numbers", "2 elements"});
  expectError(kSheet + "origin = [1, \"a\", 2]\n", 4, "sheet.origin", {"element 1"});
  expectError(kSheet + "[ground]\nenabled = 1\n", 5, "ground.enabled", {"true or false"});
  expectError("[scene]\nname = 3\n" + kSheet, 2, "scene.name", {"expected a string"});
  expectError("sheet = 3\n", 1, "sheet", {"expected a table"});
  expectError(kSheet + "[handles]\nnode = \"Handle\"\n", 4, "handles", {"array of tables"});
}

TEST(SceneErrors, BadSizes) {
  expectError("[sheet]\nwidth = -21\nheight = 29.7\n", 2, "sheet.width", {"must be > 0", "-21"});
  expectError("[sheet]\nwidth = 21\nheight = 0\n", 3, "sheet.height", {"must be > 0"});
  expectError(kSheet + "max_edge = 0\n", 4, "sheet.max_edge", {"must be > 0"});
  expectError(kSheet + "max_edge = 100\n", 4, "sheet.max_edge", {"larger than the sheet"});
  expectError(kSheet + "[ground]\nsize = -2\n", 5, "ground.size", {"must be > 0"});
}

TEST(SceneErrors, MissingRequiredKeyUsesTableLine) {
  expectError("[scene]\nfps = 24\n\n[sheet]\nwidth = 21\n", 4, "sheet.height",
              {"missing required key"});
  expectError(kSheet + "\n[[handles]]\nname = \"a\"\n", 5, "handles[0].node",
              {"missing required key"});
  expectError(kSheet + "[[lights]]\ntype = \"point\"\n", 4, "lights[0].position",
              {"missing required key"});
}

TEST(SceneErrors, MissingSheetTable) {
  try {
    parse("[scene]\nfps = 24\n");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "test.toml: 'sheet': missing required table [sheet]");
  }
}

TEST(SceneErrors, SceneValues) {
  expectError("[scene]\nfps = 0\n" + kSheet, 2, "scene.fps", {"must be > 0"});
  expectError("[scene]\nfps = -24\n" + kSheet, 2, "scene.fps", {"must be > 0"});
  expectError("[scene]\nframes = [48, 1]\n" + kSheet, 2, "scene.frames",
              {"first frame 48 is after last frame 1"});
  expectError("[scene]\nsubsteps = 0\n" + kSheet, 2, "scene.substeps", {"[1, 1024]"});
  expectError("[scene]\nsubsteps = 1025\n" + kSheet, 2, "scene.substeps", {"[1, 1024]"});
  expectError("[scene]\nunits = \"furlong\"\n" + kSheet, 2, "scene.units",
              {"unknown unit 'furlong'", "m, cm, mm, in"});
  expectError("[scene]\nseed = -1\n" + kSheet, 2, "scene.seed", {">= 0"});
  expectError("[scene]\nname = \"\"\n" + kSheet, 2, "scene.name", {"empty"});
  expectError("[scene]\nanimation = \"nope.glb\"\n" + kSheet, 2, "scene.animation",
              {"no such file", "nope.glb"});
}

TEST(SceneErrors, NonFiniteNumbers) {
  expectError("[sheet]\nwidth = nan\nheight = 1\n", 2, "sheet.width", {"finite"});
  expectError("[scene]\nfps = inf\n" + kSheet, 2, "scene.fps", {"finite"});
  expectError(kSheet + "origin = [0, -inf, 0]\n", 4, "sheet.origin", {"finite"});
}

TEST(SceneErrors, SheetShape) {
  expectError(
      "[scene]\nanimation = \"anim.gltf\"\n[sheet]\nwidth = 21\nheight = 29.7\n"
      "pattern_mesh = \"Sheet\"\n",
      4, "sheet.width", {"either width/height or pattern_mesh"});
  expectError("[sheet]\npattern_mesh = \"Sheet\"\n", 2, "sheet.pattern_mesh",
              {"needs an animation file"});
  expectError(
      "[scene]\nanimation = \"anim.gltf\"\n[sheet]\npattern_mesh = \"Sheet\"\n"
      "origin = [0, 0, 0]\n",
      5, "sheet.origin", {"only for a width/height rectangle"});
  expectError(kSheet + "u_axis = [0, 0, 0]\n", 4, "sheet.u_axis", {"non-zero"});
  expectError(kSheet + "v_axis = [1, 1, 0]\n", 4, "sheet.v_axis", {"perpendicular"});
}

const std::string kAnimSheet = "[scene]\nanimation = \"anim.gltf\"\n" + kSheet;  // lines 1-5

TEST(Scene, APatchRadiusIsInTheScenesUnits) {
  const SceneSpec s = parse("[scene]\nunits = \"cm\"\nanimation = \"anim.gltf\"\n" + kSheet +
                            "[[handles]]\nnode = \"Handle\"\ntangent_control = true\n"
                            "patch_radius = 0.5\n[[handles]]\nnode = \"Child\"\n");
  ASSERT_EQ(s.handles.size(), 2u);
  EXPECT_NEAR(s.handles[0].patchRadius, 0.005, 1e-15);
  EXPECT_EQ(s.handles[1].patchRadius, 0.0) << "tangent-plane vertices unless asked";
}

TEST(SceneErrors, Handles) {
  expectError(kAnimSheet +
                  "[[handles]]\nnode = \"Handle\"\ntangent_control = true\n"
                  "tangent_vertices = 1\n",
              9, "handles[0].tangent_vertices", {"0 (automatic) or 2, 3 or 4"});
  expectError(kAnimSheet +
                  "[[handles]]\nnode = \"Handle\"\ntangent_control = true\n"
                  "tangent_vertices = 5\n",
              9, "handles[0].tangent_vertices");
  expectError(kAnimSheet + "[[handles]]\nnode = \"Handle\"\ntangent_vertices = 3\n", 8,
              "handles[0].tangent_vertices", {"needs tangent_control = true"});
  expectError(kAnimSheet + "[[handles]]\nnode = \"Handle\"\npatch_radius = 0.5\n", 8,
              "handles[0].patch_radius", {"needs tangent_control = true"});
  expectError(kAnimSheet +
                  "[[handles]]\nnode = \"Handle\"\ntangent_control = true\n"
                  "tangent_vertices = 3\npatch_radius = 0.5\n",
              10, "handles[0].patch_radius", {"not both"});
  expectError(
      kAnimSheet + "[[handles]]\nnode = \"Handle\"\ntangent_control = true\npatch_radius = 0\n", 9,
      "handles[0].patch_radius", {"above 0", "5.25"});
  expectError(
      kAnimSheet + "[[handles]]\nnode = \"Handle\"\ntangent_control = true\npatch_radius = 6\n", 9,
      "handles[0].patch_radius", {"a quarter of the sheet's side"});
  expectError(kAnimSheet + "[[handles]]\nnode = \"Handle\"\n[[handles]]\nnode = \"Handle\"\n", 9,
              "handles[1].node", {"duplicate handle name 'Handle'"});
  expectError(kAnimSheet +
                  "[[handles]]\nname = \"a\"\nnode = \"Handle\"\n"
                  "[[handles]]\nname = \"a\"\nnode = \"Child\"\n",
              10, "handles[1].name", {"duplicate handle name 'a'"});
  expectError(kAnimSheet + "[[handles]]\nnode = \"Handle\"\npattern = [21.5, 3]\n", 8,
              "handles[0].pattern", {"outside the sheet", "[0, 21] x [0, 29.7]"});
  expectError(kAnimSheet + "[[handles]]\nnode = \"Handle\"\npattern = [3, -0.1]\n", 8,
              "handles[0].pattern", {"outside the sheet"});
  expectError(kAnimSheet + "[[handles]]\nnode = \"Handle\"\nrelease_time = -1\n", 8,
              "handles[0].release_time", {">= 0"});
  expectError(kSheet + "[[handles]]\nnode = \"Handle\"\n", 5, "handles[0].node",
              {"need an animation file"});
}

TEST(SceneErrors, Paper) {
  expectError(kSheet + "[paper]\npreset = \"papyrus\"\n", 5, "paper.preset",
              {"unknown paper preset 'papyrus'", "office-70gsm", "office-90gsm"});
  expectError(kSheet + "[paper]\npreset = \"../papers/office-70gsm\"\n", 5, "paper.preset",
              {"not a path"});
  expectError(kSheet + "[paper]\nfront_color = [1.2, 0, 0]\n", 5, "paper.front_color",
              {"component 0", "[0, 1]"});
}

TEST(SceneErrors, Camera) {
  expectError(kAnimSheet + "[camera]\nnode = \"Camera\"\nposition = [0, 1, 2]\n", 8,
              "camera.position", {"either node or position"});
  expectError(kSheet + "[camera]\nfov_deg = 40\nfocal_mm = 35\n", 6, "camera.focal_mm",
              {"either fov_deg or focal_mm"});
  expectError(kSheet + "[camera]\nfov_deg = 180\n", 5, "camera.fov_deg", {"(0, 180)"});
  expectError(kSheet + "[camera]\nsensor_mm = 36\n", 5, "camera.sensor_mm", {"needs focal_mm"});
  expectError(kSheet + "[camera]\nfocal_mm = -35\n", 5, "camera.focal_mm", {"> 0"});
  expectError(kSheet + "[camera]\nresolution = [0, 480]\n", 5, "camera.resolution", {"[1, 16384]"});
  expectError(kSheet + "[camera]\nposition = [0, 0, 0]\nlook_at = [0, 0, 0]\n", 6, "camera.look_at",
              {"must differ from position"});
  expectError(kSheet + "[camera]\nposition = [0, 1, 0]\nup = [0, 2, 0]\n", 6, "camera.up",
              {"parallel"});
  expectError(kSheet + "[camera]\nnode = \"Camera\"\n", 5, "camera.node",
              {"needs an animation file"});
}

TEST(SceneErrors, Lights) {
  expectError(kSheet + "[[lights]]\ntype = \"spot\"\n", 5, "lights[0].type",
              {"unknown light type 'spot'"});
  expectError(kSheet + "[[lights]]\nposition = [0, 1, 0]\n", 5, "lights[0].position",
              {"only for point and area lights"});
  expectError(
      kSheet + "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n", 7,
      "lights[0].direction", {"only for directional, sun and area lights"});
  expectError(kSheet + "[[lights]]\nintensity = -1\n", 5, "lights[0].intensity", {">= 0"});
  expectError(kSheet + "[[lights]]\nname = \"a\"\n[[lights]]\nname = \"a\"\n", 7, "lights[1].name",
              {"duplicate light name 'a'"});
  expectError(kSheet + "[[lights]]\ndirection = [0, 0, 0]\n", 5, "lights[0].direction",
              {"non-zero"});
}

TEST(SceneErrors, Sim) {
  expectError(kSheet + "[sim]\nmass_damping = -0.5\n", 5, "sim.mass_damping", {">= 0"});
  expectError(kSheet + "[sim]\nmax_newton_iterations = 0\n", 5, "sim.max_newton_iterations",
              {"[1, 1000]"});
}

// ---- [model] -----------------------------------------------------------------

TEST(SceneModel, ElasticWhenAbsent) {
  const SceneSpec s = parse(kSheet);
  EXPECT_EQ(s.model.type, ModelSpec::Type::Elastic);
  EXPECT_EQ(s.model.typeLine, 0);
  const SceneSpec e = parse(kSheet + "[model]\ntype = \"elastic\"\n");
  EXPECT_EQ(e.model.type, ModelSpec::Type::Elastic);
  EXPECT_EQ(e.model.typeLine, 5);
  EXPECT_EQ(parse(kSheet + "[model]\n").model.type, ModelSpec::Type::Elastic);
}

TEST(SceneModel, HybridDefaultsAreTheSeeds) {
  // Paper Table VI, thesis 2.3.3: crumple::paper::CrumpleParams's defaults.
  const SceneSpec s = parse(kSheet + "[model]\ntype = \"hybrid\"\n");
  EXPECT_EQ(s.model.type, ModelSpec::Type::Hybrid);
  EXPECT_EQ(s.model.typeLine, 5);
  const paper::CrumpleParams& h = s.crumpling;
  EXPECT_DOUBLE_EQ(h.rhoBound, 120.0);  // 1.2 per cm
  EXPECT_DOUBLE_EQ(h.rhoInt, 3600.0);   // 0.36 per cm^2
  EXPECT_DOUBLE_EQ(h.theta0, 0.01);
  EXPECT_DOUBLE_EQ(h.thetaLow, 0.001);
  EXPECT_DOUBLE_EQ(h.thetaHigh, 0.01);
  EXPECT_DOUBLE_EQ(h.epsBlaschke, 0.005);
  EXPECT_DOUBLE_EQ(h.epsC, 0.001);
  EXPECT_DOUBLE_EQ(h.sigma, 0.001);  // 0.1 cm
  EXPECT_DOUBLE_EQ(h.thetaRest, kPi / 8.0);
  EXPECT_DOUBLE_EQ(h.damage, 10.0);
  EXPECT_EQ(h.isometryIterations, 200);
  EXPECT_EQ(h.isometryLengthSweeps, 300);
  EXPECT_DOUBLE_EQ(h.isometryLengthTolerance, 1e-6);
  // Without keys, and without [model], the scene holds the model's own struct as it is.
  EXPECT_EQ(h, paper::CrumpleParams{});
  EXPECT_EQ(parse(kSheet).crumpling, paper::CrumpleParams{});
}

// Each [model] key reaches its field of paper::CrumpleParams, converted to
// SI (whatever [scene] units says), and changes nothing else.
TEST(SceneModel, EveryKeyReachesCrumpleParams) {
  const std::string head =
      "[scene]\nunits = \"mm\"\n[sheet]\nwidth = 100\nheight = 100\n[model]\ntype = \"hybrid\"\n";
  using Set = std::function<void(paper::CrumpleParams&)>;
  const std::vector<std::pair<std::string, Set>> cases = {
      {"rho_bound_per_cm = 2.5", [](auto& p) { p.rhoBound = 2.5 * 100.0; }},
      {"rho_int_per_cm2 = 6", [](auto& p) { p.rhoInt = 6.0 * 1.0e4; }},
      {"theta0 = 0.02",
       [](auto& p) {
         p.theta0 = 0.02;
         p.thetaLow = 0.02 / 10.0;
         p.thetaHigh = 0.02;
       }},
      {"theta_low = 0.003", [](auto& p) { p.thetaLow = 0.003; }},
      {"theta_high = 0.015", [](auto& p) { p.thetaHigh = 0.015; }},
      {"eps_blaschke = 0.01", [](auto& p) { p.epsBlaschke = 0.01; }},
      {"eps_c = 0.005", [](auto& p) { p.epsC = 0.005; }},
      {"sigma_cm = 0.3", [](auto& p) { p.sigma = 0.3 * 0.01; }},
      {"theta_rest = 0.5", [](auto& p) { p.thetaRest = 0.5; }},
      {"damage = 4", [](auto& p) { p.damage = 4.0; }},
      {"isometry_iterations = 50", [](auto& p) { p.isometryIterations = 50; }},
      {"isometry_length_sweeps = 0", [](auto& p) { p.isometryLengthSweeps = 0; }},
      {"isometry_length_tolerance = 1e-9", [](auto& p) { p.isometryLengthTolerance = 1e-9; }},
      {"max_singular_per_frame = 5", [](auto& p) { p.maxSingularPerFrame = 5; }},
      {"remesh_cooldown = 0", [](auto& p) { p.remeshCooldown = 0; }},
      {"max_edge_strain = 0.01", [](auto& p) { p.maxEdgeStrain = 0.01; }},
      {"lag_catch_up_speed = 0.05", [](auto& p) { p.lagCatchUpSpeed = 0.05; }},
  };
  for (const auto& [line, set] : cases) {
    paper::CrumpleParams want;
    set(want);
    EXPECT_EQ(parse(head + line + "\n").crumpling, want) << line;
  }
}

// [sim] fills sim::SimParams: its keys in their fields (m/s^2 never scaled
// by units), the rest the simulator's defaults.
TEST(SceneSim, EveryKeyReachesSimParams) {
  EXPECT_EQ(parse(kSheet).sim, sim::SimParams{});
  const SceneSpec s = parse("[scene]\nunits = \"cm\"\n" + kSheet +
                            "[sim]\ngravity = [0, -1.62, 0]\nmass_damping = 0.25\n"
                            "stiffness_damping = 0.001\nmax_newton_iterations = 12\n");
  sim::SimParams want;
  want.gravity = Vec3(0.0, -1.62, 0.0);
  want.massDamping = 0.25;
  want.stiffnessDamping = 0.001;
  want.maxNewtonIterations = 12;
  EXPECT_EQ(s.sim, want);
}

TEST(SceneModel, EveryKeyParsedAndConvertedToSI) {
  // units = "mm" must not scale the [model] parameters: their units are fixed.
  const SceneSpec s = parse(
      "[scene]\nunits = \"mm\"\n[sheet]\nwidth = 100\nheight = 100\n"
      "[model]\n"
      "type = \"hybrid\"\n"
      "rho_bound_per_cm = 2.5\n"
      "rho_int_per_cm2 = 6\n"
      "theta0 = 0.02\n"
      "theta_low = 0.003\n"
      "theta_high = 0.015\n"
      "eps_blaschke = 0.01\n"
      "eps_c = 0.005\n"
      "sigma_cm = 0.01\n"
      "theta_rest = 0.5\n"
      "damage = 4\n"
      "isometry_iterations = 50\n"
      "isometry_length_sweeps = 0\n"
      "isometry_length_tolerance = 1e-9\n"
      "max_singular_per_frame = 5\n"
      "remesh_cooldown = 0\n"
      "max_edge_strain = 0.02\n"
      "lag_catch_up_speed = 0.05\n");
  const paper::CrumpleParams& h = s.crumpling;
  EXPECT_EQ(s.model.type, ModelSpec::Type::Hybrid);
  EXPECT_DOUBLE_EQ(h.rhoBound, 250.0);
  EXPECT_DOUBLE_EQ(h.rhoInt, 60000.0);
  EXPECT_DOUBLE_EQ(h.theta0, 0.02);
  EXPECT_DOUBLE_EQ(h.thetaLow, 0.003);
  EXPECT_DOUBLE_EQ(h.thetaHigh, 0.015);
  EXPECT_DOUBLE_EQ(h.epsBlaschke, 0.01);
  EXPECT_DOUBLE_EQ(h.epsC, 0.005);
  EXPECT_DOUBLE_EQ(h.sigma, 0.0001);
  EXPECT_DOUBLE_EQ(h.thetaRest, 0.5);
  EXPECT_DOUBLE_EQ(h.damage, 4.0);
  EXPECT_EQ(h.isometryIterations, 50);
  EXPECT_EQ(h.isometryLengthSweeps, 0);
  EXPECT_DOUBLE_EQ(h.isometryLengthTolerance, 1e-9);
  EXPECT_EQ(h.maxSingularPerFrame, 5);
  EXPECT_EQ(h.remeshCooldown, 0);
  EXPECT_DOUBLE_EQ(h.maxEdgeStrain, 0.02);
  EXPECT_DOUBLE_EQ(h.lagCatchUpSpeed, 0.05);  // m/s, not scaled by [scene] units
}

TEST(SceneModel, HysteresisFollowsTheta0) {
  const std::string head = kSheet + "[model]\ntype = \"hybrid\"\n";
  const paper::CrumpleParams a = parse(head + "theta0 = 0.05\n").crumpling;
  EXPECT_DOUBLE_EQ(a.thetaLow, 0.005);
  EXPECT_DOUBLE_EQ(a.thetaHigh, 0.05);
  const paper::CrumpleParams b = parse(head + "theta0 = 0.05\ntheta_low = 0.02\n").crumpling;
  EXPECT_DOUBLE_EQ(b.thetaLow, 0.02);
  EXPECT_DOUBLE_EQ(b.thetaHigh, 0.05);
  const paper::CrumpleParams c = parse(head + "theta_high = 0.1\n").crumpling;
  EXPECT_DOUBLE_EQ(c.thetaLow, 0.001);
  EXPECT_DOUBLE_EQ(c.thetaHigh, 0.1);
  const paper::CrumpleParams d =
      parse(head + "theta_rest = 0\ndamage = 0\n").crumpling;  // no damage
  EXPECT_DOUBLE_EQ(d.thetaRest, 0.0);
  EXPECT_DOUBLE_EQ(d.damage, 0.0);
}

TEST(SceneErrors, Model) {
  const std::string head = kSheet + "[model]\ntype = \"hybrid\"\n";  // lines 1-5
  expectError(kSheet + "[model]\ntype = \"fem\"\n", 5, "model.type",
              {"unknown model 'fem'", "elastic, hybrid"});
  expectError(kSheet + "[model]\ntype = 1\n", 5, "model.type", {"expected a string"});
  expectError(kSheet + "[model]\ntype = \"elastic\"\neps_c = 0.01\n", 6, "model.eps_c",
              {"only for type = \"hybrid\""});
  expectError(kSheet + "[model]\nsigma_cm = 0.01\n", 5, "model.sigma_cm",
              {"only for type = \"hybrid\""});  // type defaults to elastic
  expectError(head + "rho_bound = 1.2\n", 6, "model.rho_bound",
              {"unknown key", "rho_bound_per_cm"});
  expectError(kSheet + "model = \"hybrid\"\n", 4, "sheet.model", {"unknown key"});
  expectError("model = \"hybrid\"\n" + kSheet, 1, "model", {"expected a table"});

  expectError(head + "rho_bound_per_cm = 0\n", 6, "model.rho_bound_per_cm", {"(0, 100)", "got 0"});
  expectError(head + "rho_bound_per_cm = 120\n", 6, "model.rho_bound_per_cm", {"(0, 100)"});
  expectError(head + "rho_bound_per_cm = \"1.2\"\n", 6, "model.rho_bound_per_cm",
              {"expected a number"});
  expectError(head + "rho_int_per_cm2 = -6\n", 6, "model.rho_int_per_cm2", {"(0, 10000)"});
  expectError(head + "rho_int_per_cm2 = nan\n", 6, "model.rho_int_per_cm2", {"finite"});
  expectError(head + "theta0 = 0\n", 6, "model.theta0", {"(0, pi/2)"});
  expectError(head + "theta0 = 2\n", 6, "model.theta0", {"(0, pi/2)"});
  expectError(head + "theta_low = -0.001\n", 6, "model.theta_low", {"(0, pi/2)"});
  expectError(head + "theta_high = 3\n", 6, "model.theta_high", {"(0, pi/2)"});
  expectError(head + "theta_low = 0.02\n", 6, "model.theta_low",
              {"theta_low must be < theta_high", "0.02", "0.01"});
  expectError(head + "theta_low = 0.005\ntheta_high = 0.005\n", 6, "model.theta_low",
              {"theta_low must be < theta_high"});
  expectError(head + "theta_high = 0.0005\n", 6, "model.theta_high",
              {"theta_low must be < theta_high"});
  expectError(head + "theta0 = 0.1\ntheta_low = 0.2\n", 7, "model.theta_low",
              {"theta_low must be < theta_high"});
  expectError(head + "eps_blaschke = 0\n", 6, "model.eps_blaschke", {"(0, 1)"});
  expectError(head + "eps_blaschke = 5\n", 6, "model.eps_blaschke", {"(0, 1)", "got 5"});
  expectError(head + "eps_c = 0\n", 6, "model.eps_c", {"(0, 0.5)"});
  expectError(head + "eps_c = 0.5\n", 6, "model.eps_c", {"(0, 0.5)"});
  expectError(head + "eps_c = 1\n", 6, "model.eps_c", {"(0, 0.5)", "got 1"});  // 1 % = 0.01
  expectError(head + "eps_c = -0.001\n", 6, "model.eps_c", {"(0, 0.5)"});
  expectError(head + "sigma_cm = 0\n", 6, "model.sigma_cm", {"(0, 100)"});
  expectError(head + "sigma_cm = inf\n", 6, "model.sigma_cm", {"finite"});
  expectError(head + "max_edge_strain = -0.01\n", 6, "model.max_edge_strain", {"[0, 0.5)"});
  expectError(head + "max_edge_strain = 2\n", 6, "model.max_edge_strain", {"[0, 0.5)", "got 2"});
  expectError(head + "max_edge_strain = nan\n", 6, "model.max_edge_strain", {"finite"});
  expectError(head + "lag_catch_up_speed = -0.01\n", 6, "model.lag_catch_up_speed", {"[0, 100)"});
  expectError(head + "lag_catch_up_speed = inf\n", 6, "model.lag_catch_up_speed", {"finite"});
  expectError(head + "theta_rest = -0.1\n", 6, "model.theta_rest", {"[0, pi)"});
  expectError(head + "theta_rest = 3.2\n", 6, "model.theta_rest", {"[0, pi)"});
  expectError(head + "damage = -1\n", 6, "model.damage", {">= 0"});
  expectError(head + "isometry_iterations = 0\n", 6, "model.isometry_iterations", {"[1, 100000]"});
  expectError(head + "isometry_iterations = 200000\n", 6, "model.isometry_iterations",
              {"[1, 100000]"});
  expectError(head + "isometry_iterations = 20.5\n", 6, "model.isometry_iterations",
              {"expected an integer"});
  expectError(head + "isometry_length_sweeps = -1\n", 6, "model.isometry_length_sweeps",
              {"[0, 100000]", "got -1"});
  expectError(head + "isometry_length_sweeps = 1e3\n", 6, "model.isometry_length_sweeps",
              {"expected an integer"});
  expectError(head + "isometry_length_tolerance = 0\n", 6, "model.isometry_length_tolerance",
              {"(0, 0.1)"});
  expectError(head + "isometry_length_tolerance = 0.5\n", 6, "model.isometry_length_tolerance",
              {"(0, 0.1)", "got 0.5"});
  expectError(head + "max_singular_per_frame = -1\n", 6, "model.max_singular_per_frame",
              {"[0, 1000]", "got -1"});
  expectError(head + "remesh_cooldown = 2.5\n", 6, "model.remesh_cooldown",
              {"expected an integer"});
}

TEST(SceneAnimation, NodesAreCheckedAgainstTheFile) {
  const std::string good = R"([scene]
animation = "anim.glb"
[sheet]
pattern_mesh = "Sheet"
[camera]
node = "Camera"
[[handles]]
node = "Handle"
[[handles]]
node = "Child"
)";
  const SceneSpec s = parse(good);
  EXPECT_EQ(s.handles[1].nodeLine, 10);
  const AnimationScene anim = AnimationScene::load(s.animationFile);
  EXPECT_NO_THROW(checkAnimationNodes(s, anim));

  auto expectCheckError = [&](const std::string& text, const std::string& prefix,
                              const std::string& fragment) {
    const SceneSpec bad = parse(text);
    try {
      checkAnimationNodes(bad, anim);
      ADD_FAILURE() << text;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(prefix, 0), 0u) << msg;
      EXPECT_NE(msg.find(fragment), std::string::npos) << msg;
      EXPECT_NE(msg.find("anim.glb"), std::string::npos) << msg;
    }
  };
  std::string text = good;
  expectCheckError(text.replace(text.find("\"Child\""), 7, "\"Thumb\""),
                   "test.toml:10: 'handles[1].node': ", "no node named 'Thumb'");
  text = good;
  expectCheckError(text.replace(text.find("\"Camera\""), 8, "\"Static\""),
                   "test.toml:6: 'camera.node': ", "holds no camera");
  text = good;
  expectCheckError(text.replace(text.find("\"Sheet\""), 7, "\"Handle\""),
                   "test.toml:4: 'sheet.pattern_mesh': ", "holds no triangle mesh");
}

// ---- The shipped samples ---------------------------------------------------------

// Every scene file in samples/*/ (a folder may hold several, e.g. paper-types).
std::vector<std::filesystem::path> sampleScenes() {
  namespace fs = std::filesystem;
  const fs::path samples = (fs::path(kData) / ".." / ".." / ".." / "samples").lexically_normal();
  std::vector<fs::path> scenes;
  for (const auto& dir : fs::directory_iterator(samples)) {
    if (!dir.is_directory()) continue;
    for (const auto& f : fs::directory_iterator(dir.path()))
      if (f.is_regular_file() && f.path().extension() == ".toml") scenes.push_back(f.path());
  }
  std::sort(scenes.begin(), scenes.end());
  return scenes;
}

TEST(Samples, EverySceneParsesAndMatchesItsAnimation) {
  const auto scenes = sampleScenes();
  ASSERT_GE(scenes.size(), 9u);  // drape, the six seeds' experiments, variants
  RecordProperty("scenes", static_cast<int>(scenes.size()));
  std::set<std::string> names;
  for (const auto& path : scenes) {
    SCOPED_TRACE(path.string());
    SceneSpec s;
    ASSERT_NO_THROW(s = loadScene(path.string()));  // animation file checked to exist
    EXPECT_TRUE(names.insert(s.name).second) << "two samples write to out/" << s.name;
    if (s.animationFile.empty()) {
      // A sample without an animation moves by the air alone (docs/AIR.md).
      EXPECT_TRUE(s.handles.empty());
      EXPECT_TRUE(s.sim.air.has_value());
      continue;
    }
    AnimationScene anim = AnimationScene::load(s.animationFile);
    EXPECT_TRUE(anim.warnings().empty());
    ASSERT_NO_THROW(checkAnimationNodes(s, anim));
    ASSERT_FALSE(s.handles.empty());
    // Each handle's node starts on the sheet point it holds: the generator
    // scripts and the scene files agree on where the sheet is.
    const double t0 = s.frameTime(s.frameStart);
    for (const HandleSpec& h : s.handles) {
      ASSERT_NE(s.sheet.kind, SheetSpec::Kind::PatternMesh);
      ASSERT_TRUE(h.patternPoint.has_value()) << h.name;
      const Vec3 held = s.sheet.origin + h.patternPoint->x() * s.sheet.uAxis +
                        h.patternPoint->y() * s.sheet.vAxis;
      EXPECT_LT((anim.worldPose(h.node, t0).position - held).norm(), 1e-6) << h.name;
      if (h.releaseTime) {
        EXPECT_LT(*h.releaseTime, s.frameTime(s.frameEnd)) << h.name;
      }
    }
    // The shot covers the whole animation.
    EXPECT_GE(s.frameTime(s.frameEnd) + 1e-6, anim.endTime());
  }
}

TEST(Samples, PaperTypesDifferOnlyInEpsC) {
  const std::string dir = kData + "/../../../samples/paper-types/";
  const SceneSpec a = loadScene(dir + "eps-1.0.toml");
  const SceneSpec b = loadScene(dir + "eps-0.5.toml");
  const SceneSpec c = loadScene(dir + "eps-0.2.toml");
  EXPECT_EQ(a.model.type, ModelSpec::Type::Hybrid);
  EXPECT_DOUBLE_EQ(a.crumpling.epsC, 0.01);
  EXPECT_DOUBLE_EQ(b.crumpling.epsC, 0.005);
  EXPECT_DOUBLE_EQ(c.crumpling.epsC, 0.002);
  EXPECT_EQ(a.animationFile, b.animationFile);
  EXPECT_EQ(a.animationFile, c.animationFile);
  EXPECT_EQ(a.handles.size(), c.handles.size());
  EXPECT_DOUBLE_EQ(a.crumpling.sigma, c.crumpling.sigma);
}

}  // namespace
}  // namespace crumple::io

// --- rendering keys --------------------------------------------------

namespace crumple::io {
namespace {

TEST(SceneRendering, LightsEnvironmentPropsLookAndDepthOfField) {
  const SceneSpec s = parse("[scene]\nunits = \"cm\"\n" + kSheet + R"(
[paper]
texture_size = [20, 30]
transmittance = 0.3
crease_deg = 45
[camera]
position = [0, 30, 60]
look_at = [0, 0, 0]
focal_mm = 50
f_stop = 2.8
[[lights]]
type = "sun"
direction = [0, -1, 0]
[[lights]]
type = "area"
position = [0, 50, 0]
direction = [0, -1, 0]
size = [20, 10]
intensity = 2
[environment]
color = [0.5, 0.6, 0.7]
intensity = 0.5
[[props]]
shape = "box"
size = [10, 4, 10]
position = [30, 2, 0]
color = [0.2, 0.3, 0.4]
)");
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].kind, LightSpec::Kind::Directional);
  EXPECT_NEAR(s.lights[0].angle, 0.53 * kPi / 180.0, 1e-12) << "a sun has the sun's disc";
  EXPECT_EQ(s.lights[1].kind, LightSpec::Kind::Area);
  EXPECT_TRUE(s.lights[1].size.isApprox(Vec2(0.2, 0.1)));
  EXPECT_TRUE(s.lights[1].position.isApprox(Vec3(0.0, 0.5, 0.0)));
  EXPECT_TRUE(s.environment.color.isApprox(Vec3(0.5, 0.6, 0.7)));
  EXPECT_DOUBLE_EQ(s.environment.intensity, 0.5);
  ASSERT_EQ(s.props.size(), 1u);
  EXPECT_EQ(s.props[0].name, "prop0");
  EXPECT_TRUE(s.props[0].boxSize.isApprox(Vec3(0.1, 0.04, 0.1)));
  EXPECT_TRUE(s.props[0].position.isApprox(Vec3(0.3, 0.02, 0.0)));
  EXPECT_TRUE(s.look.textureSize.isApprox(Vec2(0.2, 0.3)));
  EXPECT_DOUBLE_EQ(*s.look.transmittance, 0.3);
  EXPECT_NEAR(s.look.creaseAngle, kPi / 4.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.camera.fStop, 2.8);
  EXPECT_DOUBLE_EQ(s.camera.sensorWidth, 0.036);
}

TEST(SceneRendering, BadRenderingKeysNameTheirLine) {
  expectError(kSheet + "[[lights]]\ntype = \"area\"\nposition = [0, 1, 0]\n", 4,
              "lights[0].direction", {"missing"});
  expectError(kSheet + "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nsize = [1, 1]\n", 7,
              "lights[0].size");
  expectError(kSheet + "[[lights]]\ntype = \"laser\"\n", 5, "lights[0].type", {"area"});
  expectError(kSheet + "[[lights]]\ntype = \"sun\"\nangle_deg = 95\n", 6, "lights[0].angle_deg");
  expectError(kSheet + "[paper]\ntransmittance = 1.0\n", 5, "paper.transmittance");
  expectError(kSheet + "[paper]\ntexture = \"no-such.png\"\n", 5, "paper.texture",
              {"no such file"});
  expectError(kSheet + "[camera]\nfocus_distance = 2\n", 5, "camera.focus_distance", {"f_stop"});
  expectError(kSheet + "[[props]]\nshape = \"box\"\n", 4, "props[0].size", {"missing"});
  expectError(kSheet + "[[props]]\nnode = \"Cup\"\n", 5, "props[0].node", {"animation file"});
  expectError(kSheet + "[environment]\nintensity = -1\n", 5, "environment.intensity");
}

}  // namespace
}  // namespace crumple::io

namespace crumple::io {
namespace {

TEST(SceneColliders, ShapesAndErrors) {
  const SceneSpec s = parse("[scene]\nunits = \"cm\"\n" + kSheet + R"(
[[colliders]]
type = "plane"
normal = [0, 2, 0]
position = [0, 5, 0]
[[colliders]]
name = "crate"
type = "box"
size = [10, 20, 30]
[[colliders]]
type = "sphere"
radius = 4
friction = 0.5
)");
  ASSERT_EQ(s.colliders.size(), 3u);
  EXPECT_EQ(s.colliders[0].kind, ColliderSpec::Kind::Plane);
  EXPECT_EQ(s.colliders[0].name, "collider0");
  EXPECT_TRUE(s.colliders[0].normal.isApprox(Vec3::UnitY()));
  EXPECT_TRUE(s.colliders[0].position.isApprox(Vec3(0, 0.05, 0)));
  EXPECT_TRUE(s.colliders[1].size.isApprox(Vec3(0.1, 0.2, 0.3)));
  EXPECT_NEAR(s.colliders[2].radius, 0.04, 1e-15);
  EXPECT_DOUBLE_EQ(s.colliders[0].friction, 0.3);
  EXPECT_DOUBLE_EQ(s.colliders[2].friction, 0.5);
  expectError(kSheet + "[[colliders]]\nposition = [0, 0, 0]\n", 4, "colliders[0].type",
              {"missing"});
  expectError(kSheet + "[[colliders]]\ntype = \"cone\"\n", 5, "colliders[0].type", {"sphere"});
  expectError(kSheet + "[[colliders]]\ntype = \"sphere\"\nradius = 0\n", 6, "colliders[0].radius");
  expectError(kSheet + "[[colliders]]\ntype = \"box\"\nsize = [1, 1, 1]\nradius = 2\n", 7,
              "colliders[0].radius", {"only for spheres"});
  expectError(kSheet + "[[colliders]]\ntype = \"mesh\"\nnode = \"Table\"\n", 6, "colliders[0].node",
              {"animation file"});
  expectError(kSheet + "[[colliders]]\ntype = \"plane\"\n[[colliders]]\ntype = \"plane\"\n" +
                  "name = \"collider0\"\n",
              8, "colliders[1].name", {"duplicate"});
}

// ---- [friction], collider materials, nodes on boxes and spheres, [contact] -------

TEST(SceneColliders, FrictionDefaultsWithoutTable) {
  const SceneSpec s = parse(kSheet + "[[colliders]]\ntype = \"plane\"\n");
  const std::map<std::string, double> builtIn{{"default", 0.3}, {"paper", 0.3}};
  EXPECT_EQ(s.friction, builtIn);
  ASSERT_EQ(s.colliders.size(), 1u);
  EXPECT_EQ(s.colliders[0].material, "default");
  EXPECT_DOUBLE_EQ(s.colliders[0].friction, 0.3);
  // Also without any collider.
  EXPECT_EQ(parse(kSheet).friction, builtIn);
}

TEST(SceneColliders, FrictionFromMaterialExplicitOrDefault) {
  const SceneSpec s = parse(kSheet + R"(
[friction]
default = 0.1
paper = 0.25
wood = 0.4
steel_2-b = 0.2
[[colliders]]
name = "table"
type = "plane"
material = "wood"
[[colliders]]
name = "both"
type = "plane"
material = "wood"
friction = 0.7
[[colliders]]
name = "explicit"
type = "plane"
friction = 0
[[colliders]]
name = "plain"
type = "plane"
[[colliders]]
name = "odd"
type = "plane"
material = "steel_2-b"
)");
  const std::map<std::string, double> table{
      {"default", 0.1}, {"paper", 0.25}, {"wood", 0.4}, {"steel_2-b", 0.2}};
  EXPECT_EQ(s.friction, table);
  ASSERT_EQ(s.colliders.size(), 5u);
  // material looks the table up
  EXPECT_EQ(s.colliders[0].material, "wood");
  EXPECT_DOUBLE_EQ(s.colliders[0].friction, 0.4);
  // explicit friction wins over the material, whose name is kept
  EXPECT_EQ(s.colliders[1].material, "wood");
  EXPECT_DOUBLE_EQ(s.colliders[1].friction, 0.7);
  // explicit friction without material: "custom" (0 is allowed)
  EXPECT_EQ(s.colliders[2].material, "custom");
  EXPECT_DOUBLE_EQ(s.colliders[2].friction, 0.0);
  // neither: the table's (overridden) default, not the built-in 0.3
  EXPECT_EQ(s.colliders[3].material, "default");
  EXPECT_DOUBLE_EQ(s.colliders[3].friction, 0.1);
  EXPECT_EQ(s.colliders[4].material, "steel_2-b");
  EXPECT_DOUBLE_EQ(s.colliders[4].friction, 0.2);
}

TEST(SceneColliders, FrictionTableMayFollowColliders) {
  const SceneSpec s = parse(kSheet + R"(
[[colliders]]
type = "sphere"
radius = 0.1
material = "wood"
[[colliders]]
type = "plane"
[friction]
wood = 0.45
default = 0.05
)");
  ASSERT_EQ(s.colliders.size(), 2u);
  EXPECT_EQ(s.colliders[0].material, "wood");
  EXPECT_DOUBLE_EQ(s.colliders[0].friction, 0.45);
  EXPECT_EQ(s.colliders[1].material, "default");
  EXPECT_DOUBLE_EQ(s.colliders[1].friction, 0.05);
}

TEST(SceneColliders, UnknownMaterialNamesItAndTheTable) {
  const std::string text = kSheet + "[[colliders]]\ntype = \"plane\"\nmaterial = \"wood\"\n";
  try {
    parse(text);
    ADD_FAILURE() << text;
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "test.toml:6: 'colliders[0].material': material 'wood' has no coefficient: add it "
              "to [friction] (known: default, paper)");
  }
  expectError(kSheet + "[friction]\nsteel = 0.2\n[[colliders]]\ntype = \"plane\"\n" +
                  "material = \"wood\"\n",
              8, "colliders[0].material", {"'wood'", "(known: default, paper, steel)"});
  // An explicit friction does not look the material up.
  EXPECT_DOUBLE_EQ(parse(text + "friction = 0.6\n").colliders[0].friction, 0.6);
}

TEST(SceneColliders, BadFrictionValuesAndNames) {
  expectError(kSheet + "[friction]\nwood = -0.1\n", 5, "friction.wood", {"must be >= 0", "-0.1"});
  expectError(kSheet + "[friction]\nwood = 0.4\ndefault = -1\n", 6, "friction.default",
              {"must be >= 0"});
  expectError(kSheet + "[friction]\npaper = inf\n", 5, "friction.paper", {"finite"});
  expectError(kSheet + "[friction]\nwood = \"rough\"\n", 5, "friction.wood",
              {"expected a number", "a string"});
  expectError(kSheet + "[friction]\nsteel = 0.2\nWood = 0.4\n", 6, "friction.Wood",
              {"not a material name", "a-z"});
  expectError(kSheet + "[friction]\n\"oak wood\" = 0.4\n", 5, "friction.oak wood",
              {"not a material name"});
  expectError(kSheet + "[[colliders]]\ntype = \"plane\"\nfriction = -1\n", 6,
              "colliders[0].friction", {"must be >= 0"});
  expectError(kSheet + "[[colliders]]\ntype = \"plane\"\nmaterial = \"Wood\"\n", 6,
              "colliders[0].material", {"not a material name"});
  expectError(kSheet + "[[colliders]]\ntype = \"plane\"\nmaterial = 3\n", 6,
              "colliders[0].material", {"expected a string"});
  expectError(kSheet + "friction = 0.3\n", 4, "sheet.friction", {"unknown key"});
}

TEST(SceneColliders, BoxAndSphereFollowAnyNode) {
  const std::string good = R"([scene]
units = "cm"
animation = "anim.glb"
[sheet]
width = 21
height = 29.7
[[colliders]]
name = "fingertip"
type = "sphere"
radius = 1
node = "Handle"
position = [0, -2, 0]
[[colliders]]
type = "box"
size = [2, 2, 2]
node = "Static"
)";
  const SceneSpec s = parse(good);
  ASSERT_EQ(s.colliders.size(), 2u);
  const ColliderSpec& sphere = s.colliders[0];
  EXPECT_EQ(sphere.kind, ColliderSpec::Kind::Sphere);
  EXPECT_EQ(sphere.name, "fingertip");
  EXPECT_EQ(sphere.node, "Handle");
  EXPECT_EQ(sphere.nodeLine, 11);
  EXPECT_TRUE(sphere.position.isApprox(Vec3(0, -0.02, 0)));  // offset, in metres
  EXPECT_NEAR(sphere.radius, 0.01, 1e-15);
  const ColliderSpec& box = s.colliders[1];
  EXPECT_EQ(box.kind, ColliderSpec::Kind::Box);
  EXPECT_EQ(box.name, "Static");  // named after its node
  EXPECT_EQ(box.node, "Static");
  EXPECT_EQ(box.nodeLine, 16);
  EXPECT_TRUE(box.position.isZero());  // default offset

  // Handle and Static hold no mesh: a box or sphere only needs the transform.
  const AnimationScene anim = AnimationScene::load(s.animationFile);
  for (const char* node : {"Handle", "Static"}) {
    const std::optional<ImportedMesh> m = anim.mesh(node);
    ASSERT_TRUE(!m || m->triangles.empty()) << node;
  }
  EXPECT_NO_THROW(checkAnimationNodes(s, anim));

  // The node must still exist...
  std::string text = good;
  const SceneSpec missing = parse(text.replace(text.find("\"Handle\""), 8, "\"Thumb\""));
  try {
    checkAnimationNodes(missing, anim);
    ADD_FAILURE() << "node Thumb accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("test.toml:11: 'colliders[0].node': ", 0), 0u) << msg;
    EXPECT_NE(msg.find("no node named 'Thumb'"), std::string::npos) << msg;
  }
  // ...and a mesh collider still needs triangles.
  const SceneSpec mesh = parse(kAnimSheet + "[[colliders]]\ntype = \"mesh\"\nnode = \"Handle\"\n");
  try {
    checkAnimationNodes(mesh, anim);
    ADD_FAILURE() << "mesh collider on a transform node accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("test.toml:8: 'colliders[0].node': ", 0), 0u) << msg;
    EXPECT_NE(msg.find("holds no triangle mesh"), std::string::npos) << msg;
  }
}

TEST(SceneColliders, NodeErrors) {
  expectError(kAnimSheet + "[[colliders]]\ntype = \"plane\"\nnode = \"Handle\"\n", 8,
              "colliders[0].node", {"only for meshes, boxes and spheres"});
  expectError(kSheet + "[[colliders]]\ntype = \"sphere\"\nradius = 1\nnode = \"Handle\"\n", 7,
              "colliders[0].node", {"animation file"});
  expectError(kSheet + "[[colliders]]\ntype = \"box\"\nsize = [1, 1, 1]\nnode = \"Handle\"\n", 7,
              "colliders[0].node", {"animation file"});
  expectError(kAnimSheet + "[[colliders]]\ntype = \"box\"\nsize = [1, 1, 1]\nnode = \"\"\n", 9,
              "colliders[0].node", {"must not be empty"});
}

TEST(SceneContact, SelfParsesTrueFalseAuto) {
  EXPECT_EQ(parse(kSheet).contact.self, ContactSpec::Self::Auto);
  EXPECT_EQ(parse(kSheet + "[contact]\n").contact.self, ContactSpec::Self::Auto);
  EXPECT_EQ(parse(kSheet + "[contact]\nself = true\n").contact.self, ContactSpec::Self::On);
  EXPECT_EQ(parse(kSheet + "[contact]\nself = false\n").contact.self, ContactSpec::Self::Off);
  EXPECT_EQ(parse(kSheet + "[contact]\nself = \"auto\"\n").contact.self, ContactSpec::Self::Auto);
  // [contact] may come anywhere, e.g. first.
  EXPECT_EQ(parse("[contact]\nself = true\n" + kSheet).contact.self, ContactSpec::Self::On);
}

TEST(SceneContact, SelfRejectsOtherValues) {
  expectError(kSheet + "[contact]\nself = \"yes\"\n", 5, "contact.self",
              {"expected true, false or \"auto\"", "\"yes\""});
  expectError(kSheet + "[contact]\nself = \"Auto\"\n", 5, "contact.self", {"\"Auto\""});
  expectError(kSheet + "[contact]\nself = 1\n", 5, "contact.self",
              {"expected true, false or \"auto\"", "an integer"});
  expectError(kSheet + "[contact]\nself = [true]\n", 5, "contact.self", {"an array"});
  expectError(kSheet + "[contact]\nself = true\nfriction = 0.3\n", 6, "contact.friction",
              {"unknown key", "self"});
  expectError(kSheet + "contact = true\n", 4, "sheet.contact", {"unknown key"});
  expectError("contact = true\n" + kSheet, 1, "contact", {"expected a table"});
}

}  // namespace
}  // namespace crumple::io

namespace crumple::io {
namespace {

TEST(Scene, SheetOutlineIsAPolygonInSceneUnitsTurnedCounterClockwise) {
  // Clockwise as written, in cm: an L whose inward corner is at [5, 5].
  const SceneSpec s = parse(
      "[scene]\nunits = \"cm\"\n[sheet]\noutline = [[0, 0], [0, 10], [5, 10], [5, 5], [12, 5], "
      "[12, 0]]\nmax_edge = 0.5\n");
  ASSERT_EQ(s.sheet.kind, SheetSpec::Kind::Outline);
  ASSERT_EQ(s.sheet.outline.size(), 6u);
  double area = 0.0;
  for (std::size_t i = 0; i < 6; ++i) {
    const Vec2& a = s.sheet.outline[i];
    const Vec2& b = s.sheet.outline[(i + 1) % 6];
    area += 0.5 * (a.x() * b.y() - a.y() * b.x());
  }
  EXPECT_NEAR(area, 0.0085, 1e-12) << "counter-clockwise, in m^2";
  EXPECT_DOUBLE_EQ(s.sheet.width, 0.12);
  EXPECT_DOUBLE_EQ(s.sheet.height, 0.10);
  EXPECT_FALSE(s.tearEnabled) << "no [tear]: no tearing";
}

TEST(Scene, BadOutlinesAndTearKeysSayWhatIsWrong) {
  expectError("[sheet]\noutline = [[0, 0], [1, 0]]\n", 2, "sheet.outline", {"at least 3"});
  expectError("[sheet]\noutline = [[0, 0], [4, 0], [1, 1], [3, 2], [2, 0.5]]\n", 2, "sheet.outline",
              {"simple polygon"});
  expectError("[sheet]\noutline = [[0, 0], [1, 0], [-1, 1]]\n", 2, "sheet.outline",
              {"not negative"});
  expectError("[sheet]\noutline = [[0, 0], [1, 0], [0, 1]]\nwidth = 2\n", 2, "sheet.outline",
              {"one of"});
  expectError(kSheet + "[tear]\ntip_damage = 2\n", 5, "tear.tip_damage", {"[0, 1]"});
  expectError(kSheet + "[tear]\nfiber_anisotropy = 0.5\n", 5, "tear.fiber_anisotropy", {">= 1"});
  expectError(kSheet + "[tear]\nspeed = 1\n", 5, "tear.speed", {"unknown key"});
  const SceneSpec off = parse(kSheet + "[tear]\nenabled = false\n");
  EXPECT_FALSE(off.tearEnabled);
  const SceneSpec on = parse(kSheet + "[tear]\nresistance = 0.01\ntexel_mm = 0.5\n");
  EXPECT_TRUE(on.tearEnabled);
  EXPECT_DOUBLE_EQ(on.tearing.griffith.resistance, 0.01);
  EXPECT_DOUBLE_EQ(on.tearing.fibers.texelSize, 5e-4);
  EXPECT_DOUBLE_EQ(parse(kSheet + "[tear]\neps_a = 0.2\n").tearing.branchAngle, 0.2);
  expectError(kSheet + "[tear]\neps_a = 4\n", 5, "tear.eps_a", {"[0, pi)"});
}

TEST(Scene, TheSoundTableTurnsTheSoundtrackOnAndChecksItsKeys) {
  EXPECT_FALSE(parse(kSheet).soundEnabled) << "no [sound]: no events";
  const SceneSpec on = parse("[scene]\nunits = \"cm\"\n" + kSheet +
                             "[sound]\ngrid_mm = 5\ncurvature_threshold = 4\na_max = 0.4\n"
                             "free_border_radius_cm = 50\nmin_slide_mm_s = 2\n"
                             "listener = [0, 100, 200]\ndatabase = \"db\"\nchannels = 1\n"
                             "sample_rate = 44100\nformat = \"float\"\n");
  EXPECT_TRUE(on.soundEnabled);
  EXPECT_DOUBLE_EQ(on.soundEvents.gridSpacing, 0.005);
  EXPECT_DOUBLE_EQ(on.soundEvents.curvatureThreshold, 4.0);
  EXPECT_DOUBLE_EQ(on.soundEvents.maxDihedral, 0.4);
  EXPECT_DOUBLE_EQ(on.soundEvents.freeBorderRadius, 0.5);
  EXPECT_DOUBLE_EQ(on.soundEvents.minSlideSpeed, 0.002);
  ASSERT_TRUE(on.soundtrack.listener);
  EXPECT_TRUE(on.soundtrack.listener->isApprox(Vec3(0.0, 1.0, 2.0)));  // scene units: cm
  EXPECT_NE(on.soundtrack.database.find("db"), std::string::npos);
  EXPECT_EQ(on.soundtrack.channels, 1);
  EXPECT_EQ(on.soundtrack.sampleRate, 44100);
  EXPECT_TRUE(on.soundtrack.floatSamples);
  EXPECT_FALSE(parse(kSheet + "[sound]\nenabled = false\n").soundEnabled);
  expectError(kSheet + "[sound]\nchannels = 3\n", 5, "sound.channels", {"1 (mono) or 2"});
  expectError(kSheet + "[sound]\nsample_rate = 22050\n", 5, "sound.sample_rate", {"48000"});
  expectError(kSheet + "[sound]\nformat = \"mp3\"\n", 5, "sound.format", {"pcm24"});
  expectError(kSheet + "[sound]\na_max = 0\n", 5, "sound.a_max", {"(0, pi)"});
  expectError(kSheet + "[sound]\ngrid_mm = 0.01\n", 5, "sound.grid_mm", {"0.1 mm"});
  expectError(kSheet + "[sound]\nvolume = 1\n", 5, "sound.volume", {"unknown key"});
}

}  // namespace
}  // namespace crumple::io

// --- the modules' parameter structs ----------------------------------------

namespace crumple::io {
namespace {

// Each [tear] key reaches its field of tear::TearingParams, converted to SI,
// and changes nothing else; without keys the struct is the module's own.
TEST(SceneTear, EveryKeyReachesTearingParams) {
  EXPECT_EQ(parse(kSheet).tearing, tear::TearingParams{});
  EXPECT_EQ(parse(kSheet + "[tear]\n").tearing, tear::TearingParams{});
  using Set = std::function<void(tear::TearingParams&)>;
  const std::vector<std::pair<std::string, Set>> cases = {
      {"resistance = 0.01", [](auto& p) { p.griffith.resistance = 0.01; }},
      {"tip_damage = 0.25", [](auto& p) { p.griffith.tipDamage = 0.25; }},
      {"speed_m = 2", [](auto& p) { p.griffith.speed = 2.0; }},
      {"texel_mm = 0.3", [](auto& p) { p.fibers.texelSize = 0.3 * 1e-3; }},
      {"fiber_size_mm = 3", [](auto& p) { p.fibers.featureSize = 3.0 * 1e-3; }},
      {"fiber_octaves = 6", [](auto& p) { p.fibers.octaves = 6; }},
      {"fiber_anisotropy = 2", [](auto& p) { p.fibers.anisotropy = 2.0; }},
      {"fiber_direction = [0, 2]", [](auto& p) { p.fibers.fiberDirection = Vec2(0.0, 1.0); }},
      {"detail_blend = 0.25", [](auto& p) { p.detail.blend = 0.25; }},
      {"stress_width_mm = 0.75", [](auto& p) { p.detail.stressWidth = 0.75 * 1e-3; }},
      {"inward_angle_deg = 30",
       [](auto& p) { p.griffith.minInwardAngle = 30.0 * std::numbers::pi / 180.0; }},
      {"eps_a = 0.2", [](auto& p) { p.branchAngle = 0.2; }},
      {"max_new_per_frame = 3", [](auto& p) { p.maxNewTearsPerFrame = 3; }},
  };
  for (const auto& [line, set] : cases) {
    tear::TearingParams want;
    set(want);
    const SceneSpec s = parse(kSheet + "[tear]\n" + line + "\n");
    EXPECT_TRUE(s.tearEnabled) << line;
    EXPECT_EQ(s.tearing, want) << line;
  }
}

// Each of [sound]'s event keys reaches its field of sound::EventParams,
// converted to SI, and changes nothing else; the soundtrack's own keys
// (listener, database, channels, sample_rate, format) stay io's.
TEST(SceneSound, EveryEventKeyReachesEventParams) {
  EXPECT_EQ(parse(kSheet).soundEvents, sound::EventParams{});
  const SceneSpec own = parse(kSheet + "[sound]\nchannels = 1\nsample_rate = 44100\n");
  EXPECT_EQ(own.soundEvents, sound::EventParams{});
  using Set = std::function<void(sound::EventParams&)>;
  const std::vector<std::pair<std::string, Set>> cases = {
      {"grid_mm = 5", [](auto& p) { p.gridSpacing = 5.0 * 1e-3; }},
      {"curvature_threshold = 4", [](auto& p) { p.curvatureThreshold = 4.0; }},
      {"a_max = 0.4", [](auto& p) { p.maxDihedral = 0.4; }},
      {"free_border_radius_cm = 50", [](auto& p) { p.freeBorderRadius = 50.0 * 1e-2; }},
      {"min_slide_mm_s = 2", [](auto& p) { p.minSlideSpeed = 2.0 * 1e-3; }},
  };
  for (const auto& [line, set] : cases) {
    sound::EventParams want;
    set(want);
    EXPECT_EQ(parse(kSheet + "[sound]\n" + line + "\n").soundEvents, want) << line;
  }
}

// The [paper] preset is read into sim::Material: the default preset is the
// simulator's default material, another preset differs.
TEST(ScenePaper, ThePresetFillsTheMaterial) {
  EXPECT_EQ(parse(kSheet).paper.material, sim::Material{});
  const SceneSpec heavy = parse(kSheet + "[paper]\npreset = \"office-90gsm\"\n");
  EXPECT_EQ(heavy.paper.material.name, "office-90gsm");
  EXPECT_GT(heavy.paper.material.thickness, sim::Material{}.thickness);
  EXPECT_NEAR(heavy.paper.material.density * heavy.paper.material.thickness, heavy.paper.grammage,
              0.01 * heavy.paper.grammage);
}

}  // namespace
}  // namespace crumple::io
