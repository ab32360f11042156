#include "crumple/render/view.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <stdexcept>
#include <string>

#include "crumple/mesh/sheet_mesh.hpp"
#include "render_geometry.hpp"

namespace crumple::render {

Camera Camera::lookAt(const Vec3& position, const Vec3& target, const Vec3& up, double yfov,
                      int width, int height) {
  Camera c;
  c.position = position;
  c.yfov = yfov;
  c.width = width;
  c.height = height;
  const Vec3 toTarget = target - position;
  if (!(toTarget.norm() > 0.0) || !toTarget.allFinite())
    throw std::invalid_argument("Camera::lookAt: target must differ from position");
  const Vec3 forward = toTarget.normalized();
  Vec3 right = forward.cross(up);
  if (!(right.norm() > 1e-12 * std::max(1.0, up.norm()))) {
    // `up` is parallel to the view direction: pick the world axis least
    // aligned with it so the result stays well defined.
    const Vec3 a = forward.cwiseAbs();
    const Vec3 alt = (a.x() <= a.y() && a.x() <= a.z()) ? Vec3::UnitX()
                     : (a.y() <= a.z())                 ? Vec3::UnitY()
                                                        : Vec3::UnitZ();
    right = forward.cross(alt);
  }
  right.normalize();
  const Vec3 trueUp = right.cross(forward);
  Mat3 r;
  r.col(0) = right;
  r.col(1) = trueUp;
  r.col(2) = -forward;
  c.rotation = Quat(r).normalized();
  return c;
}

namespace {

// Length of [a0, a1] ∩ [b0, b1].
double overlap(double a0, double a1, double b0, double b1) {
  return std::max(0.0, std::min(a1, b1) - std::max(a0, b0));
}

}  // namespace

ImageRGBA8 makeRuledPaperTexture(int width, int height) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("makeRuledPaperTexture: width and height must be positive");
  const double w = width, h = height;
  // Proportions of an A4 ruled sheet (mm) scaled to the texture; the lines are
  // bolder than real ones (0.7 mm, 1 mm) so they survive preview resolutions.
  const double ruleSpacing = h * 8.0 / 297.0;
  const double firstRule = h * 30.0 / 297.0;
  const double ruleThickness = std::max(1.0, h * 0.7 / 297.0);
  const double marginX = w * 30.0 / 210.0;
  const double marginThickness = std::max(1.0, w * 1.0 / 210.0);

  const Vec3 paper(srgb8ToLinear(252), srgb8ToLinear(251), srgb8ToLinear(246));
  const Vec3 rule(srgb8ToLinear(110), srgb8ToLinear(150), srgb8ToLinear(215));
  const Vec3 margin(srgb8ToLinear(220), srgb8ToLinear(70), srgb8ToLinear(80));

  // Box-filtered coverage of the rules per row and of the margin per column.
  std::vector<double> rowCover(static_cast<std::size_t>(height), 0.0);
  for (int k = 0;; ++k) {
    const double c = firstRule + k * ruleSpacing;
    if (c > h - 0.5 * ruleSpacing) break;
    const double lo = c - 0.5 * ruleThickness, hi = c + 0.5 * ruleThickness;
    const int y0 = std::max(0, static_cast<int>(std::floor(lo)));
    const int y1 = std::min(height - 1, static_cast<int>(std::floor(hi)));
    for (int y = y0; y <= y1; ++y)
      rowCover[static_cast<std::size_t>(y)] =
          std::min(1.0, rowCover[static_cast<std::size_t>(y)] + overlap(y, y + 1.0, lo, hi));
  }
  std::vector<double> colCover(static_cast<std::size_t>(width), 0.0);
  {
    const double lo = marginX - 0.5 * marginThickness, hi = marginX + 0.5 * marginThickness;
    for (int x = 0; x < width; ++x)
      colCover[static_cast<std::size_t>(x)] = std::min(1.0, overlap(x, x + 1.0, lo, hi));
  }

  ImageRGBA8 img(width, height);
  for (int y = 0; y < height; ++y) {
    const double ry = rowCover[static_cast<std::size_t>(y)];
    const Vec3 rowColor = (1.0 - ry) * paper + ry * rule;
    for (int x = 0; x < width; ++x) {
      const double mx = colCover[static_cast<std::size_t>(x)];
      const Vec3 c = (1.0 - mx) * rowColor + mx * margin;
      std::uint8_t* p = img.at(x, y);
      p[0] = linearToSrgb8(c.x());
      p[1] = linearToSrgb8(c.y());
      p[2] = linearToSrgb8(c.z());
      p[3] = 255;
    }
  }
  return img;
}

Mat4 viewMatrix(const Camera& camera) {
  const Mat3 r = camera.rotation.normalized().toRotationMatrix();
  Mat4 v = Mat4::Identity();
  v.topLeftCorner<3, 3>() = r.transpose();
  v.topRightCorner<3, 1>() = -(r.transpose() * camera.position);
  return v;
}

Mat4 projectionMatrix(const Camera& camera) {
  const double aspect = static_cast<double>(camera.width) / static_cast<double>(camera.height);
  const double f = 1.0 / std::tan(0.5 * camera.yfov);
  const double n = camera.znear, fa = camera.zfar;
  Mat4 p = Mat4::Zero();
  p(0, 0) = f / aspect;
  p(1, 1) = f;
  p(2, 2) = (fa + n) / (n - fa);
  p(2, 3) = 2.0 * fa * n / (n - fa);
  p(3, 2) = -1.0;
  return p;
}

std::optional<Vec2> projectToPixel(const Camera& camera, const Vec3& world) {
  const Vec4 clip = projectionMatrix(camera) * (viewMatrix(camera) * world.homogeneous());
  if (!(clip.w() > 0.0)) return std::nullopt;
  const double nx = clip.x() / clip.w(), ny = clip.y() / clip.w();
  return Vec2((nx * 0.5 + 0.5) * camera.width, (0.5 - ny * 0.5) * camera.height);
}

std::uint8_t linearToSrgb8(double linear) {
  const double c = std::clamp(std::isnan(linear) ? 0.0 : linear, 0.0, 1.0);
  const double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
  return static_cast<std::uint8_t>(std::lround(std::clamp(s, 0.0, 1.0) * 255.0));
}

double srgb8ToLinear(std::uint8_t srgb) {
  const double s = srgb / 255.0;
  return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
}

namespace {

// srgb8ToLinear of every 8-bit level, rounded to float once.
const std::array<float, 256>& linearOfSrgb8() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i)
      t[static_cast<std::size_t>(i)] =
          static_cast<float>(srgb8ToLinear(static_cast<std::uint8_t>(i)));
    return t;
  }();
  return table;
}

}  // namespace

ImageRGBAF decodeSrgb8(const ImageRGBA8& image, bool premultiply) {
  const std::array<float, 256>& kLinear = linearOfSrgb8();
  ImageRGBAF out(image.width, image.height);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.at(x, y);
      float* q = out.at(x, y);
      const float a = static_cast<float>(p[3]) / 255.0f;
      const float scale = premultiply ? a : 1.0f;
      for (int k = 0; k < 3; ++k) q[k] = kLinear[p[k]] * scale;
      q[3] = a;
    }
  return out;
}

}  // namespace crumple::render

namespace crumple::render {

std::pair<Vec3, Vec3> areaLightFrame(const Light& light) {
  const Vec3 n = light.direction.normalized();
  const Vec3 a = n.cwiseAbs();
  const Vec3 axis = (a.x() <= a.y() && a.x() <= a.z()) ? Vec3::UnitX()
                    : (a.y() <= a.z())                 ? Vec3::UnitY()
                                                       : Vec3::UnitZ();
  const Vec3 u = (axis - axis.dot(n) * n).normalized();
  const Vec3 v = n.cross(u);
  return {u, v};
}

double paperTransmittance(double thickness) {
  if (!(thickness >= 0.0) || !std::isfinite(thickness))
    throw std::invalid_argument("paperTransmittance: thickness must be finite and >= 0");
  constexpr double kScale = 62e-6;  // m: exp(-0.1 mm / 62 um) = 0.20
  return std::exp(-thickness / kScale);
}

std::vector<std::array<Vec3, 3>> shadingNormals(const std::vector<Vec3>& positions,
                                                const std::vector<std::array<int, 3>>& triangles,
                                                double creaseAngle,
                                                const std::vector<int>& sharpVertices) {
  return detail::shadingNormals(positions, triangles, detail::faceNormals(positions, triangles),
                                creaseAngle, sharpVertices);
}

Vec4 sampleTexture(const ImageRGBA8& texture, const Vec2& uv) {
  const int w = texture.width, h = texture.height;
  if (w <= 0 || h <= 0) return Vec4(1.0, 1.0, 1.0, 1.0);
  const std::array<float, 256>& kDecode = linearOfSrgb8();
  const double x = uv.x() * w - 0.5, y = uv.y() * h - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double ax = x - fx, ay = y - fy;
  auto wrap = [](long i, int n) { return static_cast<int>(((i % n) + n) % n); };
  const int x0 = wrap(static_cast<long>(fx), w), x1 = wrap(static_cast<long>(fx) + 1, w);
  const int y0 = wrap(static_cast<long>(fy), h), y1 = wrap(static_cast<long>(fy) + 1, h);
  auto texel = [&](int xi, int yi) {
    const std::uint8_t* p = texture.at(xi, yi);
    return Vec4(kDecode[p[0]], kDecode[p[1]], kDecode[p[2]], p[3] / 255.0);
  };
  return (1.0 - ay) * ((1.0 - ax) * texel(x0, y0) + ax * texel(x1, y0)) +
         ay * ((1.0 - ax) * texel(x0, y1) + ax * texel(x1, y1));
}

std::size_t RenderScene::motionSteps() const {
  std::size_t steps = sheetMotion.size();
  for (const PropMesh& prop : props) steps = std::max(steps, prop.motion.size());
  return steps;
}

namespace {

// The motion-blur time steps of validateRenderInput: every non-empty list of
// the same count >= 2, each step as many finite positions as its mesh has.
void validateMotion(const RenderScene& scene, const mesh::SheetMesh& sheet,
                    const std::function<void(const std::string&)>& invalid) {
  const std::size_t steps = scene.motionSteps();
  const auto check = [&](const std::vector<std::vector<Vec3>>& motion, std::size_t count,
                         const std::string& what) {
    if (motion.empty()) return;
    if (motion.size() != steps || steps < 2)
      invalid(what + " has " + std::to_string(motion.size()) + " motion steps, not " +
              (steps < 2 ? std::string("at least 2") : std::to_string(steps)));
    for (const auto& step : motion) {
      if (step.size() != count)
        invalid(what + " motion step has " + std::to_string(step.size()) + " positions, not " +
                std::to_string(count));
      for (const Vec3& p : step)
        if (!p.allFinite()) invalid(what + " motion step has a non-finite position");
    }
  };
  check(scene.sheetMotion, sheet.positions.size(), "sheet");
  for (const PropMesh& prop : scene.props)
    check(prop.motion, prop.vertices.size(), "prop '" + prop.name + "'");
}

}  // namespace

void validateRenderInput(const RenderScene& scene, const mesh::SheetMesh& sheet, const char* who) {
  const auto invalid = [who](const std::string& what) {
    throw std::invalid_argument(std::string(who) + ": " + what);
  };
  const auto finite = [](const Vec3& v) { return v.allFinite(); };
  const Camera& cam = scene.camera;
  if (cam.width <= 0 || cam.height <= 0) invalid("camera width and height must be positive");
  if (!finite(cam.position) || !cam.rotation.coeffs().allFinite() || !(cam.rotation.norm() > 0.0))
    invalid("camera pose is not finite");
  if (!(cam.yfov > 0.0 && cam.yfov < std::numbers::pi)) invalid("camera needs 0 < yfov < pi");
  if (!(cam.znear > 0.0) || !(cam.zfar > cam.znear) || !std::isfinite(cam.zfar))
    invalid("camera needs 0 < znear < zfar");
  if (!(cam.apertureRadius >= 0.0) || !std::isfinite(cam.apertureRadius))
    invalid("camera apertureRadius must be finite and >= 0");
  if (cam.apertureRadius > 0.0 && !(cam.focusDistance > 0.0 && std::isfinite(cam.focusDistance)))
    invalid("camera focusDistance must be finite and > 0 with a lens");
  for (const Light& l : scene.lights) {
    if (!finite(l.color) || !std::isfinite(l.intensity) || !finite(l.position) ||
        !finite(l.direction) || !std::isfinite(l.angle) || !l.size.allFinite())
      invalid("light has non-finite parameters");
    if (l.kind != Light::Kind::Point && !(l.direction.norm() > 0.0))
      invalid("directional or area light with zero direction");
    if (l.kind == Light::Kind::Directional && !(l.angle >= 0.0 && l.angle < std::numbers::pi))
      invalid("directional light angle must be in [0, pi)");
    if (l.kind == Light::Kind::Area && !(l.size.x() > 0.0 && l.size.y() > 0.0))
      invalid("area light size must be > 0");
  }
  if (!finite(scene.environment.color) || !std::isfinite(scene.environment.intensity))
    invalid("environment is not finite");
  if (scene.ground.enabled && !(std::isfinite(scene.ground.height) && scene.ground.size > 0.0 &&
                                std::isfinite(scene.ground.size) && finite(scene.ground.color)))
    invalid("ground needs a finite height, colour and size > 0");
  const PaperLook& paper = scene.paper;
  if (!(paper.textureSize.x() > 0.0 && paper.textureSize.y() > 0.0) ||
      !paper.textureSize.allFinite())
    invalid("paper textureSize must be positive");
  if (!paper.texture.pixels.empty() &&
      (paper.texture.width <= 0 || paper.texture.height <= 0 ||
       paper.texture.pixels.size() !=
           static_cast<std::size_t>(paper.texture.width) * paper.texture.height * 4))
    invalid("paper texture size does not match its pixels");
  if (!finite(paper.frontColor) || !finite(paper.backColor))
    invalid("paper colours are not finite");
  if (!(paper.transmittance >= 0.0 && paper.transmittance <= 1.0))
    invalid("paper transmittance must be in [0, 1]");
  if (!std::isfinite(paper.creaseAngle)) invalid("paper creaseAngle is not finite");
  if (sheet.positions.size() != sheet.pattern.size())
    invalid("sheet positions and pattern differ in size");
  const auto n = static_cast<long long>(sheet.positions.size());
  for (const auto& t : sheet.triangles)
    for (const int v : t)
      if (v < 0 || v >= n) invalid("sheet triangle index out of range");
  for (std::size_t i = 0; i < sheet.positions.size(); ++i)
    if (!finite(sheet.positions[i]) || !sheet.pattern[i].allFinite())
      invalid("sheet vertex " + std::to_string(i) + " is not finite");
  if (!scene.tears.empty())
    if (const std::string problem = mesh::validate(scene.tears, sheet); !problem.empty())
      invalid("tear atlas: " + problem);
  for (const PropMesh& prop : scene.props) {
    if (!finite(prop.color)) invalid("prop '" + prop.name + "' colour is not finite");
    for (const Vec3& v : prop.vertices)
      if (!finite(v)) invalid("prop '" + prop.name + "' has a non-finite vertex");
    const auto nv = static_cast<long long>(prop.vertices.size());
    for (const auto& t : prop.triangles)
      for (const int v : t)
        if (v < 0 || v >= nv) invalid("prop '" + prop.name + "' triangle index out of range");
  }
  validateMotion(scene, sheet, invalid);
}

const ImageRGBA8& defaultPaperTexture() {
  // A4 proportions, ~0.2 mm per texel over the default 0.21 x 0.297 m.
  static const ImageRGBA8 tex = makeRuledPaperTexture(1024, 1448);
  return tex;
}

}  // namespace crumple::render
