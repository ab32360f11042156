#include "quad_pairs.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace crumple::render::pt {

namespace {

// Below this 1 - cos(dihedral) two triangles count as coplanar (float noise
// of their unit normals), so the shared edge's length decides among them.
constexpr float kCoplanar = 1e-6f;

// Two triangles across a shared edge: how far from coplanar (1 - cos of the
// angle between their normals, 0 when coplanar), the squared length of the
// edge, and the triangles with the edge's local index in each.
struct Candidate {
  float bend = 0.0f;
  float edge2 = 0.0f;
  std::uint32_t a = 0, b = 0;
  int ka = 0, kb = 0;
};

// The key of the directed edge from -> to.
std::uint64_t edgeKey(std::uint32_t from, std::uint32_t to) {
  return (static_cast<std::uint64_t>(from) << 32) | to;
}

// Rotates the three-element corners of c by r: new corner j = old (j + r) % 3.
template <class T>
void rotateCorners(std::array<T, 3>& c, int r) {
  std::rotate(c.begin(), c.begin() + r, c.end());
}

// The same for pairs of floats per corner (texture and mask coordinates).
void rotatePairs(std::array<float, 6>& c, int r) {
  std::rotate(c.begin(), c.begin() + 2 * r, c.end());
}

// Rotates triangle t's corners by r everywhere a corner is indexed.
void rotateTriangle(MeshData& m, SheetLook* look, std::uint32_t t, int r) {
  if (r == 0) return;
  rotateCorners(m.triangles[t], r);
  if (look == nullptr) return;
  SheetTri& st = look->tris[t];
  rotateCorners(st.normals, r);
  rotatePairs(st.uv, r);
  rotatePairs(st.maskUv, r);
  const unsigned bits = st.singularCorners;
  unsigned rotated = 0;
  for (int j = 0; j < 3; ++j) rotated |= ((bits >> ((j + r) % 3)) & 1u) << j;
  st.singularCorners = static_cast<std::uint8_t>(rotated);
  for (auto& step : look->stepNormals) rotateCorners(step[t], r);
}

// The candidate pairs of m's triangles: consistently oriented neighbours
// across an edge that no third triangle uses.
std::vector<Candidate> candidatePairs(const MeshData& m) {
  constexpr std::uint64_t kShared = ~std::uint64_t{0};
  std::unordered_map<std::uint64_t, std::uint64_t> directed;  // edge -> triangle * 3 + local edge
  directed.reserve(3 * m.triangles.size());
  for (std::uint32_t t = 0; t < m.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const auto& tri = m.triangles[t];
      const auto [it, fresh] =
          directed.try_emplace(edgeKey(tri[k], tri[(k + 1) % 3]), std::uint64_t{t} * 3 + k);
      if (!fresh) it->second = kShared;  // two triangles the same way round: not a manifold pair
    }
  std::vector<Candidate> out;
  for (std::uint32_t t = 0; t < m.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const auto& tri = m.triangles[t];
      const std::uint32_t from = tri[k], to = tri[(k + 1) % 3];
      const auto mine = directed.find(edgeKey(from, to));
      const auto other = directed.find(edgeKey(to, from));
      if (mine->second == kShared || other == directed.end() || other->second == kShared) continue;
      const auto u = static_cast<std::uint32_t>(other->second / 3);
      if (u <= t) continue;  // each pair once, from its lower triangle
      Candidate c;
      const float cosine = dot(m.faceNormals[t], m.faceNormals[u]);
      c.bend = 1.0f - cosine < kCoplanar ? 0.0f : 1.0f - cosine;
      const V3 e = m.vertices[to] - m.vertices[from];
      c.edge2 = dot(e, e);
      c.a = t;
      c.b = u;
      c.ka = k;
      c.kb = static_cast<int>(other->second % 3);
      out.push_back(c);
    }
  return out;
}

}  // namespace

void pairIntoQuads(MeshData& m, SheetLook* look) {
  constexpr std::uint32_t kNone = MeshData::kNoTriangle;
  std::vector<Candidate> candidates = candidatePairs(m);
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    if (x.bend != y.bend) return x.bend < y.bend;
    if (x.edge2 != y.edge2) return x.edge2 > y.edge2;
    return x.a != y.a ? x.a < y.a : x.b < y.b;
  });
  // Greedy matching in that order; partner[t] with the shared edge's local index.
  std::vector<std::uint32_t> partner(m.triangles.size(), kNone);
  std::vector<int> sharedEdge(m.triangles.size(), 0);
  for (const Candidate& c : candidates) {
    if (partner[c.a] != kNone || partner[c.b] != kNone) continue;
    partner[c.a] = c.b;
    partner[c.b] = c.a;
    sharedEdge[c.a] = c.ka;
    sharedEdge[c.b] = c.kb;
  }
  m.quads.clear();
  m.quadTriangles.clear();
  m.quads.reserve(m.triangles.size());
  m.quadTriangles.reserve(m.triangles.size());
  for (std::uint32_t t = 0; t < m.triangles.size(); ++t) {
    const std::uint32_t p = partner[t];
    if (p != kNone && p < t) continue;  // emitted with its partner
    if (p == kNone) {
      const auto& a = m.triangles[t];
      m.quads.push_back({a[0], a[1], a[2], a[2]});
      m.quadTriangles.push_back({t, kNone});
      continue;
    }
    // The shared edge to corners 1-2 of both: a = (a0, a1, a2), b = (b0, a2, a1).
    rotateTriangle(m, look, t, (sharedEdge[t] + 2) % 3);
    rotateTriangle(m, look, p, (sharedEdge[p] + 2) % 3);
    const auto& a = m.triangles[t];
    const auto& b = m.triangles[p];
    m.quads.push_back({a[0], a[1], b[0], a[2]});
    m.quadTriangles.push_back({t, p});
  }
}

}  // namespace crumple::render::pt
