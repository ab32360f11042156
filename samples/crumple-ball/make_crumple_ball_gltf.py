#!/usr/bin/env python3
"""Writes samples/crumple-ball/crumple-ball.gltf: a finger holds an A4 sheet
up by its centre, four fingers at its corners gather it like an umbrella
that closes, and two hands (sphere colliders) crush it, pressing along X and
then along Z, as a person turns a ball of paper between the palms.

Nodes (metres, seconds, Y up; every node keeps the identity rotation):
  Pinch     the finger at the sheet's centre C0 = (0, 0.30, 0), still.
  CornerFL, CornerFR, CornerBR, CornerBL
            the corners. Each swings down about C0 in the vertical plane of
            its diagonal, to PHI_END under the horizontal, and comes 3 %
            nearer C0 than on the pattern (SLACK): ribs of an umbrella.
  HandA     the centre of one hand: H + r(t) d(t).
  HandB     the centre of the other: H - r(t) d(t), H = (0, 0.21, 0).
Each hand node carries a UV-sphere mesh of radius R - INSET for the props
(the collider, radius R, is in scene.toml).

  0.00-0.25  rest, flat.
  0.25-1.25  the umbrella closes, to 75 degrees.
  1.00-2.00  the hands press along X: r goes 0.20 -> 0.075 m, 6 cm apart.
  2.00-2.25  they back off to r = 0.17 m and swing round to Z.
  2.25-3.25  they press along Z: r 0.17 -> 0.075 m.
  3.25-3.75  hold.
Every move eases in and out (smootherstep). main() checks that no two held
points get farther apart than on the pattern, that the hands start clear of
the flat sheet, never touch a finger and stay above the ground y = 0.

Run it to regenerate the file (the committed file is its output):
    python3 samples/crumple-ball/make_crumple_ball_gltf.py [OUT.gltf]
"""
import math
import os
import sys

# Shared helpers (samples/gltf_anim.py).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from gltf_anim import (add_sphere_meshes, check_no_stretch, key_times, ramp, smoother,  # noqa: E402
                       write_sample)

# ---- geometry and timing (metres, seconds) ----
W, D = 0.21, 0.297          # A4, u along X and v along -Z
C0 = (0.0, 0.30, 0.0)       # the sheet's centre, held by the finger
H = (0.0, 0.21, 0.0)        # the point the hands close in on
# The four corner fingers (node, u, v on the pattern). Each corner swings
# down about the finger like the rib of an umbrella that closes, 3 % nearer
# the centre than on the pattern: the sheet becomes a cone with its apex at
# the finger (a d-cone, paper Sec. 4), ever narrower.
CORNERS = [("CornerFL", 0.0, 0.0), ("CornerFR", W, 0.0), ("CornerBR", W, D), ("CornerBL", 0.0, D)]
SLACK = 0.97
PHI_END = math.radians(75.0)  # the ribs' angle under the horizontal at the end
T_GATHER = (0.25, 1.25)
R = 0.045                   # a hand: a sphere 9 cm across
INSET = 0.0005              # the hands are drawn this much smaller than the colliders
R_WAIT, R_SWING = 0.20, 0.17
# (t0, t1, r0, r1, axis from, axis to): r eases r0 -> r1 and the axis turns
# from one to the other over [t0, t1].
X, Y, Z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
MOVES = [
    (1.00, 2.00, R_WAIT, 0.075, X, X),
    (2.00, 2.10, 0.075, R_SWING, X, X),
    (2.10, 2.25, R_SWING, R_SWING, X, Z),
    (2.25, 3.25, R_SWING, 0.075, Z, Z),
]
T_END = 3.75
SPHERE_SEGMENTS = (48, 24)


def hand_offset(t):
    """r(t) d(t): HandA's offset from H (HandB's is its negative)."""
    r, d = R_WAIT, X
    for t0, t1, r0, r1, a, b in MOVES:
        if t < t0:
            break
        s = smoother((t - t0) / (t1 - t0))
        r = r0 + (r1 - r0) * s
        theta = 0.5 * math.pi * s if a != b else 0.0
        d = tuple(math.cos(theta) * p + math.sin(theta) * q for p, q in zip(a, b)) if a != b else a
    return tuple(r * c for c in d)


def corner_position(u, v, t):
    """A corner on its rib: from its place on the flat sheet (u along X, v
    along -Z) it turns down about the finger by phi and comes SLACK nearer."""
    rel = (u - W / 2.0, 0.0, D / 2.0 - v)
    rho = math.hypot(rel[0], rel[2])
    d = (rel[0] / rho, rel[2] / rho)
    s = ramp(t, T_GATHER)
    phi, r = PHI_END * s, rho * (1.0 - (1.0 - SLACK) * s)
    return (C0[0] + r * math.cos(phi) * d[0], C0[1] - r * math.sin(phi),
            C0[2] + r * math.cos(phi) * d[1])


def tracks():
    times = key_times(T_END)
    a = [tuple(h + o for h, o in zip(H, hand_offset(t))) for t in times]
    b = [tuple(h - o for h, o in zip(H, hand_offset(t))) for t in times]
    out = [("Pinch", [C0] * len(times), None)]
    for name, u, v in CORNERS:
        out.append((name, [corner_position(u, v, t) for t in times], None))
    return times, out + [("HandA", a, None), ("HandB", b, None)]


def check(times, tracks_):
    """The fingers never pull the sheet longer than its pattern; the hands
    start clear of the flat sheet, never touch a finger, and stay above the
    ground."""
    fingers = [t for t in tracks_ if not t[0].startswith("Hand")]
    pattern = {"Pinch": (W / 2.0, D / 2.0), **{name: (u, v) for name, u, v in CORNERS}}
    still = [(name, positions, [(0.0, 0.0, 0.0, 1.0)] * len(positions)) for name, positions, _ in fingers]
    check_no_stretch(times, still, pattern, (W, D), ((1.0, 0.0, 0.0), (0.0, 0.0, -1.0)), patch=0.0)
    hands = [positions for name, positions, _ in tracks_ if name.startswith("Hand")]
    for positions in hands:
        p = positions[0]
        # distance from the sphere's centre to the flat sheet's rectangle
        dx = max(abs(p[0] - C0[0]) - W / 2.0, 0.0)
        dz = max(abs(p[2] - C0[2]) - D / 2.0, 0.0)
        assert math.sqrt(dx * dx + (p[1] - C0[1]) ** 2 + dz * dz) > R + 0.02
        for k, (t, q) in enumerate(zip(times, positions)):
            assert q[1] > R, "a hand goes under the ground at %.2f s" % t
            for name, finger, _ in fingers:
                assert math.dist(q, finger[k]) > R + 0.01, "a hand reaches %s at %.2f s" % (name, t)


def main():
    times, tr = tracks()
    check(times, tr)
    path = write_sample(__file__, "crumple-ball.gltf", times, tr)
    add_sphere_meshes(path, [("HandA", R - INSET, None), ("HandB", R - INSET, None)],
                      SPHERE_SEGMENTS)


if __name__ == "__main__":
    main()
