"""Headless test of the crumple Blender add-on (docs/BLENDER.md "Test"),
run by scripts/blender-addon-test.sh inside Blender 3.4:

    blender -b --factory-startup --python-exit-code 1 \\
        --python tests/blender/test_addon.py -- --zip ZIP --crumple BIN --work DIR

It installs the add-on from its zip, builds the cylinder-fold shot in Blender
(a 10 cm plane and four corner empties keyed from
samples/cylinder-fold/make_cylinder_fold_gltf.py's corner_pose, converted to
Blender's Z-up), writes the scene twice (byte-identical scene.toml, whose
handles and sheet corners are where the empties and the plane are),
simulates it through the operator (synchronously) with [sound], and checks,
at several frames, what came back against crumple's own outputs:
  - the mesh shown is that frame's, with `crumple inspect --json`'s vertex
    and triangle counts (export --refine off: the cache's mesh);
  - its bounds, back in Y-up, are those of the frame's PLY (read here by a
    reader of its own, 1e-6 m);
  - every handle empty sits on a vertex of the mesh at that frame, within
    1e-4 m plus the handle error crumple reports for the frame (a handle
    lags its node where the sheet cannot follow without stretching): a
    wrong axis conversion or a frame off by one moves them apart;
  - the sound strip starts at the first frame and lasts round(duration * fps)
    frames of the WAV.
Then the error paths: no sheet, a handle off the sheet, crumple not found,
a scene crumple refuses: each an ERROR report (RuntimeError from bpy.ops
carrying the message, no traceback); and a cancelled job stops its process.
Prints one line per check; exit status 0 when all pass."""

import argparse
import json
import math
import os
import struct
import subprocess
import sys
import time
import wave

import bpy
from mathutils import Vector

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "samples", "cylinder-fold"))
from make_cylinder_fold_gltf import CORNERS, corner_pose  # noqa: E402

FAILED = []


def check(ok, what):
    print("%s %s" % ("ok  " if ok else "FAIL", what))
    if not ok:
        FAILED.append(what)


# ---------------------------------------------------------------- the scene


def gltf_to_blender(p):
    return Vector((p[0], -p[2], p[1]))


def blender_to_gltf(p):
    return (p[0], p[2], -p[1])


def build_scene(folder, first=1, last=102):
    """The cylinder-fold shot (samples/cylinder-fold/scene.toml) in Blender."""
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = first, last
    scene.render.fps, scene.render.fps_base = 24, 1.0
    bpy.ops.mesh.primitive_plane_add(size=0.1, location=(0.0, 0.0, 0.1))
    sheet = bpy.context.object
    sheet.name = "Paper"
    for name, u, v in CORNERS:
        empty = bpy.data.objects.new(name, None)
        scene.collection.objects.link(empty)
        empty.rotation_mode = "QUATERNION"
        for frame in range(first, last + 1):
            position, q = corner_pose(u, v, frame / 24.0)  # glTF: Y up, (x, y, z, w)
            empty.location = gltf_to_blender(position)
            empty.rotation_quaternion = (q[3], q[0], -q[2], q[1])
            empty.keyframe_insert("location", frame=frame)
            empty.keyframe_insert("rotation_quaternion", frame=frame)
        empty.crumple.role = "HANDLE"
        empty.crumple.tangent_control = True
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.location = (0.13, -0.20, 0.22)
    camera.rotation_euler = (math.radians(60), 0.0, math.radians(33))
    scene.camera = camera
    settings = scene.crumple
    settings.sheet = sheet
    settings.paper_preset = "office-70gsm"
    settings.model = "hybrid"
    settings.substeps = 3
    settings.sound = True
    settings.refine = "off"
    settings.directory = folder
    scene.frame_set(first)
    return scene


# ---------------------------------------------------------------- references


def ply_bounds(path):
    """Vertex count and bounds (Y up) of a binary PLY, float properties only
    in its vertex element (docs/EXPORT.md "PLY")."""
    data = open(path, "rb").read()
    end = data.index(b"\n", data.index(b"end_header")) + 1
    lines = data[:end].decode("ascii").splitlines()
    count = next(int(l.split()[2]) for l in lines if l.startswith("element vertex"))
    props = []
    for l in lines[lines.index(next(l for l in lines if l.startswith("element vertex"))) + 1:]:
        if not l.startswith("property"):
            break
        props.append(l.split()[2])
    assert props[:3] == ["x", "y", "z"], props
    rows = list(struct.iter_unpack("<%df" % len(props), data[end:end + 4 * len(props) * count]))
    lo = [min(r[k] for r in rows) for k in range(3)]
    hi = [max(r[k] for r in rows) for k in range(3)]
    return count, lo, hi


def mesh_bounds(obj):
    world = [obj.matrix_world @ v.co for v in obj.data.vertices]
    yup = [blender_to_gltf(w) for w in world]
    return [min(p[k] for p in yup) for k in range(3)], [max(p[k] for p in yup) for k in range(3)]


def check_scene_file(scene, folder, sheet, handles):
    """scene.toml's geometry against Blender's at the first frame, converted
    to Y up here: every handle's pattern point is where its empty is, the
    sheet's corners where the plane's are (1e-6 m). crumple pins the corners
    to their nodes whatever the file says, so only this sees a wrong axis in
    the writer."""
    import tomllib
    spec = tomllib.load(open(os.path.join(folder, "scene.toml"), "rb"))
    s = spec["sheet"]

    def place(u, v):
        return Vector(s["origin"]) + u * Vector(s["u_axis"]) + v * Vector(s["v_axis"])

    scene.frame_set(scene.frame_start)
    yup = {h.name: Vector(blender_to_gltf(h.matrix_world.translation)) for h in handles}
    err = max((place(*h["pattern"]) - yup[h["node"]]).length for h in spec["handles"])
    corners = [blender_to_gltf(sheet.matrix_world @ v.co) for v in sheet.data.vertices]
    want = [place(u, v) for u in (0.0, s["width"]) for v in (0.0, s["height"])]
    cerr = max(min((Vector(c) - w).length for c in corners) for w in want)
    check(len(spec["handles"]) == len(handles) and err < 1e-6 and cerr < 1e-6,
          "scene.toml: %d handles on their empties (%.1e m), sheet corners on the plane's "
          "(%.1e m)" % (len(spec["handles"]), err, cerr))


def expect_error(op, text, what, **kwargs):
    """`op` must report an ERROR containing `text` (bpy.ops raises it as a
    RuntimeError) and raise no Python exception of its own."""
    try:
        op(**kwargs)
    except RuntimeError as e:
        message = str(e)
        check(text in message and "Traceback" not in message,
              "%s: ERROR report '%s'" % (what, message.strip().splitlines()[0]))
        return
    check(False, "%s: no ERROR report" % what)


# ---------------------------------------------------------------- checks


def check_frames(scene, obj, out, inspect, handles):
    frames = {f["frame"]: f for f in inspect["frames"]}
    numbers = sorted(frames)
    changes = [n for a, n in zip(numbers, numbers[1:])
               if frames[n]["vertices"] != frames[a]["vertices"]]
    chosen = sorted({numbers[0], numbers[len(numbers) // 2], numbers[-1]} | set(changes[:2]))
    check(len(changes) > 0, "the topology changes (vertex count at frames %s)" % changes[:4])
    prefix = obj["crumple_mesh_prefix"]
    for n in chosen:
        scene.frame_set(n)
        me = obj.data
        f = frames[n]
        check(me.name == "%s%04d" % (prefix, n), "frame %d: mesh %s shown" % (n, me.name))
        check(len(me.vertices) == f["vertices"] and len(me.polygons) == f["triangles"],
              "frame %d: %d vertices, %d faces; inspect %d, %d"
              % (n, len(me.vertices), len(me.polygons), f["vertices"], f["triangles"]))
        count, lo, hi = ply_bounds(os.path.join(out, "ply", "%04d.ply" % n))
        blo, bhi = mesh_bounds(obj)
        err = max(abs(a - b) for a, b in zip(lo + hi, blo + bhi))
        check(count == len(me.vertices) and err < 1e-6,
              "frame %d: bounds [%.4f %.4f %.4f]..[%.4f %.4f %.4f] m (Y up), PLY's within %.1e m"
              % (n, *blo, *bhi, err))
        verts = [obj.matrix_world @ v.co for v in me.vertices]
        gap = max(min((h.matrix_world.translation - v).length for v in verts) for h in handles)
        lag = f["handle_error"]  # a handle lags its node where the sheet cannot follow
        check(gap < lag + 1e-4, "frame %d: every handle empty on a mesh vertex (farthest "
              "%.2e m; crumple's handle error %.2e m)" % (n, gap, lag))
    check(me.uv_layers.get("pattern") is not None and
          me.color_attributes.get("structure") is not None and len(me.materials) == 1,
          "UVs 'pattern', colours 'structure' and the paper material are there")


def check_sound(scene, out):
    strip = scene.sequence_editor.sequences.get("crumple sound") if scene.sequence_editor else None
    check(strip is not None, "sound strip imported")
    if strip is None:
        return
    with wave.open(os.path.join(out, "sound.wav")) as w:
        seconds = w.getnframes() / w.getframerate()
    fps = scene.render.fps / scene.render.fps_base
    want = round(seconds * fps)
    check(strip.frame_start == scene.frame_start and strip.frame_final_duration == want
          and want == scene.frame_end - scene.frame_start + 1,
          "sound strip at frame %d, %d frames; WAV %.4f s = %d frames at %g fps"
          % (strip.frame_start, strip.frame_final_duration, seconds, want, fps))


def check_errors(scene, crumple, handles):
    settings = scene.crumple
    sheet = settings.sheet
    settings.sheet = None
    expect_error(bpy.ops.crumple.write_scene, "No sheet chosen", "no sheet")
    expect_error(bpy.ops.crumple.simulate, "No sheet chosen", "no sheet (simulate)",
                 synchronous=True)
    settings.sheet = sheet
    stray = handles[0]
    saved = stray.animation_data.action
    stray.animation_data.action = None
    stray.location = (0.2, 0.0, 0.1)  # 15 cm beside the sheet
    expect_error(bpy.ops.crumple.write_scene, "off the sheet", "handle beside the sheet")
    stray.location = (-0.05, -0.05, 0.13)  # 3 cm above its corner
    expect_error(bpy.ops.crumple.write_scene, "off the sheet", "handle above the sheet")
    stray.animation_data.action = saved
    prefs = bpy.context.preferences.addons["crumple_blender"].preferences
    prefs.crumple_path = "/nonexistent/crumple"
    expect_error(bpy.ops.crumple.simulate, "crumple not found", "crumple missing",
                 synchronous=True)
    prefs.crumple_path = crumple
    settings.paper_preset = "no-such-paper"
    expect_error(bpy.ops.crumple.simulate, "bad input", "crumple refuses the scene",
                 synchronous=True)
    settings.paper_preset = "office-70gsm"


def check_cancel(work):
    from crumple_blender import job
    j = job.Job([job.Step("sleep", ["sleep", "30"], 1)], os.path.join(work, "cancel.log")).start()
    process = j._process
    t = time.monotonic()
    j.cancel()
    check(j.state == job.CANCELLED and process.poll() is not None and time.monotonic() - t < 6,
          "cancel stops the running command (%s, exit %s)" % (j.state, process.returncode))


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="test_addon.py")
    parser.add_argument("--zip", required=True)
    parser.add_argument("--crumple", required=True)
    parser.add_argument("--work", required=True)
    args = parser.parse_args(argv)
    print("blender %s; add-on %s" % (bpy.app.version_string, args.zip))
    bpy.ops.preferences.addon_install(filepath=args.zip, overwrite=True)
    bpy.ops.preferences.addon_enable(module="crumple_blender")
    bpy.context.preferences.addons["crumple_blender"].preferences.crumple_path = args.crumple

    folder = os.path.join(args.work, "scene")
    scene = build_scene(folder)
    handles = [bpy.data.objects[name] for name, _, _ in CORNERS]
    texts = []
    for _ in range(2):
        bpy.ops.crumple.write_scene()
        texts.append(open(os.path.join(folder, "scene.toml"), "rb").read())
    check(texts[0] == texts[1], "scene.toml written twice is byte-identical (%d bytes)"
          % len(texts[0]))
    check_scene_file(scene, folder, scene.crumple.sheet, handles)
    t = time.monotonic()
    result = bpy.ops.crumple.simulate(synchronous=True)
    check(result == {"FINISHED"}, "simulate + import: %s in %.1f s" % (result, time.monotonic() - t))
    out = os.path.join(folder, "out")
    inspect = json.loads(subprocess.run([args.crumple, "inspect", "--json",
                                         os.path.join(out, "cache.pcache")],
                                        check=True, capture_output=True, text=True).stdout)
    obj = bpy.data.objects.get("Paper (crumple)")
    check(obj is not None, "object 'Paper (crumple)' imported")
    if obj is not None:
        check_frames(scene, obj, out, inspect, handles)
    check_sound(scene, out)
    check_errors(scene, args.crumple, handles)
    check_cancel(args.work)
    print("addon test: %s" % ("all passed" if not FAILED else "%d FAILED" % len(FAILED)))
    sys.exit(1 if FAILED else 0)


if __name__ == "__main__":
    main()
