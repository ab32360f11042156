// The baked tear textures (thesis 3.3.4, Figs. 3.24-3.25; tear_atlas.hpp):
// every lip triangle of a cut gets a patch on its side, the two lips' masks
// are complementary over the whole gap between the cut and the detail path,
// and the patches lie in their triangles' planes.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <iostream>
#include <map>

#include "crumple/mesh/tear_patches.hpp"
#include "crumple/tear/cut.hpp"
#include "crumple/tear/detail_path.hpp"
#include "crumple/tear/fiber_texture.hpp"
#include "crumple/tear/lip_masks.hpp"
#include "crumple/tear/tear_atlas.hpp"

namespace crumple::tear {
namespace {

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// A 4 x 4 cm sheet (5 mm cells) torn in two advances of one tear, from the
// bottom edge up to (21.3, 13.7) mm and then to `second`, with rough detail
// paths (p = 0.3, G_t 1 mm wide: 1-2 mm from the cut).
struct TornSheet {
  mesh::SheetMesh mesh;
  std::vector<TearSegment> segments;
  std::vector<Vec2> cut;     // the whole tear's cut
  std::vector<Vec2> detail;  // and its detail path
};

TornSheet tornSheet(std::uint64_t seed, const Vec2& second) {
  TornSheet s;
  s.mesh = mesh::makeRectangleSheet(0.04, 0.04, 0.005);
  mesh::placePattern(s.mesh, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
  FiberTextureParams fp;
  fp.seed = seed;
  const FiberTexture fibers(Vec2::Zero(), Vec2(0.04, 0.04), fp);
  int from = mesh::nearestPatternVertex(s.mesh, Vec2(0.02, 0.0));
  DetailPathParams rough;
  rough.blend = 0.3;
  rough.stressWidth = 1e-3;
  for (const Vec2& to : {Vec2(0.0213, 0.0137), second}) {
    const Vec2 start = s.mesh.pattern[static_cast<std::size_t>(from)];
    const CutResult cut = cutAlong(s.mesh, from, to);
    TearSegment seg;
    seg.tear = 0;
    for (int v : cut.chain) seg.cut.push_back(s.mesh.pattern[static_cast<std::size_t>(v)]);
    seg.detail = detailPath(fibers, start, seg.cut.back(), rough);
    s.cut.insert(s.cut.end(), seg.cut.begin() + (s.cut.empty() ? 0 : 1), seg.cut.end());
    s.detail.insert(s.detail.end(), seg.detail.begin() + (s.detail.empty() ? 0 : 1),
                    seg.detail.end());
    s.segments.push_back(std::move(seg));
    from = cut.tip;
  }
  return s;
}

// The second advance turns right by 78 degrees, or back by 150 (then one
// triangle at the turn has its lip edges on both advances).
const std::array<Vec2, 2> kSecondTips{Vec2(0.032, 0.016), Vec2(0.024, 0.008)};
// Fiber seeds and second tips.
const std::array<std::pair<std::uint64_t, Vec2>, 6> kCases{{{1, kSecondTips[0]},
                                                            {2, kSecondTips[0]},
                                                            {3, kSecondTips[0]},
                                                            {1, kSecondTips[1]},
                                                            {2, kSecondTips[1]},
                                                            {3, kSecondTips[1]}}};

// The mask byte of a patch at global texel (i, j) (texel (i, j) covers
// texelSize * [i, i + 1] x [j, j + 1]); -1 outside its rect.
int maskAt(const TearAtlas& atlas, const TearPatch& p, long i, long j) {
  const long i0 = std::lround(p.rect.origin.x() / atlas.texelSize);
  const long j0 = std::lround(p.rect.origin.y() / atlas.texelSize);
  if (i < i0 || j < j0 || i >= i0 + p.rect.width || j >= j0 + p.rect.height) return -1;
  return atlas
      .mask[static_cast<std::size_t>((p.rect.y + j - j0) * atlas.width + p.rect.x + i - i0)];
}

bool inTriangle(const Vec2& q, const std::array<Vec2, 3>& t) {
  const double area = cross(t[1] - t[0], t[2] - t[0]);
  const double w1 = cross(q - t[0], t[2] - t[0]) / area, w2 = cross(t[1] - t[0], q - t[0]) / area;
  return w1 >= 0.0 && w2 >= 0.0 && w1 + w2 <= 1.0;
}

std::array<Vec2, 3> patternOf(const mesh::SheetMesh& m, int t) {
  const auto& tri = m.triangles[static_cast<std::size_t>(t)];
  return {m.pattern[static_cast<std::size_t>(tri[0])], m.pattern[static_cast<std::size_t>(tri[1])],
          m.pattern[static_cast<std::size_t>(tri[2])]};
}

// Distance from q to a polyline and the arc length of its nearest point.
std::pair<double, double> toPolyline(const std::vector<Vec2>& line, const Vec2& q) {
  double best = 1e300, param = 0.0, along = 0.0;
  for (std::size_t i = 0; i + 1 < line.size(); ++i) {
    const Vec2 ab = line[i + 1] - line[i];
    const double t = std::clamp((q - line[i]).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    const double d = (q - line[i] - t * ab).norm();
    if (d < best) {
      best = d;
      param = along + t * ab.norm();
    }
    along += ab.norm();
  }
  return {best, param};
}

TEST(TearAtlas, EveryLipTriangleOfTheCutGetsAPatchOnItsSide) {
  for (const auto& [seed, second] : kCases) {
    const TornSheet s = tornSheet(seed, second);
    const TearAtlas atlas = bakeTearAtlas(s.mesh, s.segments, TearAtlasParams{});
    EXPECT_EQ(mesh::validate(atlas, s.mesh), "");
    std::map<int, const TearPatch*> byTriangle;
    for (const TearPatch& p : atlas.patches) byTriangle[p.triangle] = &p;
    // The lip edges: boundary edges joining consecutive points of the cut;
    // the triangle is left of the cut when its counter-clockwise edge runs
    // with the cut.
    std::map<Vec2, int, bool (*)(const Vec2&, const Vec2&)> cutIndex(
        [](const Vec2& a, const Vec2& b) {
          return a.x() != b.x() ? a.x() < b.x() : a.y() < b.y();
        });
    for (std::size_t i = 0; i < s.cut.size(); ++i) cutIndex[s.cut[i]] = static_cast<int>(i);
    int lipEdges = 0, twoLipEdges = 0;
    for (const auto& e : mesh::buildEdges(s.mesh)) {
      if (e.interior()) continue;
      const auto& tri = s.mesh.triangles[static_cast<std::size_t>(e.triangles[0])];
      for (int k = 0; k < 3; ++k) {
        const int a = tri[static_cast<std::size_t>(k)],
                  b = tri[static_cast<std::size_t>((k + 1) % 3)];
        if (std::minmax(a, b) != std::minmax(e.v[0], e.v[1])) continue;
        const auto ia = cutIndex.find(s.mesh.pattern[static_cast<std::size_t>(a)]);
        const auto ib = cutIndex.find(s.mesh.pattern[static_cast<std::size_t>(b)]);
        if (ia == cutIndex.end() || ib == cutIndex.end() || std::abs(ia->second - ib->second) != 1)
          continue;
        ++lipEdges;
        const auto it = byTriangle.find(e.triangles[0]);
        ASSERT_NE(it, byTriangle.end()) << "lip triangle " << e.triangles[0] << " has no patch";
        const TearPatch& p = *it->second;
        EXPECT_TRUE((p.lipEdges >> k) & 1u) << "triangle " << p.triangle << " edge " << k;
        EXPECT_EQ(p.side, ib->second > ia->second ? LipSide::Left : LipSide::Right);
        EXPECT_EQ(p.tear, 0);
        if (std::popcount(p.lipEdges) == 2) ++twoLipEdges;
      }
    }
    // Each cut edge has a lip on either side.
    EXPECT_EQ(lipEdges, 2 * static_cast<int>(s.cut.size() - 1)) << "seed " << seed;
    if (second == kSecondTips[1]) {
      EXPECT_GT(twoLipEdges, 0) << "a triangle at the turn";
    }
    std::cout << "[ measure ] seed " << seed << ", turn to " << second.transpose() * 1e3
              << " mm: " << atlas.patches.size() << " patches, " << lipEdges << " lip edges ("
              << twoLipEdges / 2 << " triangles with two), atlas " << atlas.width << " x "
              << atlas.height << "\n";
    // The support quads reach past the detail path: their outer corners are
    // at least its largest distance from the cut away from their edge.
    double farthest = 0.0;
    for (const Vec2& q : s.detail) farthest = std::max(farthest, toPolyline(s.cut, q).first);
    for (const TearPatch& p : atlas.patches) {
      std::size_t i = 0;
      for (int k = 0; k < 3; ++k, ++i) {
        if (!((p.lipEdges >> k) & 1u)) continue;
        const Vec2 a = p.polygon[i], b = p.polygon[i + 3 < p.polygon.size() ? i + 3 : 0];
        const Vec2 n = Vec2(b - a).normalized();
        for (const Vec2& q : {p.polygon[i + 1], p.polygon[i + 2]})
          EXPECT_GE(cross(q - a, n), farthest) << "outward, beyond the detail path";
        i += 2;
      }
    }
    EXPECT_EQ(atlas, bakeTearAtlas(s.mesh, s.segments, TearAtlasParams{})) << "deterministic";
  }
}

TEST(TearAtlas, TheTwoLipsMasksAreComplementaryOverTheGap) {
  for (const auto& [seed, second] : kCases) {
    const TornSheet s = tornSheet(seed, second);
    const TearAtlas atlas = bakeTearAtlas(s.mesh, s.segments, TearAtlasParams{});
    const double texel = atlas.texelSize;
    double length = 0.0;
    for (std::size_t i = 0; i + 1 < s.cut.size(); ++i) length += (s.cut[i + 1] - s.cut[i]).norm();
    // Texel for texel: wherever a left and a right patch's rects overlap
    // (on the shared texel grid), exactly one of them shows paper.
    long overlaps = 0;
    for (const TearPatch& p : atlas.patches) {
      EXPECT_NEAR(p.rect.origin.x() / texel, std::round(p.rect.origin.x() / texel), 1e-6);
      EXPECT_NEAR(p.rect.origin.y() / texel, std::round(p.rect.origin.y() / texel), 1e-6);
    }
    for (const TearPatch& l : atlas.patches) {
      if (l.side != LipSide::Left) continue;
      for (const TearPatch& r : atlas.patches) {
        if (r.side != LipSide::Right) continue;
        const long i0 = std::lround(l.rect.origin.x() / texel),
                   j0 = std::lround(l.rect.origin.y() / texel);
        for (long j = j0; j < j0 + l.rect.height; ++j)
          for (long i = i0; i < i0 + l.rect.width; ++i) {
            const int b = maskAt(atlas, r, i, j);
            if (b < 0) continue;
            ++overlaps;
            // Beside the cut; beyond its ends both lips are whole.
            const Vec2 centre = texel * Vec2(i + 0.5, j + 0.5);
            const double param = toPolyline(s.cut, centre).second;
            if (param > 1e-9 && param < length - 1e-9)
              ASSERT_EQ(maskAt(atlas, l, i, j) + b, 255) << "texel " << i << ", " << j;
            else
              ASSERT_EQ(maskAt(atlas, l, i, j) + b, 510) << "texel " << i << ", " << j;
          }
      }
    }
    EXPECT_GT(overlaps, 1000);

    // Over the gap, what the renderers draw: at every point nearer to the
    // cut than the detail path's largest distance, behind the tip, exactly
    // one lip shows paper (its patch covers the point and its mask's texel
    // there is 255), and it is the lip on the point's side of the detail
    // path; every triangle there is a patch.
    double farthest = 0.0;
    for (const Vec2& q : s.detail) farthest = std::max(farthest, toPolyline(s.cut, q).first);
    std::vector<char> patched(s.mesh.triangleCount(), 0);
    for (const TearPatch& p : atlas.patches) patched[static_cast<std::size_t>(p.triangle)] = 1;
    // The sides of the path, continued along the cut's end edges as bakeTearAtlas does.
    std::vector<Vec2> path = s.detail;
    path.insert(path.begin(), s.cut[0] - (s.cut[1] - s.cut[0]).normalized());
    path.push_back(s.cut.back() + (s.cut.back() - s.cut[s.cut.size() - 2]).normalized());
    PixelGrid grid;
    grid.pixelSize = texel;
    grid.width = grid.height = static_cast<int>(std::ceil(0.04 / texel));
    const auto sides = leftOfPath(path, grid);
    long samples = 0, left = 0;
    const double step = texel / 3.0;
    for (double y = 0.37 * step; y < 0.04; y += step)
      for (double x = 0.41 * step; x < 0.04; x += step) {
        const Vec2 q(x, y);
        const auto [d, param] = toPolyline(s.cut, q);
        if (!(d < farthest) || !(param > 0.0 && param < length)) continue;
        const long i = static_cast<long>(std::floor(x / texel)),
                   j = static_cast<long>(std::floor(y / texel));
        // Beside the cut: the texel's centre too (beyond the ends both lips are whole).
        const double centreParam = toPolyline(s.cut, texel * Vec2(i + 0.5, j + 0.5)).second;
        if (!(centreParam > 1e-9 && centreParam < length - 1e-9)) continue;
        std::array<int, 2> shown{0, 0};
        for (const TearPatch& p : atlas.patches) {
          bool covers = false;
          for (const auto& piece : mesh::tearPatchTriangles(p, s.mesh))
            covers =
                covers || inTriangle(q, {piece[0].pattern, piece[1].pattern, piece[2].pattern});
          if (covers && maskAt(atlas, p, i, j) == 255) ++shown[static_cast<std::size_t>(p.side)];
        }
        for (int t = 0; t < static_cast<int>(s.mesh.triangleCount()); ++t)
          if (!patched[static_cast<std::size_t>(t)] && inTriangle(q, patternOf(s.mesh, t)))
            ADD_FAILURE() << "triangle " << t << " at " << q.transpose() << " is not a patch";
        ++samples;
        ASSERT_EQ((shown[0] > 0) + (shown[1] > 0), 1)
            << "lips showing paper at " << q.transpose() << ", seed " << seed;
        // The side (unless the texel's centre is on the path: a detail path
        // runs through texel centres, where rounding decides).
        const bool isLeft = sides[static_cast<std::size_t>(j * grid.width + i)] == 1;
        left += shown[0] > 0 ? 1 : 0;
        if (toPolyline(s.detail, grid.centre(static_cast<int>(i), static_cast<int>(j))).first >
            1e-6 * texel) {
          ASSERT_EQ(shown[0] > 0, isLeft) << "left lip at " << q.transpose() << ", seed " << seed;
        }
      }
    std::cout << "[ measure ] seed " << seed << ", turn to " << second.transpose() * 1e3
              << " mm: " << samples << " gap samples, " << left
              << " left of the detail path; support " << farthest * 1e3 << " mm + margin\n";
    EXPECT_GT(samples, 3000);
    EXPECT_GT(left, samples / 10);
    EXPECT_LT(left, samples - samples / 10);
  }
}

TEST(TearAtlas, PatchesLieInTheirTrianglesPlanes) {
  TornSheet s = tornSheet(2, kSecondTips[0]);
  const TearAtlas atlas = bakeTearAtlas(s.mesh, s.segments, TearAtlasParams{});
  // An affine placement: every patch point lands where the map puts it.
  Mat3 a;
  a << 0.8, 0.3, 0.0, -0.2, 0.9, 0.1, 0.4, 0.0, 1.0;
  const Vec3 shift(0.1, -0.2, 0.3);
  const auto place = [&](const Vec2& p) { return Vec3(a * Vec3(p.x(), p.y(), 0.0) + shift); };
  for (std::size_t v = 0; v < s.mesh.vertexCount(); ++v)
    s.mesh.positions[v] = place(s.mesh.pattern[v]);
  for (const TearPatch& p : atlas.patches) {
    const auto pieces = mesh::tearPatchTriangles(p, s.mesh);
    ASSERT_EQ(pieces.size(), 1u + 2u * static_cast<std::size_t>(std::popcount(p.lipEdges)));
    const auto& tri = s.mesh.triangles[static_cast<std::size_t>(p.triangle)];
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(pieces[0][static_cast<std::size_t>(k)].position,
                s.mesh.positions[static_cast<std::size_t>(tri[static_cast<std::size_t>(k)])]);
      EXPECT_EQ(pieces[0][static_cast<std::size_t>(k)].corner, k);
    }
    for (const auto& piece : pieces) {
      EXPECT_GT(cross(piece[1].pattern - piece[0].pattern, piece[2].pattern - piece[0].pattern),
                0.0)
          << "counter-clockwise";
      for (const auto& v : piece) EXPECT_LT((v.position - place(v.pattern)).norm(), 1e-15);
    }
  }
  // Bent: the quads stay in their triangle's plane.
  for (auto& x : s.mesh.positions) x.z() += 8.0 * x.x() * x.x();
  for (const TearPatch& p : atlas.patches) {
    const auto pieces = mesh::tearPatchTriangles(p, s.mesh);
    const Vec3 n = (pieces[0][1].position - pieces[0][0].position)
                       .cross(pieces[0][2].position - pieces[0][0].position)
                       .normalized();
    for (const auto& piece : pieces)
      for (const auto& v : piece)
        EXPECT_LT(std::abs(n.dot(v.position - pieces[0][0].position)), 1e-15);
  }
}

TEST(TearAtlas, RejectsBadInput) {
  const TornSheet s = tornSheet(1, kSecondTips[1]);
  TearAtlasParams bad;
  bad.texelSize = 0.0;
  EXPECT_THROW(bakeTearAtlas(s.mesh, s.segments, bad), std::invalid_argument);
  bad = TearAtlasParams{};
  bad.margin = -1.0;
  EXPECT_THROW(bakeTearAtlas(s.mesh, s.segments, bad), std::invalid_argument);
  auto segments = s.segments;
  segments[0].cut.resize(1);
  EXPECT_THROW(bakeTearAtlas(s.mesh, segments, TearAtlasParams{}), std::invalid_argument);
  segments = s.segments;
  segments[1].detail.back() += Vec2(0.001, 0.0);
  EXPECT_THROW(bakeTearAtlas(s.mesh, segments, TearAtlasParams{}), std::invalid_argument)
      << "a detail path ending elsewhere than its cut";
  EXPECT_TRUE(bakeTearAtlas(s.mesh, {}, TearAtlasParams{}).empty());
}

}  // namespace
}  // namespace crumple::tear
