#!/usr/bin/env python3
"""Writes samples/press-on-sphere/press-on-sphere.gltf: the handle curves of
the press-on-sphere sample (a sheet pushed down onto a ball resting on a
table, the way a cloth is draped over a ball) and the ball's mesh for the
renderer.

glTF 2.0, Y-up, metres, seconds; keys every 1/48 s (every frame at 24 fps and
every half frame), sampled from eased (C2 smootherstep) analytic motions.

The ball: radius R = 4 cm, centre (0, 4 cm, 0), resting on the table y = 0.
The scene makes it a sphere collider of radius R; the node Ball (static, no
animation) holds the UV-sphere mesh the scene shows as a mesh prop, drawn
BALL_INSET = 0.5 mm smaller: contacts act on the sheet's vertices, and the
flat triangles between vertices that lie on the ball cut its surface by up to
their sagitta (~0.3 mm on the scene's 1 cm mesh), which would show the red
ball through the white paper in specks.

The sheet: 15 cm x 15 cm, flat and horizontal, GAP = 3 mm above the top of
the ball (y = 8.3 cm), centred on it: pattern u along world +X, v along world
-Z (front side up). Four handles hold the corners, each with tangent-plane
control:

    CornerNW (u=0, v=15)   CornerNE (u=15, v=15)    far side (-Z)
    CornerSW (u=0, v=0)    CornerSE (u=15, v=0)     near side (+Z)

Every corner moves in the vertical plane through the ball's axis and its own
diagonal, so the four stay symmetric. The corner is placed as if the
diagonal wrapped the ball: in that plane the diagonal lies on the circle of
radius R + GAP from the top down to the angle alpha from the vertical, then
runs straight along the tangent there to the corner. Its length in all
shrinks from the pattern's half diagonal to SLACK = 95 % of it as alpha grows
(so the sheet is never pulled taut over the ball). The corner's tangent plane
turns down by alpha about the horizontal axis across the diagonal (the sheet
leaves the corner along that tangent). alpha = 0 is the flat start.

Motion (times in s):
  0.00-0.25  rest: the sheet sags a little under gravity, not yet touching.
  0.25-1.75  alpha goes from 0 to ALPHA_END = 60 degrees: the corners go down
             (from y = 8.3 cm to 1.3 cm, above the table) and in (from
             10.6 cm to 6.5 cm off the ball's axis). The middle lands on the
             ball; the sides between the corners, which cannot follow a
             sphere without compression, hang in folds.
  1.75-3.00  every node holds its pose: the sheet settles on the ball.
Every distance between held points only shrinks (check_no_stretch asserts
it), and the corners stay above the table.

Run it to regenerate the file (the committed file is its output):
    python3 samples/press-on-sphere/make_press_on_sphere_gltf.py [OUT.gltf]
"""
import math
import os
import sys

# Shared helpers (samples/gltf_anim.py).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from gltf_anim import (add_sphere_meshes, check_no_stretch, cross, handle_tracks, qaxis,  # noqa: E402
                       ramp, write_sample)

# ---- geometry and timing (metres, seconds, radians) ----
W = 0.15              # sheet side (u and v)
R = 0.04              # ball radius
C = (0.0, R, 0.0)     # ball centre: the ball rests on the table y = 0
GAP = 0.003           # the flat sheet starts 3 mm above the top of the ball
SLACK = 0.95          # the wrapped diagonal ends at 95 % of the pattern's half diagonal
ALPHA_END = math.radians(60.0)
BALL_INSET = 0.0005   # the ball is drawn this much smaller than the collider
T_PRESS = (0.25, 1.75)
T_END = 3.0
SPHERE_SEGMENTS = (48, 24)  # longitude x latitude of the ball's render mesh

# (node name, u, v) in metres on the pattern
CORNERS = [("CornerSW", 0.0, 0.0), ("CornerSE", W, 0.0),
           ("CornerNW", 0.0, W), ("CornerNE", W, W)]
U_AXIS = (1.0, 0.0, 0.0)
V_AXIS = (0.0, 0.0, -1.0)


# ---- the motion ----
def wrap(alpha):
    """(r, y): the corner's distance from the ball's axis and its height when
    the diagonal is wrapped down to angle alpha (see the docstring)."""
    rho = R + GAP
    slack = 1.0 - (1.0 - SLACK) * alpha / ALPHA_END  # the slack comes in with the wrap
    tail = slack * W / math.sqrt(2.0) - rho * alpha  # the straight part
    r = rho * math.sin(alpha) + tail * math.cos(alpha)
    y = C[1] + rho * math.cos(alpha) - tail * math.sin(alpha)
    return r, y


def corner_pose(u, v, t):
    """World position and rotation of the handle at pattern point (u, v)."""
    alpha = ALPHA_END * ramp(t, T_PRESS)
    # Horizontal unit direction from the ball's axis to this corner.
    x0 = (u - W / 2.0) * U_AXIS[0] + (v - W / 2.0) * V_AXIS[0]
    z0 = (u - W / 2.0) * U_AXIS[2] + (v - W / 2.0) * V_AXIS[2]
    n = math.hypot(x0, z0)
    d = (x0 / n, 0.0, z0 / n)
    r, y = wrap(alpha)
    # Turn the outward direction d down by alpha: axis up x d.
    axis = cross((0.0, 1.0, 0.0), d)
    return (C[0] + r * d[0], y, C[2] + r * d[2]), qaxis(axis, alpha)


def check(times, tracks):
    """No two held points ever get farther apart than on the pattern, and the
    corners stay above the table."""
    lowest = min(p[1] for _, positions, _ in tracks for p in positions)
    assert lowest > 0.005, "a corner comes within %.1f mm of the table" % (1000 * lowest)
    return check_no_stretch(times, tracks, CORNERS, (W, W), (U_AXIS, V_AXIS))


def main():
    times, tracks = handle_tracks(CORNERS, corner_pose, T_END)
    check(times, tracks)
    path = write_sample(__file__, "press-on-sphere.gltf", times, tracks)
    add_sphere_meshes(path, [("Ball", R - BALL_INSET, C)], SPHERE_SEGMENTS)


if __name__ == "__main__":
    main()
