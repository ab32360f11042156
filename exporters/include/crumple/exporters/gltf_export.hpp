#pragma once
// glTF 2.0 exports of cached frames through assimp's exporter (format
// "glb2"): one binary .glb per frame, and one for the whole shot in
// which every frame's mesh is a node whose visibility is keyed. glTF has no
// visibility, so a frame's node has its scale keyed 1 at its frame and 0
// elsewhere, with STEP interpolation, keys in seconds at frame / fps. Meshes
// carry POSITION, TEXCOORD_0 (the pattern UVs) and indices, exactly the
// cache's vertices (no vertex is joined), and one double-sided material.
// Formats: docs/EXPORT.md.
#include <memory>
#include <string>

#include "crumple/core/types.hpp"
#include "crumple/exporters/mesh_export.hpp"

namespace crumple::exporters {

// One frame as a .glb: the scene's root node "paper" holding the mesh.
// Written atomically. Throws InputError naming the path when assimp fails or
// the file cannot be written.
void writeGlb(const std::string& path, const ExportMesh& mesh, const Vec3& diffuse);

// The whole shot as one .glb: a root node "shot" whose children
// frame_NNNN hold the frames' meshes; one animation "visibility" with one
// scale channel per frame node (2 or 3 STEP keys: 0 from the first frame, 1
// at its frame, 0 from the next frame on).
class GlbShot {
 public:
  GlbShot(double fps, const Vec3& diffuse);
  ~GlbShot();
  GlbShot(const GlbShot&) = delete;
  GlbShot& operator=(const GlbShot&) = delete;
  // Frames in increasing frame order (std::invalid_argument otherwise).
  void add(const ExportMesh& mesh);
  int frames() const;
  // Throws std::logic_error without frames, InputError as writeGlb.
  void write(const std::string& path) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crumple::exporters
