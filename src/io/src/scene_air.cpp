// The scene's [air] (docs/AIR.md, docs/SCENE.md), parsed straight into
// sim::AirParams. Its presence turns the air on; its values have fixed units
// (m/s, m, s, kg/m^3) whatever [scene] units says.
#include <string>

#include "scene_parser.hpp"

namespace crumple::io::detail {

namespace {

// Beyond these the numbers are a unit mistake, not a draught.
constexpr double kMaxWind = 100.0;      // m/s
constexpr double kMaxDensity = 2000.0;  // kg/m^3 (water is 1000)
constexpr double kMaxCoefficient = 100.0;
constexpr std::int64_t kMaxGustModes = 4096;

}  // namespace

void SceneParser::parseAir(const toml::table* table) {
  if (!table) return;
  const TableReader r(*table, "air", file_);
  r.allowOnly({"enabled", "density", "wind", "wind_keys", "gust_speed", "gust_length", "gust_time",
               "gust_modes", "drag_normal", "drag_tangential", "lift_translational",
               "lift_rotational", "added_mass", "shelter"});
  if (!r.boolean("enabled").value_or(true)) return;
  sim::AirParams air;
  const auto inRange = [&r](std::string_view key, double v, double lo, double hi) {
    if (!(v >= lo && v <= hi))
      r.fail(key, "must be in [" + formatNumber(lo) + ", " + formatNumber(hi) + "] (got " +
                      formatNumber(v) + ")");
    return v;
  };
  if (auto v = r.number("density")) air.density = inRange("density", *v, 1e-6, kMaxDensity);
  if (r.has("wind") && r.has("wind_keys"))
    r.fail("wind_keys", "give either wind (constant) or wind_keys, not both");
  if (auto w = r.vec3("wind")) {
    if (w->norm() > kMaxWind) r.fail("wind", "is implausibly fast (m/s, not scaled by units)");
    air.wind.push_back({0.0, *w});
  }
  if (const toml::node* keys = r.find("wind_keys")) {
    const toml::array* list = keys->as_array();
    if (!list || list->empty())
      r.fail("wind_keys", "must be a non-empty array of [time_s, vx, vy, vz]");
    double last = -1e300;
    for (std::size_t i = 0; i < list->size(); ++i) {
      const std::string where = "wind_keys[" + std::to_string(i) + "]";
      const toml::array* key = (*list)[i].as_array();
      if (!key || key->size() != 4) r.fail("wind_keys", where + " must be [time_s, vx, vy, vz]");
      double values[4];
      for (std::size_t c = 0; c < 4; ++c) {
        const auto value = (*key)[c].value<double>();
        if (!value || !std::isfinite(*value))
          r.fail("wind_keys", where + " must hold four finite numbers");
        values[c] = *value;
      }
      if (!(values[0] > last)) r.fail("wind_keys", where + ": times must increase");
      last = values[0];
      const Vec3 w(values[1], values[2], values[3]);
      if (w.norm() > kMaxWind) r.fail("wind_keys", where + " is implausibly fast (m/s)");
      air.wind.push_back({values[0], w});
    }
  }
  sim::GustParams& g = air.gusts;
  if (auto v = r.number("gust_speed")) g.speed = inRange("gust_speed", *v, 0.0, kMaxWind);
  if (auto v = r.number("gust_length")) g.lengthScale = inRange("gust_length", *v, 1e-3, 1e4);
  if (auto v = r.number("gust_time")) g.timeScale = inRange("gust_time", *v, 1e-3, 1e4);
  if (auto n = r.integer("gust_modes")) {
    if (*n < 1 || *n > kMaxGustModes)
      r.fail("gust_modes", "must be in [1, " + std::to_string(kMaxGustModes) + "]");
    g.modes = static_cast<int>(*n);
  }
  if (auto v = r.number("drag_normal"))
    air.dragNormal = inRange("drag_normal", *v, 0.0, kMaxCoefficient);
  if (auto v = r.number("drag_tangential"))
    air.dragTangential = inRange("drag_tangential", *v, 0.0, kMaxCoefficient);
  if (auto v = r.number("lift_translational"))
    air.translationalLift = inRange("lift_translational", *v, 0.0, kMaxCoefficient);
  if (auto v = r.number("lift_rotational"))
    air.rotationalLift = inRange("lift_rotational", *v, 0.0, kMaxCoefficient);
  if (auto v = r.number("added_mass"))
    air.addedMass = inRange("added_mass", *v, 0.0, kMaxCoefficient);
  if (auto b = r.boolean("shelter")) air.shelter = *b;
  spec_.sim.air = air;
}

}  // namespace crumple::io::detail
