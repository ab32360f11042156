#!/usr/bin/env python3
"""The falling-paper regimes crumple's air gives (docs/AIR.md "Regimes").

Drops strips of the shipped paper presets, of several widths (the chord:
the strip turns about its 20 cm long axis), from 1.5 m at a release angle,
in still air, on the elastic model (fall-strip's settings), and measures
from `crumple inspect --json`: the dimensionless moment of inertia
I* = sigma / (rho chord) (Andersen, Pesavento & Wang 2005), the Reynolds
number U chord / nu at the mean speed U, the largest rotation one way
without turning back (turns), the largest tilt of the mean normal from
vertical, the lateral reversals, the drift and the fall's duration.
Prints a Markdown table.

Usage: scripts/air_regimes.py [--crumple build/crumple] [--angle 30]
       [--widths 2,3,...] [--presets office-70gsm,office-90gsm]
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

NU_AIR = 1.516e-5  # m^2/s, kinematic viscosity of air at 20 C
RHO_AIR = 1.204    # kg/m^3, [air] density's default
GRAMMAGE = {"office-70gsm": 0.070, "office-90gsm": 0.090}

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def scene_text(preset, width_cm, angle_deg):
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    with open(os.path.join(ROOT, "samples", "fall-strip", "scene.toml")) as f:
        text = f.read()
    text = text.replace("width = 5.0", f"width = {width_cm}")
    text = text.replace('preset = "office-90gsm"', f'preset = "{preset}"')
    text = text.replace("u_axis = [0.8660254, 0.5, 0.0]", f"u_axis = [{c:.8f}, {s:.8f}, 0.0]")
    text = text.replace("origin = [-2.165, 148.75, 10.0]",
                        f"origin = [{-width_cm / 2 * c:.4f}, {150 - width_cm / 2 * s:.4f}, 10.0]")
    if width_cm > 10:  # wide sheets: fall-flutter's coarser mesh
        text = text.replace("max_edge = 1.0", "max_edge = 2.0")
    return text


def measure(frames):
    landed = next((i for i, f in enumerate(frames) if f.get("contacts", 0) > 0), len(frames))
    flight = frames[:landed]
    total, last, angles = 0.0, None, []
    for f in flight:
        n = f["mean_normal"]
        a = math.atan2(n[1], n[0])
        if last is not None:
            total += math.remainder(a - last, 2 * math.pi)
        last = a
        angles.append(total)
    best = 0.0
    for sign in (1, -1):
        start, peak = 0, 0.0
        for k in range(1, len(angles)):
            reached = sign * (angles[k] - angles[start])
            if reached < peak - math.radians(1):
                start, peak = k, 0.0
                continue
            peak = max(peak, reached)
            best = max(best, peak)
    tilt = max(f["normal_angle_deg"] for f in flight)
    reversals, last_sign = 0, 0
    for f in flight[1:]:
        vx = f["centroid_velocity"][0]
        if abs(vx) < 0.01:
            continue
        sign = 1 if vx > 0 else -1
        if last_sign and sign != last_sign:
            reversals += 1
        last_sign = sign
    x0, y0 = flight[0]["centroid"][0], flight[0]["centroid"][1]
    x1, y1 = flight[-1]["centroid"][0], flight[-1]["centroid"][1]
    duration = flight[-1]["time"] - flight[0]["time"]
    speed = math.hypot(x1 - x0, y1 - y0) / duration if duration > 0 else 0.0
    return dict(landed=landed < len(frames), turns=best / (2 * math.pi), tilt=tilt,
                reversals=reversals, drift=abs(x1 - x0), duration=duration, speed=speed)


def regime(m):
    if m["turns"] > 1.0:
        return "tumbling"
    if m["tilt"] < 90.0 and m["reversals"] >= 2:
        return "fluttering"
    return "chaotic (turns over, then swings)"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--crumple", default=os.path.join(ROOT, "build", "crumple"))
    ap.add_argument("--angle", type=float, default=30.0)
    ap.add_argument("--widths", default="2,3,4,5,6,8,10,15,21,29.7")
    ap.add_argument("--presets", default="office-90gsm,office-70gsm")
    args = ap.parse_args()
    print(f"Release angle {args.angle:g} deg, 1.5 m, still air; strips 20 cm long.\n")
    print("| paper | chord (cm) | I* | Re | turns one way | largest tilt (deg) | lateral "
          "reversals | drift (m) | fall (s) | regime |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as tmp:
        for preset in args.presets.split(","):
            for w in (float(x) for x in args.widths.split(",")):
                work = os.path.join(tmp, f"{preset}-{w}")
                os.makedirs(work)
                with open(os.path.join(work, "scene.toml"), "w") as f:
                    f.write(scene_text(preset, w, args.angle))
                subprocess.run([args.crumple, "simulate", work, "--out", work + "/out"],
                               check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                out = subprocess.run([args.crumple, "inspect", "--json", work + "/out/cache.pcache"],
                                     check=True, capture_output=True, text=True).stdout
                m = measure(json.loads(out)["frames"])
                istar = GRAMMAGE[preset] / (RHO_AIR * w / 100)
                re = m["speed"] * (w / 100) / NU_AIR
                fall = f"{m['duration']:.2f}" + ("" if m["landed"] else " (still falling)")
                print(f"| {preset} | {w:g} | {istar:.2f} | {re:.0f} | {m['turns']:.2f} | "
                      f"{m['tilt']:.0f} | {m['reversals']} | {m['drift']:.2f} | {fall} | "
                      f"{regime(m)} |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
