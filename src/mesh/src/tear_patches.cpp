// A frame's tear patches (tear_patches.hpp; thesis 3.3.4, Fig. 3.25).
#include "crumple/mesh/tear_patches.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <sstream>

#include "crumple/core/index.hpp"

namespace crumple::mesh {

namespace {

// Position of a patch's corner k in its polygon.
std::size_t cornerIndex(std::uint8_t lipEdges, int k) {
  std::size_t i = 0;
  for (int e = 0; e < k; ++e) i += (lipEdges >> e) & 1u ? 3 : 1;
  return i;
}

std::string patchProblem(const TearAtlas& atlas, const TearPatch& p) {
  std::ostringstream s;
  if (p.triangle < 0) {
    s << "triangle " << p.triangle << " is negative";
  } else if (p.tear < 0) {
    s << "tear " << p.tear << " is negative";
  } else if (p.side != LipSide::Left && p.side != LipSide::Right) {
    s << "side " << static_cast<int>(p.side) << " is neither 0 (left) nor 1 (right)";
  } else if (p.lipEdges > 7) {
    s << "lip edges " << static_cast<int>(p.lipEdges) << " has bits beyond the three edges";
  } else if (p.polygon.size() != 3 + 2 * idx(std::popcount(p.lipEdges))) {
    s << p.polygon.size() << " polygon points for " << std::popcount(p.lipEdges)
      << " lip edges (3 + 2 per lip edge)";
  } else if (p.rect.width < 1 || p.rect.height < 1 || p.rect.x < 0 || p.rect.y < 0 ||
             p.rect.x > atlas.width - p.rect.width || p.rect.y > atlas.height - p.rect.height) {
    s << "rect " << p.rect.width << " x " << p.rect.height << " at (" << p.rect.x << ", "
      << p.rect.y << ") is not inside the " << atlas.width << " x " << atlas.height << " atlas";
  } else if (!p.rect.origin.allFinite()) {
    s << "rect origin is not finite";
  } else {
    for (const Vec2& q : p.polygon)
      if (!q.allFinite()) return "polygon point is not finite";
  }
  return s.str();
}

}  // namespace

Vec2 atlasPosition(const TearAtlas& atlas, const TearPatch& patch, const Vec2& p) {
  return Vec2(patch.rect.x, patch.rect.y) + (p - patch.rect.origin) / atlas.texelSize;
}

std::vector<TearPatchTriangle> tearPatchTriangles(const TearPatch& patch, const SheetMesh& mesh) {
  const auto& tri = mesh.triangles[idx(patch.triangle)];
  std::array<Vec2, 3> p;
  std::array<Vec3, 3> x;
  for (std::size_t k = 0; k < 3; ++k) {
    p[k] = mesh.pattern[idx(tri[k])];
    x[k] = mesh.positions[idx(tri[k])];
  }
  // The triangle's affine map, pattern -> 3D: x0 + J (q - p0).
  Mat2 edges2;
  edges2 << p[1] - p[0], p[2] - p[0];
  Eigen::Matrix<double, 3, 2> edges3;
  edges3 << x[1] - x[0], x[2] - x[0];
  const Eigen::Matrix<double, 3, 2> jacobian = edges3 * edges2.inverse();
  const auto corner = [&](int k) { return TearPatchVertex{x[idx(k)], p[idx(k)], k}; };
  // An outer corner pushed from corner k: placed from that corner.
  const auto outer = [&](const Vec2& q, int k) {
    return TearPatchVertex{x[idx(k)] + jacobian * (q - p[idx(k)]), q, k};
  };
  std::vector<TearPatchTriangle> out{{corner(0), corner(1), corner(2)}};
  for (int k = 0; k < 3; ++k) {
    if (!((patch.lipEdges >> k) & 1u)) continue;
    const std::size_t i = cornerIndex(patch.lipEdges, k);
    const int k1 = (k + 1) % 3;
    const TearPatchVertex a = outer(patch.polygon[i + 1], k);
    const TearPatchVertex b = outer(patch.polygon[i + 2], k1);
    out.push_back({corner(k), a, b});
    out.push_back({corner(k), b, corner(k1)});
  }
  return out;
}

std::string validate(const TearAtlas& atlas) {
  if (!(atlas.texelSize > 0.0) || !std::isfinite(atlas.texelSize))
    return "texel size is not a finite number > 0";
  if (atlas.width < 0 || atlas.height < 0) return "negative atlas size";
  if (atlas.mask.size() != idx(atlas.width) * idx(atlas.height))
    return "mask holds " + std::to_string(atlas.mask.size()) + " texels, not " +
           std::to_string(atlas.width) + " x " + std::to_string(atlas.height);
  for (std::size_t i = 0; i < atlas.mask.size(); ++i)
    if (atlas.mask[i] != 0 && atlas.mask[i] != 255)
      return "mask texel " + std::to_string(i) + " is " + std::to_string(atlas.mask[i]) +
             ", neither 0 nor 255";
  for (std::size_t i = 0; i < atlas.patches.size(); ++i) {
    const TearPatch& p = atlas.patches[i];
    std::string problem = patchProblem(atlas, p);
    if (problem.empty() && i > 0 && p.triangle <= atlas.patches[i - 1].triangle)
      problem = "triangle " + std::to_string(p.triangle) + " after triangle " +
                std::to_string(atlas.patches[i - 1].triangle) + " (sorted, once each)";
    if (!problem.empty()) return "patch " + std::to_string(i) + ": " + problem;
  }
  return {};
}

std::string validate(const TearAtlas& atlas, const SheetMesh& mesh) {
  if (std::string problem = validate(atlas); !problem.empty()) return problem;
  for (std::size_t i = 0; i < atlas.patches.size(); ++i) {
    const TearPatch& p = atlas.patches[i];
    const std::string where = "patch " + std::to_string(i) + ": ";
    if (!inRange(mesh.triangles, p.triangle))
      return where + "triangle " + std::to_string(p.triangle) + " is not in the mesh (" +
             std::to_string(mesh.triangles.size()) + " triangles)";
    const auto& tri = mesh.triangles[idx(p.triangle)];
    for (int k = 0; k < 3; ++k) {
      const int v = tri[idx(k)];
      if (!inRange(mesh.pattern, v)) return where + "its triangle's vertex is not in the mesh";
      const Vec2& q = mesh.pattern[idx(v)];
      if ((p.polygon[cornerIndex(p.lipEdges, k)] - q).norm() > 1e-9 * (1.0 + q.norm()))
        return where + "polygon corner " + std::to_string(k) +
               " is not at its triangle's pattern corner";
    }
  }
  return {};
}

double sampleTearMask(const TearAtlas& atlas, const Vec2& position) {
  const int w = atlas.width, h = atlas.height;
  if (w <= 0 || h <= 0) return 1.0;
  const double x = position.x() - 0.5, y = position.y() - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double ax = x - fx, ay = y - fy;
  const auto clampTo = [](double i, int n) {
    return static_cast<std::size_t>(std::clamp(i, 0.0, static_cast<double>(n - 1)));
  };
  const std::size_t x0 = clampTo(fx, w), x1 = clampTo(fx + 1.0, w);
  const std::size_t y0 = clampTo(fy, h), y1 = clampTo(fy + 1.0, h);
  const auto texel = [&](std::size_t xi, std::size_t yi) {
    return atlas.mask[yi * idx(w) + xi] / 255.0;
  };
  return (1.0 - ay) * ((1.0 - ax) * texel(x0, y0) + ax * texel(x1, y0)) +
         ay * ((1.0 - ax) * texel(x0, y1) + ax * texel(x1, y1));
}

}  // namespace crumple::mesh
