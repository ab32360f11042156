#pragma once
// Internal to src/paper (not installed): where a compressed strip gets its
// singular vertex (paper Sec. 5.2, Fig. 11; thesis 2.4.3), and the pieces of
// S_G surgery the compression treatment shares.
#include <cstdint>
#include <optional>
#include <vector>

#include "crumple/core/rng.hpp"
#include "crumple/paper/geometric_mesh.hpp"
#include "crumple/paper/params.hpp"
#include "region_tools.hpp"
#include "strip.hpp"

namespace crumple::paper::detail {

// A vertex at pattern point s inside the curved cell between rulings r0 and
// r1: its 3D position and velocity by barycentric interpolation in the cell
// triangle holding it (the cell split along its first diagonal). nullopt when
// s lies in neither triangle.
std::optional<GeometricVertex> vertexInCell(const GeometricMesh& g, const Ruling& r0,
                                            const Ruling& r1, const Vec2& s);

// paper Fig. 11: the cells of a curved region between its rulings lo and hi
// become two fans of rulings from the singular vertex s (one per boundary
// chain), each a cone region with apex s.
void addConeFans(GeometricMesh& g, int s, const std::vector<Ruling>& rulings, std::size_t lo,
                 std::size_t hi);

// Appends the triangle (a, b, c), counter-clockwise in the pattern, to `region`.
void addTriangleCCW(GeometricMesh& g, int a, int b, int c, int region);

// Draws a standard normal deviate from two uniforms (Box-Muller).
double normalDeviate(const CounterRng& rng, std::uint64_t& index);

// Whether a new vertex at pattern point p would sit closer than a quarter of
// the ruling spacing to an existing S_G vertex: S_P triangles that small
// (tens of micrometres when d-cones pile up) make the elastic system too
// ill-conditioned to factor, so such an insertion is declined.
bool crowded(const GeometricMesh& g, const Vec2& p, const CrumpleParams& params);

// paper Sec. 5.2 (flat-flat case): the singular vertex goes on the border
// edge itself, near where the imaginary ruling meets it, spread along the
// edge with the law exp(-d^2/sigma^2) and kept off its ends.
int placeSingularOnBorder(GeometricMesh& g, const Loop& loop, const Border& border,
                          const CrumpleParams& params, const CounterRng& rng,
                          std::uint64_t& drawIndex);

// paper Sec. 5.2 and Fig. 11 (curved case): the strip meets the border ruling
// e_lim of a curved region C. Following v-perp into C, e_sing is the first
// ruling with a dihedral angle above theta_0 (e_lim itself if none); the
// singular vertex s is drawn uniform along e_sing and normal across it with
// the law exp(-d^2/sigma^2), kept inside C. C's rulings from e_lim up to e_sup
// (the next ruling past s above theta_0, or C's far end) are replaced by two
// fans of rulings from s with a flat transition triangle, and the triangle
// between e_lim and s joins F. Returns s, or -1 (nothing changed) when C is
// already a cone with an apex.
int insertSingularInCurved(GeometricMesh& g, int flat, const Loop& loop, const Border& border,
                           const CrumpleParams& params, const CounterRng& rng,
                           std::uint64_t& drawIndex);

}  // namespace crumple::paper::detail
