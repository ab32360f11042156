"""Brings a simulated shot into Blender (docs/BLENDER.md "What comes back"):
one mesh per frame, built from `crumple export` PLY frames, held by one
object whose mesh a frame-change handler swaps (the crumpling model remeshes
and tears cut, so the topology changes from frame to frame); the pattern UVs,
the region of every face as colours (the structure view), the paper colour
and each torn frame's tear texture as the material's alpha; and the
soundtrack as a sound strip starting at the shot's first frame."""

import colorsys
import os
import re

import bpy
from bpy.app.handlers import persistent

from . import ply
from .common import CrumpleError, from_gltf

PREFIX_KEY = "crumple_mesh_prefix"  # on the object: its meshes' name prefix
FIRST_KEY, LAST_KEY = "crumple_first_frame", "crumple_last_frame"
SOUND_STRIP = "crumple sound"
REGION_ATTRIBUTE = "crumple_region"   # int per face: the PLY's region id
STRUCTURE_COLORS = "structure"        # per-corner colour of the face's region
UV_MAP = "pattern"


def frame_files(out):
    """{frame number: path} of the exported PLY frames in OUT/ply."""
    folder = os.path.join(out, "ply")
    if not os.path.isdir(folder):
        raise CrumpleError("No exported frames in %s: simulate first" % folder)
    frames = {}
    for name in os.listdir(folder):
        m = re.fullmatch(r"(\d{4,})\.ply", name)
        if m:
            frames[int(m.group(1))] = os.path.join(folder, name)
    if not frames:
        raise CrumpleError("No exported frames in %s: simulate first" % folder)
    return frames


def region_color(region):
    """A colour per region id, neighbours' ids far apart in hue (golden ratio)."""
    r, g, b = colorsys.hsv_to_rgb((region * 0.618033988749895) % 1.0, 0.55, 0.9)
    return (r, g, b, 1.0)


def build_mesh(name, frame, materials):
    """A Blender mesh of one PLY frame: Y-up metres to Blender's Z-up."""
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(frame.positions))
    me.vertices.foreach_set("co", [c for p in frame.positions for c in from_gltf(p)])
    corners = [i for f in frame.faces for i in f]
    me.loops.add(len(corners))
    me.loops.foreach_set("vertex_index", corners)
    me.polygons.add(len(frame.faces))
    starts, start = [], 0
    for f in frame.faces:
        starts.append(start)
        start += len(f)
    me.polygons.foreach_set("loop_start", starts)
    me.polygons.foreach_set("loop_total", [len(f) for f in frame.faces])
    if frame.uvs:
        uv = me.uv_layers.new(name=UV_MAP)
        uv.data.foreach_set("uv", [c for i in corners for c in frame.uvs[i]])
    if frame.regions:
        me.attributes.new(REGION_ATTRIBUTE, "INT", "FACE").data.foreach_set(
            "value", frame.regions)
        colors = me.color_attributes.new(STRUCTURE_COLORS, "BYTE_COLOR", "CORNER")
        colors.data.foreach_set("color", [c for f, r in zip(frame.faces, frame.regions)
                                          for _ in f for c in region_color(r)])
        me.color_attributes.active_color = colors
    for mat in materials:
        me.materials.append(mat)
    me.update(calc_edges=True)
    me.use_fake_user = True  # kept while another frame's mesh is shown
    return me


def paper_color(out):
    """The paper's linear colour: Kd of the exported paper.mtl."""
    try:
        with open(os.path.join(out, "obj", "paper.mtl"), encoding="utf-8") as f:
            for line in f:
                words = line.split()
                if words[:1] == ["Kd"]:
                    return tuple(float(w) for w in words[1:4]) + (1.0,)
    except OSError:
        pass
    return (0.86, 0.86, 0.84, 1.0)  # office-70gsm's


def paper_material(name, color, tears=None):
    """Principled paper, double-sided; with `tears` (the frame's
    NNNN_tears.png, pattern-space alpha on the UVs) the paper is cut where
    that alpha is below 0.5, as crumple's renderers cut it."""
    mat = bpy.data.materials.get(name) or bpy.data.materials.new(name)
    mat.use_nodes = True
    mat.use_backface_culling = False
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes.get("Principled BSDF")
    bsdf.inputs["Base Color"].default_value = color
    bsdf.inputs["Roughness"].default_value = 1.0
    mat.diffuse_color = color
    for node in [n for n in nodes if n.type == "TEX_IMAGE"]:
        nodes.remove(node)
    if tears:
        image = bpy.data.images.load(tears, check_existing=True)
        image.colorspace_settings.name = "Non-Color"
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = image
        tex.interpolation = "Closest"
        links.new(tex.outputs["Alpha"], bsdf.inputs["Alpha"])
        mat.blend_method = "CLIP"
        mat.alpha_threshold = 0.5
        mat.shadow_method = "CLIP"
    return mat


def remove_meshes(prefix):
    for me in [m for m in bpy.data.meshes if m.name.startswith(prefix)]:
        if me.users <= (1 if me.use_fake_user else 0):
            bpy.data.meshes.remove(me)


def import_shot(context, out, name):
    """Builds (or rebuilds) object `name` from OUT/ply and OUT/obj; returns it."""
    frames = frame_files(out)
    color = paper_color(out)
    plain = paper_material("%s paper" % name, color)
    prefix = "%s." % name
    obj = bpy.data.objects.get(name)
    meshes = {}
    for number in sorted(frames):
        tears = os.path.join(out, "obj", "%04d_tears.png" % number)
        mat = (paper_material("%s paper %04d" % (name, number), color, tears)
               if os.path.isfile(tears) else plain)
        try:
            data = ply.read(frames[number])
        except (OSError, ValueError, KeyError) as e:
            raise CrumpleError("Cannot read %s: %s" % (frames[number], e))
        meshes[number] = build_mesh("%s~new.%04d" % (name, number), data, [mat])
    if obj is None:
        obj = bpy.data.objects.new(name, meshes[min(meshes)])
        context.scene.collection.objects.link(obj)
    obj.data = meshes[min(meshes)]
    remove_meshes(prefix)  # the previous import's, now unused
    for number, me in meshes.items():
        me.name = "%s%04d" % (prefix, number)
    obj[PREFIX_KEY], obj[FIRST_KEY], obj[LAST_KEY] = prefix, min(meshes), max(meshes)
    swap_meshes(context.scene)
    return obj


def add_sound_strip(scene, wav, frame):
    """The soundtrack as a sound strip from `frame` (the shot's first frame:
    sample 0 is that frame's time, docs/SOUND.md "The clock")."""
    scene.sequence_editor_create()
    strips = scene.sequence_editor.sequences
    old = strips.get(SOUND_STRIP)
    if old is not None:
        strips.remove(old)
    strip = strips.new_sound(SOUND_STRIP, wav, channel=1, frame_start=frame)
    return strip


def swap_meshes(scene):
    """Shows each crumple object's mesh of the current frame (held before
    the first and after the last)."""
    for obj in scene.objects:
        prefix = obj.get(PREFIX_KEY)
        if prefix is None:
            continue
        frame = min(max(scene.frame_current, obj[FIRST_KEY]), obj[LAST_KEY])
        me = bpy.data.meshes.get("%s%04d" % (prefix, frame))
        if me is not None and obj.data != me:
            obj.data = me


@persistent
def _on_frame_change(scene, depsgraph=None):
    swap_meshes(scene)


def register():
    if _on_frame_change not in bpy.app.handlers.frame_change_pre:
        bpy.app.handlers.frame_change_pre.append(_on_frame_change)


def unregister():
    if _on_frame_change in bpy.app.handlers.frame_change_pre:
        bpy.app.handlers.frame_change_pre.remove(_on_frame_change)
