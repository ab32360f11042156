#!/usr/bin/env python3
"""Writes samples/fold-over/fold-over.gltf: the handle curves of the fold-over
sample (a sheet lying on a table is folded onto itself, a plate presses the
fold, the hand lets go, the plate lifts) and the plate's motion and mesh.

glTF 2.0, Y-up, metres, seconds; keys every 1/48 s (every frame at 24 fps and
every half frame), sampled from eased (C2 smootherstep) analytic motions.

The sheet: 15 cm x 10 cm, flat on the table (y = 0), one thickness H above
it, centred on the Y axis: pattern u along world +X, v along world -Z (front
side up). Four handles:

    CornerNW (u=0, v=10)   CornerNE (u=15, v=10)    far side (-Z)
    CornerSW (u=0, v=0)    CornerSE (u=15, v=0)     near side (+Z)

The left corners (u = 0) hold the left short edge on the table all along (a
hand keeping the sheet down); they never move. The right corners carry the
right short edge over, with tangent-plane control, and let go at T_RELEASE
(the scene's release_time).

The fold: the right edge moves as the free end of a sheet that lies flat up
to u = U_FOLD, then bends round a circle of radius R_LOOP by the angle phi
(about the fold axis, world Z), then runs straight to the edge. The edge's
tangent plane turns by phi about +Z; phi goes from 0 (flat) to pi (the edge
turned over, the flap upside down above the left half). U_FOLD = W/2 -
pi R_LOOP / 2 puts the loop's middle on the sheet's middle.

The presser: node Presser, a plate PLATE = 8 x 1 x 12 cm (x, y, z) with its
bottom face on the node, no rotation; the scene makes it a box collider and
shows the node's box mesh (written here) as a mesh prop. It covers
x = -7.5 ... 0.5 cm: the folded stack and the fold's loop, and z = -6 ... 6 cm
(the sheet's whole depth).

Motion (times in s):
  0.00-0.25  rest.
  0.25-1.50  phi goes 0 -> pi: the right edge rises (up to ~9 cm), travels
             over the fold axis and comes down, upside down, 2 R_LOOP above
             the left edge.
  1.50-2.00  the edge goes down onto the left half, to EDGE_X, one thickness
             (the contact distance) plus SLACK_H above the bottom layer, and
             its tangent turns on by ALPHA = 30 degrees: the flap comes down
             onto the bottom half along a slope and touches it at its edge
             only. (Laid down flat, the held edge would be a clamp: bending
             the flap up to the loop right next to it presses the flap into
             the bottom layer harder than the contacts can take.)
  1.90-2.50  the plate comes down from 12 cm to PRESS_Y = 1.2 cm above the
             table: it flattens the fold's loop (crest ~2.8 cm high) without
             squeezing the layers against each other.
  2.75       the right corners let go (release_time): the flap slides down
             under the plate and lies on the bottom half; the plate keeps
             the loop from springing open.
  3.25-4.50  the plate lifts slowly back to 12 cm; the loop follows it and
             the fold springs open (the paper is bent, not creased): the
             sheet lies flat again.
The right edge only ever comes nearer the left one, and the right corners
keep their 10 cm apart (check_no_stretch asserts no two held points get
farther apart than on the pattern).

Run it to regenerate the file (the committed file is its output):
    python3 samples/fold-over/make_fold_over_gltf.py [OUT.gltf]
"""
import math
import os
import sys

# Shared helpers (samples/gltf_anim.py).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from gltf_anim import (add_meshes, check_no_stretch, handle_tracks, qaxis, ramp,  # noqa: E402
                       write_sample)

# ---- geometry and timing (metres, seconds, radians) ----
W = 0.15              # sheet length (u, along X)
D = 0.10              # sheet depth (v, along -Z)
H = 9.0e-5            # paper thickness (office-70gsm): the contact distance
SLACK_H = 0.5 * H     # what the laid-down edge keeps above contact
X0 = -W / 2.0         # world x of the left edge
Z0 = D / 2.0          # world z of pattern v = 0
R_LOOP = 0.0125       # radius of the fold's loop while the edge turns over
U_FOLD = W / 2.0 - math.pi * R_LOOP / 2.0
X_FOLD = X0 + U_FOLD  # where the loop starts on the bottom layer (x ~ -2 cm)
EDGE_X = -0.065       # the edge's x once laid down (1 cm inside the left edge)
EDGE_Y = 2.0 * H + SLACK_H  # its height: the bottom layer at H, one H above it
ALPHA = math.radians(30.0)  # the laid-down edge's tangent rises this much towards the loop
PLATE = (0.08, 0.01, 0.12)  # the presser plate's sides (x, y, z)
PRESS_X = -0.035      # the plate's middle: it covers x = -7.5 ... 0.5 cm
PRESS_Y = 0.012       # where it stops: the loop's crest (~2.8 cm) pressed to 1.2 cm
PRESS_UP = 0.12       # where it waits before and goes after
T_FOLD = (0.25, 1.50)
T_LOWER = (1.50, 2.00)
T_PRESS = (1.90, 2.50)
T_RELEASE = 2.75      # the scene's release_time of the right corners
T_LIFT = (3.25, 4.50)
T_END = 4.5

# (node name, u, v) in metres on the pattern
CORNERS = [("CornerSW", 0.0, 0.0), ("CornerSE", W, 0.0),
           ("CornerNW", 0.0, D), ("CornerNE", W, D)]
U_AXIS = (1.0, 0.0, 0.0)
V_AXIS = (0.0, 0.0, -1.0)


# ---- the motion ----
def fold_edge(phi):
    """(x, y) of the right edge when the sheet bends by phi round the loop."""
    tail = W - U_FOLD - R_LOOP * phi          # the straight flap
    x = X_FOLD + R_LOOP * math.sin(phi) + tail * math.cos(phi)
    y = H + R_LOOP * (1.0 - math.cos(phi)) + tail * math.sin(phi)
    return x, y


def corner_pose(u, v, t):
    """World position and rotation of the handle at pattern point (u, v)."""
    z = Z0 - v
    if u < W / 2.0:                           # the left corners stay put
        return (X0, H, z), (0.0, 0.0, 0.0, 1.0)
    phi = math.pi * ramp(t, T_FOLD)
    x, y = fold_edge(phi)
    s = ramp(t, T_LOWER)
    x += s * (EDGE_X - x)
    y += s * (EDGE_Y - y)
    return (x, y, z), qaxis((0.0, 0.0, 1.0), phi + ALPHA * s)


def presser_y(t):
    """Height of the plate's bottom face."""
    if t < T_LIFT[0]:
        return PRESS_UP + ramp(t, T_PRESS) * (PRESS_Y - PRESS_UP)
    return PRESS_Y + ramp(t, T_LIFT) * (PRESS_UP - PRESS_Y)


def tracks():
    times, out = handle_tracks(CORNERS, corner_pose, T_END)
    out.append(("Presser", [(PRESS_X, presser_y(t), 0.0) for t in times], None))
    return times, out


def check(times, tracks_):
    """No two held points ever get farther apart than on the pattern; the
    edge lands inside the bottom layer, above its contact distance, and the
    laid-down flap is no longer than the sheet that is left for it; the
    plate stays clear of the flap until the fold is over and covers the
    stack and the loop."""
    assert X0 < EDGE_X < X_FOLD
    assert EDGE_Y > 2.0 * H
    highest = max(p[1] for _, positions, _ in tracks_[:len(CORNERS)] for p in positions)
    assert PRESS_UP - highest > 0.02, "the flap comes within 2 cm of the waiting plate"
    assert PRESS_X - PLATE[0] / 2.0 <= X0 + 1e-12 and PRESS_X + PLATE[0] / 2.0 > X_FOLD + R_LOOP
    assert PLATE[2] > D
    flap = W - U_FOLD - math.pi * R_LOOP
    assert math.hypot(X_FOLD - EDGE_X, 2.0 * R_LOOP) < flap
    return check_no_stretch(times, tracks_[:len(CORNERS)], CORNERS, (W, D), (U_AXIS, V_AXIS))


# ---- the presser's render mesh ----
def presser_mesh():
    """The box mesh of the plate's size, its bottom face on the node, as
    gltf_anim.add_meshes takes it (node Presser, for the scene's mesh
    prop)."""
    hx, hz = PLATE[0] / 2.0, PLATE[2] / 2.0
    y0, y1 = 0.0, PLATE[1]
    # Six faces, four vertices each (flat normals), counter-clockwise seen
    # from outside.
    faces = [
        ((1, 0, 0), [(hx, y0, hz), (hx, y0, -hz), (hx, y1, -hz), (hx, y1, hz)]),
        ((-1, 0, 0), [(-hx, y0, -hz), (-hx, y0, hz), (-hx, y1, hz), (-hx, y1, -hz)]),
        ((0, 1, 0), [(-hx, y1, hz), (hx, y1, hz), (hx, y1, -hz), (-hx, y1, -hz)]),
        ((0, -1, 0), [(-hx, y0, -hz), (hx, y0, -hz), (hx, y0, hz), (-hx, y0, hz)]),
        ((0, 0, 1), [(-hx, y0, hz), (hx, y0, hz), (hx, y1, hz), (-hx, y1, hz)]),
        ((0, 0, -1), [(hx, y0, -hz), (-hx, y0, -hz), (-hx, y1, -hz), (hx, y1, -hz)]),
    ]
    positions, normals, indices = [], [], []
    for normal, quad in faces:
        base = len(positions) // 3
        for p in quad:
            positions.extend(p)
            normals.extend(normal)
        indices.extend((base, base + 1, base + 2, base, base + 2, base + 3))
    return ("Presser", positions, normals, indices, ([-hx, y0, -hz], [hx, y1, hz]), None)


def main():
    times, tr = tracks()
    check(times, tr)
    add_meshes(write_sample(__file__, "fold-over.gltf", times, tr), [presser_mesh()])


if __name__ == "__main__":
    main()
