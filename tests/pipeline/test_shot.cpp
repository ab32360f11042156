// Scene-level tests: real scenes through the pipeline library.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_contacts.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/parallel.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/model/handle_rig.hpp"
#include "crumple/model/sheet_setup.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/sim/elastic_sheet.hpp"
#include "test_util.hpp"

using namespace crumple;
using namespace crumple::testing;

namespace {

pipeline::ShotOptions quiet(const fs::path& out, bool render = false) {
  pipeline::ShotOptions o;
  o.outDir = out.string();
  o.render = render;
  o.log = nullptr;  // quiet
  o.interactive = 0;
  return o;
}

// Every held vertex in the cache sits on its imported track, sampled
// independently at the frame's time.
double maxHandleDeviation(const std::string& cachePath, const io::AnimationScene& anim,
                          const std::vector<std::string>& nodes) {
  const cache::CacheReader reader(cachePath);
  double worst = 0.0;
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    const auto frame = reader.readFrame(i);
    for (std::size_t h = 0; h < nodes.size(); ++h) {
      const Vec3 track = anim.worldPose(nodes[h], frame.time).position;
      const Vec3 cached = frame.positions[static_cast<std::size_t>(frame.handleVertices[h])];
      worst = std::max(worst, (track - cached).norm());
    }
  }
  return worst;
}

}  // namespace

TEST(Shot, DrapeSampleFollowsItsHandlesAndStaysFinite) {
  TempDir tmp;
  const auto scene = io::loadScene(io::resolveScenePath(sourcePath("samples/drape")));
  auto options = quiet(tmp / "out", true);
  options.frames = pipeline::FrameRange{1, 24};
  const auto report = pipeline::runShot(scene, options);
  EXPECT_EQ(report.framesSimulated, 25)
      << "frames 0-24: simulation starts at the scene's first frame";
  EXPECT_EQ(report.framesRendered, 24);
  EXPECT_TRUE(fs::exists(tmp / "out/frames/0024.png"));
  const auto anim = io::AnimationScene::load(scene.animationFile);
  EXPECT_LT(maxHandleDeviation(report.cachePath, anim, {"HandleL", "HandleR"}), 1e-6);
  const cache::CacheReader reader(report.cachePath);
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    const auto frame = reader.readFrame(i);
    for (const auto& p : frame.positions) ASSERT_TRUE(p.allFinite());
    // Paper barely stretches: the 70 g/m^2 preset keeps edge strain small.
    EXPECT_LT(pipeline::measureFrame(frame).maxStrain, 0.02) << "frame " << frame.frame;
  }
}

// `crumple inspect`'s sharpest fold: two triangles hinged on the x axis, the
// second turned by phi about it; a lone triangle or a flat pair reads 0.
TEST(Inspect, MaxDihedralIsTheSharpestFoldBetweenAdjacentTriangles) {
  for (const double phi : {0.0, 0.3, 1.2, 3.0}) {
    cache::FrameRecord f;
    f.triangles = {{0, 1, 2}, {1, 0, 3}};
    f.pattern = {Vec2(0, 0), Vec2(1, 0), Vec2(0.5, 1), Vec2(0.5, -1)};
    f.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0),
                   Vec3(0.5, -std::cos(phi), std::sin(phi))};
    EXPECT_NEAR(pipeline::measureFrame(f).maxDihedral, phi, 1e-12) << "phi " << phi;
    f.triangles.pop_back();
    EXPECT_EQ(pipeline::measureFrame(f).maxDihedral, 0.0);
  }
}

TEST(Shot, HandlesTrackTheirCurvesForEveryFormat) {
  // One animation written as glTF, FBX and COLLADA (tests/io/data): the
  // cached handle vertex follows the imported track to 1e-6 m at every frame,
  // and the three formats give the same trajectories to 1e-5 m.
  const std::vector<std::string> files = {
      "tests/io/data/anim.gltf", "tests/io/data/anim_zup_cm.fbx", "tests/io/data/anim_zup_cm.dae"};
  std::vector<std::vector<Vec3>> trajectories;
  for (const auto& file : files) {
    TempDir tmp;
    fs::create_directories(tmp / "s");
    std::string scene = smallSceneToml("", sourcePath(file));
    // One handle on node "Handle" (at the origin at t = 0), bound to the
    // sheet point nearest to it -- the middle of the top edge -- with
    // tangent-plane control, so the node's rotation keys matter too.
    const auto first = scene.find("[[handles]]");
    const auto cameraAt = scene.find("[camera]");
    scene = scene.substr(0, first) +
            "[[handles]]\nname = \"h\"\nnode = \"Handle\"\ntangent_control = true\n" +
            scene.substr(cameraAt);
    scene.replace(scene.find("origin = [-5.0, 10.0, 0.0]"), 26, "origin = [-5.0, -10.0, 0.0]");
    scene.replace(scene.find("frames = [1, 6]"), 15, "frames = [0, 48]");
    writeFile(tmp / "s/scene.toml", scene);
    const auto spec = io::loadScene((tmp / "s/scene.toml").string());
    const auto report = pipeline::runShot(spec, quiet(tmp / "out"));
    const auto anim = io::AnimationScene::load(spec.animationFile);
    const double deviation = maxHandleDeviation(report.cachePath, anim, {"Handle"});
    RecordProperty("handle_deviation_" + fs::path(file).filename().string(), sci(deviation));
    EXPECT_LT(deviation, 1e-6) << file;
    const cache::CacheReader reader(report.cachePath);
    // The tangent-plane vertices (3 on a border) follow the node's rotation.
    const auto held = model::tangentNeighbours(model::buildSheet(spec, &anim),
                                               reader.readFrame(0).handleVertices[0], 0);
    EXPECT_EQ(held.size(), 3u);
    std::vector<Vec3> traj;
    for (std::size_t i = 0; i < reader.frameCount(); ++i) {
      const auto frame = reader.readFrame(i);
      traj.push_back(frame.positions[static_cast<std::size_t>(frame.handleVertices[0])]);
      for (int v : held) traj.push_back(frame.positions[static_cast<std::size_t>(v)]);
    }
    trajectories.push_back(traj);
  }
  double worstAgreement = 0.0;
  for (std::size_t f = 1; f < trajectories.size(); ++f) {
    ASSERT_EQ(trajectories[f].size(), trajectories[0].size());
    for (std::size_t i = 0; i < trajectories[0].size(); ++i) {
      const double d = (trajectories[f][i] - trajectories[0][i]).norm();
      worstAgreement = std::max(worstAgreement, d);
      EXPECT_LT(d, 1e-5) << files[f] << " sample " << i;
    }
  }
  RecordProperty("format_agreement_m", sci(worstAgreement));
}

TEST(Shot, SheetHungByTwoCornersComesToRest) {
  // Acceptance: the 70 g/m^2 preset, an A4 sheet held by its two top corners
  // under gravity, comes to rest (kinetic energy < 1e-9 J) with max membrane
  // strain under 1%.
  const auto preset = io::loadPaperPreset(sourcePath("assets/papers/office-70gsm.toml"));
  const sim::Material& material = preset.material;
  auto sheet = mesh::makeRectangleSheet(0.21, 0.297, 0.021);
  mesh::placePattern(sheet, Vec3(0, 0, 0), Vec3::UnitX(), -Vec3::UnitY());  // hangs down from y = 0
  sim::SimParams params;
  sim::ElasticSheet elastic(sheet, material, params);
  const int left = mesh::nearestPatternVertex(sheet, Vec2(0, 0));
  const int right = mesh::nearestPatternVertex(sheet, Vec2(0.21, 0));
  const Vec3 pl = sheet.positions[static_cast<std::size_t>(left)];
  const Vec3 pr = sheet.positions[static_cast<std::size_t>(right)];
  // Start from a perturbed shape so there is motion to damp: the sheet swings.
  auto x = sheet.positions;
  for (auto& p : x) p.z() += 0.02 * p.y() * p.y() / 0.088;
  x[static_cast<std::size_t>(left)] = pl;
  x[static_cast<std::size_t>(right)] = pr;
  elastic.setPositions(x);
  const sim::PinFunction pins = [&](double, std::vector<sim::Pin>& out) {
    out = {{left, pl}, {right, pr}};
  };
  double t = 0.0;
  const double dt = 1.0 / 96.0;
  int steps = 0;
  while (steps < 4000 && (steps < 10 || elastic.kineticEnergy() >= 1e-9)) {
    elastic.advance(t, dt, pins);
    t += dt;
    ++steps;
  }
  RecordProperty("steps", steps);
  RecordProperty("kinetic_energy_J", sci(elastic.kineticEnergy()));
  RecordProperty("max_membrane_strain", sci(elastic.maxMembraneStrain()));
  EXPECT_LT(elastic.kineticEnergy(), 1e-9) << "after " << steps << " steps (" << t << " s)";
  EXPECT_LT(elastic.maxMembraneStrain(), 0.01);
  // It really hangs: the bottom edge is far below the corners.
  double lowest = 0.0;
  for (const auto& p : elastic.positions()) lowest = std::min(lowest, p.y());
  EXPECT_LT(lowest, -0.25);
}

TEST(HandleRig, TangentControlPicksTwoThreeOrFourNeighbours) {
  const auto sheet = mesh::makeRectangleSheet(0.2, 0.2, 0.05);
  const int corner = mesh::nearestPatternVertex(sheet, Vec2(0, 0));
  const int border = mesh::nearestPatternVertex(sheet, Vec2(0.1, 0));
  const int inside = mesh::nearestPatternVertex(sheet, Vec2(0.1, 0.1));
  EXPECT_EQ(model::tangentNeighbours(sheet, corner, 0).size(), 2u);
  EXPECT_EQ(model::tangentNeighbours(sheet, border, 0).size(), 3u);
  EXPECT_EQ(model::tangentNeighbours(sheet, inside, 0).size(), 4u);
  EXPECT_EQ(model::tangentNeighbours(sheet, inside, 2).size(), 2u);
  // The four around an interior vertex span all directions.
  const auto four = model::tangentNeighbours(sheet, inside, 4);
  Vec2 sum = Vec2::Zero();
  for (int n : four) sum += (sheet.pattern[n] - sheet.pattern[inside]).normalized();
  EXPECT_LT(sum.norm(), 0.5);
}

TEST(HandleRig, TangentVerticesFollowTheNodeRotation) {
  TempDir tmp;
  fs::create_directories(tmp / "s");
  // A node that rotates 90 degrees about Y over one second, in place.
  const float h = static_cast<float>(std::sqrt(0.5));
  GltfTrack a{"A",
              {0.0f, 1.0f},
              {{-0.05f, 0.2f, 0.0f}, {-0.05f, 0.2f, 0.0f}},
              {{0.0f, 0.0f, 0.0f, 1.0f}, {0.0f, h, 0.0f, h}}};
  writeFile(tmp / "s/anim.gltf", makeGltf({a}));
  std::string scene = smallSceneToml();
  const auto first = scene.find("[[handles]]");
  const auto cameraAt = scene.find("[camera]");
  scene = scene.substr(0, first) +
          "[[handles]]\nname = \"left\"\nnode = \"A\"\npattern = [0.0, 10.0]\ntangent_control = "
          "true\n" +
          scene.substr(cameraAt);
  writeFile(tmp / "s/scene.toml", scene);
  const auto spec = io::loadScene((tmp / "s/scene.toml").string());
  const auto anim = io::AnimationScene::load(spec.animationFile);
  auto sheet = model::buildSheet(spec, &anim);
  const model::HandleRig rig(spec, &anim, sheet, 0.0);
  ASSERT_EQ(rig.handles().size(), 1u);
  EXPECT_EQ(rig.handles()[0].tangentVertices.size(), 2u) << "a corner holds two neighbours";
  rig.snap(0.0, sheet.positions);
  std::vector<sim::Pin> pins;
  rig.pins(1.0, pins);
  ASSERT_EQ(pins.size(), 3u);
  // At t = 1 s the node has turned 90 degrees about +Y: each neighbour's
  // offset from the handle turned with it (x -> -z, z -> x).
  const Vec3 handle = pins[0].position;
  const Quat turn(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()));
  for (std::size_t k = 1; k < pins.size(); ++k) {
    const Vec3 rest = sheet.positions[static_cast<std::size_t>(pins[k].vertex)] -
                      sheet.positions[static_cast<std::size_t>(pins[0].vertex)];
    EXPECT_LT((pins[k].position - handle - turn * rest).norm(), 1e-6);
  }
}

// Handle A jumps ~10 km up between two frames (t = 0.1 s and 0.125 s); B stays.
void writeJumpAnimation(const fs::path& dir) {
  fs::create_directories(dir);
  GltfTrack a{"A",
              {0.0f, 0.1f, 0.125f},
              {{-0.05f, 0.2f, 0.0f}, {-0.05f, 0.2f, 0.0f}, {-0.05f, 1e4f, 0.0f}}};
  GltfTrack b{"B", {}, {{0.05f, 0.2f, 0.0f}}};
  writeFile(dir / "anim.gltf", makeGltf({a, b}));
}

TEST(Shot, NumericalFailureNamesFrameAndKeepsTheCacheValid) {
  // A handle that jumps ~10 km between two frames on a sheet without the
  // reach limit (an outline pattern: HandleRig::reachExcess is off there):
  // the elastic solve cannot follow even with the recovery; the run must
  // stop with a NumericalError naming the frame and the stage, and the
  // cache must hold every frame before it.
  TempDir tmp;
  writeJumpAnimation(tmp / "s");
  std::string scene =
      smallSceneToml("outline = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]\n");
  scene.erase(scene.find("width = 10.0\nheight = 10.0\n"), 26);
  writeFile(tmp / "s/scene.toml", scene);
  const auto spec = io::loadScene((tmp / "s/scene.toml").string());
  try {
    pipeline::runShot(spec, quiet(tmp / "out"));
    FAIL() << "a 10 km jump in one frame cannot be followed";
  } catch (const NumericalError& e) {
    EXPECT_GE(e.frame(), 2);
    EXPECT_EQ(e.stage(), "elastic");
    EXPECT_NE(std::string(e.what()).find("frame"), std::string::npos);
    const cache::CacheReader reader((tmp / "out/cache.pcache").string());
    EXPECT_FALSE(reader.recovered()) << "the cache was closed properly";
    EXPECT_EQ(static_cast<int>(reader.frameCount()), e.frame() - 1);
    for (std::size_t i = 0; i < reader.frameCount(); ++i)
      for (const auto& p : reader.readFrame(i).positions) ASSERT_TRUE(p.allFinite());
    EXPECT_NE(readFile(tmp / "out/summary.json").find("\"error\":\"frame"), std::string::npos);
  }
}

TEST(Shot, AHandleBeyondTheSheetsReachLagsAndIsNamed) {
  // The same jump on a rectangle: the reach limit (HandleRig::reachExcess)
  // holds the jumping handle at its pattern distance from the other, so the
  // shot finishes with finite values and the summary names the handle.
  TempDir tmp;
  writeJumpAnimation(tmp / "s");
  writeFile(tmp / "s/scene.toml", smallSceneToml());
  const auto spec = io::loadScene((tmp / "s/scene.toml").string());
  const auto report = pipeline::runShot(spec, quiet(tmp / "out"));
  EXPECT_EQ(report.error, "");
  const cache::CacheReader reader(report.cachePath);
  EXPECT_EQ(static_cast<int>(reader.frameCount()), spec.frameEnd - spec.frameStart + 1);
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    const auto frame = reader.readFrame(i);
    for (const auto& p : frame.positions) ASSERT_TRUE(p.allFinite());
    const Vec3 left = frame.positions[static_cast<std::size_t>(frame.handleVertices[0])];
    const Vec3 right = frame.positions[static_cast<std::size_t>(frame.handleVertices[1])];
    EXPECT_LE((left - right).norm(), 0.1 * (1.0 + 1e-3) + 1e-9) << "frame " << frame.frame;
  }
  EXPECT_NE(readFile(tmp / "out/summary.json").find("beyond the sheet's reach"), std::string::npos);
}

TEST(Shot, PatternMeshFromTheAnimationFileBecomesTheSheet) {
  // tests/io/data/anim.gltf holds node "Sheet": a 0.2 x 0.3 m quad lying in
  // the XZ plane at y = 0.01 m.
  TempDir tmp;
  fs::create_directories(tmp / "s");
  std::string scene = smallSceneToml("", sourcePath("tests/io/data/anim.gltf"));
  const auto sheetAt = scene.find("[sheet]");
  const auto paperAt = scene.find("[paper]");
  const auto first = scene.find("[[handles]]");
  const auto cameraAt = scene.find("[camera]");
  scene = scene.substr(0, sheetAt) + "[sheet]\npattern_mesh = \"Sheet\"\n" +
          scene.substr(paperAt, first - paperAt) + scene.substr(cameraAt);
  writeFile(tmp / "s/scene.toml", scene);
  const auto spec = io::loadScene((tmp / "s/scene.toml").string());
  const auto anim = io::AnimationScene::load(spec.animationFile);
  const auto sheet = model::buildSheet(spec, &anim);
  EXPECT_EQ(mesh::validate(sheet), "");
  ASSERT_EQ(sheet.vertexCount(), 4u);
  double area = 0.0;
  for (const auto& t : sheet.triangles) {
    const Vec2 e1 = sheet.pattern[t[1]] - sheet.pattern[t[0]];
    const Vec2 e2 = sheet.pattern[t[2]] - sheet.pattern[t[0]];
    area += 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
  }
  EXPECT_NEAR(area, 0.06, 1e-6) << "counter-clockwise pattern of the right size";
  for (const auto& p : sheet.positions) EXPECT_NEAR(p.y(), 0.01, 1e-6);
  // Pattern is isometric to the imported mesh: every edge keeps its length.
  for (const auto& e : mesh::buildEdges(sheet))
    EXPECT_NEAR((sheet.pattern[e.v[0]] - sheet.pattern[e.v[1]]).norm(),
                (sheet.positions[e.v[0]] - sheet.positions[e.v[1]]).norm(), 1e-6);
  // The shot runs on it (no handles: the sheet falls freely).
  const auto report = pipeline::runShot(spec, quiet(tmp / "out"));
  EXPECT_EQ(report.triangles, 2u);
  const cache::CacheReader reader(report.cachePath);
  EXPECT_LT(reader.readFrame(reader.frameCount() - 1).positions[0].y(), 0.01);
}

TEST(FrameRange, ParsesRangesAndRejectsTheRest) {
  const auto r = pipeline::parseFrameRange("3-17");
  EXPECT_EQ(r.first, 3);
  EXPECT_EQ(r.last, 17);
  EXPECT_EQ(pipeline::parseFrameRange("5").last, 5);
  EXPECT_EQ(pipeline::parseFrameRange("-4--2").first, -4);
  EXPECT_EQ(pipeline::parseFrameRange("-4--2").last, -2);
  for (const char* bad : {"", "a-b", "3-", "-", "3-1", "1-2-3", "1.5-2", " 1-2"})
    EXPECT_THROW(pipeline::parseFrameRange(bad), InputError) << bad;
}

TEST(Shot, CameraFromTheAnimationFileIsCachedPerFrame) {
  // tests/io/data/anim.gltf holds node "Camera" at (0, 0.3, 0.6) looking down
  // -Z with a vertical field of view of 0.6 rad.
  TempDir tmp;
  fs::create_directories(tmp / "s");
  std::string scene = smallSceneToml("", sourcePath("tests/io/data/anim.gltf"));
  const auto first = scene.find("[[handles]]");
  const auto groundAt = scene.find("[ground]");
  scene = scene.substr(0, first) + "[camera]\nnode = \"Camera\"\nresolution = [160, 120]\n" +
          scene.substr(groundAt);
  writeFile(tmp / "s/scene.toml", scene);
  const auto spec = io::loadScene((tmp / "s/scene.toml").string());
  const auto report = pipeline::runShot(spec, quiet(tmp / "out", true));
  const cache::CacheReader reader(report.cachePath);
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    const auto cam = reader.readFrame(i).camera;
    EXPECT_LT((cam.position - Vec3(0.0, 0.3, 0.6)).norm(), 1e-6);
    EXPECT_NEAR(cam.yfov, 0.6, 1e-6);
    EXPECT_LT((cam.rotation * Vec3(0, 0, -1) - Vec3(0, 0, -1)).norm(), 1e-6);
  }
  EXPECT_EQ(report.framesRendered, 6);
}

TEST(PaperPreset, SimulatorDefaultsAreThe70gsmPreset) {
  const auto preset = io::loadPaperPreset(sourcePath("assets/papers/office-70gsm.toml"));
  const sim::Material defaults;
  EXPECT_EQ(defaults, preset.material);
  // Derived stiffnesses of the preset (Kirchhoff-Love plate).
  EXPECT_NEAR(defaults.stretchStiffness(), 4.0e9 * 9.0e-5 / (1 - 0.0625), 1e-6);
  EXPECT_NEAR(defaults.bendingStiffness(), 4.0e9 * 7.29e-13 / (12 * (1 - 0.0625)), 1e-12);
  // The 90 g/m^2 preset is thicker and stiffer in bending.
  const auto heavy = io::loadPaperPreset(sourcePath("assets/papers/office-90gsm.toml"));
  EXPECT_GT(heavy.material.thickness, preset.material.thickness);
  EXPECT_GT(heavy.grammage, preset.grammage);
}

TEST(HandleRig, SaysHowFarAHandleIsFromItsVertex) {
  TempDir tmp;
  fs::create_directories(tmp / "s");
  writeFile(tmp / "s/anim.gltf", smallAnimation());
  // Handle "left" asks for a pattern point between grid vertices (2.5 cm grid).
  std::string scene = smallSceneToml();
  scene.replace(scene.find("pattern = [0.0, 10.0]"), 21, "pattern = [1.0, 10.0]");
  writeFile(tmp / "s/scene.toml", scene);
  const auto spec = io::loadScene((tmp / "s/scene.toml").string());
  const auto anim = io::AnimationScene::load(spec.animationFile);
  const auto sheet = model::buildSheet(spec, &anim);
  const model::HandleRig rig(spec, &anim, sheet, spec.frameTime(spec.frameStart));
  auto count = [](const std::vector<std::string>& warnings, const std::string& what) {
    return std::count_if(warnings.begin(), warnings.end(),
                         [&](const std::string& w) { return w.find(what) != std::string::npos; });
  };
  ASSERT_EQ(count(rig.bindWarnings(), "pattern point"), 1);
  for (const auto& w : rig.bindWarnings())
    if (w.find("pattern point") != std::string::npos) {
      EXPECT_NE(w.find("'left'"), std::string::npos) << w;
      EXPECT_NE(w.find("0.01"), std::string::npos) << w;  // 1 cm from the corner
    }
  // Frame 1 is at t = 1/24 s, when node B has already moved 5.9 mm from the
  // sheet corner it holds: the vertex jumps onto the track, and a line says so.
  EXPECT_EQ(count(rig.bindWarnings(), "'right': node 'B' is 0.0058"), 1);
  // Exact corners bind to their pattern points without a word.
  writeSmallScene(tmp / "ok");
  const auto good = io::loadScene((tmp / "ok/scene.toml").string());
  const auto goodAnim = io::AnimationScene::load(good.animationFile);
  const model::HandleRig exact(good, &goodAnim, model::buildSheet(good, &goodAnim),
                               good.frameTime(good.frameStart));
  EXPECT_EQ(count(exact.bindWarnings(), "pattern point"), 0);
}

TEST(FrameView, PropsBoxesAndAnimatedMeshNodesMaterialAndSharpVertices) {
  TempDir tmp;
  writeFile(tmp / "props.gltf", movingPropGltf());
  const auto scene = io::parseScene(R"([scene]
animation = "props.gltf"
[sheet]
width = 0.2
height = 0.3
[paper]
transmittance = 0.4
crease_deg = 20
[[props]]
node = "Cup"
color = [0.9, 0.1, 0.1]
[[props]]
name = "table"
shape = "box"
size = [1.0, 0.1, 1.0]
position = [0.0, -0.05, 0.0]
[[lights]]
type = "area"
position = [0, 1, 0]
direction = [0, -1, 0]
size = [0.5, 0.25]
)",
                                    "props.toml", tmp.path().string());
  cache::FrameRecord frame;
  frame.pattern = {{0, 0}, {0.2, 0}, {0, 0.3}};
  frame.positions = {{0, 0, 0}, {0.2, 0, 0}, {0, 0, -0.3}};
  frame.triangles = {{0, 1, 2}};
  frame.singularVertices = {1};
  frame.camera.position = Vec3(0, 1, 1);
  frame.camera.yfov = 0.7;
  // The cache carries the look: the props' rest meshes in the header, their
  // motions in each frame (lookHeaderBlocks, propMotionBlock).
  const auto anim = io::AnimationScene::load(scene.animationFile);
  const auto headerBlocks = pipeline::lookHeaderBlocks(scene, &anim);
  ASSERT_EQ(headerBlocks.size(), 1u) << "no texture, one block of prop meshes";
  const pipeline::FrameViewBuilder views(scene, headerBlocks);
  for (const double t : {0.0, 0.5}) {
    frame.time = t;
    frame.extensions = {*pipeline::propMotionBlock(scene, &anim, t)};
    const auto fv = views.build(frame);
    ASSERT_EQ(fv.scene.props.size(), 2u);
    const auto& box = fv.scene.props[0];  // boxes first, then mesh props
    EXPECT_EQ(box.name, "table");
    EXPECT_EQ(box.triangles.size(), 12u);
    EXPECT_NEAR(box.vertices[0].y(), -0.1, 1e-12);
    const auto& cup = fv.scene.props[1];
    EXPECT_EQ(cup.name, "Cup");
    ASSERT_EQ(cup.vertices.size(), 3u);
    EXPECT_NEAR(cup.vertices[0].x(), t, 1e-6) << "the mesh moves with its node";
    EXPECT_NEAR(cup.vertices[1].x(), t + 0.1, 1e-6);
    EXPECT_TRUE(cup.color.isApprox(Vec3(0.9, 0.1, 0.1)));
    EXPECT_DOUBLE_EQ(fv.scene.paper.transmittance, 0.4);
    EXPECT_NEAR(fv.scene.paper.creaseAngle, 20.0 * 3.14159265358979 / 180.0, 1e-9);
    EXPECT_EQ(fv.scene.sharpVertices, std::vector<int>{1});
    ASSERT_EQ(fv.scene.lights.size(), 1u);
    EXPECT_EQ(fv.scene.lights[0].kind, render::Light::Kind::Area);
    EXPECT_TRUE(fv.scene.lights[0].size.isApprox(Vec2(0.5, 0.25)));
    EXPECT_TRUE(fv.scene.paper.textureSize.isApprox(Vec2(0.2, 0.3)));
  }
  frame.extensions.clear();
  EXPECT_THROW((void)views.build(frame), CorruptDataError) << "a frame without its prop motions";
  // The default transmittance follows the preset's thickness (90 um: 0.23).
  const auto plain = io::parseScene("[sheet]\nwidth = 0.2\nheight = 0.3\n", "p.toml", ".");
  EXPECT_TRUE(pipeline::lookHeaderBlocks(plain, nullptr).empty());
  EXPECT_FALSE(pipeline::propMotionBlock(plain, nullptr, 0.0).has_value());
  frame.extensions.clear();
  const auto fv = pipeline::FrameViewBuilder(plain, {}).build(frame);
  EXPECT_NEAR(fv.scene.paper.transmittance, std::exp(-90e-6 / 62e-6), 1e-12);
  EXPECT_EQ(fv.scene.camera.apertureRadius, 0.0) << "pinhole without f_stop";
}

TEST(Contacts, ASheetDroppedOnATableNeverEntersItAndTheRunSaysContactsRan) {
  TempDir tmp;
  fs::create_directories(tmp / "s");
  writeFile(tmp / "s/scene.toml", R"([scene]
name = "drop"
fps = 24
frames = [1, 24]
substeps = 4
[sheet]
width = 0.1
height = 0.1
max_edge = 0.025
origin = [-0.05, 0.02, 0.05]
[[colliders]]
name = "table"
type = "plane"
[[colliders]]
type = "sphere"
position = [0.3, 0, 0]
radius = 0.05
[output]
frames = false
)");
  std::string caches[2];
  for (const int threads : {1, 2}) {
    const std::string out = (tmp / ("out" + std::to_string(threads))).string();
    const auto r = runCrumple("simulate " + (tmp / "s").string() + " --threads " +
                              std::to_string(threads) + " --out " + out);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("contacts"), std::string::npos) << r.output;
    caches[threads - 1] = readFile(out + "/cache.pcache");
  }
  EXPECT_EQ(caches[0], caches[1]) << "byte-identical on 1 and 2 threads";
  const cache::CacheReader reader((tmp / "out1/cache.pcache").string());
  const double thickness = 9.0e-5;  // office-70gsm
  double lowest = 1.0;
  for (std::size_t f = 0; f < reader.frameCount(); ++f)
    for (const Vec3& x : reader.readFrame(f).positions) lowest = std::min(lowest, x.y());
  EXPECT_GE(lowest, 0.9 * thickness) << "no vertex deeper than 10 % of the thickness";
  const auto last = reader.readFrame(reader.frameCount() - 1);
  for (const Vec3& x : last.positions) EXPECT_LT(x.y(), 2.0 * thickness) << "lies on the table";
  const auto summary = readFile(tmp / "out1/summary.json");
  EXPECT_NE(summary.find("\"contacts\":true"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"collider_ms_per_frame\""), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"max_depth_thicknesses\""), std::string::npos) << summary;
  // The contact set travels in the cache: the colliders by name, and the
  // vertices lying on the table at the last frame, not sliding.
  const auto colliders = cache::decodeColliders(reader.header().extensions);
  ASSERT_TRUE(colliders.has_value());
  ASSERT_EQ(colliders->size(), 2u);
  EXPECT_EQ((*colliders)[0].name, "table");
  EXPECT_DOUBLE_EQ((*colliders)[0].friction, 0.3);
  const auto touching = cache::decodeContacts(last.extensions);
  ASSERT_TRUE(touching.has_value());
  EXPECT_EQ(touching->size(), last.positions.size()) << "every vertex lies on the table";
  double weight = 0.0;
  for (const auto& c : *touching) {
    EXPECT_EQ(c.collider, 0);
    EXPECT_LT(c.slideSpeed, 1e-3);
    weight += c.normalForce;
  }
  EXPECT_NEAR(weight, 0.070002 * 0.01 * 9.81, 0.1 * 0.070002 * 0.01 * 9.81) << "carries the sheet";
  // Without colliders and with self-contact off: no contact work, no blocks.
  writeFile(tmp / "s/scene.toml", R"([scene]
name = "free"
frames = [1, 4]
[sheet]
width = 0.1
height = 0.1
max_edge = 0.025
[contact]
self = false
[output]
frames = false
)");
  const auto f = runCrumple("simulate " + (tmp / "s").string() + " --out " + (tmp / "f").string());
  ASSERT_EQ(f.status, 0) << f.output;
  const auto freeSummary = readFile(tmp / "f/summary.json");
  EXPECT_EQ(freeSummary.find("\"contacts\":{"), std::string::npos) << freeSummary;
  EXPECT_EQ(freeSummary.find("contact check"), std::string::npos) << freeSummary;
  const cache::CacheReader freeReader((tmp / "f/cache.pcache").string());
  EXPECT_FALSE(cache::decodeColliders(freeReader.header().extensions).has_value());
}
