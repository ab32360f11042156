"""Writes the Blender-made animation files of tests/io (TimeOrigin.*):
one animation exported by Blender's own exporters with the scene starting at
frame 0 and at frame 1 (Blender's default), as FBX, glTF, GLB and COLLADA,
plus Blender's own world positions of the animated node at every frame.

Run with Blender 3.4 headless (from the repository root):
  blender -b --factory-startup --python tests/io/data/blender/make_time_origin.py

The scene: an empty "Handle" keyed at frames 1, 9, 17 and 25 (Bezier), a
parent "Rig" keyed at frames 1 and 25 (translation and a turn about Z) with
Handle under it; 24 fps, Blender's units (metres, Z up). Files, for START in
0 and 1 (the scene's frame_start; the keys are the same, so frame f shows
the same pose in both):
  start<START>.fbx   Blender's FBX exporter, baked, one take of the scene
  start<START>.gltf  glTF 2.0, separate .bin beside it
  start<START>.glb   glTF 2.0 binary
  start<START>.dae   COLLADA
  per_action.fbx     the START 1 scene with Blender's FBX defaults (a take
                     per object and action, each restarted at 0)
  start<START>.json  {"fps": 24, "frames": [f...], "handle": [[x, y, z]...]}
                     Handle's world position at each frame in Blender's
                     frame (Z up, metres)
"""
import json
import math
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
LAST = 25


def build_scene(start):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    scene.frame_start = start
    scene.frame_end = LAST
    rig = bpy.data.objects.new("Rig", None)
    handle = bpy.data.objects.new("Handle", None)
    scene.collection.objects.link(rig)
    scene.collection.objects.link(handle)
    handle.parent = rig
    for frame, loc in ((1, (0.0, 0.0, 0.0)), (9, (0.04, 0.01, 0.03)),
                       (17, (0.09, -0.02, 0.05)), (25, (0.12, 0.0, 0.02))):
        handle.location = loc
        handle.keyframe_insert("location", frame=frame)
    for frame, loc, turn in ((1, (0.0, 0.0, 0.1), 0.0), (25, (0.05, 0.03, 0.1), 60.0)):
        rig.location = loc
        rig.rotation_euler = (0.0, 0.0, math.radians(turn))
        rig.keyframe_insert("location", frame=frame)
        rig.keyframe_insert("rotation_euler", frame=frame)
    return scene, handle


def export(start):
    scene, handle = build_scene(start)
    stem = os.path.join(HERE, "start%d" % start)
    frames = list(range(start, LAST + 1))
    positions = []
    for f in frames:
        scene.frame_set(f)
        positions.append([round(v, 9) for v in handle.matrix_world.translation])
    with open(stem + ".json", "w") as out:
        json.dump({"fps": 24, "frames": frames, "handle": positions}, out, indent=1)
        out.write("\n")
    scene.frame_set(start)
    # One take of the whole scene at the scene's own frames. Blender's
    # defaults (All Actions, NLA Strips) write a take per action instead,
    # each restarted at 0 from the action's first frame: the scene's timing
    # is not in such a file (docs/SCENE.md, "FBX").
    bpy.ops.export_scene.fbx(filepath=stem + ".fbx", bake_anim_use_all_actions=False,
                             bake_anim_use_nla_strips=False)
    bpy.ops.export_scene.gltf(filepath=stem + ".gltf", export_format="GLTF_SEPARATE")
    bpy.ops.export_scene.gltf(filepath=stem + ".glb", export_format="GLB")
    bpy.ops.wm.collada_export(filepath=stem + ".dae")


for start in (0, 1):
    export(start)
# Blender's default FBX export of the frame-1 scene: a take per action.
build_scene(1)
bpy.ops.export_scene.fbx(filepath=os.path.join(HERE, "per_action.fbx"))
print("make_time_origin: wrote", sorted(os.listdir(HERE)))
sys.exit(0)
