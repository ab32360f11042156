#!/usr/bin/env python3
"""Writes samples/wiggle/wiggle.gltf: the handle curves of the wiggle sample
(thesis Fig. 4.21, "a sheet held by one border and wiggled"; issue 7: "a sheet
held by two corners and lightly shaken"), a sound-stage sample whose free
part flaps: its curvature changes sign back and forth.

glTF 2.0, Y-up, metres, seconds; keys every 1/96 s (four keys per frame at
24 fps: the shake's period is 8 frames), sampled from analytic motions.

The sheet: A5 (W = 14.8 cm wide, H = 21 cm tall), hanging in the plane z = 0
from its top edge, pattern u along world +X, v along world +Y, the pattern
origin at (-W/2, Y0 - H, 0): the top edge (v = H) at y = Y0 = 30 cm, centred
on the Y axis. Two handles, with tangent-plane control (the node's rotation
turns the corner's neighbours: a pinch between thumb and finger):

    TopL (u=0, v=H)   TopR (u=W, v=H)   the top corners, x = -/+7.4 cm

Both hands move together, rigidly (they never stretch the sheet):

    z(t)     = A   e(t) sin(2 pi F (t - T_SHAKE[0]))          towards the camera
    theta(t) = TILT e(t) sin(2 pi F (t - T_SHAKE[0]) + LEAD)  about world +X

e(t) is the shake's envelope: 0 before T_SHAKE[0], up to 1 over RAMP s
(C2 smootherstep), 1, down to 0 over the last RAMP s, 0 after T_SHAKE[1].
theta turns each corner's tangent plane about the top edge (a wrist
wiggling the sheet), leading the translation by LEAD.

Motion (times in s):
  0.00-0.50  rest: the sheet hangs still.
  0.50-3.00  shake: 2 cm amplitude (4 cm peak to peak) towards and away from
             the camera at 3 Hz (7.5 cycles), the wrist turning by up to 15
             degrees a quarter period ahead; the envelope rises over
             0.50-0.90 and falls over 2.60-3.00. The hanging sheet lags the
             hands: bending waves run down it and the free part flaps, its
             curvature changing sign each half period.
  3.00-3.75  rest: the hands still, the sheet swings out.

Run it to regenerate the file (the committed file is its output):
    python3 samples/wiggle/make_wiggle_gltf.py [OUT.gltf]
"""
import math
import os
import sys

# Shared helpers (samples/gltf_anim.py).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from gltf_anim import check_no_stretch, handle_tracks, qaxis, smoother, write_sample  # noqa: E402

# ---- geometry and timing (metres, seconds, radians) ----
W = 0.148                   # sheet width (u, world X)
H = 0.21                    # sheet height (v, world Y)
Y0 = 0.30                   # height of the held top edge
A = 0.02                    # shake amplitude (towards the camera, world +Z)
F = 3.0                     # shake frequency (Hz)
TILT = math.radians(15.0)   # the wrist's turn about the top edge (world +X)
LEAD = math.pi / 2.0        # the turn's phase ahead of the translation
T_SHAKE = (0.50, 3.00)
RAMP = 0.40                 # envelope rise and fall
T_END = 3.75
KEYS_PER_SECOND = 96

# (node name, u, v) in metres on the pattern
CORNERS = [("TopL", 0.0, H), ("TopR", W, H)]


def envelope(t):
    a, b = T_SHAKE
    return smoother((t - a) / RAMP) * smoother((b - t) / RAMP)


def pose(u, v, t):
    """World position and rotation of the handle at pattern point (u, v)."""
    phase = 2.0 * math.pi * F * (t - T_SHAKE[0])
    e = envelope(t)
    z = A * e * math.sin(phase)
    theta = TILT * e * math.sin(phase + LEAD)
    return (u - W / 2.0, Y0 - H + v, z), qaxis((1.0, 0.0, 0.0), theta)


def main():
    times, tracks = handle_tracks(CORNERS, pose, T_END, KEYS_PER_SECOND)
    check_no_stretch(times, tracks, CORNERS, (W, H), ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)))
    write_sample(__file__, "wiggle.gltf", times, tracks)


if __name__ == "__main__":
    main()
