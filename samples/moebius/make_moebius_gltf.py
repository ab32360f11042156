#!/usr/bin/env python3
"""Writes samples/moebius/moebius.gltf: the handle curves of the moebius
sample (paper Fig. 18, top row: "the deformation of a smooth paper strip
continuously twisted into a Moebius strip"; smooth, no singular vertex: the
paper's Table V reports 0 for this example).

glTF 2.0, Y-up, metres, seconds; keys every 1/48 s (every frame at 24 fps and
every half frame), sampled from eased (C2 smootherstep) analytic motions.

The strip: 24 cm x 3 cm (here L_paper is the strip's long side), lying flat
at y = 6 cm along world X (u along +X, v along -Z, centre line v = 1.5 cm on
z = 0). Each short end is held by its two corners, with tangent-plane
control, so the ends are clamped like a pinch between fingers:

    EndA0 (u=0, v=0)   EndA1 (u=0, v=3)     end A, at x = -12 cm: held still
    EndB0 (u=24, v=0)  EndB1 (u=24, v=3)    end B, at x = +12 cm: carried

End B moves as a rigid frame (the corners at +-1.5 cm across its centre
point). With s the eased progress (0 -> 1):
  - carried around: the frame stays at the far end of a circular arc of
    length 24 cm that leaves end A along +X and curls upwards (about +Z);
    the arc's total turning angle is Theta = s * 0.96 * 360 degrees, its
    radius 24 cm / Theta, so end B travels up, over and back down towards
    end A (a loop in the XY plane);
  - twisted: the frame also turns about its own strip axis by s * 180
    degrees.
At s = 1 end B faces end A across a 1 cm gap, upside down: its corner
v = 0 is next to end A's corner v = 3, which is the Moebius closure (the
strip is not glued; the handles keep it closed). The arc and the twist ask
for no stretching: no two handles ever get farther apart than on the
pattern (main() asserts it).

Motion (times in s):
  0.00-0.25  rest.
  0.25-3.75  s goes from 0 to 1.
  3.75-4.25  hold the Moebius band.

The file also holds an animated camera, node "Camera" (vertical fov 35
degrees): the strip spans 24 cm at the start, rises to 22 cm half-way and ends
as an 8 cm band, so the camera follows it, always looking from the same
direction and as close as keeps the whole strip in view (camera_track()).

Run it to regenerate the file (the committed file is its output):
    python3 samples/moebius/make_moebius_gltf.py [OUT.gltf]
"""
import math
import os
import sys

# Shared helpers (samples/gltf_anim.py).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from gltf_anim import (KEYS_PER_SECOND, check_no_stretch, cross, handle_tracks, qaxis,  # noqa: E402
                       qmul, qrot, ramp, write_sample)

# ---- geometry and timing (metres, seconds, radians) ----
LENGTH = 0.24                      # strip length (u), L_paper
WIDTH = 0.03                       # strip width (v)
Y0 = 0.06                          # height of the flat strip
X0 = -LENGTH / 2.0                 # end A's x
TURN = 0.96 * 2.0 * math.pi        # final turning angle of the loop
TWIST = math.pi                    # final twist of end B about the strip axis
T_MOVE = (0.25, 3.75)
T_END = 4.25
# The camera (node "Camera"): looks at the strip from this direction (from
# the front, above and to the right), as close as keeps it all in view.
CAMERA = "Camera"
CAMERA_DIR = (0.35, 0.45, 1.0)
CAMERA_YFOV = math.radians(35.0)
CAMERA_ASPECT = 640.0 / 480.0
CAMERA_MARGIN = 1.0                # distance factor over the bounding sphere
# Room around the strip as the handles shape it, for the shape it really
# takes: the free loop sags under gravity and the closed band flops over
# (with the elastic model the band ends 3 cm lower than the handles' circle
# and leans 3.5 cm out of its plane).
SAG_MARGIN = 0.035                 # below
SIDE_MARGIN = 0.035                # in front and behind (Z)

# (node name, u, v) in metres on the pattern
CORNERS = [("EndA0", 0.0, 0.0), ("EndA1", 0.0, WIDTH),
           ("EndB0", LENGTH, 0.0), ("EndB1", LENGTH, WIDTH)]


# ---- the motion ----
def section(s, f):
    """The strip's cross-section at the fraction f of its length from end A
    (f = 1: end B) at progress s: its centre on the arc of length LENGTH f
    and turning angle TURN s f, and its rotation (that turn about +Z, then
    the twist TWIST s f about the strip axis)."""
    a = TURN * s * f
    if a < 1e-9:
        centre = (X0 + LENGTH * f, Y0, 0.0)
    else:
        r = LENGTH * f / a
        centre = (X0 + r * math.sin(a), Y0 + r * (1.0 - math.cos(a)), 0.0)
    return centre, qmul(qaxis((0.0, 0.0, 1.0), a), qaxis((1.0, 0.0, 0.0), TWIST * s * f))


def on_section(centre, q, across):
    """The point `across` (in end A's frame, from the centre line) carried
    to the cross-section (centre, q)."""
    a = qrot(q, across)
    return (centre[0] + a[0], centre[1] + a[1], centre[2] + a[2])


def corner_pose(u, v, t):
    """World position and rotation of the handle at pattern point (u, v)."""
    across = (0.0, 0.0, WIDTH / 2.0 - v)  # from the centre line to the corner (v = 0 at +Z)
    if u < LENGTH / 2.0:                  # end A: still
        return (X0 + across[0], Y0 + across[1], across[2]), (0.0, 0.0, 0.0, 1.0)
    centre, q = section(ramp(t, T_MOVE), 1.0)
    return on_section(centre, q, across), q


def strip_points(t):
    """Points of the strip as the handles shape it at time t: the arc with a
    twist growing along it (the simulated strip stays close to this)."""
    s = ramp(t, T_MOVE)
    points = []
    for i in range(25):
        centre, q = section(s, i / 24.0)
        for side in (-1.0, 1.0):
            points.append(on_section(centre, q, (0.0, 0.0, side * WIDTH / 2.0)))
    return points


def look_at(position, target):
    """Rotation of a glTF camera (looking down its -Z, +Y up) at position
    looking at target, with the world's +Y up."""
    b = tuple(p - q for p, q in zip(position, target))
    n = math.sqrt(sum(c * c for c in b))
    b = tuple(c / n for c in b)
    r = cross((0.0, 1.0, 0.0), b)
    n = math.sqrt(sum(c * c for c in r))
    r = tuple(c / n for c in r)
    u = cross(b, r)
    m = ((r[0], u[0], b[0]), (r[1], u[1], b[1]), (r[2], u[2], b[2]))  # columns r, u, b
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0.0:
        w = math.sqrt(1.0 + tr) / 2.0
        return ((m[2][1] - m[1][2]) / (4 * w), (m[0][2] - m[2][0]) / (4 * w),
                (m[1][0] - m[0][1]) / (4 * w), w)
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    x = math.sqrt(max(0.0, 1.0 + m[i][i] - m[j][j] - m[k][k])) / 2.0
    q = [0.0, 0.0, 0.0, (m[k][j] - m[j][k]) / (4 * x)]
    q[i], q[j], q[k] = x, (m[j][i] + m[i][j]) / (4 * x), (m[k][i] + m[i][k]) / (4 * x)
    return tuple(q)


def camera_track(times):
    """A camera that keeps the whole strip in view and moves in on the band:
    it frames the bounding sphere of the strip's box over the next/last 0.3 s
    (grown by the margins), seen from CAMERA_DIR, smoothed over +-0.3 s (a
    triangle kernel, twice)."""
    dt = 1.0 / (4 * KEYS_PER_SECOND)
    fine = [k * dt for k in range(int(round(T_END / dt)) + 1)]
    boxes = []
    for t in fine:
        pts = strip_points(t)
        boxes.append((tuple(min(p[i] for p in pts) for i in range(3)),
                      tuple(max(p[i] for p in pts) for i in range(3))))
    half = int(round(0.3 / dt))
    raw = []
    for k in range(len(fine)):
        window = boxes[max(0, k - half):k + half + 1]
        lo = [min(b[0][i] for b in window) for i in range(3)]
        hi = [max(b[1][i] for b in window) for i in range(3)]
        lo[1] -= SAG_MARGIN
        lo[2] -= SIDE_MARGIN
        hi[2] += SIDE_MARGIN
        centre = [(a + b) / 2.0 for a, b in zip(lo, hi)]
        raw.append(centre + [math.dist(lo, hi) / 2.0])
    for _ in range(2):  # triangle-kernel smoothing, twice
        smooth = []
        for k in range(len(raw)):
            acc, wsum = [0.0] * 4, 0.0
            for j in range(max(0, k - half), min(len(raw), k + half + 1)):
                w = 1.0 - abs(j - k) / (half + 1.0)
                acc = [a + w * c for a, c in zip(acc, raw[j])]
                wsum += w
            smooth.append([a / wsum for a in acc])
        raw = smooth
    n = math.sqrt(sum(c * c for c in CAMERA_DIR))
    d = tuple(c / n for c in CAMERA_DIR)
    positions, rotations = [], []
    for t in times:
        c = raw[int(round(t / dt))]
        dist = CAMERA_MARGIN * c[3] / math.sin(CAMERA_YFOV / 2.0)
        p = tuple(ci + dist * di for ci, di in zip(c[:3], d))
        positions.append(p)
        rotations.append(look_at(p, tuple(c[:3])))
    return positions, rotations


def main():
    times, tracks = handle_tracks(CORNERS, corner_pose, T_END)
    # No two held points ever get farther apart than on the pattern.
    check_no_stretch(times, tracks, CORNERS, (LENGTH, WIDTH), ((1.0, 0.0, 0.0), (0.0, 0.0, -1.0)))
    write_sample(__file__, "moebius.gltf", times, tracks + [(CAMERA, *camera_track(times))],
                 camera=(CAMERA, CAMERA_YFOV, CAMERA_ASPECT))


if __name__ == "__main__":
    main()
