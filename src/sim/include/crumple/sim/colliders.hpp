#pragma once
// Rigid colliders the sheet must stay outside of (docs/CONTACTS.md: tables, props,
// fingers): analytic planes, boxes and spheres, and triangle meshes held as
// FCL BVH models, each with a pose updated per substep when animated.
// Proximity queries with a margin (the paper's thickness) are the contact
// primitive: FCL is the broad phase for meshes, the distances are computed
// exactly here (FCL's own signed distances are unreliable on overlap, see
// ../shared/DEPENDENCIES.md).
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::sim {

// A collider's shape in its own (local) frame.
struct ColliderShape {
  enum class Kind { Plane, Box, Sphere, Mesh };
  Kind kind = Kind::Plane;
  // Plane: the local XZ plane; the solid is the half-space y < 0 (normal +Y).
  Vec3 halfExtents = Vec3::Constant(0.05);  // Box: centred on the local origin
  double radius = 0.05;                     // Sphere: centred on the local origin
  // Mesh: local vertices and triangles. The solid side of a triangle is
  // behind its face (counter-clockwise front); open meshes (a table top)
  // work: only points within the margin of a triangle are found.
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

// The nearest collider surface point to a query point.
struct ColliderContact {
  int collider = -1;
  double distance = 0.0;        // signed distance from the surface, negative inside
  Vec3 point = Vec3::Zero();    // closest point on the collider's surface (world)
  Vec3 normal = Vec3::UnitY();  // unit, out of the collider (world)
};

// A point of a collider that can poke into the sheet between its vertices
// (vertex contacts alone let a ball pass through a coarse mesh): the centre
// of a sphere with its radius, the corners of a box with radius 0. Planes
// cannot (a plane meets a triangle first at a vertex); mesh colliders have
// none yet (their vertices against the sheet's faces are not tested).
struct ColliderProbe {
  int collider = -1;
  Vec3 point = Vec3::Zero();  // world, at the collider's current pose
  double radius = 0.0;
};

class ColliderSet {
 public:
  ColliderSet();
  ~ColliderSet();
  ColliderSet(ColliderSet&&) noexcept;
  ColliderSet& operator=(ColliderSet&&) noexcept;

  // Adds a collider and returns its index; `friction` is the Coulomb
  // coefficient of paper on it (>= 0). Throws std::invalid_argument for a
  // non-finite or degenerate shape (box extents or radius <= 0, a mesh
  // without triangles or with indices out of range) or a negative friction.
  int add(std::string name, ColliderShape shape, const Pose& pose, double friction = 0.0);
  double friction(int collider) const;
  // Moves an (animated) collider; its BVH is kept, only the pose changes.
  // The pose it had before is kept for surfaceDisplacement().
  void setPose(int collider, const Pose& pose);
  // How far the collider's material point now at world point p moved with
  // the last setPose (zero for a collider never moved): the motion of the
  // surface a vertex slides on, for friction against animated colliders.
  Vec3 surfaceDisplacement(int collider, const Vec3& p) const;
  std::size_t size() const;
  const std::string& name(int collider) const;

  // Among the colliders p is within `margin` of (or inside of: analytic
  // shapes; meshes only within the margin of a triangle), the one with the
  // lowest signed distance (the deepest penetration); nullopt when there is
  // none. Ties go to the lowest collider index (deterministic).
  std::optional<ColliderContact> nearest(const Vec3& p, double margin) const;
  // Every collider's probes at its current pose, in collider order.
  std::vector<ColliderProbe> probes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision
// Detection, 5.1.5), and its barycentric coordinates.
Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);
std::array<double, 3> closestBarycentricOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                                   const Vec3& c);

}  // namespace crumple::sim
