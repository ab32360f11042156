#pragma once
// What a renderer needs to draw one frame: camera, lights, ground, the paper's
// look. Shared by the OSMesa preview (and later the Embree path tracer).
#include <vector>

#include "crumple/core/image.hpp"
#include "crumple/core/types.hpp"

namespace crumple::render {

struct Camera {
  Vec3 position{0.0, 0.3, 0.6};
  Quat rotation = Quat::Identity();  // looks down local -Z, +Y up (glTF convention)
  double yfov = 0.6981317007977318;  // rad
  double znear = 0.01;               // m
  double zfar = 100.0;               // m
  int width = 640;
  int height = 480;

  // A camera at `position` looking at `target`.
  static Camera lookAt(const Vec3& position, const Vec3& target, const Vec3& up, double yfov,
                       int width, int height);
};

struct Light {
  enum class Kind { Directional, Point };
  Kind kind = Kind::Directional;
  Vec3 direction{-0.4, -1.0, -0.3};  // Directional: direction the light travels (normalised on use)
  Vec3 position = Vec3::Zero();      // Point
  Vec3 color{1.0, 1.0, 1.0};         // linear RGB
  double intensity = 1.0;
  bool shadow = false;  // at most one shadow-casting light is honoured (the key)
};

struct Ground {
  bool enabled = false;
  double height = 0.0;  // world Y
  double size = 2.0;    // m, a square centred under the paper
  Vec3 color{0.55, 0.50, 0.45};
};

struct PaperLook {
  Vec3 frontColor{0.92, 0.92, 0.90};  // linear albedo multiplying the texture
  Vec3 backColor{0.92, 0.92, 0.90};
  // The printed pattern texture, addressed by pattern coordinates divided by
  // textureSize (u, v in [0, 1] over the sheet). Empty = a procedural ruled
  // paper texture (makeRuledPaperTexture).
  ImageRGBA8 texture;
  Vec2 textureSize{0.21, 0.297};  // m covered by the texture in u and v
};

struct RenderScene {
  Camera camera;
  std::vector<Light> lights;
  Ground ground;
  PaperLook paper;
  Vec3 background{0.80, 0.82, 0.86};  // linear RGB
};

// A deterministic ruled-notebook texture (lines and a margin) so orientation
// and stretching are visible.
ImageRGBA8 makeRuledPaperTexture(int width, int height);

}  // namespace crumple::render
