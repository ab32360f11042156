"""The Blender round trip of `crumple export` (issue 8, docs/EXPORT.md).

Run by scripts/blender-roundtrip.sh inside Blender (3.4, headless):

    blender -b --factory-startup --python-exit-code 1 \\
        --python scripts/blender_roundtrip.py -- \\
        --cache CACHE --inspect INSPECT.json --export DIR --frames F [F ...]

For every frame it imports DIR/obj/NNNN.obj (wm.obj_import), DIR/ply/NNNN.ply
(import_mesh.ply) and DIR/gltf/NNNN.glb (import_scene.gltf) into an empty
scene, one at a time, and compares what Blender built with the cache: the
cache is read here, independently of crumple's C++ reader, from its byte
layout (docs/PCACHE.md), and its per-frame counts are checked against
`crumple inspect --json` too.

What is comparable, per importer (each keeps the cache's triangles as faces):
  - OBJ: Blender 3.4's importer makes one vertex per `v` line that a face of
    the object uses (the UVs are per face corner, so a UV seam splits
    nothing); so its vertices are the cache's vertices that some triangle uses.
  - PLY: one vertex per vertex record, used or not: all the cache's vertices.
  - glTF: the importer keeps the vertices the indices use (its "merge
    vertices" option is off by default, and the export joins none): the
    cache's used vertices.
Then it imports the shot's .glb once and checks, at each frame, that exactly
the frame's node is shown (scale 1; the others are keyed to 0) with the
cache's counts and bounds.
Bounds are those of the same vertices, in the cache's frame (Y up): the OBJ
and glTF importers turn Y-up files into Blender's Z-up (x, -z, y), which is
undone here; the PLY importer converts nothing. Tolerance 1e-6 m (the files
hold float32 / 9 significant digits).

Exit status 0 when everything matches, 1 when not.
"""

import argparse
import json
import os
import struct
import sys
import zlib

import bpy

TOLERANCE = 1e-6  # m


# ---------------------------------------------------------------- the cache


class CacheFrame:
    def __init__(self, number, triangles, positions):
        self.number = number
        self.triangles = triangles  # list of (a, b, c)
        self.positions = positions  # list of (x, y, z), m, Y up

    def used(self):
        return sorted({v for t in self.triangles for v in t})


def read_cache(path):
    """Every complete frame of a .pcache, by frame number (docs/PCACHE.md)."""
    data = open(path, "rb").read()
    if data[:8] != b"PCACHE\x00\x01":
        raise SystemExit("%s: not a crumple cache" % path)
    frames = {}
    pos = 8
    topology = None  # (triangles, vertex count) carried forward
    while pos + 20 <= len(data):
        tag = data[pos:pos + 4]
        length = struct.unpack_from("<Q", data, pos + 8)[0]
        end = pos + 16 + length
        if end + 4 > len(data):
            break  # truncated: an interrupted run
        crc = struct.unpack_from("<I", data, end)[0]
        if zlib.crc32(data[pos:end]) & 0xFFFFFFFF != crc:
            break
        if tag == b"FOOT":
            break
        if tag == b"FRAM":
            p = pos + 16
            number, _time, flags = struct.unpack_from("<idB", data, p)
            p += 13
            if flags & 1:
                n = struct.unpack_from("<I", data, p)[0]
                p += 4
                flat = struct.unpack_from("<%di" % (3 * n), data, p)
                p += 12 * n
                triangles = [flat[3 * i:3 * i + 3] for i in range(n)]
                n = struct.unpack_from("<I", data, p)[0]  # regionOfTriangle
                p += 4 + 4 * n
                n = struct.unpack_from("<I", data, p)[0]  # regionTypes
                p += 4 + n
                n = struct.unpack_from("<I", data, p)[0]  # pattern
                p += 4 + 16 * n
                topology = triangles
            if topology is None:
                raise SystemExit("%s: the first frame has no topology" % path)
            n = struct.unpack_from("<I", data, p)[0]
            p += 4
            flat = struct.unpack_from("<%dd" % (3 * n), data, p)
            positions = [flat[3 * i:3 * i + 3] for i in range(n)]
            frames[number] = CacheFrame(number, topology, positions)
        pos = end + 4
    return frames


def read_fps(path):
    """The cache header's fps (HEAD: u32 formatVersion, then f64 fps)."""
    with open(path, "rb") as f:
        head = f.read(8 + 20 + 12)
    return struct.unpack_from("<d", head, 8 + 16 + 4)[0]


def bounds(points):
    lo = [min(p[k] for p in points) for k in range(3)]
    hi = [max(p[k] for p in points) for k in range(3)]
    return lo, hi


# ---------------------------------------------------------------- Blender


def import_file(kind, path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if kind == "obj":
        bpy.ops.wm.obj_import(filepath=path)
    elif kind == "ply":
        bpy.ops.import_mesh.ply(filepath=path)
    else:
        bpy.ops.import_scene.gltf(filepath=path)
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    if len(meshes) != 1:
        raise RuntimeError("%s: %d mesh objects" % (path, len(meshes)))
    obj = meshes[0]
    me = obj.data
    world = [obj.matrix_world @ v.co for v in me.vertices]
    if kind in ("obj", "gltf"):  # Blender's Z up back to the file's Y up
        world = [(w.x, w.z, -w.y) for w in world]
    else:
        world = [(w.x, w.y, w.z) for w in world]
    uvs = [d.uv for d in me.uv_layers[0].data] if me.uv_layers else []
    return {
        "vertices": len(me.vertices),
        "faces": len(me.polygons),
        "triangles": all(len(p.vertices) == 3 for p in me.polygons),
        "bounds": bounds(world) if world else None,
        "uv": (min(min(u.x, u.y) for u in uvs), max(max(u.x, u.y) for u in uvs)) if uvs else None,
    }


def fmt_box(box):
    lo, hi = box
    return "[%.6f, %.6f, %.6f]..[%.6f, %.6f, %.6f]" % (*lo, *hi)


def close(a, b):
    return all(abs(x - y) <= TOLERANCE for x, y in zip(a[0] + a[1], b[0] + b[1]))


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="blender_roundtrip.py")
    parser.add_argument("--cache", required=True)
    parser.add_argument("--inspect", required=True)
    parser.add_argument("--export", required=True)
    parser.add_argument("--frames", type=int, nargs="+", required=True)
    args = parser.parse_args(argv)

    # Blender 3.4's glTF importer still says np.bool, which numpy 1.24
    # (Debian 12) removed; the builtin is what it meant.
    import numpy
    if "bool" not in numpy.__dict__:
        numpy.bool = bool

    cache = read_cache(args.cache)
    inspect = {f["frame"]: f for f in json.load(open(args.inspect))["frames"]}
    print("blender %s; cache %s: %d frames" % (bpy.app.version_string, args.cache, len(cache)))
    ok = True
    imports = 0
    for number in args.frames:
        if number not in cache:
            print("frame %d: not in the cache" % number)
            ok = False
            continue
        f = cache[number]
        used = f.used()
        all_box = bounds(f.positions)
        used_box = bounds([f.positions[v] for v in used])
        j = inspect.get(number, {})
        same = j.get("vertices") == len(f.positions) and j.get("triangles") == len(f.triangles)
        ok = ok and same
        print("frame %d: cache %d vertices (%d used), %d triangles, bounds %s m (Y up); "
              "inspect --json %s vertices, %s triangles: %s"
              % (number, len(f.positions), len(used), len(f.triangles), fmt_box(all_box),
                 j.get("vertices"), j.get("triangles"), "match" if same else "MISMATCH"))
        for kind, sub, ext, want_vertices, want_box in (
                ("obj", "obj", "obj", len(used), used_box),
                ("ply", "ply", "ply", len(f.positions), all_box),
                ("gltf", "gltf", "glb", len(used), used_box)):
            path = os.path.join(args.export, sub, "%04d.%s" % (number, ext))
            got = import_file(kind, path)
            imports += 1
            problems = []
            if got["vertices"] != want_vertices:
                problems.append("%d vertices, want %d" % (got["vertices"], want_vertices))
            if got["faces"] != len(f.triangles) or not got["triangles"]:
                problems.append("%d faces, want %d triangles" % (got["faces"], len(f.triangles)))
            if got["bounds"] is None or not close(got["bounds"], want_box):
                problems.append("bounds differ")
            if got["uv"] is None or got["uv"][0] < -1e-6 or got["uv"][1] > 1 + 1e-6:
                problems.append("UVs missing or outside [0, 1]")
            ok = ok and not problems
            print("  %-4s %5d vertices, %5d faces, bounds %s, uv [%.3f, %.3f]: %s"
                  % (kind, got["vertices"], got["faces"],
                     fmt_box(got["bounds"]) if got["bounds"] else "-",
                     *(got["uv"] or (float("nan"), float("nan"))),
                     "match" if not problems else "MISMATCH: " + "; ".join(problems)))
    # The shot's .glb: every frame a node, shown (scale 1) only on its frame.
    shots = sorted(n for n in os.listdir(os.path.join(args.export, "gltf"))
                   if n.startswith("shot") and n.endswith(".glb"))
    if len(shots) != 1:
        print("shot .glb: %d files, want 1" % len(shots))
        ok = False
    else:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        bpy.context.scene.render.fps = round(read_fps(args.cache))
        bpy.context.scene.render.fps_base = bpy.context.scene.render.fps / read_fps(args.cache)
        bpy.ops.import_scene.gltf(filepath=os.path.join(args.export, "gltf", shots[0]))
        imports += 1
        nodes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
        print("%s: %d frame nodes" % (shots[0], len(nodes)))
        for number in args.frames:
            if number not in cache:
                continue
            f = cache[number]
            bpy.context.scene.frame_set(number)
            shown = [o for o in nodes if o.matrix_world.to_scale().x > 0.5]
            name = "frame_%04d" % number
            problems = []
            if [o.name for o in shown] != [name]:
                problems.append("shown: %s, want %s" % ([o.name for o in shown][:3], name))
            text = "-"
            if len(shown) == 1:
                o = shown[0]
                world = [o.matrix_world @ v.co for v in o.data.vertices]
                box = bounds([(w.x, w.z, -w.y) for w in world])
                used = f.used()
                if len(o.data.vertices) != len(used) or len(o.data.polygons) != len(f.triangles):
                    problems.append("counts differ")
                if not close(box, bounds([f.positions[v] for v in used])):
                    problems.append("bounds differ")
                text = "%d vertices, %d faces, bounds %s" % (len(o.data.vertices),
                                                             len(o.data.polygons), fmt_box(box))
            ok = ok and not problems
            print("  at frame %d: %d of %d nodes shown (%s), %s: %s"
                  % (number, len(shown), len(nodes), ", ".join(o.name for o in shown[:3]), text,
                     "match" if not problems else "MISMATCH: " + "; ".join(problems)))
    print("round trip: %d imports of %d frames %s"
          % (imports, len(args.frames), "match the cache" if ok else "DO NOT match the cache"))
    sys.exit(0 if ok else 1)


main()
