#include "crumple/sim/colliders.hpp"

#include <fcl/fcl.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace crumple::sim {

namespace {

using BvhModel = fcl::BVHModel<fcl::OBBRSSd>;

// World <-> local of a pose.
Vec3 toLocal(const Pose& pose, const Vec3& p) {
  return pose.rotation.conjugate() * (p - pose.position);
}
Vec3 toWorld(const Pose& pose, const Vec3& p) { return pose.rotation * p + pose.position; }

// Signed distance, closest surface point and outward normal of an analytic
// shape, in its local frame.
struct LocalHit {
  double distance;
  Vec3 point;
  Vec3 normal;
};

LocalHit planeHit(const Vec3& p) { return {p.y(), Vec3(p.x(), 0.0, p.z()), Vec3::UnitY()}; }

LocalHit sphereHit(const Vec3& p, double radius) {
  const double r = p.norm();
  const Vec3 n = r > 0.0 ? Vec3(p / r) : Vec3::UnitY();
  return {r - radius, radius * n, n};
}

// Box centred on the origin: outside, the clamped point; inside, the nearest
// face (lowest axis index on ties).
LocalHit boxHit(const Vec3& p, const Vec3& h) {
  const Vec3 q = p.cwiseAbs() - h;
  if (q.maxCoeff() > 0.0) {
    const Vec3 c = p.cwiseMax(-h).cwiseMin(h);
    const Vec3 d = p - c;
    return {d.norm(), c, d / d.norm()};
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (q[k] > q[axis]) axis = k;
  Vec3 n = Vec3::Zero();
  n[axis] = p[axis] >= 0.0 ? 1.0 : -1.0;
  Vec3 c = p;
  c[axis] = n[axis] * h[axis];
  return {q[axis], c, n};
}

}  // namespace

std::array<double, 3> closestBarycentricOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                                   const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {1.0, 0.0, 0.0};
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {0.0, 1.0, 0.0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double s = d1 / (d1 - d3);
    return {1.0 - s, s, 0.0};
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {0.0, 0.0, 1.0};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double s = d2 / (d2 - d6);
    return {1.0 - s, 0.0, s};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0.0, 1.0 - s, s};
  }
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0.0)) return {1.0, 0.0, 0.0};  // degenerate triangle
  const double v = vb / denom, w = vc / denom;
  return {1.0 - v - w, v, w};
}

Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const std::array<double, 3> w = closestBarycentricOnTriangle(p, a, b, c);
  return w[0] * a + w[1] * b + w[2] * c;
}

struct ColliderSet::Impl {
  struct Collider {
    std::string name;
    ColliderShape shape;
    Pose pose;
    Pose previous;  // before the last setPose
    double friction = 0.0;
    std::shared_ptr<BvhModel> bvh;  // meshes only
  };
  std::vector<Collider> colliders;

  // The nearest mesh surface point within `margin` of local point q: FCL
  // finds the triangles a sphere of that radius touches, the exact distance
  // follows from each.
  std::optional<LocalHit> meshHit(const Collider& c, const Vec3& q, double margin) const {
    const fcl::CollisionObjectd mesh(c.bvh, fcl::Transform3d::Identity());
    fcl::Transform3d at = fcl::Transform3d::Identity();
    at.translation() = q;
    const fcl::CollisionObjectd probe(std::make_shared<fcl::Sphered>(margin), at);
    fcl::CollisionRequestd request(c.shape.triangles.size(), false);
    fcl::CollisionResultd result;
    fcl::collide(&probe, &mesh, request, result);
    std::optional<LocalHit> best;
    for (std::size_t i = 0; i < result.numContacts(); ++i) {
      const auto& contact = result.getContact(i);
      const int tri = contact.o1 == c.bvh.get() ? contact.b1 : contact.b2;
      if (tri < 0 || static_cast<std::size_t>(tri) >= c.shape.triangles.size()) continue;
      const auto& t = c.shape.triangles[static_cast<std::size_t>(tri)];
      const Vec3& a = c.shape.vertices[static_cast<std::size_t>(t[0])];
      const Vec3& b = c.shape.vertices[static_cast<std::size_t>(t[1])];
      const Vec3& d = c.shape.vertices[static_cast<std::size_t>(t[2])];
      const Vec3 x = closestPointOnTriangle(q, a, b, d);
      const Vec3 face = (b - a).cross(d - a).normalized();
      const double gap = (q - x).norm();
      // Behind the face is inside; on the face plane, the face normal.
      const double side = (q - x).dot(face) >= 0.0 ? 1.0 : -1.0;
      const Vec3 n = gap > 1e-12 ? Vec3(side * (q - x) / gap) : face;
      if (!best || gap < std::abs(best->distance)) best = LocalHit{side * gap, x, n};
    }
    return best;
  }
};

ColliderSet::ColliderSet() : impl_(std::make_unique<Impl>()) {}
ColliderSet::~ColliderSet() = default;
ColliderSet::ColliderSet(ColliderSet&&) noexcept = default;
ColliderSet& ColliderSet::operator=(ColliderSet&&) noexcept = default;

int ColliderSet::add(std::string name, ColliderShape shape, const Pose& pose, double friction) {
  const auto bad = [&](const std::string& what) {
    throw std::invalid_argument("collider '" + name + "': " + what);
  };
  if (!(friction >= 0.0) || !std::isfinite(friction)) bad("friction must be finite and >= 0");
  if (!pose.position.allFinite() || !pose.rotation.coeffs().allFinite() ||
      !(pose.rotation.norm() > 0.0))
    bad("pose is not finite");
  Impl::Collider c;
  switch (shape.kind) {
    case ColliderShape::Kind::Plane:
      break;
    case ColliderShape::Kind::Box:
      if (!shape.halfExtents.allFinite() || !(shape.halfExtents.minCoeff() > 0.0))
        bad("box extents must be finite and > 0");
      break;
    case ColliderShape::Kind::Sphere:
      if (!std::isfinite(shape.radius) || !(shape.radius > 0.0)) bad("radius must be > 0");
      break;
    case ColliderShape::Kind::Mesh: {
      if (shape.triangles.empty()) bad("mesh has no triangles");
      for (const Vec3& v : shape.vertices)
        if (!v.allFinite()) bad("mesh vertex is not finite");
      std::vector<fcl::Vector3d> points(shape.vertices.begin(), shape.vertices.end());
      std::vector<fcl::Triangle> tris;
      for (const auto& t : shape.triangles) {
        for (const int i : t)
          if (i < 0 || static_cast<std::size_t>(i) >= shape.vertices.size())
            bad("mesh triangle index out of range");
        tris.emplace_back(static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[1]),
                          static_cast<std::size_t>(t[2]));
      }
      c.bvh = std::make_shared<BvhModel>();
      c.bvh->beginModel(static_cast<int>(tris.size()), static_cast<int>(points.size()));
      c.bvh->addSubModel(points, tris);
      c.bvh->endModel();
      break;
    }
  }
  c.name = std::move(name);
  c.friction = friction;
  c.shape = std::move(shape);
  c.pose = pose;
  c.pose.rotation.normalize();
  c.previous = c.pose;
  impl_->colliders.push_back(std::move(c));
  return static_cast<int>(impl_->colliders.size()) - 1;
}

void ColliderSet::setPose(int collider, const Pose& pose) {
  if (collider < 0 || static_cast<std::size_t>(collider) >= impl_->colliders.size())
    throw std::out_of_range("ColliderSet::setPose: no collider " + std::to_string(collider));
  if (!pose.position.allFinite() || !pose.rotation.coeffs().allFinite() ||
      !(pose.rotation.norm() > 0.0))
    throw std::invalid_argument("ColliderSet::setPose: pose is not finite");
  auto& c = impl_->colliders[static_cast<std::size_t>(collider)];
  c.previous = c.pose;
  c.pose = pose;
  c.pose.rotation.normalize();
}

Vec3 ColliderSet::surfaceDisplacement(int collider, const Vec3& p) const {
  const auto& c = impl_->colliders.at(static_cast<std::size_t>(collider));
  return p - toWorld(c.previous, toLocal(c.pose, p));
}

std::size_t ColliderSet::size() const { return impl_->colliders.size(); }

double ColliderSet::friction(int collider) const {
  return impl_->colliders.at(static_cast<std::size_t>(collider)).friction;
}

const std::string& ColliderSet::name(int collider) const {
  return impl_->colliders.at(static_cast<std::size_t>(collider)).name;
}

std::optional<ColliderContact> ColliderSet::nearest(const Vec3& p, double margin) const {
  std::optional<ColliderContact> best;
  for (std::size_t i = 0; i < impl_->colliders.size(); ++i) {
    const auto& c = impl_->colliders[i];
    const Vec3 q = toLocal(c.pose, p);
    std::optional<LocalHit> hit;
    switch (c.shape.kind) {
      case ColliderShape::Kind::Plane:
        hit = planeHit(q);
        break;
      case ColliderShape::Kind::Box:
        hit = boxHit(q, c.shape.halfExtents);
        break;
      case ColliderShape::Kind::Sphere:
        hit = sphereHit(q, c.shape.radius);
        break;
      case ColliderShape::Kind::Mesh:
        if (margin > 0.0) hit = impl_->meshHit(c, q, margin);
        break;
    }
    if (!hit || hit->distance > margin) continue;
    if (best && !(hit->distance < best->distance)) continue;
    best = ColliderContact{static_cast<int>(i), hit->distance, toWorld(c.pose, hit->point),
                           c.pose.rotation * hit->normal};
  }
  return best;
}

std::vector<ColliderProbe> ColliderSet::probes() const {
  std::vector<ColliderProbe> out;
  for (std::size_t i = 0; i < impl_->colliders.size(); ++i) {
    const auto& c = impl_->colliders[i];
    const int id = static_cast<int>(i);
    if (c.shape.kind == ColliderShape::Kind::Sphere) {
      out.push_back({id, c.pose.position, c.shape.radius});
    } else if (c.shape.kind == ColliderShape::Kind::Box) {
      for (int k = 0; k < 8; ++k) {
        const Vec3& h = c.shape.halfExtents;
        const Vec3 corner((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(),
                          (k & 4) ? h.z() : -h.z());
        out.push_back({id, toWorld(c.pose, corner), 0.0});
      }
    }
  }
  return out;
}

}  // namespace crumple::sim
