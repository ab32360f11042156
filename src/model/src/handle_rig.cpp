#include "crumple/model/handle_rig.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>

#include "crumple/core/error.hpp"

namespace crumple::model {
namespace {

// Boundary vertices of the pattern: those on an edge with one triangle.
std::vector<bool> boundaryVertices(const mesh::SheetMesh& sheet) {
  std::vector<bool> onBoundary(sheet.vertexCount(), false);
  for (const auto& e : mesh::buildEdges(sheet))
    if (!e.interior())
      onBoundary[static_cast<std::size_t>(e.v[0])] = onBoundary[static_cast<std::size_t>(e.v[1])] =
          true;
  return onBoundary;
}

// The rotation that best turns the flat offsets onto where the points are
// now, both in the node's frame (Kabsch 1976), det = +1.
Mat3 bestTurn(const std::vector<Vec3>& flat, const std::vector<Vec3>& now) {
  Mat3 cov = Mat3::Zero();
  for (std::size_t k = 0; k < now.size(); ++k) cov += flat[k] * now[k].transpose();
  const Eigen::JacobiSVD<Mat3> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 fix = Mat3::Identity();
  fix(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixV() * fix * svd.matrixU().transpose();
}

}  // namespace

std::vector<int> tangentNeighbours(const mesh::SheetMesh& sheet, int vertex, int count) {
  const auto ring = mesh::vertexNeighbours(sheet, vertex);
  if (ring.empty()) return {};  // a vertex in no triangle has no tangent plane
  const auto onBoundary = boundaryVertices(sheet);
  const Vec2 p = sheet.pattern[static_cast<std::size_t>(vertex)];
  if (count <= 0) {
    int boundaryNeighbours = 0;
    for (int n : ring) boundaryNeighbours += onBoundary[static_cast<std::size_t>(n)] ? 1 : 0;
    if (!onBoundary[static_cast<std::size_t>(vertex)]) {
      count = 4;
    } else {
      // A corner's one-ring spans less than pi in the pattern; a border's spans pi.
      double minAngle = 10.0, maxAngle = -10.0;
      const Vec2 c = [&] {
        Vec2 s = Vec2::Zero();
        for (int n : ring) s += (sheet.pattern[static_cast<std::size_t>(n)] - p).normalized();
        return s.normalized().eval();
      }();
      for (int n : ring) {
        const Vec2 d = (sheet.pattern[static_cast<std::size_t>(n)] - p).normalized();
        const double a = std::atan2(c.x() * d.y() - c.y() * d.x(), c.dot(d));
        minAngle = std::min(minAngle, a);
        maxAngle = std::max(maxAngle, a);
      }
      count = (maxAngle - minAngle) < 0.75 * std::numbers::pi ? 2 : 3;
    }
  }
  count = std::clamp(count, 2, 4);
  count = std::min<int>(count, static_cast<int>(ring.size()));
  // Greedy farthest-direction selection: start with the neighbour of largest
  // distance (lowest index on ties), then repeatedly add the one whose
  // direction is angularly farthest from those chosen.
  std::vector<int> chosen;
  std::vector<Vec2> dirs;
  for (int n : ring) dirs.push_back((sheet.pattern[static_cast<std::size_t>(n)] - p).normalized());
  std::size_t first = 0;
  for (std::size_t i = 1; i < ring.size(); ++i) {
    const bool iBoundary = onBoundary[static_cast<std::size_t>(ring[i])];
    const bool fBoundary = onBoundary[static_cast<std::size_t>(ring[first])];
    if (iBoundary && !fBoundary) first = i;
  }
  std::vector<bool> taken(ring.size(), false);
  taken[first] = true;
  chosen.push_back(ring[first]);
  while (static_cast<int>(chosen.size()) < count) {
    std::size_t best = ring.size();
    double bestScore = -1.0;
    for (std::size_t i = 0; i < ring.size(); ++i) {
      if (taken[i]) continue;
      double minAngle = 10.0;
      for (std::size_t j = 0; j < ring.size(); ++j)
        if (taken[j])
          minAngle = std::min(minAngle, std::acos(std::clamp(dirs[i].dot(dirs[j]), -1.0, 1.0)));
      if (minAngle > bestScore + 1e-12) {
        bestScore = minAngle;
        best = i;
      }
    }
    taken[best] = true;
    chosen.push_back(ring[best]);
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

HandleRig::HandleRig(const io::SceneSpec& scene, const io::AnimationScene* animation,
                     const mesh::SheetMesh& sheet, double t0)
    : animation_(animation) {
  std::map<int, std::string> usedVertices;
  for (const auto& spec : scene.handles) {
    if (animation == nullptr)
      throw InputError(scene.file,
                       "handle '" + spec.name + "' needs an animation file ([scene] animation)");
    if (!animation->hasNode(spec.node))
      throw InputError(scene.file, "handle '" + spec.name + "': node '" + spec.node +
                                       "' does not exist in " + animation->file());
    BoundHandle h;
    h.name = spec.name;
    h.node = spec.node;
    const Pose pose = animation->worldPose(spec.node, t0);
    h.vertex = spec.patternPoint ? mesh::nearestPatternVertex(sheet, *spec.patternPoint)
                                 : mesh::nearestVertex(sheet, pose.position);
    constexpr double kBindTolerance = 1e-6;  // m
    const auto vertex = static_cast<std::size_t>(h.vertex);
    if (spec.patternPoint && (sheet.pattern[vertex] - *spec.patternPoint).norm() > kBindTolerance)
      warnings_.push_back("handle '" + h.name +
                          "' holds the mesh vertex nearest its pattern point, " +
                          std::to_string((sheet.pattern[vertex] - *spec.patternPoint).norm()) +
                          " m away (a finer [sheet] max_edge brings it closer)");
    if (const double jump = (sheet.positions[vertex] - pose.position).norm(); jump > kBindTolerance)
      warnings_.push_back(
          "handle '" + h.name + "': node '" + h.node + "' is " + std::to_string(jump) +
          " m from its sheet vertex at the first frame; the vertex starts on the node");
    if (auto [it, inserted] = usedVertices.emplace(h.vertex, h.name); !inserted)
      throw InputError(scene.file, spec.patternPoint ? spec.patternLine : spec.nodeLine,
                       spec.patternPoint ? "handles.pattern" : "handles.node",
                       "handles '" + it->second + "' and '" + h.name +
                           "' bind the same sheet vertex " + std::to_string(h.vertex) +
                           " (their points are closer than the mesh's spacing; move one, or "
                           "give [sheet] a finer max_edge)");
    if (spec.releaseTime) {
      h.releases = true;
      h.releaseTime = *spec.releaseTime;
    }
    if (spec.tangentControl && spec.patchRadius > 0.0) {
      h.tangentCount = 0;
      h.patchRadius = spec.patchRadius;
      h.bindRotation = pose.rotation;
      bindPatch(h, sheet, t0);
    } else if (spec.tangentControl) {
      h.tangentCount = spec.tangentVertices;
      h.tangentVertices = tangentNeighbours(sheet, h.vertex, spec.tangentVertices);
      h.bindRotation = pose.rotation;
      const Vec3 base = sheet.positions[static_cast<std::size_t>(h.vertex)];
      for (int n : h.tangentVertices) {
        if (usedVertices.count(n) != 0)
          throw InputError(scene.file, "handle '" + h.name + "': tangent-plane vertex " +
                                           std::to_string(n) + " is already held by handle '" +
                                           usedVertices[n] + "'");
        // Offset expressed in the node's frame at bind time.
        h.tangentOffsets.push_back(pose.rotation.conjugate() *
                                   (sheet.positions[static_cast<std::size_t>(n)] - base));
      }
      for (int n : h.tangentVertices) usedVertices.emplace(n, h.name);
    }
    handles_.push_back(std::move(h));
    bindTargets_.push_back(pose.position);
    bindPattern_.push_back(spec.patternPoint.value_or(sheet.pattern[vertex]));
  }
  reachLimit_ = scene.sheet.kind == io::SheetSpec::Kind::Rectangle && !scene.tearEnabled;
}

Vec3 HandleRig::target(std::size_t handle, double t) const {
  return animation_->worldPose(handles_[handle].node, t).position;
}

std::vector<Vec3> HandleRig::heldTargets(double t, std::vector<char>& held) const {
  const std::size_t n = handles_.size();
  std::vector<Vec3> nodes(n), out(n);
  held.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& h = handles_[i];
    held[i] = h.releases && t >= h.releaseTime ? 0 : 1;
    nodes[i] = out[i] = target(i, t);
  }
  if (!reachLimit_) return out;
  // A convex pattern's geodesics are straight: two held points of an
  // untearable sheet stay within their pattern distance. Violated pairs are
  // resolved in sweeps (Gauss-Seidel), the handle whose node has moved
  // farther from its first-frame position yielding onto the other's sphere.
  constexpr int kSweeps = 16;
  for (int sweep = 0; sweep < kSweeps; ++sweep) {
    bool moved = false;
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = i + 1; j < n; ++j) {
        if (!held[i] || !held[j]) continue;
        const double reach = (1.0 + kReachSlack) * (bindPattern_[i] - bindPattern_[j]).norm();
        const double d = (out[j] - out[i]).norm();
        if (d <= reach) continue;
        const bool iYields =
            (nodes[i] - bindTargets_[i]).norm() > (nodes[j] - bindTargets_[j]).norm();
        const std::size_t y = iYields ? i : j, o = iYields ? j : i;
        out[y] = out[o] + (out[y] - out[o]) * (reach / d);
        moved = true;
      }
    if (!moved) break;
  }
  return out;
}

double HandleRig::reachExcess(std::size_t handle, double t) const {
  if (!reachLimit_) return 0.0;
  std::vector<char> held;
  const std::vector<Vec3> targets = heldTargets(t, held);
  return held[handle] ? (targets[handle] - target(handle, t)).norm() : 0.0;
}

void HandleRig::pins(double t, std::vector<sim::Pin>& out) const {
  out.clear();
  std::vector<char> held;
  const std::vector<Vec3> targets = heldTargets(t, held);
  for (std::size_t i = 0; i < handles_.size(); ++i) {
    if (!held[i]) continue;
    const auto& h = handles_[i];
    const Quat rotation =
        h.tangentVertices.empty() ? Quat::Identity() : animation_->worldPose(h.node, t).rotation;
    out.push_back({h.vertex, targets[i]});
    for (std::size_t k = 0; k < h.tangentVertices.size(); ++k)
      out.push_back({h.tangentVertices[k], targets[i] + rotation * h.tangentOffsets[k]});
  }
}

void HandleRig::rebind(const mesh::SheetMesh& sheet, const std::vector<int>& handleVertices,
                       double t) {
  if (handleVertices.size() != handles_.size())
    throw std::invalid_argument("HandleRig::rebind: one vertex per handle");
  for (std::size_t h = 0; h < handles_.size(); ++h) handles_[h].vertex = handleVertices[h];
  rebindTangents(sheet, t);
}

void HandleRig::rebindTangents(const mesh::SheetMesh& sheet, double t) {
  std::vector<char> held(sheet.vertexCount(), 0);
  for (const auto& h : handles_) held[static_cast<std::size_t>(h.vertex)] = 1;
  for (auto& h : handles_) {
    if (h.tangentCount < 0) continue;
    h.tangentVertices.clear();
    h.tangentOffsets.clear();
    h.patch.clear();
    if (h.releases && t >= h.releaseTime) continue;
    if (h.patchRadius > 0.0) {
      bindPatch(h, sheet, t);
      continue;
    }
    const Pose pose = animation_->worldPose(h.node, t);
    // Where the tangent vertices are now, in the node's frame, and where the
    // pattern puts them around the handle vertex (in its plane, z = 0).
    std::vector<Vec3> now;
    std::vector<Vec3> flat;
    const Vec2 centre = sheet.pattern[static_cast<std::size_t>(h.vertex)];
    for (int n : tangentNeighbours(sheet, h.vertex, h.tangentCount)) {
      if (held[static_cast<std::size_t>(n)]) continue;  // another handle's vertex
      held[static_cast<std::size_t>(n)] = 1;
      h.tangentVertices.push_back(n);
      now.push_back(pose.rotation.conjugate() *
                    (sheet.positions[static_cast<std::size_t>(n)] - pose.position));
      const Vec2 d = sheet.pattern[static_cast<std::size_t>(n)] - centre;
      flat.emplace_back(d.x(), d.y(), 0.0);
    }
    // The offsets are the pattern's, rigidly turned to fit where the vertices
    // are (Kabsch): the tangent plane follows the sheet, but the pins never
    // freeze a stretched or compressed neighbourhood into the handle.
    const Mat3 turn = bestTurn(flat, now);
    for (const Vec3& f : flat) h.tangentOffsets.push_back(turn * f);
  }
}

void HandleRig::rebindPatches(const mesh::SheetMesh& sheet, double t) {
  for (auto& h : handles_) {
    if (h.patchRadius <= 0.0) continue;
    h.patch.clear();
    if (h.releases && t >= h.releaseTime) continue;
    bindPatch(h, sheet, t);
  }
}

// The patch points of h in `sheet`: each one's triangle and weights, and its
// flat offset from the handle in the pattern turned to fit where the points
// are now in the node's frame (Kabsch), as the tangent-plane pins are: the
// patch follows the sheet from one rebinding to the next.
void HandleRig::bindPatch(BoundHandle& h, const mesh::SheetMesh& sheet, double t) const {
  h.patch.clear();
  const Pose pose = animation_->worldPose(h.node, t);
  const Vec2 centre = sheet.pattern[static_cast<std::size_t>(h.vertex)];
  std::vector<Vec3> now, flat;
  constexpr int kDirections = 6;
  for (int k = 0; k < kDirections; ++k) {
    const double a = 2.0 * std::numbers::pi * k / kDirections;
    const Vec2 q = centre + h.patchRadius * Vec2(std::cos(a), std::sin(a));
    const auto [triangle, w] = mesh::locatePattern(sheet, q);
    if (triangle < 0) continue;  // beyond the sheet's border
    const auto& T = sheet.triangles[static_cast<std::size_t>(triangle)];
    Vec3 x = Vec3::Zero();
    for (int c = 0; c < 3; ++c)
      x += w(c) * sheet.positions[static_cast<std::size_t>(T[static_cast<std::size_t>(c)])];
    now.push_back(pose.rotation.conjugate() * (x - pose.position));
    flat.emplace_back(q.x() - centre.x(), q.y() - centre.y(), 0.0);
    h.patch.push_back({triangle, w, Vec3::Zero()});
  }
  const Mat3 turn = bestTurn(flat, now);
  for (std::size_t k = 0; k < flat.size(); ++k) h.patch[k].offset = turn * flat[k];
}

void HandleRig::grips(double t, double stiffness, std::vector<sim::Grip>& out) const {
  out.clear();
  if (std::none_of(handles_.begin(), handles_.end(),
                   [](const BoundHandle& h) { return !h.patch.empty(); }))
    return;
  std::vector<char> held;
  const std::vector<Vec3> targets = heldTargets(t, held);
  for (std::size_t i = 0; i < handles_.size(); ++i) {
    const auto& h = handles_[i];
    if (!held[i] || h.patch.empty()) continue;
    const Quat rotation = animation_->worldPose(h.node, t).rotation;
    for (const auto& p : h.patch)
      out.push_back({p.triangle, p.weights, targets[i] + rotation * p.offset, stiffness, h.vertex});
  }
}

void HandleRig::snap(double t, std::vector<Vec3>& positions) const {
  std::vector<sim::Pin> p;
  pins(t, p);
  for (const auto& pin : p) positions[static_cast<std::size_t>(pin.vertex)] = pin.position;
}

void HandleRig::saveState(StateWriter& out) const {
  out.tag("RIGS");
  out.count(handles_.size());
  for (const auto& h : handles_) {
    out.i32(h.vertex);
    out.i32s(h.tangentVertices);
    out.vec3s(h.tangentOffsets);
    for (int k = 0; k < 4; ++k) out.f64(h.bindRotation.coeffs()[k]);
    out.count(h.patch.size());
    for (const auto& p : h.patch) {
      out.i32(p.triangle);
      out.vec3s({p.weights, p.offset});
    }
  }
}

void HandleRig::restoreState(StateReader& in) {
  in.tag("RIGS");
  if (in.count(0) != handles_.size()) in.fail("the handles do not match the scene's");
  for (auto& h : handles_) {
    h.vertex = in.i32();
    h.tangentVertices = in.i32s();
    h.tangentOffsets = in.vec3s();
    for (int k = 0; k < 4; ++k) h.bindRotation.coeffs()[k] = in.f64();
    if (h.tangentVertices.size() != h.tangentOffsets.size())
      in.fail("a handle's tangent vertices do not match their offsets");
    h.patch.resize(in.count(4));
    for (auto& p : h.patch) {
      p.triangle = in.i32();
      const std::vector<Vec3> v = in.vec3s();
      if (p.triangle < 0 || v.size() != 2) in.fail("a handle's patch point is malformed");
      p.weights = v[0];
      p.offset = v[1];
    }
  }
}

}  // namespace crumple::model
