#include "structure_overlay.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace crumple::render::detail {

namespace {

// Segments of a point's disc: round at any size a debug view uses.
constexpr int kDiscSegments = 24;
// Points of at least this size get a black rim one pixel wide.
constexpr double kRimMinSizePx = 4.0;
constexpr double kRimWidthPx = 1.0;
// A point is hidden when paper lies more than this many pixels of depth in
// front of it (meshes approximate curved paper within a fraction of that).
constexpr double kPointOcclusionPx = 2.0;

bool finite(const Vec3& v) { return v.allFinite(); }

std::array<std::uint8_t, 4> srgbColor(const Vec3& linear) {
  return {linearToSrgb8(linear.x()), linearToSrgb8(linear.y()), linearToSrgb8(linear.z()), 255};
}

// World size of one pixel's height at unit eye depth.
double pixelAtUnitDepth(const Camera& camera) {
  return 2.0 * std::tan(0.5 * camera.yfov) / camera.height;
}

class Emitter {
 public:
  Emitter(std::vector<OverlayVertex>& out, int width, int height)
      : out_(out), ndcPerPx_(2.0 / width, 2.0 / height) {}

  // One vertex at clip position `c` moved by `px` pixels on screen.
  void vertex(const Vec4& c, const Vec2& px, const std::array<std::uint8_t, 4>& color) {
    OverlayVertex v{};
    v.clip = {static_cast<float>(c.x() + px.x() * ndcPerPx_.x() * c.w()),
              static_cast<float>(c.y() + px.y() * ndcPerPx_.y() * c.w()), static_cast<float>(c.z()),
              static_cast<float>(c.w())};
    v.color = color;
    out_.push_back(v);
  }

  // A quad a-b wide `halfWidth` pixels, extended by halfWidth beyond both ends.
  void segment(const Vec4& a, const Vec4& b, double halfWidth,
               const std::array<std::uint8_t, 4>& color) {
    const Vec2 pxPerNdc(1.0 / ndcPerPx_.x(), 1.0 / ndcPerPx_.y());
    const Vec2 na(a.x() / a.w(), a.y() / a.w()), nb(b.x() / b.w(), b.y() / b.w());
    Vec2 d = (nb - na).cwiseProduct(pxPerNdc);
    const double len = d.norm();
    d = len > 1e-9 ? Vec2(d / len) : Vec2(1.0, 0.0);
    const Vec2 along = halfWidth * d;
    const Vec2 side = halfWidth * Vec2(-d.y(), d.x());
    vertex(a, -along - side, color);
    vertex(b, along - side, color);
    vertex(b, along + side, color);
    vertex(a, -along - side, color);
    vertex(b, along + side, color);
    vertex(a, -along + side, color);
  }

  void disc(const Vec4& c, double radius, const std::array<std::uint8_t, 4>& color) {
    for (int i = 0; i < kDiscSegments; ++i) {
      const double a0 = 2.0 * std::numbers::pi * i / kDiscSegments;
      const double a1 = 2.0 * std::numbers::pi * (i + 1) / kDiscSegments;
      vertex(c, Vec2::Zero(), color);
      vertex(c, radius * Vec2(std::cos(a0), std::sin(a0)), color);
      vertex(c, radius * Vec2(std::cos(a1), std::sin(a1)), color);
    }
  }

 private:
  std::vector<OverlayVertex>& out_;
  Vec2 ndcPerPx_;
};

// Distance to the near plane in clip space (positive in front of it).
double nearDistance(const Vec4& c) { return c.z() + c.w(); }

// Whether a paper triangle crosses the segment camera -> p before
// 1 - tolerance of its length (Moeller-Trumbore).
bool occluded(const mesh::SheetMesh& sheet, const Vec3& camera, const Vec3& p, double tolerance) {
  const Vec3 dir = p - camera;
  const double tMax = 1.0 - tolerance;
  for (const auto& tri : sheet.triangles) {
    const Vec3& a = sheet.positions[static_cast<std::size_t>(tri[0])];
    const Vec3 e1 = sheet.positions[static_cast<std::size_t>(tri[1])] - a;
    const Vec3 e2 = sheet.positions[static_cast<std::size_t>(tri[2])] - a;
    const Vec3 pv = dir.cross(e2);
    const double det = e1.dot(pv);
    if (!(std::abs(det) > 1e-300)) continue;  // parallel or degenerate
    const double inv = 1.0 / det;
    const Vec3 tv = camera - a;
    const double u = tv.dot(pv) * inv;
    if (u < 0.0 || u > 1.0) continue;
    const Vec3 qv = tv.cross(e1);
    const double v = dir.dot(qv) * inv;
    if (v < 0.0 || u + v > 1.0) continue;
    const double t = e2.dot(qv) * inv;
    if (t > 0.0 && t < tMax) return true;
  }
  return false;
}

}  // namespace

void validateOverlay(const StructureOverlay& overlay, std::size_t triangleCount) {
  if (!overlay.triangleColors.empty() && overlay.triangleColors.size() != triangleCount)
    throw std::invalid_argument(
        "OsmesaRenderer: overlay has " + std::to_string(overlay.triangleColors.size()) +
        " triangle colours for " + std::to_string(triangleCount) + " triangles");
  for (const Vec3& c : overlay.triangleColors)
    if (!finite(c)) throw std::invalid_argument("OsmesaRenderer: overlay colour is not finite");
  for (const auto& l : overlay.lines)
    if (!finite(l.a) || !finite(l.b) || !finite(l.color))
      throw std::invalid_argument("OsmesaRenderer: overlay line is not finite");
  for (const auto& p : overlay.points)
    if (!finite(p.p) || !finite(p.color))
      throw std::invalid_argument("OsmesaRenderer: overlay point is not finite");
  if (!(overlay.lineWidthPx > 0.0 && std::isfinite(overlay.lineWidthPx)) ||
      !(overlay.pointSizePx > 0.0 && std::isfinite(overlay.pointSizePx)))
    throw std::invalid_argument(
        "OsmesaRenderer: overlay lineWidthPx and pointSizePx must be positive");
}

OverlayGeometry buildOverlayGeometry(const StructureOverlay& overlay, const mesh::SheetMesh& sheet,
                                     const Camera& camera, const Mat4& viewProj,
                                     const Vec3& origin) {
  OverlayGeometry g;
  const double unitPx = pixelAtUnitDepth(camera);

  // Lines: every end moves towards the camera by (1 + 3 * halfWidth) pixels of
  // depth, i.e. by that fraction of its distance along its own ray (which
  // keeps its image position).
  if (!overlay.lines.empty()) {
    Emitter emit(g.lines, camera.width, camera.height);
    const double halfWidth = 0.5 * overlay.lineWidthPx;
    const double shift = std::min(0.5, (1.0 + 3.0 * halfWidth) * unitPx);
    g.lines.reserve(overlay.lines.size() * 6);
    for (const auto& line : overlay.lines) {
      const Vec3 a = line.a - origin, b = line.b - origin;
      Vec4 ca = viewProj * (a + shift * (camera.position - a)).homogeneous();
      Vec4 cb = viewProj * (b + shift * (camera.position - b)).homogeneous();
      const double da = nearDistance(ca), db = nearDistance(cb);
      if (da <= 0.0 && db <= 0.0) continue;  // behind the near plane
      if (da < 0.0) ca = ca + (da / (da - db)) * (cb - ca);
      if (db < 0.0) cb = cb + (db / (db - da)) * (ca - cb);
      emit.segment(ca, cb, halfWidth, srgbColor(line.color));
    }
  }

  // Points: visible ones only, far to near.
  if (!overlay.points.empty()) {
    struct Visible {
      Vec4 clip;
      std::size_t index;
    };
    std::vector<Visible> visible;
    const Vec3 eye = camera.position + origin;
    const double tolerance = kPointOcclusionPx * unitPx;
    for (std::size_t i = 0; i < overlay.points.size(); ++i) {
      const Vec3& p = overlay.points[i].p;
      const Vec4 c = viewProj * (p - origin).homogeneous();
      if (!(nearDistance(c) > 0.0 && c.w() > 0.0)) continue;
      if (occluded(sheet, eye, p, tolerance)) continue;
      visible.push_back({c, i});
    }
    std::stable_sort(visible.begin(), visible.end(),
                     [](const Visible& x, const Visible& y) { return x.clip.w() > y.clip.w(); });
    Emitter emit(g.points, camera.width, camera.height);
    const double radius = 0.5 * overlay.pointSizePx;
    const bool rim = overlay.pointSizePx >= kRimMinSizePx;
    g.points.reserve(visible.size() * kDiscSegments * 3 * (rim ? 2 : 1));
    for (const Visible& v : visible) {
      const auto color = srgbColor(overlay.points[v.index].color);
      if (rim) {
        emit.disc(v.clip, radius, {0, 0, 0, 255});
        emit.disc(v.clip, radius - kRimWidthPx, color);
      } else {
        emit.disc(v.clip, radius, color);
      }
    }
  }
  return g;
}

}  // namespace crumple::render::detail
