#pragma once
// Fitting generalized cones to the curved regions of S_G (paper Sec. 6.2,
// eq. (2), Figs. 14-15; thesis 2.5.2, Algorithms 2-3): the Blaschke-cylinder
// apex fit, the iterative segmentation of a region's rulings into cones, the
// apex in the pattern, and the remeshing of a curved region so that each
// cone's rulings pass through its apex (arrow (f) of paper Fig. 16).
//
// The Blaschke model. An oriented plane n.x + w = 0 (|n| = 1) is the point
// (n, w) of R^4 on the Blaschke cylinder |n| = 1. The tangent planes of a
// generalized cone with apex a all lie on the hyperplane n.a + w = 0; those
// of a generalized cylinder with ruling direction d on n.d = 0 (its apex is
// the point at infinity of d). Paper eq. (2) fits a by minimizing
//   e = sum_i (n_i . a + w_i)^2,
// whose 3x3 normal matrix sum n_i n_i^T is singular for a cylinder. We fit
// the hyperplane projectively instead, as Peternell does: with a reference
// point c and a length scale L (FitFrame), u_i = (n_i, (w_i + n_i.c) / L) and
// X = (x, xi), |X| = 1, minimizing sum (u_i . X)^2 -- the eigenvector of the
// smallest eigenvalue of sum u_i u_i^T. The apex is a = c + L x / xi, or the
// point at infinity of direction x when xi = 0. On exact data this is the
// minimizer of eq. (2); on noisy data it minimizes eq. (2) divided by
// 1 + |a - c|^2 / L^2 (a mild pull towards cylinders, the common case).
//
// The error (dimensionally sound reading of the paper's "e < eps_blaschke",
// which compares a sum of squared lengths with a length). The contribution
// of ruling i is e_i = (L u_i . X)^2, i.e.
//   e_i = d_i^2 L^2 / (L^2 + |a - c|^2)   for a finite apex,
//   e_i = (L n_i . d)^2                    for an apex at infinity,
// where d_i = |n_i . a + w_i| is the distance from the tangent plane T_i to
// the apex (the paper's e_i). For an apex well within L of c it is the
// paper's squared distance; for a far apex it is L times the angle by which
// T_i misses the apex direction, and it tends continuously to the cylinder
// case. L is thus the distance beyond which an apex counts as "nearly at
// infinity". It must be well above the size of the region: with L of the
// order of the ruling length, near-parallel tangent planes of two different
// cones are explained by one far apex at a discount of L / |a - c|, and
// segments mix cones. refitCurvedRegion uses L = 10 L_paper (the angular
// tolerance at infinity is then eps_blaschke / L = 0.5 mrad).
//
// The segment error compared against eps_blaschke = epsBlaschke * L_paper
// (a length) is the largest distance
//   maxDistance = max_i sqrt(e_i)   (metres):
// every tangent plane must pass within eps_blaschke of the apex. The paper
// writes sum e_i < eps_blaschke (squared lengths against a length); we read
// it per ruling so that it does not depend on the ruling density, and use
// the maximum rather than the RMS because the RMS dilutes the plane of a
// neighbouring cone by sqrt(N) and lets it into a segment (like the paper's
// sum, a single far plane is enough to reject a fit). rms and sumSquares
// are reported too.
#include <span>
#include <string>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/paper/boundary_curve.hpp"
#include "crumple/paper/geometric_mesh.hpp"
#include "crumple/paper/params.hpp"

namespace crumple::paper {

// The tangent plane along one ruling, n.x + w = 0 (paper Sec. 6.2: T_i with
// normal n_i "constant along the ruling" and signed distance term w_i).
struct RulingPlane {
  Vec3 normal = Vec3::UnitZ();  // normalized by fitApex (w is scaled with it)
  double w = 0.0;
  // Optional unit direction of the ruling (zero = unknown). Used only to
  // choose among equally good apices when the fit is degenerate (fewer than
  // three independent planes, e.g. a segment of one or two rulings or a
  // planar strip): the apex is then put at infinity in the direction of the
  // mean ruling direction projected into the admissible set.
  Vec3 direction = Vec3::Zero();
};

// Reference point c and length scale L of the projective fit (see above).
// refitCurvedRegion: c = centroid of the ruling midpoints, L = 10 L_paper.
struct FitFrame {
  Vec3 centre = Vec3::Zero();
  double length = 1.0;  // metres, > 0
};

struct ApexFit {
  bool atInfinity = false;         // a generalized cylinder
  Vec3 apex = Vec3::Zero();        // the apex a (finite only; zero when at infinity)
  Vec3 direction = Vec3::UnitX();  // at infinity: the unit ruling direction; finite: unit (a - c)
  double sumSquares = 0.0;         // sum e_i (m^2)
  double rms = 0.0;                // sqrt(sum e_i / N) (m)
  double maxDistance = 0.0;        // max_i sqrt(e_i) (m): compared with eps_blaschke
  std::vector<double> contributions;  // e_i per ruling (m^2), in input order
  bool degenerate = false;            // the minimizer was not unique (tie broken, see RulingPlane)
};

// paper Sec. 6.2, eq. (2) (Blaschke cylinder, projective form, see above).
// Throws std::invalid_argument for no planes or frame.length <= 0, and
// NumericalError (stage "cones") for non-finite or zero normals or a
// non-finite result.
ApexFit fitApex(std::span<const RulingPlane> planes, const FitFrame& frame = {});

// A run of consecutive rulings first..last (inclusive) approximated by one
// generalized cone.
struct ConeSegment {
  int first = 0;
  int last = 0;
  ApexFit fit;
};

// paper Sec. 6.2 "Iterative segmentation algorithm", thesis Algorithms 2-3:
// fit all rulings; while maxDistance > tolerance drop the first or the last
// ruling, whichever has the larger contribution e_i; recurse on the rulings
// dropped in front and behind. Greedy, like the paper's: a short run of two
// or three rulings may be left at a transition between cones. Returns the segments ordered by
// `first`, covering 0..planes.size()-1.
//  - shareBorders = false (paper text): the dropped rulings form the front
//    and back lists, segments are disjoint (next.first == prev.last + 1).
//  - shareBorders = true (thesis Alg. 3 index lists {front, i_f},
//    {i_b, back}): neighbouring segments share their border ruling
//    (next.first == prev.last), so segments of two rulings can appear
//    between two cones.
// Any three planes meet in a point, so a segment of <= 3 rulings always
// fits. Throws std::invalid_argument for no planes or tolerance < 0.
std::vector<ConeSegment> segmentRulings(std::span<const RulingPlane> planes, double tolerance,
                                        const FitFrame& frame = {}, bool shareBorders = false);

// One ruling with its 3D endpoints A, B and pattern endpoints Abar, Bbar,
// and the unit normal of its tangent plane, oriented like faceNormal of the
// faces counter-clockwise in the pattern (so that a rotation by +phi in the
// pattern is a rotation by +phi about the normal in 3D).
struct RulingGeometry {
  Vec3 a3 = Vec3::Zero();
  Vec3 b3 = Vec3::Zero();
  Vec2 a2 = Vec2::Zero();
  Vec2 b2 = Vec2::Zero();
  Vec3 normal = Vec3::UnitZ();
};

// paper Sec. 6.2 (last step) / thesis 2.5.2: orthogonal projection of the 3D
// apex onto the ruling line A + t u (u = (B - A)/|B - A|, t = (apex - A).u),
// mapped into the pattern with the same coordinate along the ruling:
// abar = Abar + t (Bbar - Abar)/|Bbar - Abar|.
Vec2 apexInPattern(const Vec3& apex, const RulingGeometry& ruling);

// Variant of apexInPattern that keeps both coordinates of the apex in the
// tangent plane: with u the ruling direction projected into the plane and
// v = n x u, abar = Abar + ((apex - A).u) ubar + ((apex - A).v) perp(ubar).
// On a developable surface whose current rulings are chords rather than
// generators, the apex is off the ruling line by ~ D theta (theta the angle
// between chord and generator, D the apex distance); apexInPattern drops
// that offset and puts abar ~ D theta away from the true pattern apex, which
// re-aiming does not reduce. The local isometry of the tangent plane keeps
// it (exact on a cone whatever the ruling; refitCurvedRegion uses this).
Vec2 apexInPatternInPlane(const Vec3& apex, const RulingGeometry& ruling);

// The pattern image of a 3D direction d at a ruling (for an apex at
// infinity): d projected into the tangent plane makes the signed angle phi
// with the ruling about its normal; the result is the pattern ruling
// direction rotated by phi. Unit length.
Vec2 directionInPattern(const Vec3& direction, const RulingGeometry& ruling);

// The apex of a cone in the pattern: a point, or a direction (at infinity).
struct PatternApex {
  bool atInfinity = false;
  Vec2 point = Vec2::Zero();       // finite: abar^proj
  Vec2 direction = Vec2::UnitY();  // at infinity: unit pattern ruling direction
  int ruling = -1;                 // index of the ruling it was mapped through
};

// paper Sec. 6.2: the ruling of the segment with minimal contribution e_j
// carries the apex into the pattern (apexInPattern, or directionInPattern at
// infinity). Rulings whose sqrt(e_j) is within 1e-9 m of the minimum are
// tied (on exact data every e_j is rounding noise); among them the one whose
// 3D line passes closest to the apex (most parallel to the direction at
// infinity) is taken. `rulings` is indexed like the planes the segment was
// fitted on.
enum class ApexMapping {
  AlongRuling,     // apexInPattern: the paper's projection on the ruling
  InTangentPlane,  // apexInPatternInPlane
};
PatternApex patternApex(const ConeSegment& segment, std::span<const RulingGeometry> rulings,
                        ApexMapping mapping = ApexMapping::AlongRuling);

// What refitCurvedRegion did.
struct ConeRefitResult {
  bool changed = false;               // the region's rulings were replaced
  std::string skipped;                // why nothing was changed ("" when changed)
  std::vector<ConeSegment> segments;  // of the last run of free rulings refitted
  std::vector<PatternApex> apices;    // per segment
  int segmentCount = 0;               // over all runs
  int junctionCones = 0;              // gaps meshed as fans from a point of dS
  int sharedRulings = 0;              // neighbouring cones joined on one ruling
  int keptJunctions = 0;              // junctions left as the original rulings (re-aiming
                                      // the cones there would have crossed rulings)
  int addedVertices = 0;
};

// paper Sec. 6.2 (last paragraphs) + Fig. 15, thesis 2.5.2 (Fig. 2.19):
// remeshes curved region `region` of S_G (region.apex == -1, rulings
// between two boundary chains on dS) into generalized cones:
//  1. tangent plane per ruling: normal = mean faceNormal of the faces on
//     both sides (one face at the ends), w = -n . midpoint;
//  2. segmentRulings with eps_blaschke = params.epsBlaschke * paperLength
//     (disjoint segments, paper text), frame c = centroid of ruling
//     midpoints, L = 10 paperLength;
//  3. each segment's apex into the pattern (patternApex with
//     ApexMapping::InTangentPlane, see apexInPatternInPlane);
//  4. the gap before, between and after the cones becomes a junction cone:
//     a fan from the point b of dS where the neighbouring extreme rulings
//     cross (b is an endpoint of one of the original rulings bounding the
//     gap, chosen so the fan is valid), or a shared ruling when they
//     coincide; the region's first and last rulings (its borders with the
//     neighbouring regions) never change;
//  5. every cone's interior is resampled with rulings through its pattern
//     apex (parallel to its pattern direction at infinity), endpoints found
//     by intersecting those lines with the chains, spaced <= 1/rhoBound along
//     both chains (rulings are added and removed);
//  6. new endpoints are new vertices on dS (onBoundary, outlineSegment,
//     pattern = outlinePoint, position = curve.evaluate(s), velocity
//     interpolated along the chain); endpoints within 2% of the spacing of
//     a kept vertex snap to it; rebuildCurvedFaces(g, region).
// Handle, singular and corner vertices, and vertices other regions use,
// never move: they stay ruling endpoints (the ruling through them is aimed
// at the apex from them). Rulings with an endpoint off dS are kept as they
// are and split the region into runs refitted independently (a run needs
// two rulings). A region whose remeshing would produce crossing rulings or
// non-convex quads is left unchanged (`skipped` says why).
// Vertices no longer used stay in g.vertices (validate reports them): the
// caller runs compact(g) after refitting all regions.
// Throws std::out_of_range for a bad region index, std::invalid_argument
// for a flat region, paperLength <= 0 or params.rhoBound <= 0, and
// NumericalError (stage "cones") for non-finite results.
//
// tests/paper/test_cone_fit.cpp builds a 10 cm square sheet as three
// regions: flat | curved quad strip (rulings x = 3..7 cm, vertical in the
// pattern) | flat, bent as a slightly conical surface, and checks that the
// refitted rulings converge to the pattern apex.
ConeRefitResult refitCurvedRegion(GeometricMesh& g, int region, const BoundaryCurve& curve,
                                  const CrumpleParams& params, double paperLength);

// The largest compression (1 - |x_a x_b| / |p_a p_b|, 0 when stretched) of
// the rulings of curved region `region`: a ruling is a straight segment of
// the surface, so a new one shorter in space than in the pattern cuts across
// the sheet's bending. HybridSheet undoes a refit whose rulings come out
// compressed beyond the d-cone threshold (docs/CRUMPLING.md).
double worstRulingCompression(const GeometricMesh& g, int region);

}  // namespace crumple::paper
