#pragma once
// Motion blur from a shot (pipeline-internal; docs/RENDERING.md "Motion
// blur", docs/PCACHE.md SHTR, VELO, PRPV): what a shot with a shutter
// writes into its cache, and the motion-blur steps of a cached frame's view.
#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_motion.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/render/view.hpp"

namespace crumple::pipeline::detail {

// The motion-blur time steps a frame's view has: the motion is linear over
// the shutter (x + v t), so its two ends give every time in it exactly.
inline constexpr std::size_t kShutterSteps = 2;

// The scene's shutter ([camera] shutter; closed without one).
cache::Shutter sceneShutter(const io::SceneSpec& scene);

// The header block SHTR of a scene with a shutter; nullopt without one.
std::optional<cache::ExtensionBlock> shutterBlock(const io::SceneSpec& scene);

// The sheet's velocities a frame's record carries (VELO): each vertex's
// mean velocity over the frame, (x_f - x_{f-1}) / frame duration, its
// position a frame earlier x_{f-1} being its material point's (the same
// pattern position) on the previous frame's mesh, whatever that mesh was:
// the crumpling model remeshes and the sheet tears between frames. Zero for
// the first frame. (The models' own state velocities are not the motion
// shown: the crumpling model's isometry projection and a vibrating torn
// sheet move the displayed surface differently; docs/RENDERING.md "Motion
// blur".)
class FrameVelocities {
 public:
  // The previous frame: the sheet of `frame` (its topology, pattern and
  // positions; on resume, the last cached frame).
  void remember(const cache::FrameRecord& frame);
  // Per vertex of `frame`, from the frame remembered before it (m/s).
  std::vector<Vec3> of(const cache::FrameRecord& frame, double frameDuration) const;

 private:
  bool known_ = false;
  std::vector<Vec2> pattern_;
  std::vector<std::array<int, 3>> triangles_;
  std::vector<Vec3> positions_;
};

// A frame's sub-frame motion for a scene with a shutter: VELO (the sheet's
// velocities, one per vertex of the frame's mesh) and, with mesh props,
// PRPV (each prop's motion's rate over the frame ending at t, from the
// animation: (M(t) - M(t - 1 / fps)) fps, as the sheet's velocities).
// Throws NumericalError (stage "cache") unless there is one velocity per
// vertex, each finite and within cache::kMaxSpeed.
void appendMotionBlocks(const io::SceneSpec& scene, const io::AnimationScene* animation, int frame,
                        double t, const std::vector<Vec3>& velocities, std::size_t vertices,
                        std::vector<cache::ExtensionBlock>& blocks);

// Fills view.sheetMotion and the moving mesh props' motion with their
// positions at the shutter's opening and closing (kShutterSteps), shutter
// in frames of 1 / fps seconds: the sheet's x + v t from the frame's VELO,
// a mesh prop's (M + t dM/dt) x from its PRPM and PRPV. A sheet (or prop)
// that does not move is left still. The frame's mesh props are
// view.props[firstMeshProp + i], their rest meshes meshPropsAtRest[i].
// Throws CorruptDataError for a frame without its blocks or with blocks
// that do not match it.
void addShutterMotion(render::RenderScene& view, const mesh::SheetMesh& sheet,
                      const cache::FrameRecord& frame, const cache::Shutter& shutter, double fps,
                      std::size_t firstMeshProp,
                      const std::vector<render::PropMesh>& meshPropsAtRest);

}  // namespace crumple::pipeline::detail
