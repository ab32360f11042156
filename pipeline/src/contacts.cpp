#include "crumple/pipeline/contacts.hpp"

#include <algorithm>

#include "crumple/pipeline/inspect.hpp"

namespace crumple::pipeline {

SceneColliders::SceneColliders(const io::SceneSpec& scene, const io::AnimationScene* animation)
    : scene_(scene), animation_(animation) {
  for (const auto& c : scene.colliders) {
    sim::ColliderShape shape;
    Pose pose;
    pose.position = c.position;
    switch (c.kind) {
      case io::ColliderSpec::Kind::Plane:
        shape.kind = sim::ColliderShape::Kind::Plane;
        pose.rotation = Quat::FromTwoVectors(Vec3::UnitY(), c.normal);
        break;
      case io::ColliderSpec::Kind::Box:
        shape.kind = sim::ColliderShape::Kind::Box;
        shape.halfExtents = 0.5 * c.size;
        break;
      case io::ColliderSpec::Kind::Sphere:
        shape.kind = sim::ColliderShape::Kind::Sphere;
        shape.radius = c.radius;
        break;
      case io::ColliderSpec::Kind::Mesh: {
        const auto m = animation->mesh(c.node);
        shape.kind = sim::ColliderShape::Kind::Mesh;
        shape.vertices = m->vertices;
        shape.triangles = m->triangles;
        pose = Pose{};
        break;
      }
    }
    set_.add(c.name, std::move(shape), pose, c.friction);
    info_.push_back({c.name, c.material, c.friction});
  }
  moveTo(scene.frameTime(scene.frameStart));
}

void SceneColliders::moveTo(double t) {
  for (std::size_t i = 0; i < scene_.colliders.size(); ++i) {
    const auto& c = scene_.colliders[i];
    if (c.node.empty()) continue;
    const Pose pt = animation_->worldPose(c.node, t);
    Pose pose;
    if (c.kind == io::ColliderSpec::Kind::Mesh) {
      const Pose p0 = animation_->worldPose(c.node, 0.0);
      pose.rotation = pt.rotation * p0.rotation.conjugate();
      pose.position = pt.position - pose.rotation * p0.position;
    } else {
      pose.rotation = pt.rotation;
      pose.position = pt.position + pt.rotation * c.position;
    }
    set_.setPose(static_cast<int>(i), pose);
  }
}

sim::ContactOptions contactOptionsOf(const io::SceneSpec& scene, SceneColliders& colliders) {
  sim::ContactOptions o;
  o.distance = scene.paper.material.thickness;
  if (!colliders.empty()) {
    o.colliders = &colliders.set();
    o.moveColliders = [&colliders](double t) { colliders.moveTo(t); };
  }
  switch (scene.contact.self) {
    case io::ContactSpec::Self::Off:
      o.self = sim::SelfContactMode::Off;
      break;
    case io::ContactSpec::Self::On:
      o.self = sim::SelfContactMode::On;
      break;
    case io::ContactSpec::Self::Auto:
      o.self = sim::SelfContactMode::Auto;
      break;
  }
  o.selfFriction = scene.friction.at("paper");
  return o;
}

double contactDepth(const sim::ContactOptions& contact, const cache::FrameRecord& record) {
  const double d = contact.distance;
  std::vector<char> free(record.positions.size(), 1);
  for (int v : record.handleVertices)
    if (v >= 0 && static_cast<std::size_t>(v) < free.size()) free[static_cast<std::size_t>(v)] = 0;
  double depth = 0.0;
  if (contact.colliders != nullptr) {
    for (std::size_t i = 0; i < record.positions.size(); ++i) {
      if (free[i] == 0) continue;
      if (const auto c = contact.colliders->nearest(record.positions[i], d))
        depth = std::max(depth, (d - c->distance) / d);
    }
  }
  if (contact.self != sim::SelfContactMode::Off)
    depth = std::max(depth, selfPenetration(record, d, &free).depth);
  return depth;
}

}  // namespace crumple::pipeline
