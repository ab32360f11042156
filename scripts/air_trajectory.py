#!/usr/bin/env python3
"""The flight of a falling sheet drawn side on, as Andersen, Pesavento & Wang
(2005) draw their plates' trajectories: from `crumple inspect --json`, the
sheet's cross-section in the x-y plane (a segment through its centre of mass,
perpendicular to its mean normal, as long as its chord) every few frames up
to the frame it lands on, the centre's path and the table (y = 0). Writes a
PNG (stdlib only).

Usage: scripts/air_trajectory.py INSPECT.json OUT.png [--every N]
"""
import argparse
import json
import math
import struct
import zlib


def write_png(path, width, height, rows):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    def chunk(tag, data):
        return (struct.pack(">I", len(data)) + tag + data +
                struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


class Canvas:
    def __init__(self, w, h):
        self.w, self.h = w, h
        self.rows = [bytearray(b"\xff" * (3 * w)) for _ in range(h)]

    def dot(self, x, y, c, r=0):
        for dy in range(-r, r + 1):
            for dx in range(-r, r + 1):
                px, py = int(round(x)) + dx, int(round(y)) + dy
                if 0 <= px < self.w and 0 <= py < self.h:
                    self.rows[py][3 * px:3 * px + 3] = bytes(c)

    def line(self, x0, y0, x1, y1, c, r=0):
        n = int(max(abs(x1 - x0), abs(y1 - y0))) + 1
        for i in range(n + 1):
            t = i / n
            self.dot(x0 + t * (x1 - x0), y0 + t * (y1 - y0), c, r)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("inspect")
    ap.add_argument("png")
    ap.add_argument("--every", type=int, default=0, help="frames between sections (default: ~60 drawn)")
    args = ap.parse_args()
    frames = json.load(open(args.inspect))["frames"]
    # The flight: up to the first frame touching a collider (it rests after).
    landed = next((k for k, f in enumerate(frames) if f.get("contacts", 0) > 0), None)
    if landed is not None:
        frames = frames[:landed + 1]
    ext = frames[0]["extent"]
    chord = max(math.hypot(ext[0], ext[1]), 1e-3)
    every = args.every or max(1, len(frames) // 60)
    xs = [f["centroid"][0] for f in frames]
    ys = [f["centroid"][1] for f in frames]
    lo_x, hi_x = min(xs) - chord, max(xs) + chord
    lo_y, hi_y = min(0.0, min(ys)) - 0.05, max(ys) + chord
    W = 900
    scale = W * 0.9 / max(hi_x - lo_x, 1e-6)
    H = int(min(1400, max(300, (hi_y - lo_y) * scale + 0.1 * W)))
    scale = min(scale, H * 0.9 / (hi_y - lo_y))
    ox = (W - (hi_x - lo_x) * scale) / 2
    oy = (H - (hi_y - lo_y) * scale) / 2
    def px(x, y):
        return ox + (x - lo_x) * scale, H - (oy + (y - lo_y) * scale)
    c = Canvas(W, H)
    gx0, gy = px(lo_x, 0.0)
    gx1, _ = px(hi_x, 0.0)
    c.line(gx0, gy, gx1, gy, (150, 110, 70), 1)  # the table
    for a, b in zip(frames, frames[1:]):  # the centre's path
        c.line(*px(a["centroid"][0], a["centroid"][1]), *px(b["centroid"][0], b["centroid"][1]),
               (170, 170, 210))
    for k in range(0, len(frames), every):
        f = frames[k]
        n = f["mean_normal"]
        t = (n[1], -n[0])
        norm = math.hypot(*t) or 1.0
        t = (t[0] / norm * chord / 2, t[1] / norm * chord / 2)
        x, y = f["centroid"][0], f["centroid"][1]
        c.line(*px(x - t[0], y - t[1]), *px(x + t[0], y + t[1]), (20, 20, 20), 1)
        c.dot(*px(x, y), (200, 40, 40), 2)
    write_png(args.png, W, H, c.rows)


if __name__ == "__main__":
    main()
