#pragma once
// Sub-frame motion for motion blur (docs/PCACHE.md "Extension sub-blocks
// written by crumple", docs/RENDERING.md "Motion blur"): the shutter a shot
// was simulated for (header "SHTR"), and in every frame of such a shot the
// sheet's vertex velocities (frame "VELO") and the rates of the mesh
// props' motions (frame "PRPV"). A renderer moves every vertex
// linearly with its velocity over the shutter, x + v t: nothing from
// another frame is needed (its mesh may differ, and `crumple run` renders a
// frame before the next is simulated). A shot without a shutter writes none
// of them. Little-endian, on the core byte codec.
#include <array>
#include <optional>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/types.hpp"

namespace crumple::cache {

inline constexpr std::array<char, 4> kShutterTag{'S', 'H', 'T', 'R'};         // header block
inline constexpr std::array<char, 4> kVelocitiesTag{'V', 'E', 'L', 'O'};      // frame block
inline constexpr std::array<char, 4> kPropVelocitiesTag{'P', 'R', 'P', 'V'};  // frame block

// The shutter, in frames relative to a frame's time: open from `open` to
// `close`. Open (motion blur) when -1 <= open < close <= 1; {0, 0}: closed,
// no motion blur.
struct Shutter {
  double open = 0.0;
  double close = 0.0;
  bool on() const { return close > open; }
  bool operator==(const Shutter&) const = default;
};

// The largest velocity component a frame may carry (m/s): far beyond any
// paper, and it keeps x + v t finite in float and double arithmetic.
inline constexpr double kMaxSpeed = 1e9;

// "SHTR": f64 open, f64 close. std::invalid_argument unless the shutter is
// open (above).
ExtensionBlock encodeShutter(const Shutter& shutter);
// The header's shutter; nullopt without a SHTR block (no sub-frame motion
// in the frames). CorruptDataError for a malformed block, a second one, or
// a shutter that is not open within [-1, 1].
std::optional<Shutter> decodeShutter(const std::vector<ExtensionBlock>& headerBlocks);

// "VELO": u32 n, n x 3 f32, the sheet's velocity at each vertex of the
// frame's mesh (m/s, world space), rounded to float. std::invalid_argument
// for a component that is not finite or beyond kMaxSpeed.
ExtensionBlock encodeVelocities(const std::vector<Vec3>& velocities);
// nullopt without a VELO block. CorruptDataError for a malformed block, a
// second one, or a component that is not finite or beyond kMaxSpeed. The
// count is checked against the frame's vertices by cache::validate.
std::optional<std::vector<Vec3>> decodeVelocities(const std::vector<ExtensionBlock>& frameBlocks);

// "PRPV": u32 n; per mesh prop (the order of PRPM), 16 f64: the rate of
// change of its column-major 4x4 motion at the frame (1/s), so that
// the prop's vertex x of its rest mesh is at (M + t dM/dt) x a time t (s)
// after the frame. std::invalid_argument for a value that is not finite.
ExtensionBlock encodePropVelocities(const std::vector<Mat4>& derivatives);
// nullopt without a PRPV block. CorruptDataError for a malformed block, a
// second one or a value that is not finite.
std::optional<std::vector<Mat4>> decodePropVelocities(
    const std::vector<ExtensionBlock>& frameBlocks);

}  // namespace crumple::cache
