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

namespace crumple::tear {

// The thesis gives no defaults for p and G_t's width. The greedy walk is
// bimodal: it either hugs the segment (an 8-neighbour staircase, 1.10-1.15
// times the straight length) or wanders into the fibers' noise. With the
// default fiber texture, p = 0.5 and a 0.5 mm width give 1.63-2.63 times
// the straight length over seeds 1-4 (2 cm segments in 8 directions);
// p = 0.6 gives 1.14-1.92, p = 0.5 with 0.35 mm 1.12-1.14.
struct DetailPathParams {
  double blend = 0.5;           // p in eq. (3.2): 0 = fibers only, 1 = straight
  double stressWidth = 0.5e-3;  // m: the Gaussian G_t's standard deviation
};

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
