#!/usr/bin/env python3
"""Measure Blender Cycles' light units against crumple's radiometry.

    python3 bench/cycles/calibrate.py [--blender blender] [--keep DIR]

Runs render_cycles.py (the very script bench_render uses, so its factors are
what is tested) on tiny analytic scenes and compares the radiance Cycles
gives with what crumple's model (src/render/include/crumple/render/view.hpp)
predicts. A white Lambertian plane (albedo 1) faces each light; the camera
looks straight down at the plane's centre with a 0.2 degree field of view, so
the image is the radiance at the centre:
- sun, intensity I = 1 straight down: crumple radiance I = 1 (irradiance pi)
- sun with a 0.2 rad disc: the same (strength is irradiance for any angle)
- point light, I = 1, 2 m above: I / d^2 = 0.25
- area light 0.2 x 0.3 m, I = 1, 2 m above facing down: emitter radiance
  pi I / area, plane irradiance by the exact rectangle formula
- world colour 1, intensity 0.5, no light: 0.5
- paper (Diffuse a (1-T) + Translucent a T, front/back colours, a uniform
  texture): front lit from above (a_front (1 - T)) and lit from below
  through the sheet (a_front T: the side the camera sees gives the albedo)
- bounces: a closed box of albedo 0.5 (side 2 m) with a point light at its
  centre, the camera at the centre: direct light alone is 0.5 * I / 1^2;
  printed for Cycles max_bounces 0, 1, 2 (0 must equal 0.5: Cycles' count
  then equals crumple's maxBounces, 0 = direct light only).
Prints measured / expected for each; 1.000 means the factor in
render_cycles.py is right.
"""

import json
import math
import os
import shutil
import struct
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))


def write_plane(path, half, y, up=True):
    """A square at height y, normal +Y (counter-clockwise seen from above)
    or -Y, with uvs, per-corner normals."""
    n = 1.0 if up else -1.0
    with open(path, "w") as f:
        for x, z in ((-half, -half), (half, -half), (half, half), (-half, half)):
            f.write("v %g %g %g\n" % (x, y, z))
        for u, v in ((0, 0), (1, 0), (1, 1), (0, 1)):
            f.write("vt %g %g\n" % (u, v))
        f.write("vn 0 %g 0\n" % n)
        # Seen from +Y (looking down -Y), x right and z down the screen:
        # (-,-) (+,-) (+,+) is clockwise, so +Y-facing triangles are 1 4 3.
        if up:
            f.write("f 1/1/1 4/4/1 3/3/1\nf 1/1/1 3/3/1 2/2/1\n")
        else:
            f.write("f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n")


def write_box(path, half):
    """A closed cube, faces pointing inwards (Cycles' diffuse is two-sided
    anyway), flat shaded (no normals)."""
    v = [(x, y, z) for x in (-half, half) for y in (-half, half) for z in (-half, half)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    with open(path, "w") as f:
        for p in v:
            f.write("v %g %g %g\n" % p)
        for a, b, c, d in quads:
            f.write("f %d %d %d\nf %d %d %d\n" % (a + 1, b + 1, c + 1, a + 1, c + 1, d + 1))


def write_texture(path, rgba):
    """A 4x4 uniform raw RGBF texture."""
    with open(path, "wb") as f:
        f.write(b"RGBF" + struct.pack("<II", 4, 4))
        f.write(struct.pack("<64f", *(list(rgba) * 16)))


def read_raw(path):
    with open(path, "rb") as f:
        data = f.read()
    w, h = struct.unpack_from("<II", data, 4)
    return w, h, struct.unpack_from("<%df" % (w * h * 4), data, 12)


def mean_rgba(path):
    w, h, px = read_raw(path)
    n = w * h
    return [sum(px[k::4]) / n for k in range(4)]


def down_camera(height, yfov_deg=0.2):
    s = math.sqrt(0.5)
    return {"position": [0.0, height, 0.0], "rotation": [s, -s, 0.0, 0.0],
            "yfov": math.radians(yfov_deg), "znear": 0.01, "zfar": 100.0,
            "width": 16, "height": 16, "apertureRadius": 0.0, "focusDistance": 1.0}


def rect_irradiance(radiance, a, b, d):
    """Irradiance on the axis of a Lambertian a x b rectangle at distance d
    (four corner form factors: F = 1/(2 pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2))
    + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))], X = a/2d, Y = b/2d; E = pi L F)."""
    x, y = a / (2 * d), b / (2 * d)
    f = (x / math.sqrt(1 + x * x) * math.atan(y / math.sqrt(1 + x * x)) +
         y / math.sqrt(1 + y * y) * math.atan(x / math.sqrt(1 + y * y))) / (2 * math.pi)
    return 4 * math.pi * radiance * f


def run(blender, folder, name, spec, spp, max_bounces=None):
    scene_path = os.path.join(folder, name + ".json")
    with open(scene_path, "w") as f:
        json.dump(spec, f, indent=1)
    out = os.path.join(folder, name + ".exr")
    cmd = [blender, "-b", "--factory-startup", "-noaudio", "--python",
           os.path.join(HERE, "render_cycles.py"), "--", "--scene", scene_path,
           "--out", out, "--spp", str(spp), "--threads", "2"]
    if max_bounces is not None:
        cmd += ["--max-bounces", str(max_bounces)]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0 or not os.path.exists(out):
        sys.stderr.write(res.stdout[-3000:] + res.stderr[-3000:])
        raise SystemExit("calibrate: blender failed on " + name)
    return mean_rgba(os.path.splitext(out)[0] + ".rgbaf")


def main():
    blender = "blender"
    keep = None
    args = sys.argv[1:]
    while args:
        if args[0] == "--blender":
            blender = args[1]
        elif args[0] == "--keep":
            keep = args[1]
        args = args[2:]
    folder = keep or tempfile.mkdtemp(prefix="crumple-calib-")
    os.makedirs(folder, exist_ok=True)
    write_plane(os.path.join(folder, "plane.obj"), 5.0, 0.0)
    write_box(os.path.join(folder, "box.obj"), 1.0)
    black = {"color": [1, 1, 1], "intensity": 0.0}
    base = {"camera": down_camera(5.0), "environment": black, "maxBounces": 0, "seed": 0,
            "ground": {"obj": "plane.obj", "color": [1, 1, 1]}, "lights": []}
    rows = []

    def check(name, spec, expected, spp=64, channel=0, max_bounces=None):
        got = run(blender, folder, name, spec, spp, max_bounces)[channel]
        rows.append((name, got, expected))
        print("%-28s measured %.6f expected %.6f ratio %.4f" % (name, got, expected, got / expected),
              flush=True)
        return got

    sun = dict(base, lights=[{"kind": "directional", "direction": [0, -1, 0], "color": [1, 1, 1],
                              "intensity": 1.0, "angle": 0.0}])
    check("sun I=1", sun, 1.0)
    sun_disc = dict(base, lights=[dict(sun["lights"][0], angle=0.2)])
    check("sun I=1 angle 0.2 rad", sun_disc, 1.0, spp=256)
    point = dict(base, lights=[{"kind": "point", "position": [0, 2, 0], "color": [1, 1, 1],
                                "intensity": 1.0}])
    check("point I=1 d=2", point, 0.25)
    a, b, d = 0.2, 0.3, 2.0
    area = dict(base, lights=[{"kind": "area", "position": [0, d, 0], "direction": [0, -1, 0],
                               "u": [1, 0, 0], "v": [0, 0, 1], "size": [a, b],
                               "color": [1, 1, 1], "intensity": 1.0}])
    check("area I=1 0.2x0.3 d=2", area,
          rect_irradiance(math.pi * 1.0 / (a * b), a, b, d) / math.pi, spp=1024)
    # A large area light close by: the emitter must be Lambertian (spread
    # 180 degrees) for the exact formula to hold.
    a, b, d = 2.0, 1.0, 0.5
    big = dict(base, lights=[dict(area["lights"][0], position=[0, d, 0], size=[a, b])])
    check("area I=1 2x1 d=0.5", big,
          rect_irradiance(math.pi * 1.0 / (a * b), a, b, d) / math.pi, spp=1024)
    world = dict(base, environment={"color": [1, 1, 1], "intensity": 0.5})
    check("world 0.5", world, 0.5, spp=1024)

    # Paper: a uniform texture (0.8, 0.6, 0.4), front (1, 0.5, 0.25), back
    # (0.2, 0.4, 0.8), T = 0.3; the camera sees the front (+Y).
    write_texture(os.path.join(folder, "tex.rgbaf"), (0.8, 0.6, 0.4, 1.0))
    paper = {"obj": "plane.obj", "textureRaw": "tex.rgbaf", "frontColor": [1.0, 0.5, 0.25],
             "backColor": [0.2, 0.4, 0.8], "transmittance": 0.3}
    front_a = [0.8 * 1.0, 0.6 * 0.5, 0.4 * 0.25]
    # The camera looks at a point away from the plane's diagonal: a shadow
    # ray leaving the sheet towards a light behind it, from next to the edge
    # two triangles share, can hit the other triangle in Cycles (0.1 % of the
    # samples were lost with the centre, which lies on the diagonal, in view).
    off_cam = dict(down_camera(5.0), position=[1.0, 5.0, -1.0])
    p_top = dict(base, camera=off_cam, ground=None, paper=paper, lights=sun["lights"])
    for ch in range(3):
        check("paper front lit, ch %d" % ch, p_top, front_a[ch] * 0.7, channel=ch)
    p_below = dict(p_top, lights=[dict(sun["lights"][0], direction=[0, 1, 0])])
    for ch in range(3):
        check("paper lit from behind, ch %d" % ch, p_below, front_a[ch] * 0.3, channel=ch)
    # The camera below sees the back.
    cam_below = dict(down_camera(-5.0), position=[1.0, -5.0, -1.0])
    s = math.sqrt(0.5)
    cam_below["rotation"] = [s, s, 0.0, 0.0]  # looks up (+Y)
    back_a = [0.8 * 0.2, 0.6 * 0.4, 0.4 * 0.8]
    p_back = dict(p_below, camera=cam_below)
    for ch in range(3):
        check("paper back lit, ch %d" % ch, p_back, back_a[ch] * 0.7, channel=ch)

    # Bounces: a closed box, light and camera at its centre.
    box = dict(base, camera=dict(down_camera(0.0), position=[0, 0, 0], rotation=[1, 0, 0, 0]),
               ground={"obj": "box.obj", "color": [0.5, 0.5, 0.5]},
               lights=[{"kind": "point", "position": [0, 0, 0], "color": [1, 1, 1],
                        "intensity": 1.0}])
    for bounces in (0, 1, 2):
        check("box max_bounces %d" % bounces, box, 0.5, spp=4096, max_bounces=bounces)
    if not keep:
        shutil.rmtree(folder)


if __name__ == "__main__":
    main()
