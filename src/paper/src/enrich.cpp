// S_P from S_G (paper Sec. 4 "Enriching the coarse mesh before simulation",
// Fig. 4; thesis 2.3.2).
#include "crumple/paper/enrich.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "crumple/core/geometry2d.hpp"
#include "crumple/core/index.hpp"
#include "crumple/mesh/delaunay.hpp"

namespace crumple::paper {
namespace {

using Weights = std::array<double, 4>;

const Vec2& patternOf(const GeometricMesh& g, int v) { return g.vertices[idx(v)].pattern; }

const GeometricFace& faceOf(const GeometricMesh& g, int f) { return g.faces[idx(f)]; }

// Where a pattern point lies in an S_G face: the smallest barycentric
// coordinate (>= 0 inside) and the weights per face slot, over the fan
// triangles (v0, vk, vk+1) of the face.
struct Location {
  double score = -std::numeric_limits<double>::infinity();
  int face = -1;
  Weights weights{};
};

Location locateInFace(const GeometricMesh& g, int f, const Vec2& p) {
  const GeometricFace& face = faceOf(g, f);
  Location best;
  const Vec2& a = patternOf(g, face.v[0]);
  for (int k = 1; k + 1 < face.size(); ++k) {
    const Vec2& b = patternOf(g, face.v[idx(k)]);
    const Vec2& c = patternOf(g, face.v[idx(k + 1)]);
    const double area = cross2(b - a, c - a);
    if (!(area > 0.0)) continue;
    const double lb = cross2(p - a, c - a) / area;
    const double lc = cross2(b - a, p - a) / area;
    const double la = 1.0 - lb - lc;
    const double score = std::min({la, lb, lc});
    if (score > best.score) {
      best.score = score;
      best.face = f;
      best.weights = Weights{};
      best.weights[0] = la;
      best.weights[idx(k)] = lb;
      best.weights[idx(k + 1)] = lc;
    }
  }
  return best;
}

// The face of `faces` that holds p best (lowest face index on ties).
Location locate(const GeometricMesh& g, const std::vector<int>& faces, const Vec2& p) {
  Location best;
  for (const int f : faces) {
    const Location l = locateInFace(g, f, p);
    if (l.score > best.score) best = l;
  }
  return best;
}

// A directed border edge of a flat region: face slots ka -> kb of `face`.
struct BorderEdge {
  int a = -1;
  int b = -1;
  int face = -1;
  int slotA = -1;
  int slotB = -1;
};

// A CDT point of a flat region: an S_G vertex, or a new sample.
struct RegionPoint {
  Vec2 pattern = Vec2::Zero();
  int geometric = -1;  // S_G vertex index, or -1 for a sample
  PhysicalMesh::Sample sample;
};

class Builder {
 public:
  Builder(const GeometricMesh& g, const CrumpleParams& params)
      : g_(g), params_(params), edges_(buildEdges(g)) {
    usedByFace_.assign(g.vertexCount(), false);
    for (const GeometricFace& f : g.faces)
      for (int k = 0; k < f.size(); ++k) usedByFace_[idx(f.v[k])] = true;
  }

  PhysicalMesh build() {
    mesh::SheetMesh& m = out_.mesh;
    m.pattern.reserve(g_.vertexCount());
    for (const GeometricVertex& v : g_.vertices) m.pattern.push_back(v.pattern);
    for (const Region& r : g_.regions) m.regionTypes.push_back(r.type);

    std::vector<std::vector<int>> facesOfRegion(g_.regions.size());
    for (std::size_t f = 0; f < g_.faces.size(); ++f) {
      const int r = g_.faces[f].region;
      if (r < 0 || r >= static_cast<int>(g_.regions.size()))
        throw std::invalid_argument("buildPhysicalMesh: S_G face " + std::to_string(f) +
                                    " has unknown region " + std::to_string(r));
      facesOfRegion[idx(r)].push_back(static_cast<int>(f));
    }
    for (std::size_t r = 0; r < g_.regions.size(); ++r) {
      const auto& faces = facesOfRegion[r];
      if (faces.empty()) continue;
      if (g_.regions[r].type == mesh::RegionType::Flat)
        flatRegion(static_cast<int>(r), faces);
      else
        curvedRegion(static_cast<int>(r), faces);
    }
    updateSamples(out_, g_);
    return std::move(out_);
  }

 private:
  bool outlineEdge(int a, int b) const {
    const std::array<int, 2> key{std::min(a, b), std::max(a, b)};
    const auto it = std::lower_bound(
        edges_.begin(), edges_.end(), key,
        [](const GeometricEdge& e, const std::array<int, 2>& k) { return e.v < k; });
    return it != edges_.end() && it->v == key && !it->interior();
  }

  int addSample(const Vec2& pattern, const PhysicalMesh::Sample& s) {
    out_.mesh.pattern.push_back(pattern);
    out_.samples.push_back(s);
    return static_cast<int>(out_.mesh.pattern.size()) - 1;
  }

  void addTriangle(const std::array<int, 3>& t, int region, int face) {
    out_.mesh.triangles.push_back(t);
    out_.mesh.regionOfTriangle.push_back(region);
    out_.faceOfTriangle.push_back(face);
  }

  // Paper Sec. 4 / thesis 2.3.2: isotropic sampling of a flat region, joined by Delaunay.
  void flatRegion(int region, const std::vector<int>& faces) {
    // Border: face edges not shared with another face of the region.
    std::map<std::pair<int, int>, int> uses;
    for (const int f : faces) {
      const GeometricFace& face = faceOf(g_, f);
      for (int k = 0; k < face.size(); ++k) {
        const int a = face.v[idx(k)];
        const int b = face.v[idx((k + 1) % face.size())];
        ++uses[{std::min(a, b), std::max(a, b)}];
      }
    }
    std::vector<BorderEdge> border;
    std::vector<int> vertices;
    for (const int f : faces) {
      const GeometricFace& face = faceOf(g_, f);
      for (int k = 0; k < face.size(); ++k) {
        const int kb = (k + 1) % face.size();
        const int a = face.v[idx(k)];
        const int b = face.v[idx(kb)];
        vertices.push_back(a);
        if (uses[{std::min(a, b), std::max(a, b)}] == 1) border.push_back({a, b, f, k, kb});
      }
    }
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());

    Eigen::AlignedBox2d box;
    for (const int v : vertices) box.extend(patternOf(g_, v));
    const double scale = box.diagonal().norm();
    const auto borderDistance = [&](const Vec2& p) {
      double d = std::numeric_limits<double>::infinity();
      for (const BorderEdge& e : border)
        d = std::min(d, distanceToSegment(p, patternOf(g_, e.a), patternOf(g_, e.b)));
      return d;
    };

    // Unused S_G vertices strictly inside the region (e.g. a handle) join it.
    for (std::size_t v = 0; v < g_.vertexCount(); ++v) {
      if (usedByFace_[v] || !box.contains(g_.vertices[v].pattern)) continue;
      const Vec2& p = g_.vertices[v].pattern;
      if (locate(g_, faces, p).score >= 0.0 && borderDistance(p) > 1e-9 * scale)
        vertices.push_back(static_cast<int>(v));
    }

    std::vector<RegionPoint> points;
    std::map<int, int> localOf;
    for (const int v : vertices) {
      localOf[v] = static_cast<int>(points.size());
      points.push_back({patternOf(g_, v), v, {}});
    }

    // Boundary samples: split each outline edge into ceil(length * rho_bound) pieces.
    std::vector<std::array<int, 2>> constraints;
    for (const BorderEdge& e : border) {
      const Vec2& pa = patternOf(g_, e.a);
      const Vec2& pb = patternOf(g_, e.b);
      int pieces = 1;
      if (params_.rhoBound > 0.0 && outlineEdge(e.a, e.b))
        pieces =
            std::max(1, static_cast<int>(std::ceil((pb - pa).norm() * params_.rhoBound - 1e-9)));
      int previous = localOf.at(e.a);
      for (int k = 1; k < pieces; ++k) {
        const double t = static_cast<double>(k) / pieces;
        RegionPoint s;
        s.pattern = (1.0 - t) * pa + t * pb;
        s.sample.face = e.face;
        s.sample.weights[idx(e.slotA)] = 1.0 - t;
        s.sample.weights[idx(e.slotB)] = t;
        const int local = static_cast<int>(points.size());
        points.push_back(s);
        constraints.push_back({previous, local});
        previous = local;
      }
      constraints.push_back({previous, localOf.at(e.b)});
    }

    // Interior samples: hexagonal lattice of spacing h anchored at the pattern origin.
    if (params_.rhoInt > 0.0 && std::isfinite(params_.rhoInt)) {
      const double h = 1.0 / std::sqrt(params_.rhoInt);
      const double dy = h * std::sqrt(3.0) / 2.0;
      const double keep = 0.5 * h * (1.0 - 1e-9);
      const long j0 = static_cast<long>(std::ceil(box.min().y() / dy));
      const long j1 = static_cast<long>(std::floor(box.max().y() / dy));
      for (long j = j0; j <= j1; ++j) {
        const double x0 = (j % 2 != 0) ? 0.5 * h : 0.0;
        const long i0 = static_cast<long>(std::ceil((box.min().x() - x0) / h));
        const long i1 = static_cast<long>(std::floor((box.max().x() - x0) / h));
        for (long i = i0; i <= i1; ++i) {
          const Vec2 p(x0 + static_cast<double>(i) * h, static_cast<double>(j) * dy);
          const Location where = locate(g_, faces, p);
          if (where.score < 0.0 || borderDistance(p) < keep) continue;
          const bool nearVertex = std::any_of(vertices.begin(), vertices.end(), [&](int v) {
            return (patternOf(g_, v) - p).norm() < keep;
          });
          if (nearVertex) continue;
          points.push_back({p, -1, {where.face, where.weights}});
        }
      }
    }

    std::vector<Vec2> coords;
    coords.reserve(points.size());
    for (const RegionPoint& p : points) coords.push_back(p.pattern);
    std::vector<std::array<int, 3>> triangles;
    try {
      triangles = mesh::constrainedDelaunay(coords, constraints);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("buildPhysicalMesh: flat region " + std::to_string(region) +
                                  ": " + e.what());
    }

    // Samples become S_P vertices in local order (only those a triangle uses).
    std::vector<char> used(points.size(), 0);
    for (const auto& t : triangles)
      for (const int v : t) used[idx(v)] = 1;
    std::vector<int> global(points.size(), -1);
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (points[i].geometric >= 0)
        global[i] = points[i].geometric;
      else if (used[i])
        global[i] = addSample(points[i].pattern, points[i].sample);
    }
    for (const auto& t : triangles) {
      const std::array<int, 3> tri{global[idx(t[0])], global[idx(t[1])], global[idx(t[2])]};
      const Vec2 centroid = (coords[idx(t[0])] + coords[idx(t[1])] + coords[idx(t[2])]) / 3.0;
      addTriangle(tri, region, locate(g_, faces, centroid).face);
    }
  }

  // Paper Sec. 4 / thesis 2.3.2: curved triangles copied, quads split at their barycenter.
  void curvedRegion(int region, const std::vector<int>& faces) {
    for (const int f : faces) {
      const GeometricFace& face = faceOf(g_, f);
      const auto& v = face.v;
      if (face.size() == 3) {
        addTriangle({v[0], v[1], v[2]}, region, f);
        continue;
      }
      const auto ccw = [&](const Vec2& a, const Vec2& b, const Vec2& c) {
        return cross2(b - a, c - a) > 1e-18;
      };
      const auto P = [&](std::size_t k) -> const Vec2& { return patternOf(g_, v[k]); };
      const Vec2 center = 0.25 * (P(0) + P(1) + P(2) + P(3));
      if (ccw(P(0), P(1), center) && ccw(P(1), P(2), center) && ccw(P(2), P(3), center) &&
          ccw(P(3), P(0), center)) {
        const int c = addSample(center, {f, {0.25, 0.25, 0.25, 0.25}});
        for (std::size_t k = 0; k < 4; ++k) addTriangle({v[k], v[(k + 1) % 4], c}, region, f);
      } else if (ccw(P(0), P(1), P(2)) && ccw(P(0), P(2), P(3))) {
        // A non-convex quad (its barycenter outside a corner triangle): split on a diagonal.
        addTriangle({v[0], v[1], v[2]}, region, f);
        addTriangle({v[0], v[2], v[3]}, region, f);
      } else if (ccw(P(1), P(2), P(3)) && ccw(P(1), P(3), P(0))) {
        addTriangle({v[1], v[2], v[3]}, region, f);
        addTriangle({v[1], v[3], v[0]}, region, f);
      } else {
        throw std::invalid_argument("buildPhysicalMesh: curved quad face " + std::to_string(f) +
                                    " is degenerate in the pattern");
      }
    }
  }

  const GeometricMesh& g_;
  const CrumpleParams& params_;
  std::vector<GeometricEdge> edges_;
  std::vector<bool> usedByFace_;
  PhysicalMesh out_;
};

}  // namespace

// Paper Sec. 4 "Enriching the coarse mesh before simulation" (Fig. 4); thesis 2.3.2.
PhysicalMesh buildPhysicalMesh(const GeometricMesh& g, const CrumpleParams& params) {
  return Builder(g, params).build();
}

// Paper Sec. 4 / Fig. 3: S_P positions follow S_G (samples are affine combinations).
void updateSamples(PhysicalMesh& p, const GeometricMesh& g, std::vector<Vec3>* velocities) {
  const std::size_t n = g.vertexCount();
  if (p.mesh.vertexCount() != n + p.samples.size())
    throw std::invalid_argument("updateSamples: S_G has " + std::to_string(n) +
                                " vertices, S_P was built from " +
                                std::to_string(p.geometricVertexCount()));
  const auto interpolate = [&](auto&& value, auto&& out) {
    for (std::size_t i = 0; i < n; ++i) out[i] = value(g.vertices[i]);
    for (std::size_t k = 0; k < p.samples.size(); ++k) {
      const PhysicalMesh::Sample& s = p.samples[k];
      if (s.face < 0 || s.face >= static_cast<int>(g.faceCount()))
        throw std::invalid_argument("updateSamples: sample " + std::to_string(k) +
                                    " refers to a missing S_G face");
      const GeometricFace& face = g.faces[idx(s.face)];
      Vec3 x = Vec3::Zero();
      for (int j = 0; j < face.size(); ++j)
        x += s.weights[idx(j)] * value(g.vertices[idx(face.v[idx(j)])]);
      out[n + k] = x;
    }
  };
  p.mesh.positions.resize(p.mesh.vertexCount());
  interpolate([](const GeometricVertex& v) -> const Vec3& { return v.position; }, p.mesh.positions);
  if (velocities != nullptr) {
    velocities->resize(p.mesh.vertexCount());
    interpolate([](const GeometricVertex& v) -> const Vec3& { return v.velocity; }, *velocities);
  }
}

std::vector<double> sliverHingeFactors(const mesh::SheetMesh& sp,
                                       const std::vector<mesh::MeshEdge>& hinges, double ratio) {
  const auto area = [&](int t) {
    const auto& tri = sp.triangles[idx(t)];
    const Vec2 a = sp.pattern[idx(tri[1])] - sp.pattern[idx(tri[0])];
    const Vec2 b = sp.pattern[idx(tri[2])] - sp.pattern[idx(tri[0])];
    return 0.5 * std::abs(a.x() * b.y() - a.y() * b.x());
  };
  std::vector<double> out(hinges.size(), 1.0);
  for (std::size_t h = 0; h < hinges.size(); ++h) {
    const mesh::MeshEdge& e = hinges[h];
    if (!e.interior() || !(ratio > 0.0)) continue;
    const double len2 = (sp.pattern[idx(e.v[0])] - sp.pattern[idx(e.v[1])]).squaredNorm();
    out[h] = std::min(1.0, (area(e.triangles[0]) + area(e.triangles[1])) / len2 / ratio);
  }
  return out;
}

}  // namespace crumple::paper
