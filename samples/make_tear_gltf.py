#!/usr/bin/env python3
"""Writes the handle curves of the tear samples (tear-straight, tear-curved,
tear-notch, tear-slow, tear-fast): two hands pinch a hanging sheet, one
either side of where the tear will start, and draw apart in the sheet's
plane (Roman's two pulling points, thesis Fig. 3.13), optionally twisting it
open as well (the left hand towards the camera, the right one away), over a
given time (tear-slow and tear-fast: the same motion slow and fast).

glTF 2.0, Y-up, metres, seconds; keys every 1/48 s from eased (C2
smootherstep) motions. The sheet hangs in the plane z = 0, pattern u along
world +X and v along world +Y, its pattern origin at the world origin.

Usage: make_tear_gltf.py OUT.gltf UA VA UB VB [SPREAD_CM] [TWIST_CM] [DURATION_S]
  (UA, VA), (UB, VB): the two pulling points in the pattern (cm).
Motion (times in s; DURATION 2 s unless given, which is what the first three
samples use):
  0.00-0.25             rest.
  0.25-0.25+DURATION    the left hand (A) moves SPREAD (2 cm) left (-x) and
                        TWIST (0 cm) towards the camera (+z); the right hand
                        (B) the same right and away from the camera.
  then 0.5 s            hold.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gltf_anim  # noqa: E402


def main():
    out = sys.argv[1]
    ua, va, ub, vb = (float(x) / 100.0 for x in sys.argv[2:6])
    spread = float(sys.argv[6]) / 100.0 if len(sys.argv) > 6 else 0.02
    twist = float(sys.argv[7]) / 100.0 if len(sys.argv) > 7 else 0.0
    duration = float(sys.argv[8]) if len(sys.argv) > 8 else 2.0
    assert duration > 0.0, "DURATION_S must be > 0"
    span = (0.25, 0.25 + duration)

    def pose(u, v, t):
        s = gltf_anim.ramp(t, span)
        side = -1.0 if u == ua and v == va else 1.0
        return ((u + side * spread * s, v, -side * twist * s), (0.0, 0.0, 0.0, 1.0))

    times, tracks = gltf_anim.handle_tracks([("HandA", ua, va), ("HandB", ub, vb)], pose,
                                            span[1] + 0.5, 48)
    gltf_anim.write_gltf(out, "crumple samples/make_tear_gltf.py", times, tracks)


if __name__ == "__main__":
    main()
