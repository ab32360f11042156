// Render benchmark of crumple's path tracer (EmbreeRenderer) against a real
// peer, Blender's Cycles on the CPU, on one cached frame: the same scene
// exported for Blender (bench/cycles/render_cycles.py builds it and sets
// Cycles up as the same estimator of the same integral; its header has the
// light units measured by bench/cycles/calibrate.py), both rendered on the
// same thread count at equal samples per pixel.
//
//   bench_render CACHE --frame F --spp N[,N...] [--ref-spp 1024] [--threads 2]
//                [--runs 3] [--out DIR] [--blender blender] [--script PATH]
//                [--max-bounces 4] [--seed 1] [--resolution WxH]
//                [--aperture R --focus D] [--shutter OPEN,CLOSE]
//
// --resolution overrides the scene's image size (same vertical field of
// view), --aperture / --focus the camera's lens radius and focus distance (m;
// thin-lens depth of field); --spp takes a list, rendered against the same
// references. Motion blur: a cache simulated with a shutter renders blurred
// (its own shutter, or --shutter's; 0 draws it sharp), and Cycles gets the
// same motion: the sheet's (and moving props') positions at the shutter's
// steps as shape keys keyed linearly over Blender's centred shutter of the
// same length (render_cycles.py), Cycles' deformation motion blur.
//
// - Time: median wall time of --runs renders at each N (interleaved, ours
//   then Cycles, so both see the same machine load). Ours: a fresh
//   renderer (makeRenderer(Backend::Embree): the Embree device) + render()
//   (render geometry, scene/BVH build and path tracing).
//   Cycles: the time around bpy.ops.render.render() (scene sync, BVH,
//   shader compilation, path tracing) reported by the script; Blender's
//   start-up and the Python scene creation are reported apart.
// - Noise: RMSE (linear RGB, premultiplied as rendered) of the N-spp image
//   against its own renderer's reference, over the pixels covered in both
//   references (alpha >= 0.5). A reference is the average of two renders of
//   --ref-spp / 2 samples with seeds of their own (independent of each other
//   and of the N-spp images): half the RMSE between its halves is its own
//   noise, taken out of the N-spp image's RMSE to it ("noise RMSE" =
//   sqrt(RMSE^2 - reference noise^2); no assumption on how either sampler
//   converges).
// - Systematic difference: RMSE between the two references (raw, and with
//   both references' noise taken out likewise), over the covered pixels and
//   over the paper's pixels, and each reference's mean radiance over the
//   paper's pixels (alpha >= 0.5 in an albedo render without the ground).
//   Tells whether the two scenes really are the same.
//   Also the CPU time (user + system, all threads) of the same calls: the
//   machine may be shared, and CPU time is far less disturbed by other
//   processes than wall time.
// - Ratios at equal spp: speed = Cycles ms / ours ms, noise = ours / Cycles,
//   and equal-noise speed = speed / noise^2 (time to a given noise scales
//   with time * variance).
// Writes DIR/result.json, the exported scene (sheet.obj, ground.obj,
// propN.obj, paper.png, paper.rgbaf, scene.json), the Cycles EXRs and PNGs
// of every image (toSrgb8 on the scene's background).
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_motion.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/exit_status.hpp"
#include "crumple/core/parallel.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/render/renderer.hpp"
#include "crumple/render/view.hpp"
#include "json_number.hpp"

namespace fs = std::filesystem;
using namespace crumple;

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// CPU time of this process so far (user + system, all threads), ms.
double cpuMs() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  const auto ms = [](const timeval& t) { return 1e3 * t.tv_sec + 1e-3 * t.tv_usec; };
  return ms(u.ru_utime) + ms(u.ru_stime);
}

struct Options {
  std::string cache;
  int frame = std::numeric_limits<int>::min();
  std::vector<int> spp;
  int refSpp = 1024;
  int threads = 2;
  int runs = 3;
  std::string out = "bench-render";
  std::string blender = "blender";
  std::string script = std::string(CRUMPLE_SOURCE_DIR) + "/bench/cycles/render_cycles.py";
  int maxBounces = 4;
  std::uint64_t seed = 1;
  int width = 0, height = 0;  // 0: the scene's resolution
  double aperture = -1.0;     // < 0: the scene's camera
  double focus = -1.0;
  std::string shutter;  // OPEN,CLOSE in frames; empty: the cache's
};

const char* kUsage =
    "bench_render CACHE --frame F --spp N[,N...] [--ref-spp 1024] [--threads 2] [--runs 3]\n"
    "             [--out DIR] [--blender blender] [--script render_cycles.py]\n"
    "             [--max-bounces 4] [--seed 1] [--resolution WxH] [--aperture R --focus D]\n"
    "             [--shutter OPEN,CLOSE]\n";

Options parseArgs(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw InputError("bench_render: " + a + " needs a value");
      return argv[++i];
    };
    if (a == "--frame") {
      o.frame = std::stoi(value());
    } else if (a == "--spp") {
      std::stringstream list(value());
      for (std::string item; std::getline(list, item, ',');) o.spp.push_back(std::stoi(item));
    } else if (a == "--ref-spp") {
      o.refSpp = std::stoi(value());
    } else if (a == "--threads") {
      o.threads = std::stoi(value());
    } else if (a == "--runs") {
      o.runs = std::stoi(value());
    } else if (a == "--out") {
      o.out = value();
    } else if (a == "--blender") {
      o.blender = value();
    } else if (a == "--script") {
      o.script = value();
    } else if (a == "--max-bounces") {
      o.maxBounces = std::stoi(value());
    } else if (a == "--resolution") {
      const std::string v = value();
      const auto x = v.find('x');
      if (x == std::string::npos) throw InputError("bench_render: --resolution wants WxH");
      o.width = std::stoi(v.substr(0, x));
      o.height = std::stoi(v.substr(x + 1));
      if (o.width < 1 || o.height < 1) throw InputError("bench_render: bad --resolution " + v);
    } else if (a == "--aperture") {
      o.aperture = std::stod(value());
    } else if (a == "--focus") {
      o.focus = std::stod(value());
    } else if (a == "--shutter") {
      o.shutter = value();
    } else if (a == "--seed") {
      o.seed = std::stoull(value());
    } else if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (!a.empty() && a[0] != '-' && o.cache.empty()) {
      o.cache = a;
    } else {
      throw InputError("bench_render: unknown argument '" + a + "'\n" + kUsage);
    }
  }
  if (o.cache.empty() || o.spp.empty() || o.frame == std::numeric_limits<int>::min())
    throw InputError(std::string("bench_render: CACHE, --frame and --spp are required\n") + kUsage);
  for (const int n : o.spp)
    if (n < 1) throw InputError("bench_render: --spp values must be >= 1");
  if (o.refSpp < 2 || o.threads < 1 || o.runs < 1 || o.maxBounces < 0)
    throw InputError(
        "bench_render: --ref-spp must be >= 2, --threads, --runs >= 1, --max-bounces >= 0");
  return o;
}

// --- Export -----------------------------------------------------------------

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
std::string vec(const Vec3& v) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "[%.17g, %.17g, %.17g]", v.x(), v.y(), v.z());
  return buf;
}
std::string quote(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::ofstream openOut(const fs::path& path) {
  std::ofstream f(path);
  if (!f) throw InputError(path.string(), "cannot write");
  f.precision(17);
  return f;
}

// The sheet for Blender: positions, texture coordinates (OBJ convention, v
// upwards from the image's bottom row: 1 - patternToUv().y, so that the
// texture's top row, crumple's v = 0, is at OBJ v = 1) per vertex, the
// shading normals of shadingNormals() per corner (Blender custom split
// normals: Cycles interpolates exactly those), triangles as in the mesh
// (counter-clockwise = front).
void writeSheetObj(const fs::path& path, const mesh::SheetMesh& sheet,
                   const render::RenderScene& scene) {
  auto f = openOut(path);
  f << "# crumple sheet: vt = (u, 1 - v) of patternToUv, vn per corner (shadingNormals)\n";
  f << "s off\n";
  for (const Vec3& p : sheet.positions) f << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const Vec2& q : sheet.pattern) {
    const Vec2 uv = render::patternToUv(q, scene.paper.textureSize);
    f << "vt " << uv.x() << ' ' << 1.0 - uv.y() << '\n';
  }
  const auto normals = render::shadingNormals(sheet.positions, sheet.triangles,
                                              scene.paper.creaseAngle, scene.sharpVertices);
  for (const auto& corner : normals)
    for (const Vec3& n : corner) f << "vn " << n.x() << ' ' << n.y() << ' ' << n.z() << '\n';
  for (std::size_t t = 0; t < sheet.triangles.size(); ++t) {
    f << 'f';
    for (int k = 0; k < 3; ++k) {
      const int v = sheet.triangles[t][static_cast<std::size_t>(k)] + 1;
      f << ' ' << v << '/' << v << '/' << 3 * t + static_cast<std::size_t>(k) + 1;
    }
    f << '\n';
  }
}

// The ground square (as both renderers place it): side `size` at Y =
// height, centred in x and z under the sheet's bounding-box centre,
// counter-clockwise seen from above.
void writeGroundObj(const fs::path& path, const render::Ground& ground,
                    const mesh::SheetMesh& sheet) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : sheet.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Vec3 c = sheet.positions.empty() ? Vec3::Zero() : Vec3(0.5 * (lo + hi));
  const double h = 0.5 * ground.size;
  auto f = openOut(path);
  f << "# crumple ground\n";
  const double corners[4][2] = {{-h, h}, {h, h}, {h, -h}, {-h, -h}};
  for (const auto& xz : corners)
    f << "v " << c.x() + xz[0] << ' ' << ground.height << ' ' << c.z() + xz[1] << '\n';
  f << "f 1 2 3\nf 1 3 4\n";
}

void writePropObj(const fs::path& path, const render::PropMesh& prop) {
  auto f = openOut(path);
  f << "# crumple prop " << prop.name << '\n';
  for (const Vec3& p : prop.vertices) f << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const auto& t : prop.triangles)
    f << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
}

// A mesh's vertex positions at one motion-blur step, as an OBJ of v lines
// (the same vertices, in the same order, as its mesh's OBJ).
void writeStepObj(const fs::path& path, const std::vector<Vec3>& positions) {
  auto f = openOut(path);
  f << "# crumple motion-blur step: vertex positions only\n";
  for (const Vec3& p : positions) f << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
}

// The motion steps' OBJs of the sheet and the moving props, and their JSON
// ("motion" of scene.json: null when nothing moves).
std::string writeMotion(const fs::path& dir, const render::RenderScene& s, double shutterFrames) {
  if (s.motionSteps() == 0) return "null";
  const auto steps = [&](const std::vector<std::vector<Vec3>>& motion, const std::string& name) {
    std::string list = "[";
    for (std::size_t k = 0; k < motion.size(); ++k) {
      const std::string file = name + "_step" + std::to_string(k) + ".obj";
      writeStepObj(dir / file, motion[k]);
      list += (k ? ", " : "") + quote(file);
    }
    return list + "]";
  };
  std::string json = "{\"shutterFrames\": " + num(shutterFrames) +
                     ", \"steps\": " + std::to_string(s.motionSteps()) + ", \"sheet\": " +
                     (s.sheetMotion.empty() ? "null" : steps(s.sheetMotion, "sheet")) +
                     ", \"props\": [";
  for (std::size_t i = 0; i < s.props.size(); ++i)
    json += (i ? ", " : "") + (s.props[i].motion.empty()
                                   ? std::string("null")
                                   : steps(s.props[i].motion, "prop" + std::to_string(i)));
  return json + "]}";
}

// The raw float image format shared with render_cycles.py: "RGBF", uint32
// width, uint32 height (little-endian), float32 RGBA rows top to bottom.
void writeRgbaf(const fs::path& path, const ImageRGBAF& image) {
  std::ofstream f(path, std::ios::binary);
  if (!f) throw InputError(path.string(), "cannot write");
  const std::uint32_t wh[2] = {static_cast<std::uint32_t>(image.width),
                               static_cast<std::uint32_t>(image.height)};
  f.write("RGBF", 4);
  f.write(reinterpret_cast<const char*>(wh), sizeof wh);
  f.write(reinterpret_cast<const char*>(image.pixels.data()),
          static_cast<std::streamsize>(image.pixels.size() * sizeof(float)));
}

ImageRGBAF readRgbaf(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  char magic[4] = {};
  std::uint32_t wh[2] = {};
  f.read(magic, 4);
  f.read(reinterpret_cast<char*>(wh), sizeof wh);
  if (!f || std::string(magic, 4) != "RGBF" || wh[0] == 0 || wh[1] == 0 || wh[0] > 1u << 15 ||
      wh[1] > 1u << 15)
    throw InputError(path.string(), "not an RGBF raw image");
  ImageRGBAF image(static_cast<int>(wh[0]), static_cast<int>(wh[1]));
  f.read(reinterpret_cast<char*>(image.pixels.data()),
         static_cast<std::streamsize>(image.pixels.size() * sizeof(float)));
  if (!f) throw InputError(path.string(), "truncated RGBF raw image");
  return image;
}

void writeSceneJson(const fs::path& path, const render::RenderScene& s, bool hasGround,
                    int maxBounces, std::uint64_t seed, const std::string& motion) {
  auto f = openOut(path);
  const auto& c = s.camera;
  f << "{\n  \"camera\": {\"position\": " << vec(c.position) << ", \"rotation\": ["
    << num(c.rotation.w()) << ", " << num(c.rotation.x()) << ", " << num(c.rotation.y()) << ", "
    << num(c.rotation.z()) << "], \"yfov\": " << num(c.yfov) << ", \"znear\": " << num(c.znear)
    << ", \"zfar\": " << num(c.zfar) << ", \"width\": " << c.width << ", \"height\": " << c.height
    << ", \"apertureRadius\": " << num(c.apertureRadius)
    << ", \"focusDistance\": " << num(c.focusDistance) << "},\n  \"lights\": [";
  for (std::size_t i = 0; i < s.lights.size(); ++i) {
    const auto& l = s.lights[i];
    f << (i ? ",\n    " : "\n    ") << "{\"kind\": ";
    if (l.kind == render::Light::Kind::Directional) {
      f << "\"directional\", \"direction\": " << vec(l.direction.normalized())
        << ", \"angle\": " << num(l.angle);
    } else if (l.kind == render::Light::Kind::Point) {
      f << "\"point\", \"position\": " << vec(l.position);
    } else {
      const auto [u, v] = render::areaLightFrame(l);
      f << "\"area\", \"position\": " << vec(l.position)
        << ", \"direction\": " << vec(l.direction.normalized()) << ", \"u\": " << vec(u)
        << ", \"v\": " << vec(v) << ", \"size\": [" << num(l.size.x()) << ", " << num(l.size.y())
        << "]";
    }
    f << ", \"color\": " << vec(l.color) << ", \"intensity\": " << num(l.intensity) << "}";
  }
  f << "\n  ],\n  \"environment\": {\"color\": " << vec(s.environment.color)
    << ", \"intensity\": " << num(s.environment.intensity) << "},\n"
    << "  \"background\": " << vec(s.background) << ",\n"
    << "  \"maxBounces\": " << maxBounces << ",\n  \"seed\": " << seed << ",\n"
    << "  \"paper\": {\"obj\": \"sheet.obj\", \"texture\": \"paper.png\", \"textureRaw\": "
       "\"paper.rgbaf\", \"textureSize\": ["
    << num(s.paper.textureSize.x()) << ", " << num(s.paper.textureSize.y())
    << "], \"frontColor\": " << vec(s.paper.frontColor)
    << ", \"backColor\": " << vec(s.paper.backColor)
    << ", \"transmittance\": " << num(s.paper.transmittance)
    << ", \"creaseAngle\": " << num(s.paper.creaseAngle) << "},\n  \"ground\": ";
  if (hasGround)
    f << "{\"obj\": \"ground.obj\", \"color\": " << vec(s.ground.color) << "}";
  else
    f << "null";
  f << ",\n  \"props\": [";
  for (std::size_t i = 0; i < s.props.size(); ++i)
    f << (i ? ", " : "") << "{\"obj\": \"prop" << i
      << ".obj\", \"name\": " << quote(s.props[i].name) << ", \"color\": " << vec(s.props[i].color)
      << "}";
  f << "],\n  \"motion\": " << motion << "\n}\n";
}

// --- Rendering ----------------------------------------------------------------

struct Timed {
  ImageRGBAF image;
  double ms = 0.0;       // what is compared: wall time
  double cpuMs = 0.0;    // CPU time (user + system, every thread) of the same
  double extraMs = 0.0;  // Cycles: the whole Blender process
  double blenderMs = 0.0;
};

Timed renderOurs(const pipeline::FrameView& fv, int spp, const Options& o, std::uint64_t seed,
                 int frame, render::RenderPass pass = render::RenderPass::Beauty) {
  render::RendererOptions options;
  options.samplesPerPixel = spp;
  options.maxBounces = o.maxBounces;
  options.seed = seed;
  render::FrameSettings settings;
  settings.frame = frame;
  Timed t;
  const double cpu0 = cpuMs();
  const auto start = Clock::now();
  const std::unique_ptr<render::Renderer> renderer =
      render::makeRenderer(render::Backend::Embree, options);
  const render::RenderedImage image = renderer->render(fv.scene, fv.sheet, settings, pass);
  t.ms = msSince(start);
  t.cpuMs = cpuMs() - cpu0;
  t.image = image.linear();
  if (renderer->droppedSamples() > 0)
    std::fprintf(stderr, "bench_render: ours dropped %llu non-finite samples\n",
                 static_cast<unsigned long long>(renderer->droppedSamples()));
  return t;
}

std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string readText(const fs::path& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

double jsonNumber(const std::string& text, const std::string& key) {
  return bench::jsonNumber(text, key, -1.0);
}

Timed renderCycles(const fs::path& dir, const std::string& name, int spp, std::uint64_t seed,
                   const Options& o) {
  const fs::path exr = dir / (name + ".exr");
  const fs::path timing = dir / (name + ".timing.json");
  const fs::path log = dir / (name + ".log");
  fs::remove(timing);
  const std::string cmd =
      shellQuote(o.blender) + " -b --factory-startup -noaudio --python " + shellQuote(o.script) +
      " -- --scene " + shellQuote((dir / "scene.json").string()) + " --out " +
      shellQuote(exr.string()) + " --spp " + std::to_string(spp) + " --threads " +
      std::to_string(o.threads) + " --timing " + shellQuote(timing.string()) + " --seed " +
      std::to_string(seed) + " > " + shellQuote(log.string()) + " 2>&1";
  const auto start = Clock::now();
  const int status = std::system(cmd.c_str());
  Timed t;
  t.extraMs = msSince(start);
  if (status != 0 || !fs::exists(timing))
    throw std::runtime_error("bench_render: Blender failed (see " + log.string() + "): " + cmd);
  const std::string text = readText(timing);
  t.ms = 1000.0 * jsonNumber(text, "render_wall_s");
  t.cpuMs = 1000.0 * jsonNumber(text, "render_cpu_s");
  t.blenderMs = 1000.0 * jsonNumber(text, "blender_reported_s");
  t.image = readRgbaf(dir / (name + ".rgbaf"));
  return t;
}

// --- Measures -----------------------------------------------------------------

// Pixels with alpha >= 0.5 in every image given.
std::vector<char> coverage(const std::vector<const ImageRGBAF*>& images) {
  const std::size_t n = images.front()->pixels.size() / 4;
  std::vector<char> mask(n, 1);
  for (const ImageRGBAF* im : images)
    for (std::size_t i = 0; i < n; ++i)
      if (!(im->pixels[4 * i + 3] >= 0.5f)) mask[i] = 0;
  return mask;
}

std::size_t count(const std::vector<char>& mask) {
  return static_cast<std::size_t>(std::count(mask.begin(), mask.end(), 1));
}

double rmse(const ImageRGBAF& a, const ImageRGBAF& b, const std::vector<char>& mask) {
  if (a.width != b.width || a.height != b.height)
    throw std::runtime_error("bench_render: image sizes differ");
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    for (int k = 0; k < 3; ++k) {
      const double d = static_cast<double>(a.pixels[4 * i + static_cast<std::size_t>(k)]) -
                       b.pixels[4 * i + static_cast<std::size_t>(k)];
      sum += d * d;
    }
    n += 3;
  }
  return n > 0 ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
}

double meanRadiance(const ImageRGBAF& a, const std::vector<char>& mask) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    for (int k = 0; k < 3; ++k) sum += a.pixels[4 * i + static_cast<std::size_t>(k)];
    n += 3;
  }
  return n > 0 ? sum / static_cast<double>(n) : 0.0;
}

ImageRGBAF average(const ImageRGBAF& a, const ImageRGBAF& b) {
  if (a.width != b.width || a.height != b.height)
    throw std::runtime_error("bench_render: image sizes differ");
  ImageRGBAF out(a.width, a.height);
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    out.pixels[i] = 0.5f * (a.pixels[i] + b.pixels[i]);
  return out;
}

// The first three fields of /proc/loadavg (others share the machine: timings
// are only as good as the load was low).
std::string loadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return in ? a + " " + b + " " + c : std::string("?");
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Row {
  int spp = 0;
  double oursMs = 0.0, cyclesMs = 0.0, cyclesProcessMs = 0.0, cyclesBlenderMs = 0.0;
  double oursCpuMs = 0.0, cyclesCpuMs = 0.0;
  std::vector<double> oursAll, cyclesAll, oursCpuAll, cyclesCpuAll;
  double oursRmse = 0.0, cyclesRmse = 0.0;    // to the own reference
  double oursNoise = 0.0, cyclesNoise = 0.0;  // the reference's noise taken out
  std::string oursPng, cyclesPng, cyclesExr;
};

int run(const Options& o) {
  const cache::CacheReader reader(o.cache);
  const auto& header = reader.header();
  const io::SceneSpec scene =
      io::parseScene(header.sceneText, header.sceneFile + " (in " + o.cache + ")",
                     fs::path(header.sceneFile).parent_path().string(), /*checkFiles=*/false);
  std::size_t index = reader.frameCount();
  for (std::size_t i = 0; i < reader.frameCount(); ++i)
    if (reader.frameNumber(i) == o.frame) index = i;
  if (index == reader.frameCount())
    throw InputError(o.cache, "no frame " + std::to_string(o.frame) + " in the cache");
  const cache::FrameRecord record = reader.readFrame(index);
  pipeline::FrameViewBuilder builder(scene, header.extensions);
  if (!o.shutter.empty()) {
    const auto comma = o.shutter.find(',');
    if (comma == std::string::npos) throw InputError("bench_render: --shutter wants OPEN,CLOSE");
    const cache::Shutter s{std::stod(o.shutter.substr(0, comma)),
                           std::stod(o.shutter.substr(comma + 1))};
    if (s.on() && !cache::decodeShutter(header.extensions))
      throw InputError(o.cache, "--shutter: the cache holds no sub-frame motion");
    builder.setShutter(s.on() ? s : cache::Shutter{});
  }
  pipeline::FrameView fv = builder.build(record);
  const double shutterFrames = builder.shutter().close - builder.shutter().open;
  if (o.width > 0) {
    fv.scene.camera.width = o.width;
    fv.scene.camera.height = o.height;
  }
  if (o.aperture >= 0.0) fv.scene.camera.apertureRadius = o.aperture;
  if (o.focus > 0.0) fv.scene.camera.focusDistance = o.focus;
  const render::RenderScene& rs = fv.scene;
  if (rs.paper.texture.width == 0)
    throw std::runtime_error("bench_render: the frame has no texture");

  const fs::path dir = o.out;
  fs::create_directories(dir);
  writeSheetObj(dir / "sheet.obj", fv.sheet, rs);
  const bool ground = rs.ground.enabled;
  if (ground) writeGroundObj(dir / "ground.obj", rs.ground, fv.sheet);
  for (std::size_t i = 0; i < rs.props.size(); ++i)
    writePropObj(dir / ("prop" + std::to_string(i) + ".obj"), rs.props[i]);
  exporters::writePng((dir / "paper.png").string(), rs.paper.texture);
  writeRgbaf(dir / "paper.rgbaf", render::decodeSrgb8(rs.paper.texture, /*premultiply=*/false));
  writeSceneJson(dir / "scene.json", rs, ground, o.maxBounces, o.seed,
                 writeMotion(dir, rs, shutterFrames));

  setThreadCount(o.threads);
  const std::string loadBefore = loadAverage();
  const std::uint64_t refSeed = o.seed + 1000;  // independent of the N-spp images
  std::printf("bench_render: %s frame %d, %dx%d, %zu triangles, %d threads, %d runs, %s\n",
              o.cache.c_str(), o.frame, rs.camera.width, rs.camera.height,
              fv.sheet.triangles.size(), o.threads, o.runs,
              rs.motionSteps() > 0 ? ("motion blur over " + num(shutterFrames) + " frames").c_str()
                                   : "no motion blur");
  std::fflush(stdout);

  // References: two halves of refSpp / 2 samples with independent seeds,
  // averaged; half their difference measures the reference's own noise.
  const int half = o.refSpp / 2;
  std::printf("  references at %d spp (2 x %d) ...\n", 2 * half, half);
  std::fflush(stdout);
  const Timed oursA = renderOurs(fv, half, o, refSeed, o.frame);
  const Timed oursB = renderOurs(fv, half, o, refSeed + 1, o.frame);
  const ImageRGBAF oursRef = average(oursA.image, oursB.image);
  exporters::writePng((dir / "ours_ref.png").string(), render::toSrgb8(oursRef, rs.background));
  writeRgbaf(dir / "ours_ref.rgbaf", oursRef);
  const Timed cyclesA = renderCycles(dir, "cycles_refA", half, refSeed, o);
  const Timed cyclesB = renderCycles(dir, "cycles_refB", half, refSeed + 1, o);
  const ImageRGBAF cyclesRef = average(cyclesA.image, cyclesB.image);
  exporters::writePng((dir / "cycles_ref.png").string(), render::toSrgb8(cyclesRef, rs.background));
  writeRgbaf(dir / "cycles_ref.rgbaf", cyclesRef);
  const double oursRefMs = oursA.ms + oursB.ms, cyclesRefMs = cyclesA.ms + cyclesB.ms;
  std::printf("  references: ours %.0f ms, cycles %.0f ms\n", oursRefMs, cyclesRefMs);

  // The paper's pixels: an albedo render without the ground (props kept).
  pipeline::FrameView noGround = fv;
  noGround.scene.ground.enabled = false;
  const Timed paperAlbedo =
      renderOurs(noGround, 16, o, o.seed, o.frame, render::RenderPass::Albedo);
  const auto covered = coverage({&oursRef, &cyclesRef});
  const auto paper = coverage({&oursRef, &cyclesRef, &paperAlbedo.image});
  // Noise of each averaged reference: Var((A + B) / 2) = Var(A - B) / 4.
  const double oursRefNoise = 0.5 * rmse(oursA.image, oursB.image, covered);
  const double cyclesRefNoise = 0.5 * rmse(cyclesA.image, cyclesB.image, covered);
  // An N-spp image and its (independent) reference: RMSE^2 = noise^2 +
  // reference noise^2.
  const auto own = [](double rmseToRef, double refNoise) {
    return std::sqrt(std::max(0.0, rmseToRef * rmseToRef - refNoise * refNoise));
  };

  std::vector<Row> rows;
  for (const int spp : o.spp) {
    Row row;
    row.spp = spp;
    Timed ours, cycles;
    std::vector<double> processMs, blenderMs;
    for (int r = 0; r < o.runs; ++r) {
      ours = renderOurs(fv, spp, o, o.seed, o.frame);
      cycles = renderCycles(dir, "cycles_" + std::to_string(spp), spp, o.seed, o);
      row.oursAll.push_back(ours.ms);
      row.cyclesAll.push_back(cycles.ms);
      row.oursCpuAll.push_back(ours.cpuMs);
      row.cyclesCpuAll.push_back(cycles.cpuMs);
      processMs.push_back(cycles.extraMs);
      blenderMs.push_back(cycles.blenderMs);
      std::printf(
          "  %4d spp run %d: ours %8.1f ms (CPU %8.1f), cycles %8.1f ms (CPU %8.1f; Blender "
          "process %.0f ms)\n",
          spp, r + 1, ours.ms, ours.cpuMs, cycles.ms, cycles.cpuMs, cycles.extraMs);
      std::fflush(stdout);
    }
    row.oursMs = median(row.oursAll);
    row.cyclesMs = median(row.cyclesAll);
    row.oursCpuMs = median(row.oursCpuAll);
    row.cyclesCpuMs = median(row.cyclesCpuAll);
    row.cyclesProcessMs = median(processMs);
    row.cyclesBlenderMs = median(blenderMs);
    row.oursRmse = rmse(ours.image, oursRef, covered);
    row.cyclesRmse = rmse(cycles.image, cyclesRef, covered);
    row.oursNoise = own(row.oursRmse, oursRefNoise);
    row.cyclesNoise = own(row.cyclesRmse, cyclesRefNoise);
    row.oursPng = (dir / ("ours_" + std::to_string(spp) + ".png")).string();
    row.cyclesPng = (dir / ("cycles_" + std::to_string(spp) + ".png")).string();
    row.cyclesExr = (dir / ("cycles_" + std::to_string(spp) + ".exr")).string();
    exporters::writePng(row.oursPng, render::toSrgb8(ours.image, rs.background));
    exporters::writePng(row.cyclesPng, render::toSrgb8(cycles.image, rs.background));
    writeRgbaf(dir / ("ours_" + std::to_string(spp) + ".rgbaf"), ours.image);
    rows.push_back(row);
  }

  const double refDiff = rmse(oursRef, cyclesRef, covered);
  const double refDiffPaper = rmse(oursRef, cyclesRef, paper);
  const double systematicPaper =
      own(refDiffPaper, std::hypot(0.5 * rmse(oursA.image, oursB.image, paper),
                                   0.5 * rmse(cyclesA.image, cyclesB.image, paper)));
  const double systematic = own(refDiff, std::hypot(oursRefNoise, cyclesRefNoise));
  const double meanOurs = meanRadiance(oursRef, paper);
  const double meanCycles = meanRadiance(cyclesRef, paper);
  const double meanOursAll = meanRadiance(oursRef, covered);
  const double meanCyclesAll = meanRadiance(cyclesRef, covered);

  std::printf("\n%-9s %5s %11s %11s %11s %11s %10s\n", "renderer", "spp", "median ms", "median CPU",
              "RMSE to ref", "noise RMSE", "rel noise");
  for (const Row& r : rows) {
    std::printf("%-9s %5d %11.1f %11.1f %11.5f %11.5f %9.2f%%\n", "crumple", r.spp, r.oursMs,
                r.oursCpuMs, r.oursRmse, r.oursNoise, 100.0 * r.oursNoise / meanOursAll);
    std::printf("%-9s %5d %11.1f %11.1f %11.5f %11.5f %9.2f%%\n", "cycles", r.spp, r.cyclesMs,
                r.cyclesCpuMs, r.cyclesRmse, r.cyclesNoise, 100.0 * r.cyclesNoise / meanCyclesAll);
  }
  std::printf("\n%5s %18s %16s %18s %24s\n", "spp", "speed cycles/ours", "CPU cycles/ours",
              "noise ours/cycles", "equal-noise speed c/o");
  for (const Row& r : rows) {
    const double speed = r.cyclesMs / r.oursMs;
    const double noise = r.oursNoise / r.cyclesNoise;
    // The time to reach a given noise scales with time * variance.
    std::printf("%5d %17.2fx %15.2fx %17.2fx %23.2fx\n", r.spp, speed, r.cyclesCpuMs / r.oursCpuMs,
                noise, speed / (noise * noise));
  }
  std::printf(
      "\nreference vs reference (%d spp each): RMSE %.5f over %zu covered pixels (%.2f%% of their "
      "mean radiance %.4f);\n  the references' own noise (ours %.5f, cycles %.5f) removed: "
      "systematic %.5f (%.2f%%);\n  over the %zu paper pixels RMSE %.5f, systematic %.5f (%.2f%%)\n"
      "mean paper radiance: ours %.5f, cycles %.5f (cycles/ours %.4f)\n",
      2 * half, refDiff, count(covered), 100.0 * refDiff / meanOursAll, meanOursAll, oursRefNoise,
      cyclesRefNoise, systematic, 100.0 * systematic / meanOursAll, count(paper), refDiffPaper,
      systematicPaper, 100.0 * systematicPaper / meanOurs, meanOurs, meanCycles,
      meanCycles / meanOurs);

  const std::string loadAfter = loadAverage();
  std::printf("load average (1, 5, 15 min) before: %s, after: %s (%u hardware threads)\n",
              loadBefore.c_str(), loadAfter.c_str(), std::thread::hardware_concurrency());
  auto f = openOut(dir / "result.json");
  const auto list = [](const std::vector<double>& v) {
    std::string s = "[";
    for (std::size_t k = 0; k < v.size(); ++k) s += (k ? ", " : "") + num(v[k]);
    return s + "]";
  };
  f << "{\n  \"cache\": " << quote(o.cache) << ",\n  \"frame\": " << o.frame
    << ",\n  \"width\": " << rs.camera.width << ",\n  \"height\": " << rs.camera.height
    << ",\n  \"triangles\": " << fv.sheet.triangles.size() << ",\n  \"threads\": " << o.threads
    << ",\n  \"hardware_threads\": " << std::thread::hardware_concurrency()
    << ",\n  \"load_average_before\": " << quote(loadBefore)
    << ",\n  \"load_average_after\": " << quote(loadAfter) << ",\n  \"runs\": " << o.runs
    << ",\n  \"motion_blur_frames\": " << num(rs.motionSteps() > 0 ? shutterFrames : 0.0)
    << ",\n  \"max_bounces\": " << o.maxBounces << ",\n  \"ref_spp\": " << 2 * half
    << ",\n  \"seed\": " << o.seed << ",\n  \"ref_seeds\": [" << refSeed << ", " << refSeed + 1
    << "],\n  \"covered_pixels\": " << count(covered) << ",\n  \"paper_pixels\": " << count(paper)
    << ",\n  \"reference\": {\"ours_ms\": " << num(oursRefMs)
    << ", \"cycles_ms\": " << num(cyclesRefMs) << ", \"ours_noise_rmse\": " << num(oursRefNoise)
    << ", \"cycles_noise_rmse\": " << num(cyclesRefNoise)
    << ", \"rmse_ours_vs_cycles\": " << num(refDiff)
    << ", \"rmse_ours_vs_cycles_systematic\": " << num(systematic)
    << ", \"rmse_ours_vs_cycles_paper\": " << num(refDiffPaper)
    << ", \"rmse_ours_vs_cycles_paper_systematic\": " << num(systematicPaper)
    << ", \"mean_radiance_paper_ours\": " << num(meanOurs)
    << ", \"mean_radiance_paper_cycles\": " << num(meanCycles)
    << ", \"mean_radiance_covered_ours\": " << num(meanOursAll)
    << ", \"mean_radiance_covered_cycles\": " << num(meanCyclesAll)
    << ", \"ours_png\": " << quote((dir / "ours_ref.png").string())
    << ", \"cycles_png\": " << quote((dir / "cycles_ref.png").string())
    << ", \"cycles_exr_halves\": [" << quote((dir / "cycles_refA.exr").string()) << ", "
    << quote((dir / "cycles_refB.exr").string()) << "]},\n  \"rows\": [";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    f << (i ? "," : "") << "\n    {\"spp\": " << r.spp << ", \"ours_ms\": " << num(r.oursMs)
      << ", \"ours_ms_runs\": " << list(r.oursAll) << ", \"cycles_ms\": " << num(r.cyclesMs)
      << ", \"cycles_ms_runs\": " << list(r.cyclesAll) << ", \"ours_cpu_ms\": " << num(r.oursCpuMs)
      << ", \"ours_cpu_ms_runs\": " << list(r.oursCpuAll)
      << ", \"cycles_cpu_ms\": " << num(r.cyclesCpuMs)
      << ", \"cycles_cpu_ms_runs\": " << list(r.cyclesCpuAll)
      << ", \"speed_ratio_cpu_cycles_over_ours\": " << num(r.cyclesCpuMs / r.oursCpuMs)
      << ", \"cycles_blender_reported_ms\": " << num(r.cyclesBlenderMs)
      << ", \"cycles_process_ms\": " << num(r.cyclesProcessMs)
      << ", \"ours_rmse_to_ref\": " << num(r.oursRmse)
      << ", \"cycles_rmse_to_ref\": " << num(r.cyclesRmse)
      << ", \"ours_noise_rmse\": " << num(r.oursNoise)
      << ", \"cycles_noise_rmse\": " << num(r.cyclesNoise)
      << ", \"speed_ratio_cycles_over_ours\": " << num(r.cyclesMs / r.oursMs)
      << ", \"noise_ratio_ours_over_cycles\": " << num(r.oursNoise / r.cyclesNoise)
      << ", \"ours_png\": " << quote(r.oursPng) << ", \"cycles_png\": " << quote(r.cyclesPng)
      << ", \"cycles_exr\": " << quote(r.cyclesExr) << "}";
  }
  f << "\n  ]\n}\n";
  std::printf("results: %s\n", (dir / "result.json").string().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return runWithExitStatus("bench_render", [&] { return run(parseArgs(argc, argv)); });
}
