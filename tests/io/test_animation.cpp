// Animation import: the same hand-written scene (tests/io/data/make_test_data.py)
// as glTF, GLB, COLLADA (cm, Z up) and ASCII FBX (cm Z up; m Y up) must give
// the same world-frame tracks.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "crumple/core/error.hpp"
#include "crumple/io/animation.hpp"

namespace crumple::io {
namespace {

const std::string kData = CRUMPLE_IO_TEST_DATA;
constexpr double kPi = 3.14159265358979323846;
constexpr double kTol = 1e-6;

std::string data(const std::string& name) { return kData + "/" + name; }

double deg(double d) { return d * kPi / 180.0; }
Quat rotY(double degrees) { return Quat(Eigen::AngleAxisd(deg(degrees), Vec3::UnitY())); }
Quat rotX(double degrees) { return Quat(Eigen::AngleAxisd(deg(degrees), Vec3::UnitX())); }

double angleBetween(const Quat& a, const Quat& b) { return a.angularDistance(b); }

::testing::AssertionResult VecNear(const Vec3& a, const Vec3& b, double tol) {
  if ((a - b).norm() <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got " << a.transpose() << ", expected " << b.transpose()
                                       << " (distance " << (a - b).norm() << ")";
}

::testing::AssertionResult RotNear(const Quat& a, const Quat& b, double tol) {
  if (angleBetween(a, b) <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "got " << a.coeffs().transpose() << ", expected " << b.coeffs().transpose()
         << " (angle " << angleBetween(a, b) << ")";
}

#define EXPECT_VEC_NEAR(a, b, tol) EXPECT_TRUE(VecNear((a), (b), (tol)))
#define EXPECT_ROT_NEAR(a, b, tol) EXPECT_TRUE(RotNear((a), (b), (tol)))

// ---- The reference animation, in crumple's frame ---------------------------

Vec3 handlePosition(double t) {
  const Vec3 k[3] = {{0, 0, 0}, {0.1, 0.2, 0}, {0.3, 0.2, 0.1}};
  if (t <= 0) return k[0];
  if (t >= 2) return k[2];
  const int i = t < 1 ? 0 : 1;
  const double s = t - i;
  return k[i] + s * (k[i + 1] - k[i]);
}
double handleAngle(double t) {
  const double a[3] = {0, 40, 100};
  if (t <= 0) return a[0];
  if (t >= 2) return a[2];
  const int i = t < 1 ? 0 : 1;
  return a[i] + (t - i) * (a[i + 1] - a[i]);
}
double clamp02(double t) { return std::min(2.0, std::max(0.0, t)); }
Vec3 parentPosition(double t) { return {0.1 * clamp02(t), 0.1, 0.0}; }
double parentAngle(double t) { return 45.0 * clamp02(t); }
double parentScale(double t) { return 1.0 + 0.25 * clamp02(t); }
Vec3 childPosition(double t) {
  return parentPosition(t) + rotY(parentAngle(t)) * (parentScale(t) * Vec3(0.05, 0, 0));
}
const Vec3 kStaticPosition{-0.1, 0.05, 0.2};

// A Z-up file keeps its local frames: a node's world rotation is the Y-up
// rotation followed by the file's local axes, i.e. q_world = q_yup * B with
// B = Rx(-90 deg) (file +Z -> world +Y).
const Quat kZupLocal = rotX(-90.0);

struct FileCase {
  const char* file;
  Quat localFrame;  // world rotation = reference rotation * localFrame
};

std::ostream& operator<<(std::ostream& os, const FileCase& c) { return os << c.file; }

class AnimationFormats : public ::testing::TestWithParam<FileCase> {
 protected:
  static AnimationScene load() { return AnimationScene::load(data(GetParam().file)); }
  Quat local() const { return GetParam().localFrame; }
};

TEST_P(AnimationFormats, LoadsAllNodes) {
  const AnimationScene scene = load();
  EXPECT_EQ(scene.file(), data(GetParam().file));
  for (const char* name : {"Handle", "Parent", "Child", "Static", "Camera", "Sheet"}) {
    EXPECT_TRUE(scene.hasNode(name)) << name;
  }
  EXPECT_FALSE(scene.hasNode("Nope"));
  EXPECT_TRUE(scene.warnings().empty()) << scene.warnings().front();
  EXPECT_NEAR(scene.startTime(), 0.0, kTol);
  EXPECT_NEAR(scene.endTime(), 2.0, kTol);
}

TEST_P(AnimationFormats, PositionsAtKeysAndBetween) {
  const AnimationScene scene = load();
  for (double t : {0.0, 1.0, 2.0, 0.5, 0.25, 1.5, 1.9}) {
    EXPECT_VEC_NEAR(scene.worldPose("Handle", t).position, handlePosition(t), kTol) << "t=" << t;
  }
  // Exactly linear between keys: the midpoint of (0.1,0.2,0) and (0.3,0.2,0.1).
  EXPECT_VEC_NEAR(scene.worldPose("Handle", 1.5).position, Vec3(0.2, 0.2, 0.05), kTol);
}

TEST_P(AnimationFormats, ClampsOutsideTheKeys) {
  const AnimationScene scene = load();
  EXPECT_VEC_NEAR(scene.worldPose("Handle", -3.0).position, Vec3::Zero(), kTol);
  EXPECT_VEC_NEAR(scene.worldPose("Handle", 7.0).position, Vec3(0.3, 0.2, 0.1), kTol);
  EXPECT_ROT_NEAR(scene.worldPose("Handle", 7.0).rotation, rotY(100) * local(), kTol);
}

TEST_P(AnimationFormats, RotationsSlerp) {
  const AnimationScene scene = load();
  for (double t : {0.0, 0.5, 1.0, 1.25, 2.0}) {
    EXPECT_ROT_NEAR(scene.worldPose("Handle", t).rotation, rotY(handleAngle(t)) * local(), kTol)
        << "t=" << t;
  }
}

TEST_P(AnimationFormats, ChildFollowsAnimatedParent) {
  const AnimationScene scene = load();
  for (double t : {0.0, 0.7, 1.0, 2.0, 3.0}) {
    EXPECT_VEC_NEAR(scene.worldPose("Parent", t).position, parentPosition(t), kTol) << t;
    EXPECT_VEC_NEAR(scene.worldPose("Child", t).position, childPosition(t), kTol) << t;
    EXPECT_ROT_NEAR(scene.worldPose("Child", t).rotation, rotY(parentAngle(t)) * local(), kTol);
  }
  // Scale 1.25 at t = 1 stretches the child offset; the pose stays a rotation.
  // (The world matrix also holds the file's unit scale: 0.01 for cm files.)
  const double s0 = scene.worldMatrix("Child", 0.0).topLeftCorner<3, 3>().col(0).norm();
  const double s1 = scene.worldMatrix("Child", 1.0).topLeftCorner<3, 3>().col(0).norm();
  EXPECT_NEAR(s1 / s0, 1.25, kTol);
}

TEST_P(AnimationFormats, StaticNodeIsConstant) {
  const AnimationScene scene = load();
  for (double t : {-1.0, 0.0, 1.3, 5.0}) {
    EXPECT_VEC_NEAR(scene.worldPose("Static", t).position, kStaticPosition, kTol);
    EXPECT_ROT_NEAR(scene.worldPose("Static", t).rotation, rotX(45) * local(), kTol);
  }
  EXPECT_TRUE(scene.localKeys("Static").positionTimes.empty());
}

TEST_P(AnimationFormats, Camera) {
  const AnimationScene scene = load();
  for (const std::string node : {"Camera", ""}) {
    const std::optional<CameraPose> cam = scene.camera(node, 0.5);
    ASSERT_TRUE(cam.has_value());
    EXPECT_VEC_NEAR(cam->position, Vec3(0, 0.3, 0.6), kTol);
    // Looks down -Z with +Y up.
    EXPECT_VEC_NEAR(cam->rotation * Vec3(0, 0, -1), Vec3(0, 0, -1), kTol);
    EXPECT_VEC_NEAR(cam->rotation * Vec3(0, 1, 0), Vec3(0, 1, 0), kTol);
    EXPECT_NEAR(cam->yfov, 0.6, 1e-5);
    EXPECT_NEAR(cam->aspect, 1.5, 1e-6);
  }
  EXPECT_FALSE(scene.camera("Handle", 0.0).has_value());
}

TEST_P(AnimationFormats, SheetMeshInWorldSpace) {
  const AnimationScene scene = load();
  const std::optional<ImportedMesh> mesh = scene.mesh("Sheet");
  ASSERT_TRUE(mesh.has_value());
  ASSERT_EQ(mesh->vertices.size(), 4u);
  ASSERT_EQ(mesh->triangles.size(), 2u);
  for (const Vec3& expected : {Vec3(-0.1, 0.01, -0.15), Vec3(0.1, 0.01, -0.15),
                               Vec3(0.1, 0.01, 0.15), Vec3(-0.1, 0.01, 0.15)}) {
    double best = 1e9;
    for (const Vec3& v : mesh->vertices) best = std::min(best, (v - expected).norm());
    EXPECT_LE(best, kTol) << expected.transpose();
  }
  double area = 0.0;
  for (const auto& t : mesh->triangles) {
    const Vec3 a = mesh->vertices[t[0]], b = mesh->vertices[t[1]], c = mesh->vertices[t[2]];
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  EXPECT_NEAR(area, 0.2 * 0.3, kTol);
  EXPECT_FALSE(scene.mesh("Handle").has_value());
}

TEST_P(AnimationFormats, UnknownNodeNamesFileAndNode) {
  const AnimationScene scene = load();
  try {
    scene.worldPose("Nope", 0.0);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(GetParam().file), std::string::npos) << msg;
    EXPECT_NE(msg.find("'Nope'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("Handle"), std::string::npos) << msg;  // lists the nodes
  }
  EXPECT_THROW(scene.camera("Nope", 0.0), InputError);
  EXPECT_THROW(scene.mesh("Nope"), InputError);
}

INSTANTIATE_TEST_SUITE_P(Files, AnimationFormats,
                         ::testing::Values(FileCase{"anim.gltf", Quat::Identity()},
                                           FileCase{"anim.glb", Quat::Identity()},
                                           FileCase{"anim_zup_cm.dae", kZupLocal},
                                           FileCase{"anim_zup_cm.fbx", kZupLocal},
                                           FileCase{"anim_yup_m.fbx", Quat::Identity()}),
                         [](const ::testing::TestParamInfo<FileCase>& info) {
                           std::string n = info.param.file;
                           for (char& c : n) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return n;
                         });

TEST(AnimationAgreement, AllFormatsAgreeInWorldFrame) {
  const AnimationScene ref = AnimationScene::load(data("anim.gltf"));
  for (const FileCase& c :
       {FileCase{"anim.glb", Quat::Identity()}, FileCase{"anim_zup_cm.dae", kZupLocal},
        FileCase{"anim_zup_cm.fbx", kZupLocal}, FileCase{"anim_yup_m.fbx", Quat::Identity()}}) {
    const AnimationScene other = AnimationScene::load(data(c.file));
    for (const char* node : {"Handle", "Parent", "Child", "Static", "Camera"}) {
      for (double t = -0.5; t <= 2.5; t += 0.05) {
        const Pose a = ref.worldPose(node, t), b = other.worldPose(node, t);
        EXPECT_LE((a.position - b.position).norm(), 1e-5) << c.file << " " << node << " t=" << t;
        // Camera nodes differ in local axes between formats (FBX cameras look
        // down local +X); camera() handles that and is checked per format.
        if (std::string(node) == "Camera") continue;
        EXPECT_LE(angleBetween(a.rotation * c.localFrame, b.rotation), 1e-5)
            << c.file << " " << node << " t=" << t;
      }
    }
  }
}

// ---- What each importer does (pinned so an assimp upgrade is noticed) ------

TEST(AnimationImporters, FbxUnitsAndAxesAreConvertedHereNotByAssimp) {
  const AnimationScene zup = AnimationScene::load(data("anim_zup_cm.fbx"));
  // assimp leaves FBX keys in file units and axes: Handle key 1 is (10, 0, 20) cm, Z up.
  const NodeKeys k = zup.localKeys("Handle");
  ASSERT_EQ(k.positions.size(), 3u);
  EXPECT_VEC_NEAR(k.positions[1], Vec3(10, 0, 20), 1e-5);
  // TimeMode 11 (24 fps): assimp stores frames with 24 ticks/s; seconds here.
  EXPECT_NEAR(k.positionTimes[1], 1.0, 1e-9);
  Mat4 expected = Mat4::Identity();
  expected.topLeftCorner<3, 3>() << 0.01, 0, 0, 0, 0, 0.01, 0, -0.01, 0;
  EXPECT_LE((zup.fileToWorld() - expected).norm(), 1e-12);

  const AnimationScene yup = AnimationScene::load(data("anim_yup_m.fbx"));
  EXPECT_LE((yup.fileToWorld() - Mat4::Identity()).norm(), 1e-12);   // UnitScaleFactor 100 = m
  EXPECT_NEAR(yup.localKeys("Handle").positionTimes[2], 2.0, 1e-9);  // TimeMode default
}

TEST(AnimationImporters, ColladaUnitAndUpAxisAreBakedIntoTheRootByAssimp) {
  const AnimationScene dae = AnimationScene::load(data("anim_zup_cm.dae"));
  EXPECT_LE((dae.fileToWorld() - Mat4::Identity()).norm(), 1e-12);
  EXPECT_VEC_NEAR(dae.localKeys("Handle").positions[2], Vec3(30, -10, 20), 1e-5);  // cm, Z up
  EXPECT_VEC_NEAR(dae.worldPose("Handle", 2.0).position, Vec3(0.3, 0.2, 0.1), kTol);
  // Nodes are named by their COLLADA `name` ("Handle"), not their `id` ("handle_node").
  EXPECT_FALSE(dae.hasNode("handle_node"));
}

TEST(AnimationImporters, FbxKeysWithoutTakeRangeKeepTheirTimes) {
  // shifted.fbx (ASCII) keys at 0.5 s and 1.5 s, no LocalStart/LocalStop:
  // assimp 5.2.5 subtracts the first key time; crumple reads the first key
  // from the file and puts it back.
  const AnimationScene s = AnimationScene::load(data("shifted.fbx"));
  EXPECT_NEAR(s.startTime(), 0.5, 1e-9);
  EXPECT_NEAR(s.endTime(), 1.5, 1e-9);
  EXPECT_VEC_NEAR(s.worldPose("Handle", 0.5).position, Vec3(0, 0, 0), kTol);
  EXPECT_VEC_NEAR(s.worldPose("Handle", 1.0).position, Vec3(0.5, 0, 0), kTol);
}

TEST(AnimationImporters, FbxWithZeroFrameRateIsAnError) {
  try {
    AnimationScene::load(data("ticks0.fbx"));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("ticks0.fbx"), std::string::npos) << msg;
    EXPECT_NE(msg.find("frame rate 0"), std::string::npos) << msg;
  }
}

// ---- Errors ------------------------------------------------------------------

void expectLoadError(const std::string& file, std::initializer_list<const char*> parts) {
  try {
    AnimationScene::load(file);
    FAIL() << "expected InputError for " << file;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(file, 0), 0u) << "message should start with the file: " << msg;
    for (const char* p : parts) EXPECT_NE(msg.find(p), std::string::npos) << msg;
  }
}

TEST(AnimationErrors, MissingFile) { expectLoadError(data("missing.glb"), {"no such file"}); }
TEST(AnimationErrors, Folder) { expectLoadError(kData, {"not a regular file"}); }
TEST(AnimationErrors, MalformedGltf) { expectLoadError(data("malformed.gltf"), {"cannot import"}); }
TEST(AnimationErrors, BrokenGltf) {
  expectLoadError(data("broken.gltf"), {"cannot import", "bufferViews"});
}
TEST(AnimationErrors, MalformedFbx) { expectLoadError(data("malformed.fbx"), {"cannot import"}); }
TEST(AnimationErrors, NanKeyInGlb) {
  expectLoadError(data("nan.glb"), {"node 'Handle'", "non-finite position key 1"});
}
TEST(AnimationErrors, NanKeyInCollada) {
  expectLoadError(data("nan.dae"), {"node 'Handle'", "non-finite"});
}

// ---- Sampling and time helpers -----------------------------------------------

TEST(AnimationSampling, TicksToSeconds) {
  EXPECT_DOUBLE_EQ(ticksToSeconds(1500.0, 1000.0), 1.5);  // glTF, COLLADA: ms
  EXPECT_DOUBLE_EQ(ticksToSeconds(48.0, 24.0), 2.0);      // FBX: frames
  EXPECT_DOUBLE_EQ(ticksToSeconds(50.0, 0.0), 2.0);       // no rate: 25 ticks/s
  EXPECT_DOUBLE_EQ(ticksToSeconds(50.0, -1.0), 2.0);
}

TEST(AnimationSampling, Positions) {
  const std::vector<double> t{0.0, 1.0, 3.0};
  const std::vector<Vec3> v{{0, 0, 0}, {1, 0, 0}, {1, 2, 0}};
  const Vec3 fb(9, 9, 9);
  EXPECT_VEC_NEAR(samplePosition({}, {}, 0.5, fb), fb, 0);
  EXPECT_VEC_NEAR(samplePosition(t, v, -1.0, fb), v[0], 0);
  EXPECT_VEC_NEAR(samplePosition(t, v, 5.0, fb), v[2], 0);
  EXPECT_VEC_NEAR(samplePosition(t, v, 0.25, fb), Vec3(0.25, 0, 0), 1e-15);
  EXPECT_VEC_NEAR(samplePosition(t, v, 2.0, fb), Vec3(1, 1, 0), 1e-15);
  EXPECT_VEC_NEAR(samplePosition({2.0}, {Vec3(1, 2, 3)}, 0.0, fb), Vec3(1, 2, 3), 0);
  // Two keys at the same time: a jump, the later key wins after it.
  EXPECT_VEC_NEAR(samplePosition({0.0, 1.0, 1.0}, {v[0], v[1], v[2]}, 1.0, fb), v[2], 0);
}

TEST(AnimationSampling, RotationsTakeTheShortPath) {
  const Quat a = Quat::Identity();
  Quat b = rotY(10);
  b.coeffs() = -b.coeffs();  // same rotation, opposite hemisphere
  const Quat mid = sampleRotation({0.0, 1.0}, {a, b}, 0.5, Quat::Identity());
  EXPECT_ROT_NEAR(mid, rotY(5), 1e-12);
  EXPECT_ROT_NEAR(sampleRotation({0.0, 1.0}, {a, rotY(90)}, 0.25, a), rotY(22.5), 1e-12);
  EXPECT_ROT_NEAR(sampleRotation({}, {}, 0.5, rotX(3)), rotX(3), 0);
}

}  // namespace
}  // namespace crumple::io
