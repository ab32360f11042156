#!/usr/bin/env python3
"""Writes samples/cylinder-fold/cylinder-fold.gltf: the handle curves of the
cylinder-fold sample (paper Fig. 1: "Interactive folding of a virtual sheet of
paper, after a cylindrical wrap"; Sec. 7.3: "after smoothly wrapping the sheet
into a cylindrical shape, a second bending is applied orthogonally to the
cylinder axis. The resulting shape exhibits sharp singularities").

glTF 2.0, Y-up, metres, seconds; keys every 1/48 s (every frame at 24 fps and
every half frame), sampled from eased (C2 smootherstep) analytic motions, so
the linear interpolation between keys is smooth to the eye.

The sheet: 10 cm x 10 cm, lying flat at y = 10 cm, centred on the Y axis,
pattern u along world +X, v along world -Z (front edge v = 0 at z = +5 cm,
nearest the camera). Four handles hold the corners, each with tangent-plane
control (the node's rotation turns the corner's two neighbour vertices):

    CornerFL (u=0, v=0)    CornerFR (u=10, v=0)     front, z = +5 cm
    CornerBL (u=0, v=10)   CornerBR (u=10, v=10)    back,  z = -5 cm

Motion (times in s):
  0.00-0.25  rest.
  0.25-1.75  wrap: the left and right edges (u = 0 and u = 10) roll up and
             towards each other. At wrap angle phi the cross-section is a
             circular arc of length 10 cm, radius 10/phi, whose bottom line
             (u = 5) stays at y = 10 cm; each corner sits on the arc and its
             tangent plane turns with it (rotation about Z by the arc angle,
             +-phi/2). phi grows from 0 to 240 degrees: a "C"-shaped tube,
             open at the top, axis along Z, radius 2.39 cm.
  1.75-2.25  hold the cylinder.
  2.25-3.75  bend orthogonally to the cylinder axis: the two ends of the tube
             (z = +-5 cm) turn about the X axis by +-beta (beta up to 15
             degrees) as rigid cross-sections, so that the tube's bottom line
             becomes a circular arc of length 10 cm bulging down (the ends
             rise). The open top of the tube, where the held edges are, is on
             the inside of the bend: the edges' corners come 20 % closer
             (10 cm -> 8.0 cm). A cylinder cannot bend along its axis without
             stretching, so the compressed top must buckle: singular points
             (d-cones) form along the held edges.
  3.75-4.25  hold the final pose.

Run it to regenerate the file (the committed file is its output):
    python3 samples/cylinder-fold/make_cylinder_fold_gltf.py [OUT.gltf]
samples/paper-types runs the same motion (make_paper_types_gltf.py imports
this script's tracks()).
"""
import math
import os
import sys

# Shared helpers (samples/gltf_anim.py).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from gltf_anim import (check_no_stretch, handle_tracks, qaxis, qmul, qrot, ramp,  # noqa: E402
                       write_sample)

# ---- geometry and timing (metres, seconds, radians) ----
W = 0.10                 # sheet width (u, across the cylinder)
L = 0.10                 # sheet height (v, along the cylinder axis)
Y0 = 0.10                # height of the flat sheet and of the tube's bottom line
PHI = math.radians(240)  # final wrap angle of the cross-section
BETA = math.radians(15)  # final half-angle of the axis bend
T_WRAP = (0.25, 1.75)
T_BEND = (2.25, 3.75)
T_END = 4.25

# (node name, u, v) in metres on the pattern
CORNERS = [("CornerFL", 0.0, 0.0), ("CornerFR", W, 0.0),
           ("CornerBL", 0.0, L), ("CornerBR", W, L)]


# ---- the motion ----
def corner_pose(u, v, t):
    """World position and rotation of the handle at pattern point (u, v)."""
    phi = PHI * ramp(t, T_WRAP)
    beta = BETA * ramp(t, T_BEND)
    # Cross-section: an arc of length W and angle phi, bottom (u = W/2) at the origin.
    if phi < 1e-9:
        alpha, d = 0.0, (u - W / 2.0, 0.0, 0.0)
    else:
        r = W / phi
        alpha = (u - W / 2.0) / r
        d = (r * math.sin(alpha), r * (1.0 - math.cos(alpha)), 0.0)
    # Axis bend: the bottom line becomes an arc of length L and angle 2 beta,
    # centre above; the end at z = s L/2 turns about X by -s beta.
    s = 1.0 if v < L / 2.0 else -1.0
    if beta < 1e-9:
        b = (0.0, Y0, s * L / 2.0)
    else:
        rb = L / (2.0 * beta)
        b = (0.0, Y0 + rb * (1.0 - math.cos(beta)), s * rb * math.sin(beta))
    q_end = qaxis((1.0, 0.0, 0.0), -s * beta)
    p = qrot(q_end, d)
    position = (b[0] + p[0], b[1] + p[1], b[2] + p[2])
    rotation = qmul(q_end, qaxis((0.0, 0.0, 1.0), alpha))
    return position, rotation


def tracks():
    """The corners' keys, (times, tracks) for write_sample, checked: no two
    held points ever get farther apart than on the pattern."""
    times, out = handle_tracks(CORNERS, corner_pose, T_END)
    check_no_stretch(times, out, CORNERS, (W, L), ((1.0, 0.0, 0.0), (0.0, 0.0, -1.0)))
    return times, out


def main():
    write_sample(__file__, "cylinder-fold.gltf", *tracks())


if __name__ == "__main__":
    main()
