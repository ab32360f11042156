#pragma once
// Compression analysis (thesis 2.4.1-2.4.2; paper Sec. 5.1 (a)).
#include <array>

#include "crumple/core/types.hpp"

namespace crumple::paper {

// Principal stretches of a triangle against its pattern, from the stretch
// tensor U = (F^T F)^(1/2) with F = [e0 e1][ē0 ē1]^-1 (thesis 2.4.2,
// after Rohmer et al. 2010). Directions are in the pattern.
struct TriangleCompression {
  double lambdaMin = 1.0;      // smallest principal stretch (< 1: compressed)
  double lambdaMax = 1.0;      // largest principal stretch
  Vec2 v = Vec2::UnitX();      // direction of maximal compression (eigenvector of lambdaMin)
  Vec2 vPerp = Vec2::UnitY();  // direction of minimal compression, orthogonal to v
  double ratio() const { return 1.0 - lambdaMin; }  // compression ratio 1 - lambda
};

// Throws std::invalid_argument for a degenerate pattern triangle.
TriangleCompression analyzeCompression(const std::array<Vec2, 3>& pattern,
                                       const std::array<Vec3, 3>& position);

// Edge compression c_e = (l̄ - l) / l̄ (thesis 2.4.1): > 0 when shorter than in the pattern.
double edgeCompression(const Vec2& patternA, const Vec2& patternB, const Vec3& a, const Vec3& b);

}  // namespace crumple::paper
