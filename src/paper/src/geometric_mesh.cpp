#include "crumple/paper/geometric_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

#include "crumple/core/geometry2d.hpp"
#include "crumple/core/index.hpp"

namespace crumple::paper {

std::vector<GeometricEdge> buildEdges(const GeometricMesh& g) {
  // Half-edges sorted by (min, max) vertex pair, then by face: one
  // allocation, the same order as a map would give.
  struct Half {
    std::pair<int, int> key;
    int face;
  };
  std::vector<Half> halves;
  halves.reserve(4 * g.faces.size());
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    const GeometricFace& face = g.faces[f];
    const int n = face.size();
    for (int k = 0; k < n; ++k) {
      const int a = face.v[k];
      const int b = face.v[(k + 1) % n];
      halves.push_back({{std::min(a, b), std::max(a, b)}, static_cast<int>(f)});
    }
  }
  std::sort(halves.begin(), halves.end(), [](const Half& x, const Half& y) {
    return x.key != y.key ? x.key < y.key : x.face < y.face;
  });
  std::vector<GeometricEdge> out;
  out.reserve(halves.size() / 2 + 1);
  for (std::size_t i = 0; i < halves.size();) {
    std::size_t j = i + 1;
    while (j < halves.size() && halves[j].key == halves[i].key) ++j;
    if (j - i > 2) {
      std::ostringstream msg;
      msg << "S_G edge (" << halves[i].key.first << ", " << halves[i].key.second
          << ") has more than two faces";
      throw std::invalid_argument(msg.str());
    }
    GeometricEdge e;
    e.v = {halves[i].key.first, halves[i].key.second};
    e.faces = {halves[i].face, j - i == 2 ? halves[i + 1].face : -1};
    out.push_back(e);
    i = j;
  }
  return out;
}

Vec3 faceNormal(const GeometricMesh& g, int face) {
  const GeometricFace& f = g.faces[idx(face)];
  const auto P = [&](int k) -> const Vec3& { return g.vertices[idx(f.v[k])].position; };
  Vec3 n;
  if (f.size() == 3) {
    n = (P(1) - P(0)).cross(P(2) - P(0));
  } else {
    n = (P(2) - P(0)).cross(P(3) - P(1));
  }
  const double len = n.norm();
  return len > 0.0 ? Vec3(n / len) : Vec3::Zero();
}

double dihedralAngle(const GeometricMesh& g, int faceA, int faceB) {
  const Vec3 a = faceNormal(g, faceA);
  const Vec3 b = faceNormal(g, faceB);
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

double patternArea(const GeometricMesh& g, int face) {
  const GeometricFace& f = g.faces[idx(face)];
  const int n = f.size();
  double area = 0.0;
  for (int k = 0; k < n; ++k) {
    area += cross2(g.vertices[idx(f.v[k])].pattern, g.vertices[idx(f.v[(k + 1) % n])].pattern);
  }
  return 0.5 * area;
}

double outlineArea(const GeometricMesh& g) {
  double area = 0.0;
  const std::size_t n = g.outline.size();
  for (std::size_t k = 0; k < n; ++k) area += cross2(g.outline[k], g.outline[(k + 1) % n]);
  return 0.5 * area;
}

double outlinePerimeter(const GeometricMesh& g) {
  double length = 0.0;
  const std::size_t n = g.outline.size();
  for (std::size_t k = 0; k < n; ++k) length += (g.outline[(k + 1) % n] - g.outline[k]).norm();
  return length;
}

double outlineParameter(const GeometricMesh& g, const Vec2& p, int segment) {
  const std::size_t n = g.outline.size();
  double s = 0.0;
  for (std::size_t k = 0; k < idx(segment); ++k) {
    s += (g.outline[(k + 1) % n] - g.outline[k]).norm();
  }
  const Vec2& a = g.outline[idx(segment)];
  const Vec2& b = g.outline[(idx(segment) + 1) % n];
  const Vec2 d = b - a;
  const double len = d.norm();
  const double t = std::clamp((p - a).dot(d) / (len * len), 0.0, 1.0);
  return s + t * len;
}

Vec2 outlinePoint(const GeometricMesh& g, double s, int* segment) {
  const std::size_t n = g.outline.size();
  const double perimeter = outlinePerimeter(g);
  s = std::fmod(s, perimeter);
  if (s < 0.0) s += perimeter;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2& a = g.outline[k];
    const Vec2& b = g.outline[(k + 1) % n];
    const double len = (b - a).norm();
    if (s <= len || k + 1 == n) {
      if (segment != nullptr) *segment = static_cast<int>(k);
      return a + (b - a) * std::clamp(s / len, 0.0, 1.0);
    }
    s -= len;
  }
  return g.outline.front();
}

int addVertex(GeometricMesh& g, const GeometricVertex& v) {
  g.vertices.push_back(v);
  return static_cast<int>(g.vertices.size()) - 1;
}

void removeRegionFaces(GeometricMesh& g, int region) {
  std::erase_if(g.faces, [region](const GeometricFace& f) { return f.region == region; });
}

// Face k of a curved region: the polygon between rulings r_k and r_{k+1}
// (paper Sec. 3.2: quads between boundary vertices, triangles at an apex).
void rebuildCurvedFaces(GeometricMesh& g, int region) {
  removeRegionFaces(g, region);
  const std::vector<Ruling>& rulings = g.regions[idx(region)].rulings;
  for (std::size_t k = 0; k + 1 < rulings.size(); ++k) {
    const Ruling& r0 = rulings[k];
    const Ruling& r1 = rulings[k + 1];
    std::array<int, 4> poly{r0.a, r1.a, r1.b, r0.b};
    GeometricFace face;
    face.region = region;
    int n = 0;
    for (std::size_t k2 = 0; k2 < 4; ++k2) {
      const int v = poly[k2];
      if (n > 0 && face.v[idx(n - 1)] == v) continue;
      if (k2 == 3 && v == face.v[0]) continue;
      face.v[idx(n++)] = v;
    }
    if (n < 3) continue;  // two identical rulings: no face
    if (n == 3) face.v[3] = -1;
    g.faces.push_back(face);
    if (patternArea(g, static_cast<int>(g.faces.size()) - 1) < 0.0) {
      GeometricFace& f = g.faces.back();
      std::reverse(f.v.begin(), f.v.begin() + n);
    }
  }
}

std::vector<int> compact(GeometricMesh& g) {
  // Regions without faces go (curved regions are kept while they have rulings).
  std::vector<int> faceCount(g.regions.size(), 0);
  for (const GeometricFace& f : g.faces) ++faceCount[idx(f.region)];
  std::vector<int> regionMap(g.regions.size(), -1);
  std::vector<Region> regions;
  for (std::size_t r = 0; r < g.regions.size(); ++r) {
    if (faceCount[r] == 0) continue;
    regionMap[r] = static_cast<int>(regions.size());
    regions.push_back(std::move(g.regions[r]));
  }
  g.regions = std::move(regions);
  for (GeometricFace& f : g.faces) f.region = regionMap[idx(f.region)];

  std::vector<char> used(g.vertices.size(), 0);
  for (const GeometricFace& f : g.faces) {
    for (int k = 0; k < f.size(); ++k) used[idx(f.v[k])] = 1;
  }
  std::vector<int> map(g.vertices.size(), -1);
  std::vector<GeometricVertex> vertices;
  for (std::size_t v = 0; v < g.vertices.size(); ++v) {
    if (!used[v] && !g.vertices[v].singular && !g.vertices[v].handle) continue;
    map[v] = static_cast<int>(vertices.size());
    vertices.push_back(g.vertices[v]);
  }
  g.vertices = std::move(vertices);
  for (GeometricFace& f : g.faces) {
    for (int k = 0; k < f.size(); ++k) f.v[k] = map[idx(f.v[k])];
  }
  for (Region& r : g.regions) {
    for (Ruling& ruling : r.rulings) {
      ruling.a = map[idx(ruling.a)];
      ruling.b = map[idx(ruling.b)];
    }
    if (r.apex >= 0) r.apex = map[idx(r.apex)];
  }
  return map;
}

std::vector<int> junctionVertices(const GeometricMesh& g) {
  std::vector<std::vector<int>> regionsOf(g.vertices.size());
  for (const GeometricFace& f : g.faces) {
    for (int k = 0; k < f.size(); ++k) regionsOf[idx(f.v[k])].push_back(f.region);
  }
  std::vector<int> out;
  for (std::size_t v = 0; v < g.vertices.size(); ++v) {
    if (!g.vertices[v].onBoundary) continue;
    auto& rs = regionsOf[v];
    std::sort(rs.begin(), rs.end());
    rs.erase(std::unique(rs.begin(), rs.end()), rs.end());
    const bool curved = std::any_of(rs.begin(), rs.end(), [&](int r) {
      return g.regions[idx(r)].type == mesh::RegionType::Curved;
    });
    if (curved && rs.size() >= 2) out.push_back(static_cast<int>(v));
  }
  return out;
}

std::string validate(const GeometricMesh& g, double planarityTolerance) {
  std::ostringstream msg;
  const int nv = static_cast<int>(g.vertices.size());
  if (g.outline.size() < 3) return "outline has fewer than 3 corners";
  const double area = outlineArea(g);
  if (!(area > 0.0)) return "outline is not counter-clockwise";
  const double perimeter = outlinePerimeter(g);
  for (int v = 0; v < nv; ++v) {
    const GeometricVertex& gv = g.vertices[idx(v)];
    if (!gv.pattern.allFinite() || !gv.position.allFinite() || !gv.velocity.allFinite()) {
      msg << "vertex " << v << " is not finite";
      return msg.str();
    }
    if (gv.onBoundary) {
      const int seg = gv.outlineSegment;
      if (seg < 0 || seg >= static_cast<int>(g.outline.size())) {
        msg << "boundary vertex " << v << " has no outline segment";
        return msg.str();
      }
      const Vec2 q = outlinePoint(g, outlineParameter(g, gv.pattern, seg));
      if ((q - gv.pattern).norm() > 1e-9 * perimeter) {
        msg << "boundary vertex " << v << " is " << (q - gv.pattern).norm() << " m off the outline";
        return msg.str();
      }
    }
  }
  double sum = 0.0;
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    const GeometricFace& face = g.faces[f];
    if (face.region < 0 || face.region >= static_cast<int>(g.regions.size())) {
      msg << "face " << f << " has no valid region";
      return msg.str();
    }
    for (int k = 0; k < face.size(); ++k) {
      if (face.v[k] < 0 || face.v[k] >= nv) {
        msg << "face " << f << " has a vertex index out of range";
        return msg.str();
      }
    }
    const double a = patternArea(g, static_cast<int>(f));
    if (!(a > 1e-14 * area)) {
      msg << "face " << f << " is degenerate or clockwise in the pattern (area " << a << ")";
      return msg.str();
    }
    if (face.size() == 4 && g.regions[idx(face.region)].type != mesh::RegionType::Curved) {
      msg << "face " << f << " is a quad outside a curved region";
      return msg.str();
    }
    sum += a;
  }
  if (std::abs(sum - area) > 1e-9 * area) {
    msg << "faces cover " << sum << " m^2 of the " << area << " m^2 sheet";
    return msg.str();
  }
  {
    std::vector<char> used(g.vertices.size(), 0);
    for (const GeometricFace& f : g.faces) {
      for (int k = 0; k < f.size(); ++k) used[idx(f.v[k])] = 1;
    }
    for (std::size_t v = 0; v < used.size(); ++v) {
      if (!used[v]) {
        msg << "vertex " << v << " belongs to no face";
        return msg.str();
      }
    }
  }
  std::vector<GeometricEdge> edges;
  try {
    edges = buildEdges(g);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  // Every edge with one face lies on the outline (the faces tile the sheet).
  for (const GeometricEdge& e : edges) {
    if (e.interior()) continue;
    const GeometricVertex& a = g.vertices[idx(e.v[0])];
    const GeometricVertex& b = g.vertices[idx(e.v[1])];
    if (!a.onBoundary || !b.onBoundary) {
      msg << "edge (" << e.v[0] << ", " << e.v[1] << ") has one face but is not on the outline";
      return msg.str();
    }
  }
  // Curved regions: each ruling is an edge of the mesh.
  std::map<std::pair<int, int>, int> edgeIndex;
  for (std::size_t k = 0; k < edges.size(); ++k)
    edgeIndex[{edges[k].v[0], edges[k].v[1]}] = static_cast<int>(k);
  for (std::size_t r = 0; r < g.regions.size(); ++r) {
    const Region& region = g.regions[r];
    if (region.type != mesh::RegionType::Curved) continue;
    for (const Ruling& ruling : region.rulings) {
      if (ruling.a < 0 || ruling.b < 0 || ruling.a >= nv || ruling.b >= nv ||
          ruling.a == ruling.b) {
        msg << "curved region " << r << " has an invalid ruling";
        return msg.str();
      }
      if (!edgeIndex.contains({std::min(ruling.a, ruling.b), std::max(ruling.a, ruling.b)})) {
        msg << "ruling (" << ruling.a << ", " << ruling.b << ") of curved region " << r
            << " is not an S_G edge";
        return msg.str();
      }
    }
  }
  if (planarityTolerance >= 0.0) {
    for (const GeometricEdge& e : edges) {
      if (!e.interior()) continue;
      const GeometricFace& f0 = g.faces[idx(e.faces[0])];
      const GeometricFace& f1 = g.faces[idx(e.faces[1])];
      if (f0.region != f1.region) continue;
      if (g.regions[idx(f0.region)].type != mesh::RegionType::Flat) continue;
      const double angle = dihedralAngle(g, e.faces[0], e.faces[1]);
      if (angle > planarityTolerance) {
        msg << "flat region " << f0.region << " is not planar: dihedral " << angle
            << " rad at edge (" << e.v[0] << ", " << e.v[1] << ")";
        return msg.str();
      }
    }
  }
  return {};
}

}  // namespace crumple::paper
