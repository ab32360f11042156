#!/usr/bin/env python3
"""Writes the stability suite's scenes (issue 9, item 3): for every case
tests/stability/scenes/<case>/scene.toml and its handle curves anim.gltf
(glTF 2.0, Y-up, metres, seconds; samples/gltf_anim.py's writer).

Every scene is the elastic model (no [model] table); the test runs each one
under both models by appending `[model] type = "hybrid"`
(tests/stability/test_stability.cpp). The cases and their motions are listed
in CASES below and in docs/STABILITY.md. The random run is seeded (SEED), its
keys are 4 per second and the importer interpolates linearly between them.

Run it to regenerate every case (the committed files are its output):
    python3 tests/stability/scenes/make_scenes.py
"""
import math
import os
import random
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "samples"))
from gltf_anim import (check_no_stretch, handle_tracks, key_times, qaxis, ramp,  # noqa: E402
                       write_gltf)

SEED = 9  # random-10000's motion
GENERATOR = "crumple tests/stability/scenes/make_scenes.py"


def scene_toml(header, name, units, frames, substeps, sheet, handles, paper="office-70gsm",
               extra=""):
    """The scene file: header comment, [scene], [sheet], [paper], [[handles]]."""
    lines = ["# " + l.strip() if l.strip() else "#" for l in header.strip().split("\n")]
    lines += ["# Written by tests/stability/scenes/make_scenes.py (edit it, not this file).",
              "[scene]", 'name = "stability-%s"' % name, 'units = "%s"' % units, "fps = 24",
              "frames = [%d, %d]" % frames, "substeps = %d" % substeps, "seed = 1",
              'animation = "anim.gltf"', "", "[sheet]"]
    lines += ["%s = %s" % kv for kv in sheet]
    lines += ["", "[paper]", 'preset = "%s"' % paper]
    for h in handles:
        lines += ["", "[[handles]]", 'name = "%s"' % h[0], 'node = "%s"' % h[0],
                  "pattern = [%g, %g]" % (h[1], h[2])]
        if len(h) > 3 and h[3]:
            lines.append("tangent_control = true")
    return "\n".join(lines) + "\n" + extra


def sheet_table(width, height, max_edge, origin, v_axis=(0.0, 1.0, 0.0)):
    """The [sheet] table's keys for scene_toml, in the scene's units (pass
    floats: they are written as Python prints them): pattern u along world
    +X, v along v_axis (by default +Y: a sheet in the XY plane)."""
    def vec(v):
        return "[%s]" % ", ".join(repr(c) for c in v)
    return [("width", repr(width)), ("height", repr(height)), ("max_edge", repr(max_edge)),
            ("origin", vec(origin)), ("u_axis", vec((1.0, 0.0, 0.0))), ("v_axis", vec(v_axis))]


def sample(times, funcs):
    """[(node, [position at t])] from {node: t -> position}."""
    return [(name, [f(t) for t in times], None) for name, f in funcs]


def lerp(a, b, s):
    return tuple(x + (y - x) * s for x, y in zip(a, b))


def write(case, toml, times, tracks):
    folder = os.path.join(HERE, case)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "scene.toml"), "w") as f:
        f.write(toml)
    write_gltf(os.path.join(folder, "anim.gltf"), GENERATOR, times, tracks)


# A 10 x 10 cm sheet hanging in the XY plane from its top corners (v = 10 cm
# at y = 20 cm, x = -5 .. 5 cm): the frame of most cases.
HANG_SHEET = sheet_table(10.0, 10.0, 1.0, (-5.0, 10.0, 0.0))
HANG_HANDLES = [("A", 0.0, 10.0), ("B", 10.0, 10.0)]
A0 = (-0.05, 0.20, 0.0)
B0 = (0.05, 0.20, 0.0)
HANG_AXES = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))


def hang_check(times, tracks, size=(0.10, 0.10), handles=HANG_HANDLES, scale=0.01):
    """No two handles ever farther apart than on the pattern (the handles
    have no tangent-plane control: the held points are the handles')."""
    pattern = {n: (u * scale, v * scale) for n, u, v, *_ in handles}
    check_no_stretch(times, tracks, pattern, size, HANG_AXES, patch=1e-6)


def swing(a0, b0, gap, lift, t):
    """Top corners a0, b0 move together to `gap` apart (m) and out of the
    plane by `lift` over 0.25-1.0 s, hold to 1.25 s, back apart by 2.0 s."""
    s = ramp(t, (0.25, 1.0)) - ramp(t, (1.25, 2.0))
    mid = lerp(a0, b0, 0.5)
    half = (b0[0] - a0[0]) / 2.0
    a = (mid[0] - half + (half - gap / 2.0) * s, a0[1], a0[2] + lift * s)
    b = (mid[0] + half - (half - gap / 2.0) * s, b0[1], b0[2] + lift * s)
    return a, b


def case_compress():
    """compress-10: a 10 x 10 cm sheet lying flat at y = 10 cm is held along
    two opposite sides (three handles each, at v = 0, 5, 10 cm); the right
    side slides over 0.25-1.5 s towards the left one until they are 1 cm apart
    (10 % of the width), holds to 2 s, comes back to 9 cm by 2.75 s and holds
    to 3 s. The sheet buckles down under gravity into a deep U."""
    sheet = sheet_table(10.0, 10.0, 1.0, (-5.0, 10.0, 5.0), v_axis=(0.0, 0.0, -1.0))
    handles = [("L%d" % i, 0.0, v) for i, v in enumerate((0.0, 5.0, 10.0))] + \
              [("R%d" % i, 10.0, v) for i, v in enumerate((0.0, 5.0, 10.0))]

    def pos(name, v, t):
        s = ramp(t, (0.25, 1.5)) - 8.0 / 9.0 * ramp(t, (2.0, 2.75))
        x = -0.05 if name[0] == "L" else 0.05 - 0.09 * s
        return (x, 0.10, 0.05 - v * 0.01)

    times = key_times(3.0)
    tracks = [(n, [pos(n, v, t) for t in times], None) for n, _, v in handles]
    toml = scene_toml(case_compress.__doc__, "compress-10", "cm", (0, 72), 4, sheet, handles)
    write("compress-10", toml, times, tracks)


def case_twist():
    """twist-4pi: a 24 x 3 cm strip lying along X at y = 10 cm, each short end
    clamped by its two corners with tangent-plane control. End A stays; end B
    turns by 4 pi (two full turns) about the strip's long axis over
    0.25-2.25 s while it comes 10 cm closer (the borders of a strip twisted
    by 4 pi over 14 cm are helices of about 24 cm: the paper's length),
    holds to 2.75 s, untwists back by 4.75 s and holds to 5 s."""
    length, width = 0.24, 0.03
    sheet = sheet_table(24.0, 3.0, 1.0, (-12.0, 10.0, 1.5), v_axis=(0.0, 0.0, -1.0))
    handles = [("EndA0", 0.0, 0.0, True), ("EndA1", 0.0, 3.0, True),
               ("EndB0", 24.0, 0.0, True), ("EndB1", 24.0, 3.0, True)]

    def pose(u, v, t):
        across = (0.0, 0.0, width / 2.0 - v)
        if u < length / 2.0:
            return (-length / 2.0, 0.10, across[2]), (0.0, 0.0, 0.0, 1.0)
        s = ramp(t, (0.25, 2.25)) - ramp(t, (2.75, 4.75))
        angle = 4.0 * math.pi * s
        c, sn = math.cos(angle), math.sin(angle)
        # Rotation about +X: (y, z) -> (y c - z s, y s + z c).
        offset = (0.0, -across[2] * sn, across[2] * c)
        x = length / 2.0 - 0.10 * s
        return (x, 0.10 + offset[1], offset[2]), qaxis((1.0, 0.0, 0.0), angle)

    pattern = [(name, u * 0.01, v * 0.01) for name, u, v, _ in handles]  # metres
    times, tracks = handle_tracks(pattern, pose, 5.0)
    check_no_stretch(times, tracks, pattern, (length, width), ((1.0, 0.0, 0.0), (0.0, 0.0, -1.0)))
    toml = scene_toml(case_twist.__doc__, "twist-4pi", "cm", (0, 120), 4, sheet, handles)
    write("twist-4pi", toml, times, tracks)


def case_jump():
    """handle-jump: the hanging 10 x 10 cm sheet (top corners A, B). B jumps by
    half the sheet (5 cm) within 1 ms three times: towards A at 0.5 s, back
    at 1.0 s (the top edge taut again at once), out of the sheet's plane
    (+z) at 1.5 s; it holds to 2.5 s."""
    jumps = [(0.5, (0.0, 0.20, 0.0)), (1.0, B0), (1.5, (0.025, 0.20, 0.05 * math.sqrt(0.75)))]
    times = [0.0]
    b = [B0]
    for t, p in jumps:
        times += [t, t + 0.001]
        b += [b[-1], p]
    times.append(2.5)
    b.append(b[-1])
    # The last jump keeps B within the sheet's reach of A: |B - A| <= 10 cm.
    tracks = [("A", [A0] * len(times), None), ("B", b, None)]
    hang_check(times, tracks)
    toml = scene_toml(case_jump.__doc__, "handle-jump", "cm", (0, 60), 4, HANG_SHEET,
                      HANG_HANDLES)
    write("handle-jump", toml, times, tracks)


def case_same_point():
    """same-point: the hanging 10 x 10 cm sheet; both top corners are driven
    onto one point (the top edge's midpoint, 2 cm towards the camera) over
    0.25-1.0 s, stay there together to 1.5 s, and part again by 2.25 s; hold
    to 2.5 s."""
    target = (0.0, 0.20, 0.02)

    def at(p0):
        return lambda t: lerp(p0, target, ramp(t, (0.25, 1.0)) - ramp(t, (1.5, 2.25)))

    times = key_times(2.5)
    tracks = sample(times, [("A", at(A0)), ("B", at(B0))])
    hang_check(times, tracks)
    toml = scene_toml(case_same_point.__doc__, "same-point", "cm", (0, 60), 4, HANG_SHEET,
                      HANG_HANDLES)
    write("same-point", toml, times, tracks)


def case_beyond_reach():
    """beyond-reach: the hanging 10 x 10 cm sheet; A holds still while B is
    pulled straight away from it over 0.25-1.0 s to 40 cm from A (four times
    the sheet's reach: no paper can follow), stays there to 1.5 s, comes back
    to its start by 2.25 s and holds to 2.5 s."""
    far = (0.35, 0.20, 0.0)
    times = key_times(2.5)
    tracks = sample(times, [("A", lambda t: A0),
                            ("B", lambda t: lerp(B0, far, ramp(t, (0.25, 1.0)) -
                                                 ramp(t, (1.5, 2.25))))])
    toml = scene_toml(case_beyond_reach.__doc__, "beyond-reach", "cm", (0, 60), 4, HANG_SHEET,
                      HANG_HANDLES)
    write("beyond-reach", toml, times, tracks)


def swing_case(case, doc, sheet, handles, a0, b0, gap, lift, units, scale, paper, frames,
               size, substeps=4):
    times = key_times(2.25)
    tracks = [(handles[0][0], [swing(a0, b0, gap, lift, t)[0] for t in times], None),
              (handles[1][0], [swing(a0, b0, gap, lift, t)[1] for t in times], None)]
    hang_check(times, tracks, size=size, handles=handles, scale=scale)
    toml = scene_toml(doc, case, units, frames, substeps, sheet, handles, paper=paper)
    write(case, toml, times, tracks)


def case_papers():
    """The hanging 10 x 10 cm sheet of PAPER: its top corners swing together
    to 2 cm apart and 4 cm towards the camera over 0.25-1.0 s, hold to
    1.25 s, and go back apart by 2.0 s; hold to 2.25 s. The preset is in
    tests/stability/papers (the test sets CRUMPLE_ASSETS=tests/stability)."""
    for case, paper in (("thin", "tissue-12gsm"), ("thick", "board-600gsm")):
        doc = case + ": " + case_papers.__doc__.replace("PAPER", paper)
        swing_case(case, doc, HANG_SHEET, HANG_HANDLES, A0, B0, 0.02, 0.04, "cm", 0.01, paper,
                   (0, 54), (0.10, 0.10))


def case_substeps():
    """substeps: the hanging 10 x 10 cm sheet, its top corners swung together
    to 2 cm apart and 4 cm towards the camera over 0.25-1.0 s and back apart
    by 2.0 s; hold to 2.25 s. The test overrides [scene] substeps with 1, 2,
    4, 8, 16, 32 and 64."""
    swing_case("substeps", case_substeps.__doc__, HANG_SHEET, HANG_HANDLES, A0, B0, 0.02, 0.04,
               "cm", 0.01, "office-70gsm", (0, 54), (0.10, 0.10))


def case_tiny():
    """tiny-1cm: a 1 x 1 cm sheet (units mm, 1 mm mesh) hanging from its top
    corners, which swing together to 2 mm apart and 4 mm towards the camera
    over 0.25-1.0 s and back apart by 2.0 s; hold to 2.25 s."""
    # The hanging sheet's table, read in millimetres.
    swing_case("tiny-1cm", case_tiny.__doc__, HANG_SHEET, HANG_HANDLES, (-0.005, 0.02, 0.0),
               (0.005, 0.02, 0.0), 0.002, 0.004, "mm", 0.001, "office-70gsm", (0, 54),
               (0.01, 0.01))


def case_poster():
    """poster-1m: a 100 x 70 cm poster (5 cm mesh) hanging from its top
    corners, which swing together to 20 cm apart and 40 cm towards the camera
    over 0.25-1.0 s and back apart by 2.0 s; hold to 2.25 s."""
    sheet = sheet_table(100.0, 70.0, 5.0, (-50.0, 30.0, 0.0))
    handles = [("A", 0.0, 70.0), ("B", 100.0, 70.0)]
    swing_case("poster-1m", case_poster.__doc__, sheet, handles, (-0.5, 1.0, 0.0),
               (0.5, 1.0, 0.0), 0.2, 0.4, "cm", 0.01, "office-70gsm", (0, 54), (1.0, 0.7))


def case_random():
    """random-10000: the hanging 10 x 10 cm sheet (1.25 cm mesh, 2 substeps)
    held by three handles, the top corners A, B and the bottom edge's middle
    C, each moving at random for 10 000 frames (seeded): every 0.25 s a new
    key, a step of up to 3 cm in each axis, kept in a 30 cm box and kept
    within 95 % of the sheet's reach of the other handles (no handle pair is
    ever farther apart than on the pattern)."""
    sheet = sheet_table(10.0, 10.0, 1.25, (-5.0, 10.0, 0.0))
    handles = HANG_HANDLES + [("C", 5.0, 0.0)]
    rest = {"A": A0, "B": B0, "C": (0.0, 0.10, 0.0)}
    reach = {}
    for i, (n, u, v) in enumerate(handles):
        for m, u2, v2 in handles[i + 1:]:
            reach[(n, m)] = reach[(m, n)] = 0.95 * math.hypot(u - u2, v - v2) * 0.01
    rng = random.Random(SEED)
    t_end = 10001 / 24.0
    times = key_times(math.ceil(t_end * 4) / 4.0, 4)
    pos = [dict(rest)]
    # First key at rest (the handles start on their sheet points), then
    # every key a random step that keeps every pair within reach.
    for _ in times[1:]:
        cur = dict(pos[-1])
        for n, _, _ in handles:
            for _attempt in range(100):
                p = tuple(c + rng.uniform(-0.03, 0.03) for c in cur[n])
                if any(abs(p[k] - (0.0, 0.15, 0.0)[k]) > 0.15 for k in range(3)):
                    continue
                if all(math.dist(p, cur[m]) <= reach[(n, m)] for m in cur if m != n):
                    cur[n] = p
                    break
        pos.append(cur)
    tracks = [(n, [p[n] for p in pos], None) for n, _, _ in handles]
    hang_check(times, tracks, handles=handles)
    toml = scene_toml(case_random.__doc__, "random-10000", "cm", (0, 10000), 2, sheet, handles)
    write("random-10000", toml, times, tracks)


def main():
    case_compress()
    case_twist()
    case_jump()
    case_same_point()
    case_beyond_reach()
    case_papers()
    case_substeps()
    case_tiny()
    case_poster()
    case_random()


if __name__ == "__main__":
    main()
