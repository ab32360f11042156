#include "render_test_scenes.hpp"

#include <cmath>
#include <numbers>

namespace crumple::render::test {

mesh::SheetMesh flatSheet(double y, double maxEdge) {
  mesh::SheetMesh m = mesh::makeRectangleSheet(kSheetWidth, kSheetHeight, maxEdge);
  mesh::placePattern(m, Vec3(-0.5 * kSheetWidth, y, 0.5 * kSheetHeight), Vec3::UnitX(),
                     -Vec3::UnitZ());
  return m;
}

mesh::SheetMesh bentSheet(double lift, double maxEdge) {
  mesh::SheetMesh m = flatSheet(0.0, maxEdge);
  const double flatPart = 0.06, radius = 0.05;
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const double u = m.pattern[i].x(), v = m.pattern[i].y();
    const double s = u - flatPart;
    double x = s, y = 0.0;
    if (s > 0.0) {
      x = radius * std::sin(s / radius);
      y = radius * (1.0 - std::cos(s / radius));
    }
    // A gentle sag along v so that the shading varies in both directions.
    y += 0.01 * std::sin(std::numbers::pi * v / kSheetHeight);
    m.positions[i] = Vec3(x - 0.02, y + lift, 0.5 * kSheetHeight - v);
  }
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

}  // namespace crumple::render::test
