#include "render_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "crumple/mesh/tear_patches.hpp"

namespace crumple::render::detail {

namespace {

// Unit normal of the triangle (a, b, c), counter-clockwise front; zero when
// degenerate.
Vec3 unitNormal(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double len = n.norm();
  return len > 0.0 ? Vec3(n / len) : Vec3::Zero();
}

// The sheet's vertices, texture coordinates, normals and the triangles drawn
// as they are; `replaced` marks those a tear patch is drawn instead of.
void addSheet(const RenderScene& scene, const mesh::SheetMesh& sheet,
              const std::vector<char>& replaced, RenderGeometry& g) {
  g.positions.reserve(sheet.positions.size());
  for (const Vec3& p : sheet.positions) g.positions.push_back(toFloat3(p - g.origin));
  g.uvs.reserve(sheet.pattern.size());
  for (const Vec2& q : sheet.pattern) {
    // The texture's top row sits at pattern y = textureSize.y: seen from the
    // front with the pattern's +y up, the image is upright and not mirrored.
    const Vec2 uv = patternToUv(q, scene.paper.textureSize);
    g.uvs.push_back({static_cast<float>(uv.x()), static_cast<float>(uv.y())});
  }
  g.faceNormals = faceNormals(sheet.positions, sheet.triangles);
  g.cornerNormals = shadingNormals(sheet.positions, sheet.triangles, g.faceNormals,
                                   scene.paper.creaseAngle, scene.sharpVertices);
  g.drawnTriangles.reserve(sheet.triangles.size());
  for (std::size_t t = 0; t < sheet.triangles.size(); ++t)
    if (!replaced[t]) g.drawnTriangles.push_back(t);
}

// The tear patches (thesis 3.3.4, Fig. 3.25): the triangle and its support
// quads, each corner its own vertex, cut by the patch's mask.
void addTearPatches(const RenderScene& scene, const mesh::SheetMesh& sheet, RenderGeometry& g) {
  for (const mesh::TearPatch& patch : scene.tears.patches) {
    const auto t = static_cast<std::size_t>(patch.triangle);
    for (const mesh::TearPatchTriangle& piece : mesh::tearPatchTriangles(patch, sheet)) {
      PatchPiece& out = g.patchPieces.emplace_back();
      out.triangle = t;
      for (std::size_t k = 0; k < 3; ++k) {
        const mesh::TearPatchVertex& pv = piece[k];
        PatchCorner& c = out.corners[k];
        c.position = toFloat3(pv.position - g.origin);
        c.normal = toFloat3(g.cornerNormals[t][static_cast<std::size_t>(pv.corner)]);
        const Vec2 uv = patternToUv(pv.pattern, scene.paper.textureSize);
        c.uv = {static_cast<float>(uv.x()), static_cast<float>(uv.y())};
        c.atlas = mesh::atlasPosition(scene.tears, patch, pv.pattern);
      }
      out.faceNormal = unitNormal(piece[0].position, piece[1].position, piece[2].position);
    }
  }
}

// The props relative to the origin, with their flat face normals; at
// motion-blur time step `step` (when not kNoStep) those of them that move
// are at their positions of that step.
void addProps(const RenderScene& scene, RenderGeometry& g, std::size_t step) {
  g.props.reserve(scene.props.size());
  for (const PropMesh& prop : scene.props) {
    PropGeometry& p = g.props.emplace_back();
    p.mesh = &prop;
    const std::vector<Vec3>& at =
        step != kNoStep && !prop.motion.empty() ? prop.motion[step] : prop.vertices;
    p.vertices.reserve(at.size());
    for (const Vec3& v : at) p.vertices.push_back(toFloat3(v - g.origin));
    p.faceNormals.reserve(prop.triangles.size());
    for (const auto& t : prop.triangles)
      p.faceNormals.push_back(toFloat3(unitNormal(at[static_cast<std::size_t>(t[0])] - g.origin,
                                                  at[static_cast<std::size_t>(t[1])] - g.origin,
                                                  at[static_cast<std::size_t>(t[2])] - g.origin)));
  }
}

// buildRenderGeometry about a given origin, at motion-blur time step `step`
// (kNoStep: the scene's own positions).
RenderGeometry buildAbout(const RenderScene& scene, const mesh::SheetMesh& sheet,
                          bool withTearPatches, const Vec3& origin, double sheetSize,
                          std::size_t step) {
  RenderGeometry g;
  g.origin = origin;
  g.sheetSize = sheetSize;
  g.camera = scene.camera;
  g.camera.position -= g.origin;
  g.lights = scene.lights;
  if (g.lights.empty()) g.lights.push_back(Light{});
  for (Light& l : g.lights) l.position -= g.origin;

  const bool torn = withTearPatches && !scene.tears.empty();
  std::vector<char> replaced(sheet.triangles.size(), 0);
  if (torn)
    for (const mesh::TearPatch& p : scene.tears.patches)
      replaced[static_cast<std::size_t>(p.triangle)] = 1;
  addSheet(scene, sheet, replaced, g);
  if (torn) addTearPatches(scene, sheet, g);
  addProps(scene, g, step);

  if (scene.ground.enabled) {
    const double h = 0.5 * scene.ground.size;
    const double y = scene.ground.height - g.origin.y();
    g.ground = std::array<Vec3, 4>{Vec3(-h, y, h), Vec3(h, y, h), Vec3(h, y, -h), Vec3(-h, y, -h)};
  }
  return g;
}

}  // namespace

RenderGeometry buildRenderGeometry(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                   bool withTearPatches) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (const Vec3& p : sheet.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const bool any = !sheet.positions.empty();
  return buildAbout(scene, sheet, withTearPatches, any ? Vec3(0.5 * (lo + hi)) : Vec3(Vec3::Zero()),
                    any ? (hi - lo).norm() : 0.0, kNoStep);
}

RenderGeometry buildStepGeometry(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                 bool withTearPatches, const RenderGeometry& base,
                                 std::size_t step) {
  if (scene.sheetMotion.empty())
    return buildAbout(scene, sheet, withTearPatches, base.origin, base.sheetSize, step);
  mesh::SheetMesh moved = sheet;
  moved.positions = scene.sheetMotion[step];
  return buildAbout(scene, moved, withTearPatches, base.origin, base.sheetSize, step);
}

std::vector<Vec3> faceNormals(const std::vector<Vec3>& positions,
                              const std::vector<std::array<int, 3>>& triangles) {
  std::vector<Vec3> face(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    face[t] = unitNormal(positions[static_cast<std::size_t>(tri[0])],
                         positions[static_cast<std::size_t>(tri[1])],
                         positions[static_cast<std::size_t>(tri[2])]);
  }
  return face;
}

std::vector<std::array<Vec3, 3>> shadingNormals(const std::vector<Vec3>& positions,
                                                const std::vector<std::array<int, 3>>& triangles,
                                                const std::vector<Vec3>& face, double creaseAngle,
                                                const std::vector<int>& sharpVertices) {
  const std::size_t nt = triangles.size();
  const std::size_t nv = positions.size();
  // Corners of each vertex, and the triangles on each side of every edge.
  std::vector<std::vector<std::pair<std::size_t, int>>> corners(nv);
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k)
      corners[static_cast<std::size_t>(triangles[t][k])].push_back({t, k});
  std::vector<bool> sharp(nv, false);
  for (const int v : sharpVertices)
    if (v >= 0 && static_cast<std::size_t>(v) < nv) sharp[static_cast<std::size_t>(v)] = true;
  const double cosCrease = std::cos(creaseAngle);

  std::vector<std::array<Vec3, 3>> out(nt);
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) out[t][static_cast<std::size_t>(k)] = face[t];

  std::vector<int> group;  // per corner of the current vertex: its smoothing group
  for (std::size_t v = 0; v < nv; ++v) {
    const auto& cs = corners[v];
    if (cs.size() < 2 || sharp[v]) continue;
    // Two corners of v are joined when their triangles share an edge at v
    // whose dihedral angle is below the crease angle (union-find).
    group.assign(cs.size(), 0);
    for (std::size_t i = 0; i < cs.size(); ++i) group[i] = static_cast<int>(i);
    auto find = [&](int i) {
      while (group[static_cast<std::size_t>(i)] != i) i = group[static_cast<std::size_t>(i)];
      return i;
    };
    for (std::size_t i = 0; i < cs.size(); ++i)
      for (std::size_t j = i + 1; j < cs.size(); ++j) {
        const auto& ti = triangles[cs[i].first];
        const auto& tj = triangles[cs[j].first];
        int shared = 0;
        for (const int a : ti)
          for (const int b : tj)
            if (a == b) ++shared;
        if (shared != 2) continue;
        if (face[cs[i].first].dot(face[cs[j].first]) <= cosCrease) continue;
        const int gi = find(static_cast<int>(i)), gj = find(static_cast<int>(j));
        if (gi != gj) group[static_cast<std::size_t>(std::max(gi, gj))] = std::min(gi, gj);
      }
    // Angle-weighted sums per group.
    std::vector<Vec3> sum(cs.size(), Vec3::Zero());
    for (std::size_t i = 0; i < cs.size(); ++i) {
      const auto& tri = triangles[cs[i].first];
      const int k = cs[i].second;
      const Vec3& p = positions[v];
      const Vec3 e1 = positions[static_cast<std::size_t>(tri[(k + 1) % 3])] - p;
      const Vec3 e2 = positions[static_cast<std::size_t>(tri[(k + 2) % 3])] - p;
      const double angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
      sum[static_cast<std::size_t>(find(static_cast<int>(i)))] += angle * face[cs[i].first];
    }
    for (std::size_t i = 0; i < cs.size(); ++i) {
      const Vec3& s = sum[static_cast<std::size_t>(find(static_cast<int>(i)))];
      const double len = s.norm();
      if (len > 1e-12) out[cs[i].first][static_cast<std::size_t>(cs[i].second)] = s / len;
    }
  }
  return out;
}

bool hasCutOuts(const ImageRGBA8& texture) {
  for (std::size_t i = 3; i < texture.pixels.size(); i += 4)
    if (texture.pixels[i] < 128) return true;
  return false;
}

}  // namespace crumple::render::detail
