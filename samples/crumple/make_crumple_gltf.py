#!/usr/bin/env python3
"""Writes samples/crumple/crumple.gltf: the handle curves of the crumple
sample (paper Fig. 22, second row: "a full crumpling animation where more
than twenty singular vertices are progressively generated"; Table V reports
up to 15 interior singular vertices for it).

glTF 2.0, Y-up, metres, seconds; keys every 1/48 s (every frame at 24 fps and
every half frame), sampled from eased (C2 smootherstep) analytic motions.

The sheet: 10 cm x 10 cm, flat at y = 10 cm, centred on the Y axis, pattern
u along world +X, v along world -Z (front edge v = 0 at z = +5 cm). Eight
handles, all with tangent-plane control, hold the corners and the edge
midpoints (pattern point (u, v) in cm):

    BackL (0,10)    MidB (5,10)    BackR (10,10)        z = -5 cm
    MidL  (0,5)                    MidR  (10,5)
    FrontL (0,0)    MidF (5,0)     FrontR (10,0)        z = +5 cm

Each handle's position is (with c the sheet's centre and (x, z) its pattern
offset from c)
    c + Ry(yaw) (sx x, 0, sz z) + (0, lift, 0)
and its rotation Ry(yaw) Rx(rx) Rz(rz) R(tilt), R(tilt) turning the handle's
inward direction up (tilt > 0) or down (tilt < 0) about its border's axis
(for a corner: the axis across its diagonal). sx, sz are shared by all
handles, so horizontal distances only shrink; the three handles of a side
turn together (rx, rz), so the side stays straight; lift, tilt and yaw are
per handle (PLAN). Four overlapping phases compress the sheet from ever more
sides, so singular points keep appearing:
  A 0.25-1.75  left and right sides move in: sx 1 -> 0.7. Each side's three
               handles turn 35 degrees about Z so that the sheet arches up
               across X; MidF and MidB rise 1.5 cm (their borders arch too).
  B 1.00-2.50  front and back sides move in: sz 1 -> 0.7. Each side's three
               handles turn 35 degrees about X so that the sheet arches down
               across Z; MidL and MidR sink 1 cm: a saddle, which no
               developable surface makes smoothly.
  C 2.00-3.50  the corners take over: FrontL and BackR rise 1.5 cm and fold
               up 40 degrees, FrontR and BackL sink 0.5 cm and fold down 25
               degrees; the corners yaw +15 degrees about the vertical, the
               midpoints -5 degrees (a twist).
  D 2.00-4.00  everything squeezes further in: sx, sz -> 0.45.
  4.00-4.50    hold.
main() asserts that no two held points (handle vertices and their tangent
neighbours) ever get farther apart than on the pattern: the handles only
ever compress the sheet, never stretch it. There are no contacts yet
(README), so the sheet may pass through itself at the end.

Run it to regenerate the file (the committed file is its output):
    python3 samples/crumple/make_crumple_gltf.py [OUT.gltf]
"""
import math
import os
import sys

# Shared helpers (samples/gltf_anim.py).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from gltf_anim import (check_no_stretch, cross, handle_tracks, qaxis, qmul, qrot,  # noqa: E402
                       ramp, write_sample)

# ---- geometry and timing (metres, seconds, radians) ----
W = 0.10            # sheet side
Y0 = 0.10           # height of the flat sheet
T_A = (0.25, 1.75)
T_B = (1.00, 2.50)
T_C = (2.00, 3.50)
T_D = (2.00, 4.00)
T_END = 4.50
DEG = math.pi / 180.0

# (node name, u, v) in metres on the pattern
HANDLES = [("FrontL", 0.0, 0.0), ("MidF", W / 2, 0.0), ("FrontR", W, 0.0),
           ("MidR", W, W / 2), ("BackR", W, W), ("MidB", W / 2, W),
           ("BackL", 0.0, W), ("MidL", 0.0, W / 2)]

# Per handle, per phase: what the handle has reached at the phase's end:
#   lift  m, up;
#   rx    rad, turn about world X (front/back side arches: the sheet's
#         in-plane direction towards the middle goes up or down);
#   rz    rad, turn about world Z (left/right side arches);
#   tilt  rad, turn about the handle's own border axis (for a corner, the
#         axis across its diagonal), inward direction up if > 0;
#   yaw   rad, turn about the vertical (also turns the handle's offset from
#         the centre: a twist).
# A side's three handles turn together, so that the side stays straight.
LEFT, RIGHT = ("FrontL", "MidL", "BackL"), ("FrontR", "MidR", "BackR")
FRONT, BACK = ("FrontL", "MidF", "FrontR"), ("BackL", "MidB", "BackR")
PLAN = {name: {} for name, _, _ in HANDLES}


def plan(phase, names, **moves):
    for name in names:
        PLAN[name].setdefault(phase, {}).update(moves)


ARCH = 35 * DEG
plan("A", LEFT, rz=ARCH)                  # left and right sides: arch up across X
plan("A", RIGHT, rz=-ARCH)
plan("A", ("MidF", "MidB"), lift=0.015)   # the front and back borders arch up too
plan("B", FRONT, rx=-ARCH)                # front and back sides: arch down across Z
plan("B", BACK, rx=ARCH)
plan("B", ("MidL", "MidR"), lift=-0.01)   # the left and right borders sink: a saddle
plan("C", ("FrontL", "BackR"), lift=0.015, tilt=40 * DEG, yaw=15 * DEG)  # corners fold up
plan("C", ("FrontR", "BackL"), lift=-0.005, tilt=-25 * DEG, yaw=15 * DEG)  # and down
plan("C", ("MidF", "MidR", "MidB", "MidL"), yaw=-5 * DEG)  # against the corners' twist
SPANS = {"A": T_A, "B": T_B, "C": T_C}


# ---- the motion ----
def scales(t):
    a, b, d = ramp(t, T_A), ramp(t, T_B), ramp(t, T_D)
    sx = 1.0 - 0.30 * a - 0.25 * d
    sz = 1.0 - 0.30 * b - 0.25 * d
    return sx, sz


def handle_pose(name, u, v, t):
    """World position and rotation of handle `name` at pattern point (u, v)."""
    x, z = u - W / 2.0, W / 2.0 - v
    total = {"lift": 0.0, "rx": 0.0, "rz": 0.0, "tilt": 0.0, "yaw": 0.0}
    for phase, moves in PLAN[name].items():
        e = ramp(t, SPANS[phase])
        for key, value in moves.items():
            total[key] += value * e
    sx, sz = scales(t)
    q_yaw = qaxis((0.0, 1.0, 0.0), total["yaw"])
    p = qrot(q_yaw, (sx * x, 0.0, sz * z))
    # Tilt about the border's axis: cross(inward, up) turns `inward` upwards.
    n = math.hypot(x, z)
    inward = (-x / n, 0.0, -z / n)
    axis = cross(inward, (0.0, 1.0, 0.0))
    q = qmul(q_yaw, qmul(qaxis((1.0, 0.0, 0.0), total["rx"]),
                         qmul(qaxis((0.0, 0.0, 1.0), total["rz"]), qaxis(axis, total["tilt"]))))
    return (p[0], Y0 + total["lift"] + p[1], p[2]), q


def main():
    names = {(u, v): name for name, u, v in HANDLES}  # handle_pose finds a handle's PLAN by name
    times, tracks = handle_tracks(HANDLES, lambda u, v, t: handle_pose(names[(u, v)], u, v, t),
                                  T_END)
    # No two held points ever get farther apart than on the pattern.
    check_no_stretch(times, tracks, HANDLES, (W, W), ((1.0, 0.0, 0.0), (0.0, 0.0, -1.0)))
    write_sample(__file__, "crumple.gltf", times, tracks)


if __name__ == "__main__":
    main()
