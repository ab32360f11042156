#!/usr/bin/env python3
"""Writes samples/slide-on-table/slide-on-table.gltf: the handle curves of the
slide-on-table sample (thesis Fig. 4.4: "the back edge of the sheet is held
while the front edge slides toward it, thereby curving the paper; then, when
the back edge is released and the front edge is pinched, the back edge stands
up").

glTF 2.0, Y-up, metres, seconds; keys every 1/48 s (every frame at 24 fps and
every half frame), sampled from eased (C2 smootherstep) analytic motions.

The sheet: 21 cm x 14.8 cm (A5), lying flat on the table (y = 0) one paper
thickness above it (Y0 = 0.1 mm), centred on the origin: pattern u along world
+X, v along world -Z (front side up). The front edge (v = 0) is nearest the
camera (z = +7.4 cm), the back edge (v = 14.8 cm) farthest (z = -7.4 cm).
Seven handles, all positions only (no tangent-plane control):

    BackL (u=0, v=14.8)   BackM (u=10.5, v=14.8)   BackR (u=21, v=14.8)
        the back edge, pressed on the table; still; the scene releases them
        at T_RELEASE (release_time)
    FrontL (u=0, v=0)     FrontM (u=10.5, v=0)     FrontR (u=21, v=0)
        the front edge: its corners and its middle
    Grip (u=10.5, v=2.5)
        with FrontM, the thumb and finger that hold the middle of the front
        edge: the strip between them turns with the hand

Motion (times in s):
  0.00-0.30  rest.
  0.30-1.60  the front edge slides SLIDE = 6 cm along the table towards the
             back edge (FrontL, FrontM, FrontR stay at y = Y0) while the grip
             turns up by GAMMA = 65 degrees about the edge (Grip = FrontM +
             GRIP along the pattern's v turned up about +X): the sheet bows
             up into an arch between the edges, leaving the front edge
             steeply.
  1.60-2.00  hold.
  2.00       the back handles let go (the scene's release_time).
  2.00-2.50  pinch: the front corners move PINCH = 3 cm each towards each
             other along the table, and the front edge bends into a circular
             arc of its own length in the plane of the edge and the sheet's
             normal n (tilted back by GAMMA): FrontM and Grip move by the
             arc's sagitta along n (forwards and up, 2.6 cm up at the end).
             A sheet curved across its front edge cannot bend along it any
             more (it is developable): the released arch straightens into a
             curved wall leaning back from the front edge, and the free back
             edge stands up (16 cm above the table).
  2.50-3.50  every node holds its pose; the sheet settles.

Why a grip and not tangent-plane control: the crumpling model re-binds a
handle's tangent-plane pins to the sheet at every rebuild of S_P
(HandleRig::rebindTangents), so a node's rotation drives turns from there on,
not an absolute tilt; tilted corners did not hold the front edge up once the
back let go, and turning them back pushed their pins into the table. Grips on
every column of the front edge (not only the middle) fold the sheet along
v = GRIP during the slide, and the pinch then crumples it at that crease
instead of bending it smoothly.

Run it to regenerate the file (the committed file is its output):
    python3 samples/slide-on-table/make_slide_on_table_gltf.py [OUT.gltf]
"""
import math
import os
import sys

# Shared helpers (samples/gltf_anim.py).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from gltf_anim import handle_tracks, qaxis, qrot, ramp, write_sample  # noqa: E402

# ---- geometry and timing (metres, seconds, radians) ----
W = 0.21              # sheet width (u, world X)
H = 0.148             # sheet depth (v, world -Z)
Y0 = 0.0001           # height of the sheet: one paper thickness (90 um) and a bit
SLIDE = 0.06          # the front edge slides this far towards the back edge
GAMMA = math.radians(65.0)  # the grip's turn about the front edge
GRIP = 0.025          # the grip holds the sheet this far behind the front edge
PINCH = 0.03          # then each front corner moves this far towards the other
T_SLIDE = (0.30, 1.60)
T_RELEASE = 2.00      # the scene's release_time of the back handles
T_PINCH = (2.00, 2.50)
T_END = 3.50

# (node name, u, v) in metres on the pattern
FRONT = [("FrontL", 0.0, 0.0), ("FrontM", W / 2.0, 0.0), ("FrontR", W, 0.0),
         ("Grip", W / 2.0, GRIP)]
BACK = [("BackL", 0.0, H), ("BackM", W / 2.0, H), ("BackR", W, H)]


def arc(psi):
    """A straight edge of length W bent into a circular arc whose ends turn by
    psi: (chord, sagitta)."""
    if psi < 1e-9:
        return W, 0.0
    return W * math.sin(psi) / psi, W * (1.0 - math.cos(psi)) / (2.0 * psi)


def solve_psi(chord):
    """The end angle of the arc of length W over this chord (bisection)."""
    lo, hi = 0.0, math.pi / 2.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if arc(mid)[0] > chord else (lo, mid)
    return 0.5 * (lo + hi)


PSI = solve_psi(W - 2.0 * PINCH)   # end angle of the pinched front edge (79 degrees)


# ---- the motion ----
def pose(u, v, t):
    """World position of the handle at pattern point (u, v) (and the identity
    rotation: the scene uses positions only)."""
    still = (0.0, 0.0, 0.0, 1.0)
    if v > H / 2.0:  # the back edge: still until released
        return (u - W / 2.0, Y0, -H / 2.0), still
    s = ramp(t, T_SLIDE)
    psi = PSI * ramp(t, T_PINCH)
    tilt = qaxis((1.0, 0.0, 0.0), GAMMA * s)
    z = H / 2.0 - SLIDE * s
    # The front edge is a circular arc of end angle psi in the plane spanned
    # by the edge direction (X) and the sheet's normal n there (turned back
    # with the grip): the point at arc length sigma from the middle sits at
    # x = r sin(sigma / r), and sag - r (1 - cos(sigma / r)) along n above
    # the chord through the corners (which stay on the table).
    sigma = u - W / 2.0
    chord, sag = arc(psi)
    if psi < 1e-9:
        x, h = sigma, 0.0
    else:
        r = W / (2.0 * psi)
        x, h = r * math.sin(sigma / r), sag - r * (1.0 - math.cos(sigma / r))
    n = qrot(tilt, (0.0, 1.0, 0.0))
    # A point v behind the edge lies on the ruling there: the pattern's v
    # direction (world -Z) turned up with the grip; the strip is a cylinder.
    rv = qrot(tilt, (0.0, 0.0, -v))
    return (x + h * n[0] + rv[0], Y0 + h * n[1] + rv[1], z + h * n[2] + rv[2]), still


def tracks():
    times, tr = handle_tracks(FRONT + BACK, pose, T_END)
    return times, [(name, positions, None) for name, positions, _ in tr]  # positions only


def check(times, tracks_):
    """The handles never stretch the sheet: no two held points get farther
    apart than on the pattern (while the back handles hold, until T_RELEASE,
    all of them; after it, the front ones). Positions-only handles hold single
    points, so this compares the nodes themselves (gltf_anim.check_no_stretch
    would carry a patch around each without turning it). Also: no node goes
    below the sheet's rest height (into the table). Returns the worst ratio."""
    pattern = {name: (u, v) for name, u, v in FRONT + BACK}
    front = {name for name, _, _ in FRONT}
    worst = 0.0
    for name, positions, _ in tracks_:
        assert min(p[1] for p in positions) >= Y0 - 1e-12, name + " goes into the table"
    for i, (a, pa, _) in enumerate(tracks_):
        for b, pb, _ in tracks_[i + 1:]:
            d0 = math.dist(pattern[a], pattern[b])
            for t, x, y in zip(times, pa, pb):
                if t <= T_RELEASE or (a in front and b in front):
                    worst = max(worst, math.dist(x, y) / d0)
    assert worst <= 1.0 + 1e-9, "the handles stretch the sheet by %.3g %%" % (100 * (worst - 1))
    return worst


def main():
    times, tr = tracks()
    check(times, tr)
    write_sample(__file__, "slide-on-table.gltf", times, tr)


if __name__ == "__main__":
    main()
