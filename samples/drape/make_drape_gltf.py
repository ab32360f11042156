#!/usr/bin/env python3
"""Writes samples/drape/drape.gltf: the keyframed handle curves of the drape
sample, as a DCC would export them (glTF 2.0, Y-up, metres, seconds).

Two nodes, HandleL and HandleR, hold the top corners of an A4 sheet that hangs
in the XY plane (top edge at y = 0.40 m, x = -0.105 .. 0.105 m). They move
together (to x = +-0.05 m, and 5 cm towards the camera), hold, then apart
again to the sheet's width, so the top edge is taut once more.

Run it to regenerate the file (the committed file is its output):
    python3 samples/drape/make_drape_gltf.py
"""
import base64
import json
import os
import struct

TIMES = [0.0, 0.5, 1.25, 1.75, 2.5, 3.0]
LEFT = [(-0.105, 0.40, 0.0), (-0.105, 0.40, 0.0), (-0.05, 0.40, 0.05),
        (-0.05, 0.40, 0.05), (-0.105, 0.40, 0.0), (-0.105, 0.40, 0.0)]
RIGHT = [(-x, y, z) for (x, y, z) in LEFT]


def main():
    blob = bytearray()
    views, accessors = [], []

    def add(data, fmt, count, type_, comp=5126, minmax=None):
        offset = len(blob)
        blob.extend(struct.pack("<" + fmt, *data))
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": struct.calcsize("<" + fmt)})
        acc = {"bufferView": len(views) - 1, "componentType": comp, "count": count, "type": type_}
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    t_acc = add(TIMES, "%df" % len(TIMES), len(TIMES), "SCALAR",
                minmax=([min(TIMES)], [max(TIMES)]))
    l_acc = add([c for p in LEFT for c in p], "%df" % (3 * len(LEFT)), len(LEFT), "VEC3")
    r_acc = add([c for p in RIGHT for c in p], "%df" % (3 * len(RIGHT)), len(RIGHT), "VEC3")

    gltf = {
        "asset": {"version": "2.0", "generator": "crumple samples/drape/make_drape_gltf.py"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [
            {"name": "HandleL", "translation": list(LEFT[0])},
            {"name": "HandleR", "translation": list(RIGHT[0])},
        ],
        "animations": [{
            "name": "drape",
            "samplers": [
                {"input": t_acc, "output": l_acc, "interpolation": "LINEAR"},
                {"input": t_acc, "output": r_acc, "interpolation": "LINEAR"},
            ],
            "channels": [
                {"sampler": 0, "target": {"node": 0, "path": "translation"}},
                {"sampler": 1, "target": {"node": 1, "path": "translation"}},
            ],
        }],
        "buffers": [{
            "byteLength": len(blob),
            "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode(),
        }],
        "bufferViews": views,
        "accessors": accessors,
    }
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "drape.gltf")
    with open(path, "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
