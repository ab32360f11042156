#!/usr/bin/env python3
"""How the air samples' motion depends on the step (docs/AIR.md "Time step").

Runs fall-flutter and fall-strip at several substeps per frame and, since a
falling leaf is chaotic, at several release angles around the sample's, and
measures from `crumple inspect --json` (air_regimes.measure):
  fall-flutter: the first swing's largest tilt (the first 1.25 s), the
    largest tilt of the whole flight, the lateral reversals, the fall;
  fall-strip: its steady tumble between 2 and 4 s (descent and sideways
    speed, turns per second), its turns one way and the fall.
Prints two Markdown tables, one row per (substeps, angle), and each
substep count's medians over the angles.

Usage: scripts/air_timestep.py [--crumple build/crumple] [--substeps 4,8,16]
       [--flutter-angles 8,9,10,11,12] [--strip-angles 28,30,32] [--jobs 2]
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from air_regimes import measure  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FPS = 48


def scene_text(sample, substeps, angle_deg):
    """The sample released at angle_deg about its centre, with `substeps`."""
    with open(os.path.join(ROOT, "samples", sample, "scene.toml")) as f:
        lines = f.read().splitlines()
    width = {"fall-flutter": 29.7, "fall-strip": 5.0}[sample]
    centre_y, z = {"fall-flutter": (150.0, 10.5), "fall-strip": (150.0, 10.0)}[sample]
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    out = []
    for line in lines:
        if line.startswith("substeps ="):
            line = f"substeps = {substeps}"
        elif line.startswith("origin ="):
            line = f"origin = [{-width / 2 * c:.4f}, {centre_y - width / 2 * s:.4f}, {z}]"
        elif line.startswith("u_axis ="):
            line = f"u_axis = [{c:.8f}, {s:.8f}, 0.0]"
        out.append(line)
    return "\n".join(out) + "\n"


def run(crumple, tmp, sample, substeps, angle):
    work = os.path.join(tmp, f"{sample}-{substeps}-{angle}")
    os.makedirs(work)
    with open(os.path.join(work, "scene.toml"), "w") as f:
        f.write(scene_text(sample, substeps, angle))
    subprocess.run([crumple, "simulate", work, "--out", work + "/out"], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    out = subprocess.run([crumple, "inspect", "--json", work + "/out/cache.pcache"], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)["frames"]


def flutter_row(frames):
    m = measure(frames)
    first = max(f["normal_angle_deg"] for f in frames[:int(1.25 * FPS) + 1])
    return dict(first=first, tilt=m["tilt"], reversals=m["reversals"], fall=m["duration"],
                landed=m["landed"])


def strip_row(frames):
    m = measure(frames)
    a, b = 2 * FPS, 4 * FPS
    turns, last = [0.0], None
    for f in frames:
        n = f["mean_normal"]
        ang = math.atan2(n[1], n[0])
        if last is not None:
            turns.append(turns[-1] + math.remainder(ang - last, 2 * math.pi))
        last = ang
    landing = next((i for i, f in enumerate(frames) if f.get("contacts", 0) > 0), len(frames))
    if landing <= b:
        nan = float("nan")
        return dict(descent=nan, sideways=nan, rate=nan, turns=m["turns"], fall=m["duration"],
                    landed=m["landed"])
    span = (b - a) / FPS
    descent = (frames[a]["centroid"][1] - frames[b]["centroid"][1]) / span
    sideways = abs(frames[b]["centroid"][0] - frames[a]["centroid"][0]) / span
    rate = abs(turns[b] - turns[a]) / (2 * math.pi) / span
    return dict(descent=descent, sideways=sideways, rate=rate, turns=m["turns"],
                fall=m["duration"], landed=m["landed"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--crumple", default=os.path.join(ROOT, "build", "crumple"))
    ap.add_argument("--substeps", default="4,8,16")
    ap.add_argument("--flutter-angles", default="8,9,10,11,12")
    ap.add_argument("--strip-angles", default="28,30,32")
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    subs = [int(x) for x in args.substeps.split(",")]
    runs = [("fall-flutter", s, float(a)) for s in subs for a in args.flutter_angles.split(",")]
    runs += [("fall-strip", s, float(a)) for s in subs for a in args.strip_angles.split(",")]
    with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(args.jobs) as pool:
        frames = list(pool.map(lambda r: run(args.crumple, tmp, *r), runs))
    rows = {r: (flutter_row if r[0] == "fall-flutter" else strip_row)(f)
            for r, f in zip(runs, frames)}
    print("fall-flutter (48 fps):\n")
    print_table(rows, "fall-flutter", subs, [("first swing (deg)", "first", ".1f"),
                                             ("largest tilt (deg)", "tilt", ".1f"),
                                             ("reversals", "reversals", "g")])
    print("\nfall-strip (48 fps; its steady tumble between 2 and 4 s; + still falling at "
          "the shot's end):\n")
    print_table(rows, "fall-strip", subs, [("descent (m/s)", "descent", ".3f"),
                                           ("sideways (m/s)", "sideways", ".3f"),
                                           ("turns per s", "rate", ".2f"),
                                           ("turns one way", "turns", ".1f")])


def print_table(rows, sample, subs, columns):
    """One row per (substeps, angle) and each substep count's medians."""
    heads = " | ".join(h for h, _, _ in columns)
    print(f"| substeps | release (deg) | {heads} | fall (s) |")
    print("| --- | --- | " + "--- | " * len(columns) + "--- |")
    for s in subs:
        mine = [(r, v) for r, v in rows.items() if r[0] == sample and r[1] == s]
        for (_, _, a), v in mine:
            cells = " | ".join(format(v[k], f) for _, k, f in columns)
            fall = f"{v['fall']:.2f}" + ("" if v["landed"] else "+")
            print(f"| {s} | {a:g} | {cells} | {fall} |")
        cells = " | ".join(format(statistics.median(v[k] for _, v in mine), f)
                           for _, k, f in columns)
        print(f"| {s} | median | {cells} | "
              f"{statistics.median(v['fall'] for _, v in mine):.2f} |")

if __name__ == "__main__":
    sys.exit(main())
