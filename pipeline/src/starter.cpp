#include "crumple/pipeline/starter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "crumple/core/error.hpp"

namespace crumple::pipeline {

namespace {

// The gather, in metres and seconds (glTF: Y up).
constexpr double kSheet = 0.20;     // side of the square sheet
constexpr double kHeight = 0.10;    // the corners' height at rest
constexpr double kDrawIn = 0.15;    // share of each corner's distance to the middle it moves in
constexpr double kLift = 0.06;      // how far the corners rise
constexpr double kTiltDeg = -10.0;  // the corners' tangent planes, about the sheet's diagonals
constexpr double kStart = 0.25, kSpan = 2.0, kEnd = 3.0;
constexpr int kKeysPerSecond = 48;

// C2 ease in/out on [0, 1] (smootherstep), clamped.
double smoother(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * x * (x * (6.0 * x - 15.0) + 10.0);
}

struct CornerTrack {
  const char* node;
  double u, v;                   // pattern corner, 0 or 1
  std::vector<float> positions;  // x, y, z per key
  std::vector<float> rotations;  // x, y, z, w per key
};

// A corner's pose at time t: drawn in along its diagonal, lifted, its
// tangent plane turned about the horizontal line across its diagonal.
void sampleCorner(CornerTrack& c, double t) {
  const double s = smoother((t - kStart) / kSpan);
  const double x0 = (c.u - 0.5) * kSheet, z0 = (0.5 - c.v) * kSheet;
  c.positions.insert(c.positions.end(), {static_cast<float>(x0 * (1.0 - kDrawIn * s)),
                                         static_cast<float>(kHeight + kLift * s),
                                         static_cast<float>(z0 * (1.0 - kDrawIn * s))});
  const double n = std::hypot(x0, z0);
  const double angle = -kTiltDeg * std::numbers::pi / 180.0 * s;
  const double h = std::sin(0.5 * angle) / n;
  c.rotations.insert(c.rotations.end(),
                     {static_cast<float>(-z0 * h), 0.0f, static_cast<float>(x0 * h),
                      static_cast<float>(std::cos(0.5 * angle))});
}

std::string base64(const std::vector<std::uint8_t>& bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t n = static_cast<std::uint32_t>(bytes[i]) << 16 |
                            (i + 1 < bytes.size() ? bytes[i + 1] << 8 : 0u) |
                            (i + 2 < bytes.size() ? bytes[i + 2] : 0u);
    out += kAlphabet[n >> 18 & 63];
    out += kAlphabet[n >> 12 & 63];
    out += i + 1 < bytes.size() ? kAlphabet[n >> 6 & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[n & 63] : '=';
  }
  return out;
}

// glTF 2.0 (Khronos, "glTF 2.0 Specification", Sec. 3.11 animations): the
// four corner nodes with LINEAR translation and rotation samplers sharing
// one time accessor, the data in one embedded base64 buffer.
std::string gatherGltf() {
  std::vector<CornerTrack> corners{{"CornerFL", 0, 0, {}, {}},
                                   {"CornerFR", 1, 0, {}, {}},
                                   {"CornerBL", 0, 1, {}, {}},
                                   {"CornerBR", 1, 1, {}, {}}};
  const int keys = static_cast<int>(std::lround(kEnd * kKeysPerSecond)) + 1;
  std::vector<float> times;
  for (int k = 0; k < keys; ++k) {
    const double t = static_cast<double>(k) / kKeysPerSecond;
    times.push_back(static_cast<float>(t));
    for (CornerTrack& c : corners) sampleCorner(c, t);
  }
  std::vector<std::uint8_t> blob;
  std::ostringstream views, accessors;
  int count = 0;
  const auto add = [&](const float* data, std::size_t floats, int elements, const char* type,
                       const std::string& minmax) {
    const std::size_t offset = blob.size();
    blob.resize(offset + 4 * floats);
    std::memcpy(blob.data() + offset, data, 4 * floats);  // little-endian hosts only
    views << (count ? ",\n  " : "  ") << "{\"buffer\": 0, \"byteOffset\": " << offset
          << ", \"byteLength\": " << 4 * floats << "}";
    accessors << (count ? ",\n  " : "  ") << "{\"bufferView\": " << count
              << ", \"componentType\": 5126, \"count\": " << elements << ", \"type\": \"" << type
              << "\"" << minmax << "}";
    return count++;
  };
  std::ostringstream range;
  range.precision(9);
  range << ", \"min\": [0], \"max\": [" << times.back() << "]";
  add(times.data(), times.size(), keys, "SCALAR", range.str());
  std::ostringstream nodes, samplers, channels;
  nodes.precision(9);
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const CornerTrack& c = corners[i];
    const int p = add(c.positions.data(), c.positions.size(), keys, "VEC3", "");
    const int r = add(c.rotations.data(), c.rotations.size(), keys, "VEC4", "");
    nodes << (i ? ",\n  " : "  ") << "{\"name\": \"" << c.node << "\", \"translation\": ["
          << c.positions[0] << ", " << c.positions[1] << ", " << c.positions[2] << "]}";
    samplers << (i ? ",\n   " : "   ") << "{\"input\": 0, \"interpolation\": \"LINEAR\", "
             << "\"output\": " << p << "},\n   {\"input\": 0, \"interpolation\": \"LINEAR\", "
             << "\"output\": " << r << "}";
    channels << (i ? ",\n   " : "   ") << "{\"sampler\": " << 2 * i
             << ", \"target\": {\"node\": " << i
             << ", \"path\": \"translation\"}},\n   {\"sampler\": " << 2 * i + 1
             << ", \"target\": {\"node\": " << i << ", \"path\": \"rotation\"}}";
  }
  std::ostringstream out;
  out << "{\n \"asset\": {\"version\": \"2.0\", \"generator\": \"crumple init\"},\n"
      << " \"scene\": 0,\n \"scenes\": [{\"nodes\": [0, 1, 2, 3]}],\n"
      << " \"nodes\": [\n"
      << nodes.str() << "\n ],\n"
      << " \"animations\": [{\"name\": \"gather\",\n  \"samplers\": [\n"
      << samplers.str() << "\n  ],\n  \"channels\": [\n"
      << channels.str() << "\n  ]}],\n"
      << " \"buffers\": [{\"byteLength\": " << blob.size()
      << ", \"uri\": \"data:application/octet-stream;base64," << base64(blob) << "\"}],\n"
      << " \"bufferViews\": [\n"
      << views.str() << "\n ],\n"
      << " \"accessors\": [\n"
      << accessors.str() << "\n ]\n}\n";
  return out.str();
}

// The scene file, commented for a first reader (every key: docs/SCENE.md).
constexpr const char* kSceneToml = R"(# A starter shot written by `crumple init`: run it with
#   crumple run DIR
# (the frames, the cache and sound.wav go to out/starter/ in the working
# directory), then change what you like; docs/SCENE.md lists every key.
#
# A 20 cm square of office paper is held level 10 cm above the ground by its
# four corners (the handles), which draw in towards the middle by 15 % and
# rise 6 cm over two seconds while their tangent planes tilt out by 10
# degrees: the sheet gathers and bends. The handles' curves are in
# gather.gltf (nodes CornerFL, CornerFR, CornerBL, CornerBR); make your own in
# any DCC (glTF, FBX or COLLADA) and point `animation` at it.

[scene]
name = "starter"
units = "cm"            # lengths below in centimetres (the glTF is in metres, as glTF is)
fps = 24
frames = [0, 72]        # 3 s
substeps = 2            # animation steps per frame: raise it for fast motions
seed = 1                # same seed, same result, byte for byte
animation = "gather.gltf"

[sheet]                 # the pattern: a width x height rectangle placed in space
width = 20.0
height = 20.0
origin = [-10.0, 10.0, 10.0]   # where pattern point (0, 0) starts
u_axis = [1.0, 0.0, 0.0]       # the pattern's width direction
v_axis = [0.0, 0.0, -1.0]      # the pattern's height direction

[paper]
preset = "office-70gsm"  # or "office-90gsm" (assets/papers)

[model]
type = "hybrid"          # the crumpling model (flat and curved regions, singular points).
                         # Four pinched corners drawn together are its hard case: even this
                         # gentle gather ends with warnings that the handles lag behind
                         # their nodes by up to 1 mm on a few frames (docs/CRUMPLING.md).
                         # "elastic" (a plain elastic sheet) runs it without warnings, but
                         # makes no crumpling sounds.

# One handle per corner: `node` is the animation node it follows, `pattern`
# the point of the sheet it holds (in the pattern, cm), `tangent_control`
# holds the sheet's tangent plane too (a pinch rather than a point).
[[handles]]
name = "front-left"
node = "CornerFL"
pattern = [0.0, 0.0]
tangent_control = true

[[handles]]
name = "front-right"
node = "CornerFR"
pattern = [20.0, 0.0]
tangent_control = true

[[handles]]
name = "back-left"
node = "CornerBL"
pattern = [0.0, 20.0]
tangent_control = true

[[handles]]
name = "back-right"
node = "CornerBR"
pattern = [20.0, 20.0]
tangent_control = true

[camera]
position = [26.0, 34.0, 40.0]
look_at = [0.0, 10.0, 0.0]
up = [0.0, 1.0, 0.0]
fov_deg = 35.0
resolution = [640, 480]
# shutter = [-0.25, 0.25]   # motion blur in the path tracer (--backend embree)

[[lights]]
name = "key"
type = "directional"
direction = [-0.35, -1.0, -0.45]
intensity = 1.0
shadow = true            # the preview's shadow map

[[lights]]
name = "fill"
type = "directional"
direction = [0.6, -0.3, -0.8]
intensity = 0.35

[ground]
enabled = true
height = 0.0
size = 80.0

[sound]                  # the soundtrack: `crumple run` writes sound.wav beside the cache
)";

// Writes `text` to `path` whole, or throws InputError.
void writeFile(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw InputError(path.string(), "cannot write");
}

}  // namespace

void writeStarterShot(const std::filesystem::path& dir, bool overwrite) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw InputError(dir.string(), "cannot create the folder" + (ec ? ": " + ec.message() : ""));
  for (const char* name : {"scene.toml", "gather.gltf"})
    if (!overwrite && std::filesystem::exists(dir / name))
      throw InputError((dir / name).string(), "already exists; `crumple init --force` replaces it");
  writeFile(dir / "gather.gltf", gatherGltf());
  writeFile(dir / "scene.toml", kSceneToml);
}

}  // namespace crumple::pipeline
