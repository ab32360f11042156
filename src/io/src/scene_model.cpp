// The scene file's simulation parameters, parsed straight into the modules'
// structs: [model] (paper::CrumpleParams), [sim] (sim::SimParams), [tear]
// (tear::TearingParams) and [sound] (sound::EventParams and the soundtrack's
// own SoundtrackSpec).
#include <iterator>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene_parser.hpp"

namespace crumple::io::detail {

namespace {

// Upper limits of the hybrid parameters: far beyond any useful value, they
// catch numbers written in another unit (per m instead of per cm, ...).
constexpr double kMaxRhoBoundPerCm = 100.0;   // 0.1 mm between boundary samples
constexpr double kMaxRhoIntPerCm2 = 10000.0;  // 0.1 mm between interior samples
constexpr double kMaxSigmaCm = 100.0;
constexpr std::int64_t kMaxIsometryIterations = 100000;

}  // namespace

// [model]: which sheet model runs, and the hybrid model's parameters (paper
// Table VI). The parameters have fixed units (their names say which),
// whatever [scene] units says.
void SceneParser::parseModel(const toml::table* table) {
  if (!table) return;
  const TableReader r(*table, "model", file_);
  static constexpr std::string_view kHybridKeys[] = {"rho_bound_per_cm",
                                                     "rho_int_per_cm2",
                                                     "theta0",
                                                     "theta_low",
                                                     "theta_high",
                                                     "eps_blaschke",
                                                     "eps_c",
                                                     "sigma_cm",
                                                     "theta_rest",
                                                     "damage",
                                                     "isometry_iterations",
                                                     "isometry_length_sweeps",
                                                     "isometry_length_tolerance",
                                                     "max_singular_per_frame",
                                                     "remesh_cooldown",
                                                     "max_edge_strain",
                                                     "lag_catch_up_speed"};
  std::vector<std::string_view> allowed = {"type"};
  allowed.insert(allowed.end(), std::begin(kHybridKeys), std::end(kHybridKeys));
  r.allowOnly(allowed);
  ModelSpec& m = spec_.model;
  m.typeLine = r.lineOf("type");
  const std::string type = r.string("type").value_or("elastic");
  if (type == "elastic") {
    m.type = ModelSpec::Type::Elastic;
    // A hybrid parameter under the elastic model is a mistake, not a no-op:
    // report the first one in file order.
    std::string_view first;
    long firstLine = 0;
    for (std::string_view key : kHybridKeys) {
      if (r.has(key) && (first.empty() || r.lineOf(key) < firstLine)) {
        first = key;
        firstLine = r.lineOf(key);
      }
    }
    if (!first.empty()) {
      r.fail(first, "only for type = \"hybrid\" (the elastic model has no such parameter)");
    }
    return;
  }
  if (type != "hybrid") {
    r.fail("type", "unknown model '" + type + "' (expected one of: elastic, hybrid)");
  }
  m.type = ModelSpec::Type::Hybrid;
  paper::CrumpleParams& h = spec_.crumpling;
  // value in (lo, hi), or [lo, hi) when loClosed; hiText names hi in the message.
  auto inRange = [&](std::string_view key, double v, double lo, double hi, bool loClosed,
                     const std::string& hiText = {}) {
    if (!((loClosed ? v >= lo : v > lo) && v < hi)) {
      r.fail(key, "must be in " + std::string(loClosed ? "[" : "(") + formatNumber(lo) + ", " +
                      (hiText.empty() ? formatNumber(hi) : hiText) + ") (got " + formatNumber(v) +
                      ")");
    }
    return v;
  };
  constexpr double kHalfPi = kPi / 2.0;
  const std::string halfPi = "pi/2";
  if (auto v = r.number("rho_bound_per_cm")) {
    h.rhoBound = inRange("rho_bound_per_cm", *v, 0.0, kMaxRhoBoundPerCm, false) * 100.0;
  }
  if (auto v = r.number("rho_int_per_cm2")) {
    h.rhoInt = inRange("rho_int_per_cm2", *v, 0.0, kMaxRhoIntPerCm2, false) * 1.0e4;
  }
  if (auto v = r.number("theta0")) {
    h.theta0 = inRange("theta0", *v, 0.0, kHalfPi, false, halfPi);
    // The hysteresis thresholds follow theta0 unless given (Table VI).
    h.thetaLow = h.theta0 / 10.0;
    h.thetaHigh = h.theta0;
  }
  if (auto v = r.number("theta_low")) {
    h.thetaLow = inRange("theta_low", *v, 0.0, kHalfPi, false, halfPi);
  }
  if (auto v = r.number("theta_high")) {
    h.thetaHigh = inRange("theta_high", *v, 0.0, kHalfPi, false, halfPi);
  }
  if (!(h.thetaLow < h.thetaHigh)) {
    const char* key = r.has("theta_low") ? "theta_low" : "theta_high";
    r.fail(key, "theta_low must be < theta_high (got theta_low = " + formatNumber(h.thetaLow) +
                    ", theta_high = " + formatNumber(h.thetaHigh) + ")");
  }
  if (auto v = r.number("eps_blaschke")) {
    h.epsBlaschke = inRange("eps_blaschke", *v, 0.0, 1.0, false);
  }
  if (auto v = r.number("eps_c")) h.epsC = inRange("eps_c", *v, 0.0, 0.5, false);
  if (auto v = r.number("sigma_cm")) {
    h.sigma = inRange("sigma_cm", *v, 0.0, kMaxSigmaCm, false) * 0.01;
  }
  if (auto v = r.number("theta_rest"))
    h.thetaRest = inRange("theta_rest", *v, 0.0, kPi, true, "pi");
  if (auto v = r.number("damage")) h.damage = r.requireNonNegative("damage", *v);
  if (auto n = r.integer("isometry_iterations")) {
    if (*n < 1 || *n > kMaxIsometryIterations) {
      r.fail("isometry_iterations", "must be in [1, " + std::to_string(kMaxIsometryIterations) +
                                        "] (got " + std::to_string(*n) + ")");
    }
    h.isometryIterations = static_cast<int>(*n);
  }
  // The isometry's Gauss-Seidel length sweeps after Phase II and their
  // early-exit tolerance (isometry.hpp deviation 7); 0 sweeps keeps the
  // paper's projection alone.
  if (auto n = r.integer("isometry_length_sweeps")) {
    if (*n < 0 || *n > kMaxIsometryIterations) {
      r.fail("isometry_length_sweeps", "must be in [0, " + std::to_string(kMaxIsometryIterations) +
                                           "] (got " + std::to_string(*n) + ")");
    }
    h.isometryLengthSweeps = static_cast<int>(*n);
  }
  if (auto v = r.number("isometry_length_tolerance")) {
    h.isometryLengthTolerance = inRange("isometry_length_tolerance", *v, 0.0, 0.1, false);
  }
  // How fast the sheet may crumple: new singular vertices per frame, and
  // animation steps a remeshed region waits before it is remeshed again.
  const auto count = [&](std::string_view key, long hi) -> std::optional<int> {
    const auto n = r.integer(key);
    if (!n) return std::nullopt;
    if (*n < 0 || *n > hi) {
      r.fail(key, "must be in [0, " + std::to_string(hi) + "] (got " + std::to_string(*n) + ")");
    }
    return static_cast<int>(*n);
  };
  if (auto n = count("max_singular_per_frame", 1000)) h.maxSingularPerFrame = *n;
  if (auto n = count("remesh_cooldown", 1000)) h.remeshCooldown = *n;
  // Paper stays paper: S_P's edge-strain bound after every animation step
  // (0 turns the strain limit off).
  if (auto v = r.number("max_edge_strain"))
    h.maxEdgeStrain = inRange("max_edge_strain", *v, 0.0, 0.5, true);
  // How fast a handle the bound left behind comes back (m/s; 0: at once).
  if (auto v = r.number("lag_catch_up_speed"))
    h.lagCatchUpSpeed = inRange("lag_catch_up_speed", *v, 0.0, 100.0, true);
}

void SceneParser::parseSim(const toml::table* table) {
  if (!table) return;
  const TableReader r(*table, "sim", file_);
  r.allowOnly({"gravity", "mass_damping", "stiffness_damping", "max_newton_iterations"});
  sim::SimParams& s = spec_.sim;
  if (auto g = r.vec3("gravity")) {
    if (g->norm() > 1000.0) r.fail("gravity", "is implausibly large (m/s^2, not scaled by units)");
    s.gravity = *g;
  }
  if (auto a = r.number("mass_damping")) s.massDamping = r.requireNonNegative("mass_damping", *a);
  if (auto b = r.number("stiffness_damping")) {
    s.stiffnessDamping = r.requireNonNegative("stiffness_damping", *b);
  }
  if (auto n = r.integer("max_newton_iterations")) {
    if (*n < 1 || *n > 1000) {
      r.fail("max_newton_iterations", "must be in [1, 1000] (got " + std::to_string(*n) + ")");
    }
    s.maxNewtonIterations = static_cast<int>(*n);
  }
}

// [tear]: the table's presence enables tearing (enabled = false keeps it off).
void SceneParser::parseTear(const toml::table* table) {
  if (!table) return;
  const TableReader r(*table, "tear", file_);
  r.allowOnly({"enabled", "resistance", "tip_damage", "speed_m", "texel_mm", "fiber_size_mm",
               "fiber_octaves", "fiber_anisotropy", "fiber_direction", "detail_blend",
               "stress_width_mm", "inward_angle_deg", "eps_a", "max_new_per_frame"});
  spec_.tearEnabled = r.boolean("enabled").value_or(true);
  tear::TearingParams& t = spec_.tearing;
  if (auto v = r.number("resistance"))
    t.griffith.resistance = r.requireNonNegative("resistance", *v);
  if (auto v = r.number("tip_damage")) {
    if (!(*v >= 0.0 && *v <= 1.0)) r.fail("tip_damage", "must be in [0, 1]");
    t.griffith.tipDamage = *v;
  }
  if (auto v = r.number("speed_m")) t.griffith.speed = r.requirePositive("speed_m", *v);
  if (auto v = r.number("texel_mm")) {
    t.fibers.texelSize = r.requirePositive("texel_mm", *v) * 1e-3;
    if (t.fibers.texelSize < 2e-5) r.fail("texel_mm", "must be at least 0.02 mm");
  }
  if (auto v = r.number("fiber_size_mm"))
    t.fibers.featureSize = r.requirePositive("fiber_size_mm", *v) * 1e-3;
  if (auto v = r.integer("fiber_octaves")) {
    if (*v < 1 || *v > 12) r.fail("fiber_octaves", "must be in [1, 12]");
    t.fibers.octaves = static_cast<int>(*v);
  }
  if (auto v = r.number("fiber_anisotropy")) {
    if (!(*v >= 1.0)) r.fail("fiber_anisotropy", "must be >= 1 (1 = isotropic)");
    t.fibers.anisotropy = *v;
  }
  if (auto v = r.vec2("fiber_direction")) {
    if (!(v->norm() > 0.0)) r.fail("fiber_direction", "must not be zero");
    t.fibers.fiberDirection = v->normalized();
  }
  if (auto v = r.number("detail_blend")) {
    if (!(*v >= 0.0 && *v <= 1.0)) r.fail("detail_blend", "must be in [0, 1]");
    t.detail.blend = *v;
  }
  if (auto v = r.number("stress_width_mm"))
    t.detail.stressWidth = r.requirePositive("stress_width_mm", *v) * 1e-3;
  if (auto v = r.number("inward_angle_deg")) {
    if (!(*v >= 0.0 && *v < 180.0)) r.fail("inward_angle_deg", "must be in [0, 180)");
    t.griffith.minInwardAngle = *v * std::numbers::pi / 180.0;
  }
  if (auto v = r.number("eps_a")) {
    if (!(*v >= 0.0 && *v < std::numbers::pi)) r.fail("eps_a", "must be in [0, pi) (rad)");
    t.branchAngle = *v;
  }
  if (auto v = r.integer("max_new_per_frame")) {
    if (*v < 0 || *v > 100) r.fail("max_new_per_frame", "must be in [0, 100]");
    t.maxNewTearsPerFrame = static_cast<int>(*v);
  }
}

// [sound]: the table's presence enables the sound events and the soundtrack.
void SceneParser::parseSound(const toml::table* table) {
  if (!table) return;
  const TableReader r(*table, "sound", file_);
  r.allowOnly({"enabled", "grid_mm", "curvature_threshold", "a_max", "free_border_radius_cm",
               "min_slide_mm_s", "listener", "database", "channels", "sample_rate", "format"});
  spec_.soundEnabled = r.boolean("enabled").value_or(true);
  sound::EventParams& s = spec_.soundEvents;
  if (auto v = r.number("grid_mm")) {
    s.gridSpacing = r.requirePositive("grid_mm", *v) * 1e-3;
    if (s.gridSpacing < 1e-4) r.fail("grid_mm", "must be at least 0.1 mm");
  }
  if (auto v = r.number("curvature_threshold"))
    s.curvatureThreshold = r.requirePositive("curvature_threshold", *v);
  if (auto v = r.number("a_max")) {
    if (!(*v > 0.0 && *v < std::numbers::pi)) r.fail("a_max", "must be in (0, pi) (rad)");
    s.maxDihedral = *v;
  }
  if (auto v = r.number("free_border_radius_cm"))
    s.freeBorderRadius = r.requirePositive("free_border_radius_cm", *v) * 1e-2;
  if (auto v = r.number("min_slide_mm_s"))
    s.minSlideSpeed = r.requireNonNegative("min_slide_mm_s", *v) * 1e-3;
  SoundtrackSpec& out = spec_.soundtrack;
  if (auto v = r.vec3("listener")) out.listener = *v * mpu();
  if (auto d = r.string("database")) {
    out.databaseLine = r.lineOf("database");
    out.database = resolvePath(*d);
  }
  if (auto v = r.integer("channels")) {
    if (*v != 1 && *v != 2) r.fail("channels", "must be 1 (mono) or 2 (stereo)");
    out.channels = static_cast<int>(*v);
  }
  if (auto v = r.integer("sample_rate")) {
    if (*v != 48000 && *v != 44100) r.fail("sample_rate", "must be 48000 or 44100");
    out.sampleRate = static_cast<int>(*v);
  }
  if (auto f = r.string("format")) {
    if (*f != "pcm24" && *f != "float") r.fail("format", "must be \"pcm24\" or \"float\"");
    out.floatSamples = *f == "float";
  }
}

}  // namespace crumple::io::detail
