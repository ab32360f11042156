#!/usr/bin/env python3
"""Writes samples/tear-cylinder/tear-cylinder.gltf: thesis Fig. 3.26, "a
piece of paper bent into a cylinder by two hands ... Then the two hands
rotate to flatten one border of the cylinder until creating a tear."

glTF 2.0, Y-up, metres, seconds; keys every 1/48 s from eased (C2
smootherstep) motions. The sheet: 10 cm x 10 cm, flat at y = 10 cm, pattern
u along world +X and v along world -Z. Two hands, each two fingers on one
side edge (positions and rotations: tangent-plane control), hold the left
and the right edge near its front and back corners:

    LeftFront (u=0, v=1.5)   LeftBack (u=0, v=8.5)
    RightFront (u=10, v=1.5) RightBack (u=10, v=8.5)

Motion (times in s):
  0.00-0.25  rest, flat.
  0.25-1.25  wrap: both hands roll their edges up and towards each other;
             the cross-section is a circular arc of the sheet's width whose
             angle grows to 180 degrees (a half tube, axis along Z).
  1.25-1.50  hold the half tube.
  1.50-2.75  flatten the front border: the front fingers unroll back to
             the flat sheet's front edge while the back fingers keep the
             tube. A developable sheet cannot do that without stretching
             between the hands' fingers: it tears.
  2.75-3.00  hold.
"""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from gltf_anim import handle_tracks, qaxis, ramp, write_sample  # noqa: E402

W = 0.10
L = 0.10
Y0 = 0.10
PHI = math.pi
T_WRAP = (0.25, 1.25)
T_FLAT = (1.50, 2.75)
T_END = 3.0
FINGERS = [("LeftFront", 0.0, 0.015), ("LeftBack", 0.0, 0.085),
           ("RightFront", W, 0.015), ("RightBack", W, 0.085)]


def pose(u, v, t):
    front = v < L / 2.0
    phi = PHI * ramp(t, T_WRAP) * (1.0 - (ramp(t, T_FLAT) if front else 0.0))
    if phi < 1e-9:
        alpha, x, y = 0.0, u - W / 2.0, 0.0
    else:
        r = W / phi
        alpha = (u - W / 2.0) / r
        x, y = r * math.sin(alpha), r * (1.0 - math.cos(alpha))
    return (x, Y0 + y, L / 2.0 - v), qaxis((0.0, 0.0, 1.0), alpha)


def main():
    write_sample(__file__, "tear-cylinder.gltf", *handle_tracks(FINGERS, pose, T_END))


if __name__ == "__main__":
    main()
