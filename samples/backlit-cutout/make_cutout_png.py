#!/usr/bin/env python3
"""Writes cutout.png: the printed side of the backlit-cutout sample's sheet.

An A4 page (512 x 724 texels, sRGB, straight alpha) with a printed border,
a few lines of "text" bars, and cut-outs (alpha 0): a row of five round
holes and a flower-shaped window. Cut-outs stand in for tears until tearing
lands (issue 6); the renderers cut the paper where alpha < 0.5.
Only the Python standard library is used (zlib, struct).
"""
import math
import struct
import zlib

W, H = 512, 724


def flower_inside(x, y, cx, cy, r_out, r_in, points=5):
    """True when (x, y) lies inside a five-petalled flower shape."""
    dx, dy = x - cx, y - cy
    r = math.hypot(dx, dy)
    if r > r_out:
        return False
    a = (math.atan2(dy, dx) + math.pi / 2) % (2 * math.pi / points)
    half = math.pi / points
    t = abs(a - half) / half  # 0 at an inner vertex, 1 at an outer one
    # Radius of the star's edge along this angle (linear between the vertices
    # in angle is close enough for a decoration).
    edge = r_in + (r_out - r_in) * t
    return r < edge


def pixel(x, y):
    # Paper, border and text bars (opaque), then cut-outs (transparent).
    r, g, b = 250, 247, 238
    if 24 <= x < 488 and 24 <= y < 700 and not (30 <= x < 482 and 30 <= y < 694):
        r, g, b = 150, 40, 40
    for k in range(8):
        top = 440 + 28 * k
        if top <= y < top + 10 and 60 <= x < 452 - (k % 3) * 60:
            r, g, b = 40, 40, 60
    alpha = 255
    for k in range(5):
        if math.hypot(x + 0.5 - (96 + 80 * k), y + 0.5 - 110) < 26:
            alpha = 0
    if flower_inside(x + 0.5, y + 0.5, 256, 270, 110, 45):
        alpha = 0
    return bytes((r, g, b, alpha))


def write_png(path):
    raw = b"".join(b"\x00" + b"".join(pixel(x, y) for x in range(W)) for y in range(H))

    def chunk(tag, data):
        body = tag + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 6, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9))
    png += chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


if __name__ == "__main__":
    write_png("cutout.png")
