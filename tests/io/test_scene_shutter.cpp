// The scene's [camera] shutter (docs/SCENE.md, docs/RENDERING.md "Motion
// blur"): absent or 0 is no motion blur, [open, close] and a single
// centred length both reach CameraSpec, and bad values are one clear error
// at their line.
#include <gtest/gtest.h>

#include <string>

#include "crumple/io/scene.hpp"
#include "scene_test.hpp"

namespace crumple::io {
namespace {

using testing::expectError;
using testing::parse;

const std::string kSheet = "[sheet]\nwidth = 21\nheight = 29.7\n";

TEST(SceneShutter, AbsentOrZeroIsNoMotionBlur) {
  for (const std::string& camera :
       {std::string(), std::string("[camera]\n"), std::string("[camera]\nshutter = 0\n"),
        std::string("[camera]\nshutter = 0.0\n"), std::string("[camera]\nshutter = [0, 0]\n"),
        std::string("[camera]\nshutter = [-0.0, 0.0]\n")}) {
    SCOPED_TRACE(camera);
    const CameraSpec c = parse(kSheet + camera).camera;
    EXPECT_FALSE(c.motionBlur());
    EXPECT_EQ(c.shutterOpen, 0.0);
    EXPECT_EQ(c.shutterClose, 0.0);
    EXPECT_FALSE(std::signbit(c.shutterOpen));  // [-0.0, ...] is stored as 0
  }
}

TEST(SceneShutter, OpenAndCloseInFramesRelativeToTheFrame) {
  const CameraSpec c = parse(kSheet + "[camera]\nshutter = [-0.25, 0.25]\n").camera;
  EXPECT_TRUE(c.motionBlur());
  EXPECT_EQ(c.shutterOpen, -0.25);
  EXPECT_EQ(c.shutterClose, 0.25);
  EXPECT_EQ(c.shutterLine, 5);
  // Asymmetric (a shutter trailing the frame), integers, the bounds themselves.
  const CameraSpec trailing = parse(kSheet + "[camera]\nshutter = [-0.5, 0]\n").camera;
  EXPECT_EQ(trailing.shutterOpen, -0.5);
  EXPECT_EQ(trailing.shutterClose, 0.0);
  const CameraSpec widest = parse(kSheet + "[camera]\nshutter = [-1, 1]\n").camera;
  EXPECT_EQ(widest.shutterOpen, -1.0);
  EXPECT_EQ(widest.shutterClose, 1.0);
}

TEST(SceneShutter, OneNumberIsTheTimeOpenCentredOnTheFrame) {
  const CameraSpec half = parse(kSheet + "[camera]\nshutter = 0.5\n").camera;
  EXPECT_EQ(half.shutterOpen, -0.25);
  EXPECT_EQ(half.shutterClose, 0.25);
  const CameraSpec two = parse(kSheet + "[camera]\nshutter = 2\n").camera;
  EXPECT_EQ(two.shutterOpen, -1.0);
  EXPECT_EQ(two.shutterClose, 1.0);
}

TEST(SceneShutter, BadValuesAreErrorsAtTheirLine) {
  const std::string cam = kSheet + "[camera]\n";  // shutter on line 5
  expectError(cam + "shutter = [0.25, -0.25]\n", 5, "camera.shutter", {"open before it closes"});
  expectError(cam + "shutter = [0.1, 0.1]\n", 5, "camera.shutter", {"open before it closes"});
  expectError(cam + "shutter = [-1.5, 0]\n", 5, "camera.shutter", {"within 1 frame"});
  expectError(cam + "shutter = [0, 1.01]\n", 5, "camera.shutter", {"within 1 frame"});
  expectError(cam + "shutter = -0.5\n", 5, "camera.shutter", {"[0, 2]"});
  expectError(cam + "shutter = 2.5\n", 5, "camera.shutter", {"[0, 2]"});
  expectError(cam + "shutter = nan\n", 5, "camera.shutter", {"finite"});
  expectError(cam + "shutter = [0, inf]\n", 5, "camera.shutter", {"finite"});
  expectError(cam + "shutter = [-0.25, 0, 0.25]\n", 5, "camera.shutter", {"2 numbers"});
  expectError(cam + "shutter = \"180deg\"\n", 5, "camera.shutter", {"number"});
  expectError(cam + "shutter = true\n", 5, "camera.shutter", {"number"});
}

}  // namespace
}  // namespace crumple::io
