#pragma once
// The detailed path of a tear between two successive tips (thesis 3.2.2,
// 3.3.4): a greedy walk over the texels of the breaking coefficient
// nu_t = (1 - p) T_fibers + p G_t (eq. (3.2)), G_t a Gaussian of the
// distance to the segment s_t s_{t+1}; from s_t, each step goes to the
// neighbouring texel with the highest nu among those whose direction makes
// an angle below pi/2 with the direction to s_{t+1} (Fig. 3.8), until the
// walk reaches s_{t+1}'s texel.
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/tear/fiber_texture.hpp"
#include "crumple/tear/params.hpp"

namespace crumple::tear {

// nu_t at pattern point q for the segment [from, to] (eq. (3.2)).
double breakingCoefficient(const FiberTexture& fibers, const Vec2& q, const Vec2& from,
                           const Vec2& to, const DetailPathParams& params);

// The path from `from` to `to` (pattern, m): `from`, the centres of the
// texels walked through, then `to`. Deterministic; it always ends at `to`
// (a walk that stops getting nearer, at most 4 times the texels of the
// straight line, goes straight there).
std::vector<Vec2> detailPath(const FiberTexture& fibers, const Vec2& from, const Vec2& to,
                             const DetailPathParams& params);

// Length of a polyline (m).
double pathLength(const std::vector<Vec2>& path);

}  // namespace crumple::tear
