#pragma once
// Linear-algebra vocabulary shared by every module. SI units inside (metres,
// seconds, kilograms); see units.hpp for the scene-file conversions.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace crumple {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Mat2 = Eigen::Matrix2d;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Quat = Eigen::Quaterniond;

// A rigid pose: world = rotation * local + position.
struct Pose {
  Vec3 position = Vec3::Zero();
  Quat rotation = Quat::Identity();
};

}  // namespace crumple
