"""Writes the scene folder from the Blender scene (docs/BLENDER.md "What is
written"): scene.toml (docs/SCENE.md) and animation.gltf, the handles',
colliders' and camera's motion through Blender's own glTF exporter.

crumple's world is Y-up metres; the exporter turns Blender's Z-up into Y-up
(export_yup), so every position and direction in scene.toml is converted the
same way (common.to_gltf) and `units` is "m". The same Blender scene gives
the same scene.toml, byte for byte: objects are taken sorted by name and
numbers printed with common.number."""

import contextlib
import os

import bpy
from mathutils import Vector

from .common import CrumpleError, number, string, to_gltf, vector

SCENE_FILE = "scene.toml"
ANIMATION_FILE = "animation.gltf"
# How far a handle may start from the sheet's plane or outside its
# rectangle, in metres: a handle must touch the sheet at the first frame.
ON_SHEET_TOLERANCE = 1e-3
# The sheet must be flat and its axes perpendicular to this relative error.
FLAT_TOLERANCE = 1e-6


class Sheet:
    """The rectangle the sheet mesh spans at the first frame (Blender world)."""

    def __init__(self, origin, u_axis, v_axis, width, height):
        self.origin, self.u_axis, self.v_axis = origin, u_axis, v_axis
        self.normal = u_axis.cross(v_axis)
        self.width, self.height = width, height


def scene_folder(context):
    """The absolute scene folder; a '//' path needs a saved .blend."""
    path = context.scene.crumple.directory
    if path.startswith("//") and not bpy.data.filepath:
        raise CrumpleError("Save the .blend file first, or choose an absolute "
                           "crumple folder (it is relative to the .blend: %s)" % path)
    path = bpy.path.abspath(path)
    if not path.strip():
        raise CrumpleError("No crumple folder chosen")
    return os.path.normpath(path)


@contextlib.contextmanager
def at_frame(scene, frame):
    """Evaluates the scene at `frame`, restoring the current frame after."""
    current, subframe = scene.frame_current, scene.frame_subframe
    scene.frame_set(frame)
    try:
        yield
    finally:
        scene.frame_set(current, subframe=subframe)


def sheet_rectangle(obj):
    """The sheet mesh's local XY bounding rectangle in the world: pattern u
    along local +X, v along local +Y, pattern (0, 0) at the (min x, min y)
    corner; the front (crumple's u x v) is local +Z."""
    me = obj.data
    if len(me.vertices) < 3:
        raise CrumpleError("Sheet '%s' has no faces: it must be a plane" % obj.name)
    xs = [v.co.x for v in me.vertices]
    ys = [v.co.y for v in me.vertices]
    zs = [v.co.z for v in me.vertices]
    size = max(max(xs) - min(xs), max(ys) - min(ys))
    if size <= 0.0 or max(zs) - min(zs) > FLAT_TOLERANCE * size + 1e-9:
        raise CrumpleError("Sheet '%s' is not flat in its local XY plane" % obj.name)
    m = obj.matrix_world
    ux, vy = m.col[0].xyz, m.col[1].xyz
    if ux.length == 0.0 or vy.length == 0.0:
        raise CrumpleError("Sheet '%s' is scaled to zero" % obj.name)
    if abs(ux.normalized().dot(vy.normalized())) > FLAT_TOLERANCE:
        raise CrumpleError("Sheet '%s' is sheared: its local X and Y must stay "
                           "perpendicular" % obj.name)
    origin = m @ Vector((min(xs), min(ys), zs[0]))
    return Sheet(origin, ux.normalized(), vy.normalized(),
                 (max(xs) - min(xs)) * ux.length, (max(ys) - min(ys)) * vy.length)


def pattern_point(sheet, position, what):
    """Where `position` (Blender world) touches the sheet: its (u, v) in
    metres; an error naming `what` when it is off the sheet."""
    d = position - sheet.origin
    u, v, off = d.dot(sheet.u_axis), d.dot(sheet.v_axis), d.dot(sheet.normal)
    tol = ON_SHEET_TOLERANCE
    if abs(off) > tol:
        raise CrumpleError("%s is off the sheet: %.1f mm from its plane at the "
                           "first frame" % (what, off * 1000.0))
    if not (-tol <= u <= sheet.width + tol and -tol <= v <= sheet.height + tol):
        raise CrumpleError("%s is off the sheet: it lies outside the sheet's "
                           "rectangle at the first frame (u %.1f mm, v %.1f mm, "
                           "sheet %.1f x %.1f mm)"
                           % (what, u * 1e3, v * 1e3, sheet.width * 1e3, sheet.height * 1e3))
    return (min(max(u, 0.0), sheet.width), min(max(v, 0.0), sheet.height))


def handle_entries(scene, sheet_obj, sheet):
    """[[handles]]: marked objects (their origins) and marked pose bones
    (their heads), with the objects to export for them."""
    entries, export = [], []
    for obj in sorted(scene.objects, key=lambda o: o.name):
        if obj == sheet_obj:
            continue
        if obj.crumple.role == "HANDLE":
            where = obj.matrix_world.translation
            entries.append((obj.name, pattern_point(sheet, where, "Handle '%s'" % obj.name),
                            obj.crumple.tangent_control))
            export.append(obj)
        if obj.type == "ARMATURE" and obj.pose:
            for bone in sorted(obj.pose.bones, key=lambda b: b.name):
                if bone.crumple.is_handle:
                    where = obj.matrix_world @ bone.head
                    what = "Handle bone '%s' of '%s'" % (bone.name, obj.name)
                    entries.append((bone.name, pattern_point(sheet, where, what),
                                    bone.crumple.tangent_control))
                    export.append(obj)
    return entries, export


def collider_entries(scene, sheet_obj):
    """[[colliders]] of the objects marked as colliders (docs/SCENE.md):
    mesh, box and sphere follow their node; a plane is fixed where it is at
    the first frame."""
    entries, export = [], []
    for obj in sorted(scene.objects, key=lambda o: o.name):
        if obj == sheet_obj or obj.crumple.role != "COLLIDER":
            continue
        shape = obj.crumple.collider_shape
        lines = ["name = %s" % string(obj.name), "type = %s" % string(shape.lower())]
        if shape == "PLANE":
            m = obj.matrix_world
            lines.append("position = %s" % vector(to_gltf(m.translation)))
            lines.append("normal = %s" % vector(to_gltf(m.col[2].xyz.normalized())))
        elif shape == "MESH" and obj.type != "MESH":
            raise CrumpleError("Collider '%s' is a mesh collider but not a mesh" % obj.name)
        else:
            lines.append("node = %s" % string(obj.name))
            dims = obj.dimensions
            if shape == "BOX":  # local axes as the exporter writes them: Y up
                lines.append("size = %s" % vector((dims.x, dims.z, dims.y)))
            elif shape == "SPHERE":
                lines.append("radius = %s" % number(max(dims) / 2.0))
            export.append(obj)
        entries.append(lines)
    return entries, export


class Shot:
    """Everything scene.toml says, gathered from Blender and checked."""

    def __init__(self, context):
        scene = context.scene
        settings = scene.crumple
        self.name = scene.name
        self.blend = os.path.basename(bpy.data.filepath) or "an unsaved .blend"
        self.settings = settings
        sheet_obj = settings.sheet
        if sheet_obj is None:
            raise CrumpleError("No sheet chosen: pick the paper's plane in "
                               "Properties > Scene > Crumple")
        if sheet_obj.name not in scene.objects:
            raise CrumpleError("Sheet '%s' is not in scene '%s'" % (sheet_obj.name, scene.name))
        if abs(scene.unit_settings.scale_length - 1.0) > 1e-9:
            raise CrumpleError("Unit scale %g: crumple needs 1 Blender unit = 1 m "
                               "(Scene > Units > Unit Scale = 1)"
                               % scene.unit_settings.scale_length)
        self.first, self.last = scene.frame_start, scene.frame_end
        self.fps = scene.render.fps / scene.render.fps_base
        with at_frame(scene, self.first):
            self.sheet = sheet_rectangle(sheet_obj)
            self.handles, handle_objects = handle_entries(scene, sheet_obj, self.sheet)
            self.colliders, collider_objects = collider_entries(scene, sheet_obj)
        self.camera = scene.camera
        self.resolution = (round(scene.render.resolution_x * scene.render.resolution_percentage / 100),
                           round(scene.render.resolution_y * scene.render.resolution_percentage / 100))
        self.export = []
        for obj in handle_objects + collider_objects + ([self.camera] if self.camera else []):
            if obj not in self.export:
                self.export.append(obj)
        self._check_node_names()

    def _check_node_names(self):
        """crumple finds nodes by name and refuses a name two glTF nodes
        share: a bone named like another handle or like an exported object."""
        names = [h[0] for h in self.handles]
        names += [o.name for o in self.export if o.crumple.role != "HANDLE"]
        for n in names:
            if names.count(n) > 1:
                raise CrumpleError("Two crumple nodes are called '%s' (a bone named "
                                   "like an object?): rename one" % n)

    def has_animation(self):
        return bool(self.export)

    def toml(self):
        """scene.toml's text (docs/SCENE.md), in metres and Y up."""
        s, sheet = self.settings, self.sheet
        out = ["# Written by the crumple Blender add-on from %s, scene '%s'."
               % (self.blend.replace("\n", " "), self.name.replace("\n", " ")),
               "# Lengths in metres, Y up (Blender's (x, y, z) is (x, z, -y) here).",
               "[scene]",
               "name = %s" % string(self.name),
               'units = "m"',
               "fps = %s" % number(self.fps),
               "frames = [%d, %d]" % (self.first, self.last),
               "substeps = %d" % s.substeps,
               "seed = %d" % s.seed]
        if self.has_animation():
            out.append("animation = %s" % string(ANIMATION_FILE))
        out += ["", "[sheet]",
                "width = %s" % number(sheet.width),
                "height = %s" % number(sheet.height)]
        if s.max_edge > 0.0:
            out.append("max_edge = %s" % number(s.max_edge))
        out += ["origin = %s" % vector(to_gltf(sheet.origin)),
                "u_axis = %s" % vector(to_gltf(sheet.u_axis)),
                "v_axis = %s" % vector(to_gltf(sheet.v_axis)),
                "", "[paper]", "preset = %s" % string(s.paper_preset),
                "", "[model]", "type = %s" % string(s.model)]
        for name, (u, v), tangent in self.handles:
            out += ["", "[[handles]]", "name = %s" % string(name), "node = %s" % string(name),
                    "pattern = %s" % vector((u, v)),
                    "tangent_control = %s" % ("true" if tangent else "false")]
        for lines in self.colliders:
            out += ["", "[[colliders]]"] + lines
        if self.camera:
            out += ["", "[camera]", "node = %s" % string(self.camera.name),
                    "resolution = [%d, %d]" % self.resolution]
        if s.sound:
            out += ["", "[sound]"]
        return "\n".join(out) + "\n"


def export_animation(context, objects, path):
    """The nodes' motion over the scene's frame range through Blender's glTF
    exporter: frame f is keyed at f / fps seconds, which is crumple's time of
    frame f (docs/SCENE.md "Time"). Sampled at every frame (constraints and
    drivers included), one animation for all nodes (no NLA split: crumple
    takes the first animation of a node). Parents go too, so a child's world
    motion is the one exported. Selection and active object are restored."""
    wanted = set()
    for obj in objects:
        while obj is not None:
            wanted.add(obj)
            obj = obj.parent
    view_layer = context.view_layer
    selected = [o for o in view_layer.objects if o.select_get()]
    active = view_layer.objects.active
    _numpy_bool_alias()
    try:
        for obj in view_layer.objects:
            obj.select_set(obj in wanted)
        result = bpy.ops.export_scene.gltf(
            filepath=path, export_format="GLTF_EMBEDDED", use_selection=True,
            export_yup=True, export_apply=False, export_animations=True,
            export_frame_range=True, export_force_sampling=True,
            export_nla_strips=False, export_cameras=True, export_lights=False,
            export_materials="NONE", export_extras=False)
    finally:
        for obj in view_layer.objects:
            obj.select_set(obj in selected)
        view_layer.objects.active = active
    if "FINISHED" not in result or not os.path.isfile(path):
        raise CrumpleError("Blender's glTF exporter did not write %s" % path)


def _numpy_bool_alias():
    """Blender 3.4's glTF add-on still says numpy.bool, which numpy 1.24
    (Debian 12) removed; the builtin is what it meant."""
    import numpy
    if "bool" not in numpy.__dict__:
        numpy.bool = bool


def write(context):
    """Checks the Blender scene and writes the scene folder; returns
    (folder, shot). Raises CrumpleError on bad input."""
    shot = Shot(context)
    folder = scene_folder(context)
    try:
        os.makedirs(folder, exist_ok=True)
        text = shot.toml()
        animation = os.path.join(folder, ANIMATION_FILE)
        if shot.has_animation():
            export_animation(context, shot.export, animation)
        elif os.path.exists(animation):
            os.remove(animation)
        with open(os.path.join(folder, SCENE_FILE), "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
    except OSError as e:
        raise CrumpleError("Cannot write the scene folder %s: %s" % (folder, e.strerror or e))
    return folder, shot
