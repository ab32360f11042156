#!/usr/bin/env python3
"""Writes samples/unload/unload.gltf: the handle curves of the unload sample
(paper Fig. 18, bottom row: "the creation of a singularity ... we get the same
effect of the sheet straightening when the constrained points at the back are
unloaded ... the singular vertex is persistent in the model even if the
surface is totally unloaded").

glTF 2.0, Y-up, metres, seconds; keys every 1/48 s (every frame at 24 fps and
every half frame), sampled from eased (C2 smootherstep) analytic motions.

The sheet: 10 cm x 10 cm, standing upright in the XY plane facing the camera
(+Z), bottom edge at y = 5 cm, centred on the Y axis: pattern u along world
+X, v along world +Y. Four handles hold the corners, each with tangent-plane
control:

    CornerTL (u=0, v=10)   CornerTR (u=10, v=10)    top: held throughout
    CornerBL (u=0, v=0)    CornerBR (u=10, v=0)     bottom: released (the
                                                    scene sets release_time)

Motion (times in s), the first-singularity experiment turned by 90 degrees,
then unloaded:
  0.00-0.25  rest.
  0.25-1.25  the top and bottom sides move 10 % closer (0.5 cm each); their
             tangent planes turn by gamma = 2 sqrt(delta) (up to 36 degrees,
             the end slope of a sine arch of extra length delta) so that the
             sheet bows towards the camera. Rotation about X: -gamma at the
             top, +gamma at the bottom.
  1.50-2.50  the top border's corners move 0.5 cm each towards each other
             (10 % of the border) and turn towards the camera by the same rule
             (rotation about the corner's local in-sheet Y axis): the arch
             cannot bend along this direction smoothly, a singular point
             appears near the top border.
  2.50-4.25  every node holds its pose. The scene releases the bottom handles
             at 2.75 s: the sheet hangs from the top corners and, in ~1.5 s,
             straightens (gravity pulls it down in its plane, the bow
             relaxes) while the singular vertex stays.

Run it to regenerate the file (the committed file is its output):
    python3 samples/unload/make_unload_gltf.py [OUT.gltf]
"""
import os
import sys

# Shared helpers (samples/gltf_anim.py).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from gltf_anim import (check_no_stretch, handle_tracks, qaxis, qmul, ramp,  # noqa: E402
                       squeeze_and_pinch, write_sample)

# ---- geometry and timing (metres, seconds, radians) ----
W = 0.10              # sheet side (u and v)
Y0 = 0.05             # height of the bottom edge
SQUEEZE = 0.10        # the top and bottom sides come 10 % closer
PINCH = 0.10          # then the top border is compressed by 10 %
T_SQUEEZE = (0.25, 1.25)
T_PINCH = (1.50, 2.50)
T_RELEASE = 2.75      # the scene's release_time of the bottom handles
T_END = 4.25

# (node name, u, v) in metres on the pattern
CORNERS = [("CornerBL", 0.0, 0.0), ("CornerBR", W, 0.0),
           ("CornerTL", 0.0, W), ("CornerTR", W, W)]


# ---- the motion ----
def corner_pose(u, v, t):
    """World position and rotation of the handle at pattern point (u, v)."""
    # The top and bottom sides move towards each other (y); the top border's
    # corners towards each other (x).
    top = v > W / 2.0
    y, x, gamma, psi = squeeze_and_pinch(v - W / 2.0, u - W / 2.0, W, SQUEEZE * ramp(t, T_SQUEEZE),
                                         PINCH * ramp(t, T_PINCH) if top else 0.0)
    # Both arches turn the in-sheet direction towards +Z: gamma the one across
    # Y (about X, the other way round), psi the one along the top border
    # (about Y).
    q = qmul(qaxis((1.0, 0.0, 0.0), -gamma), qaxis((0.0, 1.0, 0.0), psi))
    return (x, Y0 + W / 2.0 + y, 0.0), q


def main():
    times, tracks = handle_tracks(CORNERS, corner_pose, T_END)
    # No two held points ever get farther apart than on the pattern.
    check_no_stretch(times, tracks, CORNERS, (W, W), ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)))
    write_sample(__file__, "unload.gltf", times, tracks)


if __name__ == "__main__":
    main()
