#pragma once
// The tear path's errors against Roman's predictions (thesis 3.3.1, 3.3.5),
// shared by the tear samples' tests and `crumple bench`: a tear pulled by two
// mirror-image points runs down their bisector (tear-straight), and in
// general the path's tangent bisects the directions to the pulling points (a
// hyperbola; tear-curved).
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/pipeline/shot.hpp"

namespace crumple::pipeline {

// samples/tear-straight: its pulling points are mirror images about u = 6 cm
// on a 12 cm wide sheet (m).
inline constexpr double kTearStraightBisectorU = 0.06;
inline constexpr double kTearStraightWidth = 0.12;
// samples/tear-curved: its pulling points A and B in the pattern (m).
inline const Vec2 kTearCurvedPullA{0.03, 0.09526279441628825};
inline const Vec2 kTearCurvedPullB{0.075, 0.09526279441628825};

// The tips s_0, s_1, ... of tear `tear` in the pattern (m), from the shot's
// tip advances (empty when it never tore).
std::vector<Vec2> tearTips(const ShotReport& report, int tear = 0);

// Straight tear: the largest distance (m) of the points from the line
// u = bisectorU (0 for no points).
double straightTearDeviation(const std::vector<Vec2>& points, double bisectorU);

// Hyperbola: the angle (degrees) between the path and the bisector of the
// directions from the pulling points a and b, sampled every `step` (m) along
// the polyline `tips` (at the middle of each sub-segment).
std::vector<double> hyperbolaAngleErrors(const std::vector<Vec2>& tips, const Vec2& a,
                                         const Vec2& b, double step = 5e-4);

}  // namespace crumple::pipeline
