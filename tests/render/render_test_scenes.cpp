#include "render_test_scenes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace crumple::render::test {

mesh::SheetMesh flatSheet(double y, double maxEdge) {
  mesh::SheetMesh m = mesh::makeRectangleSheet(kSheetWidth, kSheetHeight, maxEdge);
  mesh::placePattern(m, Vec3(-0.5 * kSheetWidth, y, 0.5 * kSheetHeight), Vec3::UnitX(),
                     -Vec3::UnitZ());
  return m;
}

Vec3 bentSheetPoint(double u, double v, double lift) {
  const double s = u - kBentFlatPart, radius = 0.05;
  double x = s, y = 0.0;
  if (s > 0.0) {
    x = radius * std::sin(s / radius);
    y = radius * (1.0 - std::cos(s / radius));
  }
  // A gentle sag along v so that the shading varies in both directions.
  y += 0.01 * std::sin(std::numbers::pi * v / kSheetHeight);
  return Vec3(x - 0.02, y + lift, 0.5 * kSheetHeight - v);
}

mesh::SheetMesh bentSheet(double lift, double maxEdge) {
  mesh::SheetMesh m = flatSheet(0.0, maxEdge);
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    m.positions[i] = bentSheetPoint(m.pattern[i].x(), m.pattern[i].y(), lift);
  return m;
}

Camera topCamera(double height, int width, int height_px) {
  return Camera::lookAt(Vec3(0.0, height, 0.0), Vec3::Zero(), -Vec3::UnitZ(), 0.7, width,
                        height_px);
}

RenderScene bentScene(int width, int height) {
  RenderScene s;
  s.camera = Camera::lookAt(Vec3(0.17, 0.21, 0.30), Vec3(0.0, 0.03, 0.0), Vec3::UnitY(), 0.75,
                            width, height);
  Light key;
  key.direction = Vec3(-0.5, -1.0, -0.35);
  key.intensity = 0.8;
  key.shadow = true;
  Light fill;
  fill.direction = Vec3(0.6, -0.5, -0.6);
  fill.intensity = 0.25;
  fill.color = Vec3(0.9, 0.95, 1.0);
  s.lights = {key, fill};
  s.ground.enabled = true;
  s.ground.height = 0.0;
  s.ground.size = 1.0;
  s.paper.frontColor = Vec3(0.95, 0.95, 0.93);
  s.paper.backColor = Vec3(0.95, 0.80, 0.55);
  return s;
}

mesh::SheetMesh bentSceneSheet() { return bentSheet(0.015, 0.015); }

StructureOverlay bentSheetStructure(const mesh::SheetMesh& sheet) {
  const StructurePalette palette;
  StructureOverlay o;
  o.triangleColors.reserve(sheet.triangles.size());
  for (const auto& t : sheet.triangles) {
    double u = 0.0;
    for (const int v : t) u += sheet.pattern[static_cast<std::size_t>(v)].x() / 3.0;
    o.triangleColors.push_back(u < kBentFlatPart ? palette.flat : palette.curved);
  }
  // Vertical polylines through the mesh vertices of a grid column (they run
  // along mesh edges, so they lie on the drawn surface).
  auto column = [&](double u, const Vec3& color) {
    std::vector<int> ids;
    for (std::size_t i = 0; i < sheet.pattern.size(); ++i)
      if (std::abs(sheet.pattern[i].x() - u) < 1e-9) ids.push_back(static_cast<int>(i));
    std::sort(ids.begin(), ids.end(), [&](int a, int b) {
      return sheet.pattern[static_cast<std::size_t>(a)].y() <
             sheet.pattern[static_cast<std::size_t>(b)].y();
    });
    for (std::size_t k = 1; k < ids.size(); ++k)
      o.lines.push_back({sheet.positions[static_cast<std::size_t>(ids[k - 1])],
                         sheet.positions[static_cast<std::size_t>(ids[k])], color});
  };
  constexpr double kCell = 0.015;  // kSheetWidth / 14
  column(kBentFlatPart, palette.border);
  for (int k = 5; k < 14; ++k) column(k * kCell, palette.ruling);
  auto vertexAt = [&](double u, double v) {
    return sheet.positions[static_cast<std::size_t>(mesh::nearestPatternVertex(sheet, Vec2(u, v)))];
  };
  o.points.push_back({vertexAt(0.03, 0.045), palette.singular});
  o.points.push_back({vertexAt(kBentFlatPart, 0.0), palette.junction});
  o.points.push_back({vertexAt(kBentFlatPart, kSheetHeight), palette.junction});
  o.points.push_back({vertexAt(0.0, 0.0), palette.handle});
  return o;
}

}  // namespace crumple::render::test
