#!/usr/bin/env python3
"""Writes samples/first-singularity/first-singularity.gltf: the handle curves
of the first-singularity sample, the validation experiment of the paper's
Sec. 7.1 and Fig. 17: "we moved the two opposite sides of an undamaged square
sheet of paper closer to each other by a factor 10%. Then we applied an
orthogonal constraint on one of the borders until a singular point appeared."

glTF 2.0, Y-up, metres, seconds; keys every 1/48 s (every frame at 24 fps and
every half frame), sampled from eased (C2 smootherstep) analytic motions.

The sheet: 10 cm x 10 cm (L_paper = 10 cm, as in the paper's validation),
standing upright in the XY plane facing the camera (+Z), bottom edge at
y = 5 cm, centred on the Y axis: pattern u along world +X, v along world +Y.
Upright, gravity acts in the sheet's plane and does not bend it, so the bow
below is the one the handles ask for (a 10 cm sheet of 70 g/m^2 paper lying
horizontally sags under its own weight as much as it bows: w L^3 / B ~ 2.7).
Four handles hold the corners, each with tangent-plane control:

    CornerTL (u=0, v=10)   CornerTR (u=10, v=10)    top,    y = 15 cm
    CornerBL (u=0, v=0)    CornerBR (u=10, v=0)     bottom, y = 5 cm

The left side (u = 0: BL, TL) and the right side (u = 10: BR, TR) are the
two held opposite sides; the left side is also the border that gets the
orthogonal constraint.

Motion (times in s):
  0.00-0.25  rest.
  0.25-1.50  the two sides move 10 % closer: each 0.5 cm towards the middle
             (1 cm in total). So that the sheet bows towards the camera as a
             smooth arch, the held sides' tangent planes turn by
             gamma = 2 sqrt(delta) (delta the compression fraction, up to 0.1:
             gamma = 36 degrees), the end slope of the sine-shaped arch whose
             extra length is delta (pinned ends: w = A sin(pi x / L),
             delta ~ (pi A / 2 L)^2). Rotation about Y, -gamma on the left,
             +gamma on the right.
  1.50-1.75  hold the arch.
  1.75-3.25  orthogonal constraint on the left border: its two corners move
             towards each other along it (Y), 0.5 cm each, 10 % of the
             border, and the border's tangent turns towards the camera by the
             same rule (rotation about the corner's local in-sheet X axis,
             after the arch's). The arch is curved across this direction, so
             it cannot bend along it smoothly: a singular point (d-cone)
             appears near the left border.
  3.25-4.00  hold the end pose.

Run it to regenerate the file (the committed file is its output):
    python3 samples/first-singularity/make_first_singularity_gltf.py [OUT.gltf]
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
SQUEEZE = 0.10        # the two held sides come 10 % closer
PINCH = 0.10          # then the left border is compressed by 10 %
T_SQUEEZE = (0.25, 1.50)
T_PINCH = (1.75, 3.25)
T_END = 4.00

# (node name, u, v) in metres on the pattern
CORNERS = [("CornerBL", 0.0, 0.0), ("CornerBR", W, 0.0),
           ("CornerTL", 0.0, W), ("CornerTR", W, W)]


# ---- the motion ----
def corner_pose(u, v, t):
    """World position and rotation of the handle at pattern point (u, v)."""
    # The sides move towards each other (x); the left border's corners towards
    # each other (y).
    left = u < W / 2.0
    x, y, gamma, psi = squeeze_and_pinch(u - W / 2.0, v - W / 2.0, W, SQUEEZE * ramp(t, T_SQUEEZE),
                                         PINCH * ramp(t, T_PINCH) if left else 0.0)
    # Both arches turn the in-sheet direction towards +Z: gamma the one across
    # X (about Y), psi the one along the left border (about X, the other way
    # round).
    q = qmul(qaxis((0.0, 1.0, 0.0), gamma), qaxis((1.0, 0.0, 0.0), -psi))
    return (x, Y0 + W / 2.0 + y, 0.0), q


def main():
    times, tracks = handle_tracks(CORNERS, corner_pose, T_END)
    # No two held points ever get farther apart than on the pattern.
    check_no_stretch(times, tracks, CORNERS, (W, W), ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)))
    write_sample(__file__, "first-singularity.gltf", times, tracks)


if __name__ == "__main__":
    main()
