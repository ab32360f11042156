#pragma once
// Mesh exports of cached frames (`crumple export`): OBJ sequences
// with their .mtl and the pattern-space tear texture, binary PLY sequences,
// and one USDA file with a time-varying Mesh. Every writer takes one frame
// as an ExportMesh (positions, triangles, regions, the pattern as UVs), so
// topology may change from frame to frame. Files are written atomically
// (PATH.<pid>.tmp, then rename) and identical input gives identical bytes (numbers
// printed with %.9g, no dates, no hosts). Formats: docs/EXPORT.md.
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/image.hpp"
#include "crumple/core/types.hpp"

namespace crumple::exporters {

// Pattern coordinates to texture coordinates: u = (x - origin.x) / size.x,
// v = (y - origin.y) / size.y, the pattern's bounding box mapped onto
// [0, 1]^2 (v up, as OBJ, PLY and USD read it; glTF's exporter flips it).
struct UvMapping {
  Vec2 origin = Vec2::Zero();  // m
  Vec2 size = Vec2::Ones();    // m, both > 0
  Vec2 operator()(const Vec2& pattern) const;
  Vec2 pattern(const Vec2& uv) const;  // the inverse
};
// The bounding box of `pattern`. Throws CorruptDataError naming `what` for an
// empty pattern, a coordinate that is not finite or a box without area.
UvMapping uvMappingOf(const std::vector<Vec2>& pattern, const std::string& what);

// One frame's mesh, as the writers take it.
struct ExportMesh {
  int frame = 0;
  double time = 0.0;            // s: frame / fps (docs/SCENE.md "Time")
  std::vector<Vec3> positions;  // m
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> regionOfTriangle;  // per triangle
  std::vector<Vec2> uvs;              // per vertex: the pattern through a UvMapping
};
// A cached frame as an ExportMesh. Throws CorruptDataError naming the frame
// when its arrays disagree (a triangle index out of range, fewer pattern
// points or regions than needed, a position that is not finite).
ExportMesh exportMesh(const cache::FrameRecord& frame, double fps, const UvMapping& uv);

// A frame's file name stem: 4 digits or more, like the rendered frames ("0042").
std::string frameStem(int frame);

// Writes `bytes` to PATH.<pid>.tmp, then renames it to PATH (so a reader
// never sees a partial file, and two processes writing the same file at once
// cannot mix their bytes). Throws InputError naming the path when it cannot.
void writeFileAtomically(const std::string& path, const std::string& bytes);

// The material an OBJ frame uses (newmtl `name`): a diffuse colour (Kd,
// linear RGB) and, for a torn frame, the tear texture as its alpha (map_d, a
// file name beside the .mtl).
struct ObjMaterial {
  std::string name = "paper";
  Vec3 diffuse{0.92, 0.92, 0.90};
  std::string alphaTexture;  // empty: no texture
};
// The .mtl text of one material.
std::string mtlText(const ObjMaterial& material);
// One frame as Wavefront OBJ text: `mtllib mtlFile`, one `v` and one `vt`
// per vertex (the same index), `usemtl`, one `f v/vt v/vt v/vt` per triangle.
std::string objText(const ExportMesh& mesh, const std::string& mtlFile,
                    const std::string& materialName);
// One frame as binary little-endian PLY: vertex x y z u v s t (float; s t
// repeat u v under the names Blender's importer reads), face vertex_indices
// (uchar count, int indices) and region (int). Header lines end with CR LF.
std::string plyBytes(const ExportMesh& mesh);

// The frame's baked tear masks (its TEAR block, docs/PCACHE.md) drawn in
// pattern space, the texture an OBJ's map_d cuts the paper with: one RGBA
// texel grid over the UV square (row 0 at v = 1, as images go), at the
// atlas's texel size (larger when a side would exceed maxSide texels). A
// texel whose centre lies in a patch's triangle holds that patch's mask
// there (bilinear, as the renderers look it up); every other texel is 255.
// R = G = B = A, so a tool may read either the alpha or the value. nullopt
// for a frame without a TEAR block. Throws CorruptDataError naming the frame
// for a malformed block or a patch whose triangle the frame lacks.
std::optional<ImageRGBA8> tearTexture(const cache::FrameRecord& frame, const UvMapping& uv,
                                      int maxSide = 4096);

// The whole shot as one USDA layer: /Shot (Xform) holding /Shot/Paper, a
// Mesh whose points and extent have a time sample per frame (time code =
// frame number) and whose faceVertexCounts, faceVertexIndices, primvars:st
// (texCoord2f, vertex interpolation) and primvars:region (int, uniform) have
// one where the topology changed (always at the first frame). The layer's
// startTimeCode / endTimeCode are the first and last frames added,
// timeCodesPerSecond = framesPerSecond = fps, upAxis "Y", metersPerUnit 1.
// Frames go to temporary files as they come; close() assembles
// PATH.<pid>.tmp and renames it. Without close() nothing is written.
class UsdaWriter {
 public:
  // Throws InputError when the temporary files cannot be made.
  UsdaWriter(std::string path, std::string sceneName, double fps);
  ~UsdaWriter();
  UsdaWriter(const UsdaWriter&) = delete;
  UsdaWriter& operator=(const UsdaWriter&) = delete;
  // Frames in increasing frame order (std::invalid_argument otherwise).
  void add(const ExportMesh& mesh);
  // Throws std::logic_error without frames, InputError when writing fails.
  void close();
  int framesAdded() const;
  int topologySamples() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crumple::exporters
