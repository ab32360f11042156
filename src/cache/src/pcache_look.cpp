// The look sub-blocks PTEX, PROP, PRPM. Byte layout: docs/PCACHE.md.
#include "crumple/cache/pcache_look.hpp"

#include <string>
#include <utility>

#include "sub_block.hpp"

namespace crumple::cache {

using detail::decodeBlock;
using detail::findOneBlock;
using detail::readRecords;
using detail::SubBlockReader;
using detail::writeRecords;

ExtensionBlock encodePaperTexture(std::vector<std::uint8_t> png) {
  return {kPaperTextureTag, std::move(png)};
}

const std::vector<std::uint8_t>* findPaperTexture(const std::vector<ExtensionBlock>& headerBlocks) {
  const ExtensionBlock* block = findOneBlock(headerBlocks, kPaperTextureTag);
  return block ? &block->data : nullptr;
}

ExtensionBlock encodePropMeshes(const std::vector<PropMeshRecord>& meshes) {
  Bytes bytes;
  ByteWriter w(bytes);
  const auto valid = [](const PropMeshRecord&) { return std::string(); };
  writeRecords(w, meshes, "encodePropMeshes", "prop", valid, [&](const PropMeshRecord& m) {
    w.count32(m.vertices.size(), "prop vertices");
    for (const Vec3& v : m.vertices)
      for (int k = 0; k < 3; ++k) w.f64(v[k]);
    w.count32(m.triangles.size(), "prop triangles");
    for (const auto& t : m.triangles)
      for (const int i : t) w.i32(i);
  });
  return {kPropMeshesTag, std::move(bytes)};
}

std::optional<std::vector<PropMeshRecord>> decodePropMeshes(
    const std::vector<ExtensionBlock>& headerBlocks) {
  return decodeBlock(headerBlocks, kPropMeshesTag, [](SubBlockReader& r) {
    return readRecords<PropMeshRecord>(r, 8, "prop", [&](PropMeshRecord& m) {
      m.vertices.resize(r.count32(24, "vertex count"));
      for (Vec3& v : m.vertices) {
        for (int k = 0; k < 3; ++k) v[k] = r.f64("vertex");
        if (!v.allFinite()) r.fail("a vertex is not finite");
      }
      m.triangles.resize(r.count32(12, "triangle count"));
      for (auto& t : m.triangles)
        for (int& k : t) {
          k = r.i32("triangle");
          if (k < 0 || static_cast<std::size_t>(k) >= m.vertices.size())
            r.fail("vertex index " + std::to_string(k) + " out of range");
        }
    });
  });
}

ExtensionBlock encodePropMotions(const std::vector<Mat4>& motions) {
  Bytes bytes;
  ByteWriter w(bytes);
  const auto valid = [](const Mat4&) { return std::string(); };
  writeRecords(w, motions, "encodePropMotions", "prop", valid, [&](const Mat4& motion) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) w.f64(motion(r, c));
  });
  return {kPropMotionsTag, std::move(bytes)};
}

std::optional<std::vector<Mat4>> decodePropMotions(const std::vector<ExtensionBlock>& frameBlocks) {
  return decodeBlock(frameBlocks, kPropMotionsTag, [](SubBlockReader& r) {
    return readRecords<Mat4>(r, 128, "prop", [&](Mat4& motion) {
      for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row) motion(row, c) = r.f64("motion");
      if (!motion.allFinite()) r.fail("the motion is not finite");
    });
  });
}

}  // namespace crumple::cache
