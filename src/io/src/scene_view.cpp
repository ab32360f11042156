// The scene file's view of the shot: [camera], [[lights]], [environment],
// [ground] and [[props]] (render only).
#include <cmath>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "scene_parser.hpp"

namespace crumple::io::detail {

namespace {

// The OSMesa preview's limits on Debian 12's Mesa 22.3 (llvmpipe): a side up
// to GL_MAX_RENDERBUFFER_SIZE, and its 4-sample colour buffer within 2 GiB
// (measured: 11584 x 11584 renders, 11600 x 11600 and 16384 x 16384 give an
// incomplete framebuffer; docs/RELIABILITY.md).
constexpr std::int64_t kMaxResolution = 16384;
constexpr std::int64_t kMaxPixels = std::int64_t{1} << 27;

// `shutter`: [open, close] in frames relative to the frame's time, or one
// number s, the fraction of a frame it is open, centred on the frame
// ([-s/2, s/2]). 0 (or [0, 0]) is no motion blur. Within a frame of the
// frame's time: the cache's velocities extrapolate the sheet linearly from
// it (docs/RENDERING.md "Motion blur").
void parseShutter(const TableReader& r, CameraSpec& c) {
  const toml::node* node = r.find("shutter");
  if (!node) return;
  double open = 0.0, close = 0.0;
  if (node->is_array()) {
    const Vec2 v = *r.vec2("shutter");
    open = v.x();
    close = v.y();
    if (std::abs(open) > 1.0 || std::abs(close) > 1.0)
      r.fail("shutter",
             "open and close must be within 1 frame of the frame's time, in [-1, 1] "
             "(got [" +
                 formatNumber(open) + ", " + formatNumber(close) + "])");
    if (!(open < close) && !(open == 0.0 && close == 0.0))
      r.fail("shutter", "the shutter must open before it closes (got [" + formatNumber(open) +
                            ", " + formatNumber(close) + "]); 0 or [0, 0]: no motion blur");
  } else {
    const double s = *r.number("shutter");
    if (!(s >= 0.0 && s <= 2.0))
      r.fail("shutter",
             "must be in [0, 2] frames, the time the shutter is open centred on the "
             "frame (got " +
                 formatNumber(s) + "), or [open, close]");
    open = -0.5 * s;
    close = 0.5 * s;
  }
  c.shutterOpen = open + 0.0;  // no -0.0
  c.shutterClose = close + 0.0;
  c.shutterLine = r.lineOf("shutter");
}

}  // namespace

void SceneParser::parseCamera(const toml::table* table) {
  if (!table) return;
  const TableReader r(*table, "camera", file_);
  r.allowOnly({"node", "position", "look_at", "up", "fov_deg", "focal_mm", "sensor_mm",
               "resolution", "f_stop", "focus_distance", "shutter"});
  CameraSpec& c = spec_.camera;
  if (auto res = r.intPair("resolution")) {
    for (std::int64_t v : *res) {
      if (v < 1 || v > kMaxResolution) {
        r.fail("resolution", "width and height must be in [1, " + std::to_string(kMaxResolution) +
                                 "] (got " + std::to_string(v) + ")");
      }
    }
    if ((*res)[0] * (*res)[1] > kMaxPixels)
      r.fail("resolution", std::to_string((*res)[0] * (*res)[1]) + " pixels, more than the " +
                               std::to_string(kMaxPixels) +
                               " the renderers can draw (11584 x 11584)");
    c.width = static_cast<int>((*res)[0]);
    c.height = static_cast<int>((*res)[1]);
  }
  if (auto node = r.string("node")) {
    if (node->empty()) r.fail("node", "must not be empty");
    if (spec_.animationFile.empty()) {
      r.fail("node", "a camera node needs an animation file ([scene] animation)");
    }
    for (const char* key : {"position", "look_at", "up"}) {
      if (r.has(key)) r.fail(key, "give either node or position/look_at/up, not both");
    }
    c.node = *node;
    c.nodeLine = r.lineOf("node");
  } else {
    if (auto p = r.vec3("position")) c.position = *p * mpu();
    if (auto l = r.vec3("look_at")) c.lookAt = *l * mpu();
    if (auto u = r.vec3("up")) c.up = r.requireDirection("up", *u);
    const Vec3 view = c.lookAt - c.position;
    if (view.norm() < 1e-12) {
      r.fail(r.has("look_at") ? "look_at" : "position", "look_at must differ from position");
    }
    if (view.normalized().cross(c.up).norm() < 1e-6) {
      r.fail(r.has("up") ? "up" : "look_at", "up must not be parallel to the view direction");
    }
  }
  if (r.has("fov_deg") && r.has("focal_mm")) {
    r.fail("focal_mm", "give either fov_deg or focal_mm, not both");
  }
  if (r.has("sensor_mm") && !r.has("focal_mm")) r.fail("sensor_mm", "needs focal_mm");
  if (auto fov = r.number("fov_deg")) {
    if (!(*fov > 0.0 && *fov < 180.0)) {
      r.fail("fov_deg", "must be in (0, 180) degrees (got " + formatNumber(*fov) + ")");
    }
    c.yfov = *fov * kPi / 180.0;
    c.fovExplicit = true;
  }
  if (auto focal = r.number("focal_mm")) {
    const double f = r.requirePositive("focal_mm", *focal);
    const double sensor =
        r.has("sensor_mm") ? r.requirePositive("sensor_mm", *r.number("sensor_mm")) : 36.0;
    // sensor_mm is the sensor width; the vertical extent follows the aspect.
    const double aspect = static_cast<double>(c.width) / static_cast<double>(c.height);
    c.yfov = 2.0 * std::atan(sensor / aspect / (2.0 * f));
    c.sensorWidth = sensor * 1e-3;
    c.fovExplicit = true;
  }
  if (auto n = r.number("f_stop")) c.fStop = r.requirePositive("f_stop", *n);
  if (auto d = r.number("focus_distance")) {
    if (!(c.fStop > 0.0)) r.fail("focus_distance", "needs f_stop (depth of field)");
    c.focusDistance = r.requirePositive("focus_distance", *d) * mpu();
  }
  parseShutter(r, c);
}

void SceneParser::parseLights(const TableReader& root) {
  const toml::array* lights = root.tableArray("lights");
  if (!lights) {
    LightSpec key;
    key.name = "key";
    key.direction = Vec3(-0.4, -1.0, -0.3).normalized();
    key.shadow = true;
    LightSpec fill;
    fill.name = "fill";
    fill.direction = Vec3(0.6, -0.5, 0.4).normalized();
    fill.intensity = 0.35;
    fill.shadow = false;
    spec_.lights = {key, fill};
    return;
  }
  std::set<std::string> names;
  for (std::size_t i = 0; i < lights->size(); ++i) {
    const TableReader r(*lights->get(i)->as_table(), "lights[" + std::to_string(i) + "]", file_);
    r.allowOnly({"name", "type", "direction", "position", "color", "intensity", "shadow",
                 "angle_deg", "size"});
    LightSpec l;
    l.name = r.string("name").value_or("light" + std::to_string(i));
    if (l.name.empty()) r.fail("name", "must not be empty");
    if (!names.insert(l.name).second) r.fail("name", "duplicate light name '" + l.name + "'");
    const std::string type = r.string("type").value_or("directional");
    if (type == "directional" || type == "sun") {
      l.kind = LightSpec::Kind::Directional;
      if (r.has("position")) r.fail("position", "only for point and area lights");
      if (r.has("size")) r.fail("size", "only for area lights (type = \"area\")");
      l.direction = l.direction.normalized();
      if (auto d = r.vec3("direction")) l.direction = r.requireDirection("direction", *d);
      // A sun is a directional light with the sun's disc (0.53 degrees) by default.
      double angleDeg = type == "sun" ? 0.53 : 0.0;
      if (auto a = r.number("angle_deg")) {
        if (!(*a >= 0.0 && *a < 90.0))
          r.fail("angle_deg", "must be in [0, 90) degrees (got " + formatNumber(*a) + ")");
        angleDeg = *a;
      }
      l.angle = angleDeg * kPi / 180.0;
    } else if (type == "point" || type == "area") {
      l.kind = type == "point" ? LightSpec::Kind::Point : LightSpec::Kind::Area;
      if (r.has("angle_deg")) r.fail("angle_deg", "only for directional and sun lights");
      const std::optional<Vec3> p = r.vec3("position");
      if (!p) r.missing("position");
      l.position = *p * mpu();
      if (type == "point") {
        if (r.has("direction")) r.fail("direction", "only for directional, sun and area lights");
        if (r.has("size")) r.fail("size", "only for area lights (type = \"area\")");
      } else {
        const std::optional<Vec3> d = r.vec3("direction");
        if (!d) r.missing("direction");
        l.direction = r.requireDirection("direction", *d);
        if (auto sz = r.vec2("size")) {
          if (!(sz->x() > 0.0 && sz->y() > 0.0)) r.fail("size", "both sides must be > 0");
          l.size = *sz * mpu();
        }
      }
    } else {
      r.fail("type",
             "unknown light type '" + type + "' (expected directional, sun, point or area)");
    }
    if (auto c = r.vec3("color")) l.color = r.requireColor("color", *c, 1.0);
    if (auto v = r.number("intensity")) l.intensity = r.requireNonNegative("intensity", *v);
    l.shadow = r.boolean("shadow").value_or(false);
    spec_.lights.push_back(std::move(l));
  }
}

void SceneParser::parseEnvironment(const toml::table* table) {
  if (!table) return;
  const TableReader r(*table, "environment", file_);
  r.allowOnly({"color", "intensity"});
  if (auto c = r.vec3("color")) spec_.environment.color = r.requireColor("color", *c, 1.0);
  if (auto v = r.number("intensity"))
    spec_.environment.intensity = r.requireNonNegative("intensity", *v);
}

void SceneParser::parseGround(const toml::table* table) {
  if (!table) return;
  const TableReader r(*table, "ground", file_);
  r.allowOnly({"enabled", "height", "size", "color"});
  GroundSpec& g = spec_.ground;
  g.enabled = r.boolean("enabled").value_or(true);  // the table's presence enables it
  if (auto h = r.number("height")) g.height = *h * mpu();
  if (auto s = r.number("size")) g.size = r.requirePositive("size", *s) * mpu();
  if (auto c = r.vec3("color")) g.color = r.requireColor("color", *c, 1.0);
}

void SceneParser::parseProps(const TableReader& root) {
  const toml::array* props = root.tableArray("props");
  if (!props) return;
  std::set<std::string> names;
  for (std::size_t i = 0; i < props->size(); ++i) {
    const TableReader r(*props->get(i)->as_table(), "props[" + std::to_string(i) + "]", file_);
    r.allowOnly({"name", "node", "shape", "size", "position", "color"});
    PropSpec p;
    const std::string shape = r.string("shape").value_or(r.has("node") ? "mesh" : "box");
    if (shape == "mesh") {
      const std::optional<std::string> node = r.string("node");
      if (!node) r.missing("node");
      if (node->empty()) r.fail("node", "must not be empty");
      if (spec_.animationFile.empty())
        r.fail("node", "a mesh prop needs an animation file ([scene] animation)");
      for (const char* key : {"size", "position"})
        if (r.has(key)) r.fail(key, "only for shape = \"box\" (a mesh prop moves with its node)");
      p.node = *node;
      p.nodeLine = r.lineOf("node");
    } else if (shape == "box") {
      if (r.has("node")) r.fail("node", "a box has no node (use shape = \"mesh\")");
      const std::optional<Vec3> sz = r.vec3("size");
      if (!sz) r.missing("size");
      if (!(sz->minCoeff() > 0.0)) r.fail("size", "every side must be > 0");
      p.boxSize = *sz * mpu();
      if (auto pos = r.vec3("position")) p.position = *pos * mpu();
    } else {
      r.fail("shape", "unknown shape '" + shape + "' (expected box or mesh)");
    }
    p.name = r.string("name").value_or(p.node.empty() ? "prop" + std::to_string(i) : p.node);
    if (p.name.empty()) r.fail("name", "must not be empty");
    if (!names.insert(p.name).second) r.fail("name", "duplicate prop name '" + p.name + "'");
    if (auto c = r.vec3("color")) p.color = r.requireColor("color", *c, 1.0);
    spec_.props.push_back(std::move(p));
  }
}

}  // namespace crumple::io::detail
