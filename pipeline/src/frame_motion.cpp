// Motion blur from a shot: the cache's sub-frame motion written by the
// frame record stage, read back into a frame's view (frame_motion.hpp).
#include "frame_motion.hpp"

#include <string>

#include "crumple/core/error.hpp"
#include "pattern_locator.hpp"

namespace crumple::pipeline::detail {

cache::Shutter sceneShutter(const io::SceneSpec& scene) {
  if (!scene.camera.motionBlur()) return {};
  return {scene.camera.shutterOpen, scene.camera.shutterClose};
}

std::optional<cache::ExtensionBlock> shutterBlock(const io::SceneSpec& scene) {
  const cache::Shutter shutter = sceneShutter(scene);
  if (!shutter.on()) return std::nullopt;
  return cache::encodeShutter(shutter);
}

void FrameVelocities::remember(const cache::FrameRecord& frame) {
  pattern_ = frame.pattern;
  triangles_ = frame.triangles;
  positions_ = frame.positions;
  known_ = true;
}

std::vector<Vec3> FrameVelocities::of(const cache::FrameRecord& frame, double frameDuration) const {
  const std::size_t n = frame.positions.size();
  std::vector<Vec3> velocities(n, Vec3::Zero());
  if (!known_ || triangles_.empty()) return velocities;
  const PatternLocator previous(pattern_, triangles_);
  // A triangle of each vertex (its first): the side of a tear the vertex is on.
  std::vector<int> incident(n, -1);
  for (std::size_t t = 0; t < frame.triangles.size(); ++t)
    for (const int v : frame.triangles[t])
      if (incident[static_cast<std::size_t>(v)] < 0)
        incident[static_cast<std::size_t>(v)] = static_cast<int>(t);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& p = frame.pattern[i];
    // Looked up a thousandth of the way into its triangle, so that a vertex
    // on a tear's lip finds the previous frame's triangle on its own side
    // (the lips' twins share their pattern positions), then p's own
    // coordinates in it.
    Vec2 into = p;
    if (const int t = incident[i]; t >= 0) {
      Vec2 centroid = Vec2::Zero();
      for (const int v : frame.triangles[static_cast<std::size_t>(t)])
        centroid += frame.pattern[static_cast<std::size_t>(v)] / 3.0;
      into = p + 1e-3 * (centroid - p);
    }
    const PatternLocator::Hit hit = previous.locate(into);
    if (hit.triangle < 0) continue;
    // Outside the previous sheet (a pattern point that moved out of it): its
    // nearest point there.
    const auto w = hit.inside ? previous.barycentric(hit.triangle, p).w : hit.w;
    const auto& tri = triangles_[static_cast<std::size_t>(hit.triangle)];
    Vec3 before = Vec3::Zero();
    for (int k = 0; k < 3; ++k)
      before += w[static_cast<std::size_t>(k)] *
                positions_[static_cast<std::size_t>(tri[static_cast<std::size_t>(k)])];
    velocities[i] = (frame.positions[i] - before) / frameDuration;
  }
  return velocities;
}

namespace {

// The rate of a mesh prop's motion M(t) = W(t) W(0)^-1 (W: the node's
// world matrix) over the frame ending at t, (M(t) - M(t - dt)) / dt: its
// vertices' mean velocities over the frame, as the sheet's are.
Mat4 motionDerivative(const io::AnimationScene& animation, const std::string& node, double t,
                      double frameDuration) {
  const Mat4 rest = animation.worldMatrix(node, 0.0).inverse();
  return (animation.worldMatrix(node, t) - animation.worldMatrix(node, t - frameDuration)) * rest /
         frameDuration;
}

}  // namespace

void appendMotionBlocks(const io::SceneSpec& scene, const io::AnimationScene* animation, int frame,
                        double t, const std::vector<Vec3>& velocities, std::size_t vertices,
                        std::vector<cache::ExtensionBlock>& blocks) {
  if (velocities.size() != vertices)
    throw NumericalError("cache", frame,
                         std::to_string(velocities.size()) + " velocities for " +
                             std::to_string(vertices) + " vertices (motion blur)");
  for (std::size_t i = 0; i < velocities.size(); ++i)
    if (!velocities[i].allFinite() || velocities[i].cwiseAbs().maxCoeff() > cache::kMaxSpeed)
      throw NumericalError("cache", frame,
                           "the velocity of vertex " + std::to_string(i) +
                               " is not finite or beyond 1e9 m/s (motion blur)");
  blocks.push_back(cache::encodeVelocities(velocities));
  if (animation == nullptr) return;
  std::vector<Mat4> derivatives;
  for (const auto& p : scene.props)
    if (!p.node.empty())
      derivatives.push_back(motionDerivative(*animation, p.node, t, 1.0 / scene.fps));
  if (!derivatives.empty()) blocks.push_back(cache::encodePropVelocities(derivatives));
}

namespace {

std::string frameName(const cache::FrameRecord& frame) {
  return "frame " + std::to_string(frame.frame) + " of the cache: ";
}

// The positions at each of the shutter's steps, p + v t, or nothing when no
// vertex moves.
std::vector<std::vector<Vec3>> linearSteps(const std::vector<Vec3>& positions,
                                           const std::vector<Vec3>& velocities, double t0,
                                           double t1, const cache::FrameRecord& frame,
                                           const char* what) {
  bool moves = false;
  for (const Vec3& v : velocities) moves = moves || !v.isZero(0.0);
  if (!moves) return {};
  std::vector<std::vector<Vec3>> steps(kShutterSteps, positions);
  for (std::size_t k = 0; k < kShutterSteps; ++k) {
    const double t = t0 + (t1 - t0) * static_cast<double>(k) / (kShutterSteps - 1);
    for (std::size_t i = 0; i < positions.size(); ++i) {
      steps[k][i] += t * velocities[i];
      if (!steps[k][i].allFinite())
        throw CorruptDataError(frameName(frame) + what + " " + std::to_string(i) +
                               " leaves the finite numbers within the shutter");
    }
  }
  return steps;
}

}  // namespace

void addShutterMotion(render::RenderScene& view, const mesh::SheetMesh& sheet,
                      const cache::FrameRecord& frame, const cache::Shutter& shutter, double fps,
                      std::size_t firstMeshProp,
                      const std::vector<render::PropMesh>& meshPropsAtRest) {
  const double t0 = shutter.open / fps, t1 = shutter.close / fps;  // s
  const auto velocities = cache::decodeVelocities(frame.extensions);
  if (!velocities) throw CorruptDataError(frameName(frame) + "no sheet velocities (VELO)");
  if (velocities->size() != sheet.positions.size())
    throw CorruptDataError(frameName(frame) + "VELO holds " + std::to_string(velocities->size()) +
                           " velocities for " + std::to_string(sheet.positions.size()) +
                           " vertices");
  view.sheetMotion = linearSteps(sheet.positions, *velocities, t0, t1, frame, "sheet vertex");
  if (meshPropsAtRest.empty()) return;
  const auto derivatives = cache::decodePropVelocities(frame.extensions);
  if (!derivatives || derivatives->size() != meshPropsAtRest.size() ||
      view.props.size() != firstMeshProp + meshPropsAtRest.size())
    throw CorruptDataError(frameName(frame) + "the prop velocities (PRPV) do not match its props");
  for (std::size_t i = 0; i < meshPropsAtRest.size(); ++i) {
    // The prop at the frame (M x, placed by the frame view) and its vertices' velocities.
    render::PropMesh& prop = view.props[firstMeshProp + i];
    const Mat4& d = (*derivatives)[i];
    std::vector<Vec3> velocity;
    for (const Vec3& x : meshPropsAtRest[i].vertices)
      velocity.push_back((d * x.homogeneous()).head<3>());
    if (velocity.size() != prop.vertices.size())
      throw CorruptDataError(frameName(frame) + "prop '" + prop.name + "' does not match its mesh");
    prop.motion = linearSteps(prop.vertices, velocity, t0, t1, frame, "prop vertex");
  }
}

}  // namespace crumple::pipeline::detail
