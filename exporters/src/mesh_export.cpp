// OBJ, PLY and USDA exports of cached frames, and the pattern-space tear
// texture (docs/EXPORT.md).
#include "crumple/exporters/mesh_export.hpp"

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <utility>

#include "crumple/cache/pcache_tear.hpp"
#include "crumple/core/error.hpp"

namespace crumple::exporters {
namespace {

// Appends printf-formatted text.
template <typename... Args>
void appendf(std::string& out, const char* format, Args... args) {
  char buf[256];
  const int n = std::snprintf(buf, sizeof buf, format, args...);
  if (n < 0) throw std::runtime_error("appendf: formatting failed");
  if (static_cast<std::size_t>(n) < sizeof buf) {
    out.append(buf, static_cast<std::size_t>(n));
    return;
  }
  std::string big(static_cast<std::size_t>(n) + 1, '\0');
  std::snprintf(big.data(), big.size(), format, args...);
  out.append(big.data(), static_cast<std::size_t>(n));
}

std::string frameName(int frame) { return "frame " + std::to_string(frame); }

// PATH.<pid>.tmp: the process id keeps two farm tasks that write the same
// file at once (the shared paper.mtl, a retried chunk) from mixing bytes.
std::string temporaryPath(const std::string& path) {
  return path + "." + std::to_string(::getpid()) + ".tmp";
}

// Little-endian bytes of a float / an int32.
void putF32(std::string& out, float v) {
  const auto bits = std::bit_cast<std::uint32_t>(v);
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<char>((bits >> (8 * k)) & 0xffu));
}
void putI32(std::string& out, std::int32_t v) {
  const auto bits = static_cast<std::uint32_t>(v);
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<char>((bits >> (8 * k)) & 0xffu));
}

// Twice the signed area of (a, b, c).
double cross2(const Vec2& a, const Vec2& b, const Vec2& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

// A USD string literal (quotes and backslashes escaped, control characters dropped).
std::string usdString(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out.push_back('\\');
    if (static_cast<unsigned char>(c) >= 0x20) out.push_back(c);
  }
  return out + "\"";
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

}  // namespace

Vec2 UvMapping::operator()(const Vec2& p) const {
  return Vec2((p.x() - origin.x()) / size.x(), (p.y() - origin.y()) / size.y());
}

Vec2 UvMapping::pattern(const Vec2& uv) const {
  return Vec2(origin.x() + uv.x() * size.x(), origin.y() + uv.y() * size.y());
}

UvMapping uvMappingOf(const std::vector<Vec2>& pattern, const std::string& what) {
  if (pattern.empty()) throw CorruptDataError(what + ": the pattern is empty");
  Vec2 lo = pattern.front(), hi = pattern.front();
  for (const Vec2& p : pattern) {
    if (!p.allFinite()) throw CorruptDataError(what + ": a pattern point is not finite");
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  UvMapping m;
  m.origin = lo;
  m.size = hi - lo;
  if (!(m.size.x() > 0.0) || !(m.size.y() > 0.0))
    throw CorruptDataError(what + ": the pattern's bounding box has no area");
  return m;
}

ExportMesh exportMesh(const cache::FrameRecord& frame, double fps, const UvMapping& uv) {
  const std::string name = frameName(frame.frame);
  const std::size_t n = frame.positions.size();
  if (frame.pattern.size() != n)
    throw CorruptDataError(name + ": " + std::to_string(n) + " positions but " +
                           std::to_string(frame.pattern.size()) + " pattern points");
  if (frame.regionOfTriangle.size() != frame.triangles.size())
    throw CorruptDataError(name + ": " + std::to_string(frame.triangles.size()) +
                           " triangles but " + std::to_string(frame.regionOfTriangle.size()) +
                           " region ids");
  for (std::size_t t = 0; t < frame.triangles.size(); ++t)
    for (const int v : frame.triangles[t])
      if (v < 0 || static_cast<std::size_t>(v) >= n)
        throw CorruptDataError(name + ": triangle " + std::to_string(t) + " has vertex " +
                               std::to_string(v) + " of " + std::to_string(n));
  for (const Vec3& x : frame.positions)
    if (!x.allFinite()) throw CorruptDataError(name + ": a position is not finite");
  ExportMesh m;
  m.frame = frame.frame;
  m.time = static_cast<double>(frame.frame) / fps;
  m.positions = frame.positions;
  m.triangles = frame.triangles;
  m.regionOfTriangle = frame.regionOfTriangle;
  m.uvs.reserve(n);
  for (const Vec2& p : frame.pattern) m.uvs.push_back(uv(p));
  return m;
}

std::string frameStem(int frame) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%04d", frame);
  return buf;
}

void writeFileAtomically(const std::string& path, const std::string& bytes) {
  const std::string tmp = temporaryPath(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path, std::string("cannot write: ") + std::strerror(errno));
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::remove(tmp.c_str());
      throw InputError(path, "cannot write (disk full?)");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    std::remove(tmp.c_str());
    throw InputError(path, "cannot rename the temporary file: " + why);
  }
}

std::string mtlText(const ObjMaterial& material) {
  std::string out = "# crumple export: the paper's material\n";
  appendf(out, "newmtl %s\n", material.name.c_str());
  appendf(out, "Ka 0 0 0\nKd %.9g %.9g %.9g\nKs 0 0 0\nd 1\nillum 1\n", material.diffuse.x(),
          material.diffuse.y(), material.diffuse.z());
  // The tear texture cuts the paper: its alpha (= its value) is 0 where the
  // tear masks say there is no paper.
  if (!material.alphaTexture.empty()) appendf(out, "map_d %s\n", material.alphaTexture.c_str());
  return out;
}

std::string objText(const ExportMesh& mesh, const std::string& mtlFile,
                    const std::string& materialName) {
  std::string out;
  out.reserve(mesh.positions.size() * 64 + mesh.triangles.size() * 40 + 256);
  appendf(out, "# crumple export: frame %d, t = %.9g s\n", mesh.frame, mesh.time);
  out +=
      "# vt = the vertex's pattern point (m) over the pattern's bounding box: u = (x - x0) / "
      "width, v = (y - y0) / height\n";
  appendf(out, "mtllib %s\no paper\n", mtlFile.c_str());
  for (const Vec3& x : mesh.positions) appendf(out, "v %.9g %.9g %.9g\n", x.x(), x.y(), x.z());
  for (const Vec2& t : mesh.uvs) appendf(out, "vt %.9g %.9g\n", t.x(), t.y());
  appendf(out, "usemtl %s\n", materialName.c_str());
  for (const auto& tri : mesh.triangles) {
    const int a = tri[0] + 1, b = tri[1] + 1, c = tri[2] + 1;
    appendf(out, "f %d/%d %d/%d %d/%d\n", a, a, b, b, c, c);
  }
  return out;
}

std::string plyBytes(const ExportMesh& mesh) {
  // Header lines end with CR LF (the PLY spec's "carriage-return terminated"
  // lines): assimp 5.2 drops the first byte after "end_header\n" when it is
  // a line feed, as an x coordinate's low byte may be, but reads "\r\n".
  std::string out = "ply\r\nformat binary_little_endian 1.0\r\n";
  appendf(out, "comment crumple export: frame %d, t = %.9g s\r\n", mesh.frame, mesh.time);
  out +=
      "comment u v = s t = the pattern point over the pattern's bounding box (s t: the names "
      "Blender reads)\r\n";
  appendf(out, "element vertex %zu\r\n", mesh.positions.size());
  out +=
      "property float x\r\nproperty float y\r\nproperty float z\r\n"
      "property float u\r\nproperty float v\r\nproperty float s\r\nproperty float t\r\n";
  appendf(out, "element face %zu\r\n", mesh.triangles.size());
  out += "property list uchar int vertex_indices\r\nproperty int region\r\nend_header\r\n";
  out.reserve(out.size() + mesh.positions.size() * 28 + mesh.triangles.size() * 17);
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3& x = mesh.positions[i];
    putF32(out, static_cast<float>(x.x()));
    putF32(out, static_cast<float>(x.y()));
    putF32(out, static_cast<float>(x.z()));
    for (int k = 0; k < 2; ++k) {
      putF32(out, static_cast<float>(mesh.uvs[i].x()));
      putF32(out, static_cast<float>(mesh.uvs[i].y()));
    }
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    out.push_back(static_cast<char>(3));
    for (const int v : mesh.triangles[t]) putI32(out, v);
    putI32(out, mesh.regionOfTriangle[t]);
  }
  return out;
}

std::optional<ImageRGBA8> tearTexture(const cache::FrameRecord& frame, const UvMapping& uv,
                                      int maxSide) {
  const std::string name = frameName(frame.frame);
  std::optional<mesh::TearAtlas> atlas;
  try {
    atlas = cache::decodeTearAtlas(frame.extensions);
  } catch (const CorruptDataError& e) {
    throw CorruptDataError(name + ": " + e.what());
  }
  if (!atlas) return std::nullopt;
  if (maxSide < 1) throw std::invalid_argument("tearTexture: maxSide must be at least 1");
  // The texel: the atlas's, or larger so that no side exceeds maxSide.
  const double texel =
      std::max(atlas->texelSize, std::max(uv.size.x(), uv.size.y()) / static_cast<double>(maxSide));
  const auto side = [&](double extent) {
    return std::clamp(static_cast<int>(std::ceil(extent / texel - 1e-9)), 1, maxSide);
  };
  ImageRGBA8 image(side(uv.size.x()), side(uv.size.y()));
  std::fill(image.pixels.begin(), image.pixels.end(), std::uint8_t{255});
  const int w = image.width, h = image.height;
  for (const mesh::TearPatch& patch : atlas->patches) {
    if (patch.triangle < 0 || static_cast<std::size_t>(patch.triangle) >= frame.triangles.size())
      throw CorruptDataError(name + ": a tear patch's triangle " + std::to_string(patch.triangle) +
                             " is not in the frame's " + std::to_string(frame.triangles.size()));
    const auto& tri = frame.triangles[static_cast<std::size_t>(patch.triangle)];
    std::array<Vec2, 3> p;  // the triangle in pattern space
    for (std::size_t k = 0; k < 3; ++k) {
      const int v = tri[k];
      if (v < 0 || static_cast<std::size_t>(v) >= frame.pattern.size())
        throw CorruptDataError(name + ": triangle " + std::to_string(patch.triangle) +
                               " has no pattern point " + std::to_string(v));
      p[k] = frame.pattern[static_cast<std::size_t>(v)];
    }
    const double area = cross2(p[0], p[1], p[2]);
    if (!(std::abs(area) > 0.0)) continue;  // a degenerate triangle covers no texel
    // Its texel range: texel (i, r) has its centre at u = (i + 0.5) / w, v = 1 - (r + 0.5) / h.
    double u0 = 1.0, u1 = 0.0, v0 = 1.0, v1 = 0.0;
    for (const Vec2& q : p) {
      const Vec2 t = uv(q);
      u0 = std::min(u0, t.x());
      u1 = std::max(u1, t.x());
      v0 = std::min(v0, t.y());
      v1 = std::max(v1, t.y());
    }
    const int i0 = std::max(0, static_cast<int>(std::floor(u0 * w - 0.5)));
    const int i1 = std::min(w - 1, static_cast<int>(std::ceil(u1 * w - 0.5)));
    const int r0 = std::max(0, static_cast<int>(std::floor((1.0 - v1) * h - 0.5)));
    const int r1 = std::min(h - 1, static_cast<int>(std::ceil((1.0 - v0) * h - 0.5)));
    for (int r = r0; r <= r1; ++r) {
      for (int i = i0; i <= i1; ++i) {
        const Vec2 q = uv.pattern(Vec2((i + 0.5) / w, 1.0 - (r + 0.5) / h));
        // Inside (or on the border of) the triangle, whichever its winding.
        const double b0 = cross2(p[1], p[2], q) / area;
        const double b1 = cross2(p[2], p[0], q) / area;
        const double b2 = cross2(p[0], p[1], q) / area;
        if (b0 < 0.0 || b1 < 0.0 || b2 < 0.0) continue;
        const double value = mesh::sampleTearMask(*atlas, mesh::atlasPosition(*atlas, patch, q));
        const auto a = static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(value, 0.0, 1.0)));
        std::uint8_t* px = image.at(i, r);
        px[0] = px[1] = px[2] = px[3] = a;
      }
    }
  }
  return image;
}

// ---------------------------------------------------------------- USDA

struct UsdaWriter::Impl {
  std::string path;
  std::string sceneName;
  double fps = 24.0;
  int frames = 0;
  int topologies = 0;
  int firstFrame = 0;
  int lastFrame = 0;
  // The previous frame's topology, to key it only where it changes.
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> regions;
  std::vector<Vec2> uvs;
  // The time samples of each attribute, as text, in temporary files.
  FilePtr points, extent, counts, indices, st, region;
  bool closed = false;
};

UsdaWriter::UsdaWriter(std::string path, std::string sceneName, double fps)
    : impl_(std::make_unique<Impl>()) {
  if (!(fps > 0.0) || !std::isfinite(fps))
    throw std::invalid_argument("UsdaWriter: fps must be finite and > 0");
  impl_->path = std::move(path);
  impl_->sceneName = std::move(sceneName);
  impl_->fps = fps;
  for (FilePtr* f : {&impl_->points, &impl_->extent, &impl_->counts, &impl_->indices, &impl_->st,
                     &impl_->region}) {
    f->reset(std::tmpfile());
    if (!*f)
      throw InputError(impl_->path,
                       std::string("cannot make a temporary file: ") + std::strerror(errno));
  }
}

UsdaWriter::~UsdaWriter() = default;

int UsdaWriter::framesAdded() const { return impl_->frames; }
int UsdaWriter::topologySamples() const { return impl_->topologies; }

void UsdaWriter::add(const ExportMesh& mesh) {
  Impl& s = *impl_;
  if (s.closed) throw std::logic_error("UsdaWriter::add after close");
  if (s.frames > 0 && mesh.frame <= s.lastFrame)
    throw std::invalid_argument("UsdaWriter::add: frame " + std::to_string(mesh.frame) +
                                " after frame " + std::to_string(s.lastFrame));
  const auto emit = [&](std::FILE* f, const std::string& text) {
    if (std::fwrite(text.data(), 1, text.size(), f) != text.size())
      throw InputError(s.path, "cannot write a temporary file (disk full?)");
  };
  std::string line;
  appendf(line, "            %d: [", mesh.frame);
  const std::string key = line;
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3& x = mesh.positions[i];
    appendf(line, i == 0 ? "(%.9g, %.9g, %.9g)" : ", (%.9g, %.9g, %.9g)", x.x(), x.y(), x.z());
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  if (mesh.positions.empty()) lo = hi = Vec3::Zero();
  emit(s.points.get(), line + "],\n");
  line = key;
  appendf(line, "(%.9g, %.9g, %.9g), (%.9g, %.9g, %.9g)],\n", lo.x(), lo.y(), lo.z(), hi.x(),
          hi.y(), hi.z());
  emit(s.extent.get(), line);
  const bool changed = s.frames == 0 || mesh.triangles != s.triangles ||
                       mesh.regionOfTriangle != s.regions || mesh.uvs != s.uvs;
  if (changed) {
    line = key;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) line += t == 0 ? "3" : ", 3";
    emit(s.counts.get(), line + "],\n");
    line = key;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& tri = mesh.triangles[t];
      appendf(line, t == 0 ? "%d, %d, %d" : ", %d, %d, %d", tri[0], tri[1], tri[2]);
    }
    emit(s.indices.get(), line + "],\n");
    line = key;
    for (std::size_t i = 0; i < mesh.uvs.size(); ++i)
      appendf(line, i == 0 ? "(%.9g, %.9g)" : ", (%.9g, %.9g)", mesh.uvs[i].x(), mesh.uvs[i].y());
    emit(s.st.get(), line + "],\n");
    line = key;
    for (std::size_t t = 0; t < mesh.regionOfTriangle.size(); ++t)
      appendf(line, t == 0 ? "%d" : ", %d", mesh.regionOfTriangle[t]);
    emit(s.region.get(), line + "],\n");
    s.triangles = mesh.triangles;
    s.regions = mesh.regionOfTriangle;
    s.uvs = mesh.uvs;
    ++s.topologies;
  }
  if (s.frames == 0) s.firstFrame = mesh.frame;
  s.lastFrame = mesh.frame;
  ++s.frames;
}

void UsdaWriter::close() {
  Impl& s = *impl_;
  if (s.closed) return;
  if (s.frames == 0) throw std::logic_error("UsdaWriter::close without frames");
  const std::string tmp = temporaryPath(s.path);
  FilePtr out(std::fopen(tmp.c_str(), "wb"));
  if (!out) throw InputError(s.path, std::string("cannot write: ") + std::strerror(errno));
  bool ok = true;
  const auto put = [&](const std::string& text) {
    ok = ok && std::fwrite(text.data(), 1, text.size(), out.get()) == text.size();
  };
  // Copies a temporary file's samples into the layer.
  const auto copy = [&](std::FILE* from) {
    ok = ok && std::fflush(from) == 0 && std::fseek(from, 0, SEEK_SET) == 0;
    char buf[1 << 16];
    while (ok) {
      const std::size_t n = std::fread(buf, 1, sizeof buf, from);
      if (n == 0) break;
      ok = std::fwrite(buf, 1, n, out.get()) == n;
    }
    ok = ok && std::ferror(from) == 0;
  };
  std::string head;
  appendf(head,
          "#usda 1.0\n(\n"
          "    defaultPrim = \"Shot\"\n"
          "    doc = %s\n"
          "    endTimeCode = %d\n"
          "    framesPerSecond = %.9g\n"
          "    metersPerUnit = 1\n"
          "    startTimeCode = %d\n"
          "    timeCodesPerSecond = %.9g\n"
          "    upAxis = \"Y\"\n"
          ")\n\n",
          usdString("crumple export of scene '" + s.sceneName + "', frames " +
                    std::to_string(s.firstFrame) + "-" + std::to_string(s.lastFrame) +
                    "; time code = frame number")
              .c_str(),
          s.lastFrame, s.fps, s.firstFrame, s.fps);
  head +=
      "def Xform \"Shot\" (\n    kind = \"component\"\n)\n{\n"
      "    def Mesh \"Paper\"\n    {\n"
      "        uniform bool doubleSided = 1\n"
      "        uniform token orientation = \"rightHanded\"\n"
      "        uniform token subdivisionScheme = \"none\"\n";
  put(head);
  put("        float3[] extent.timeSamples = {\n");
  copy(s.extent.get());
  put("        }\n        int[] faceVertexCounts.timeSamples = {\n");
  copy(s.counts.get());
  put("        }\n        int[] faceVertexIndices.timeSamples = {\n");
  copy(s.indices.get());
  put("        }\n        point3f[] points.timeSamples = {\n");
  copy(s.points.get());
  put("        }\n        int[] primvars:region (\n            interpolation = \"uniform\"\n"
      "        )\n        int[] primvars:region.timeSamples = {\n");
  copy(s.region.get());
  put("        }\n        texCoord2f[] primvars:st (\n            interpolation = \"vertex\"\n"
      "        )\n        texCoord2f[] primvars:st.timeSamples = {\n");
  copy(s.st.get());
  put("        }\n    }\n}\n");
  ok = std::fclose(out.release()) == 0 && ok;
  if (!ok) {
    std::remove(tmp.c_str());
    throw InputError(s.path, "cannot write (disk full?)");
  }
  if (std::rename(tmp.c_str(), s.path.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    std::remove(tmp.c_str());
    throw InputError(s.path, "cannot rename the temporary file: " + why);
  }
  s.closed = true;
}

}  // namespace crumple::exporters
