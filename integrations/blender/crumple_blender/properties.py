"""The add-on's settings, stored in the .blend file:
  Scene.crumple      the shot: sheet, paper, model, output folder, job state
  Object.crumple     an object's role: handle (an empty) or collider
  PoseBone.crumple   a bone as a handle
and the add-on preferences (the crumple binary)."""

import os

import bpy
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, IntProperty,
                       PointerProperty, StringProperty)

SHIPPED_PRESETS = ("office-70gsm", "office-90gsm")  # assets/papers


def preset_folders(crumple_path):
    """Where crumple looks for paper presets (docs/SCENE.md "Paper presets"):
    $CRUMPLE_ASSETS/papers, then the source tree's assets/papers, which for a
    build in the tree is beside the binary's folder."""
    folders = []
    if os.environ.get("CRUMPLE_ASSETS"):
        folders.append(os.path.join(os.environ["CRUMPLE_ASSETS"], "papers"))
    if crumple_path:
        here = os.path.dirname(os.path.realpath(crumple_path))
        folders.append(os.path.join(here, "..", "assets", "papers"))
        folders.append(os.path.join(here, "..", "..", "assets", "papers"))
    return folders


def preset_names(crumple_path):
    names = set(SHIPPED_PRESETS)
    for folder in preset_folders(crumple_path):
        if os.path.isdir(folder):
            names.update(f[:-5] for f in os.listdir(folder) if f.endswith(".toml"))
    return sorted(names)


def _search_presets(self, context, edit_text):
    from .job import find_crumple  # late: job imports this module
    path = find_crumple(context)
    return [n for n in preset_names(path) if edit_text.lower() in n.lower()]


def _is_mesh(self, obj):
    return obj.type == "MESH"


class CrumplePreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    crumple_path: StringProperty(
        name="crumple binary", subtype="FILE_PATH", default="",
        description="The crumple executable; empty: $CRUMPLE_BIN, else crumple on PATH")

    def draw(self, context):
        self.layout.prop(self, "crumple_path")


class CrumpleSceneSettings(bpy.types.PropertyGroup):
    sheet: PointerProperty(
        name="Sheet", type=bpy.types.Object, poll=_is_mesh,
        description="A flat rectangular mesh: the paper at the first frame "
                    "(u along its local X, v along its local Y, front = local +Z)")
    paper_preset: StringProperty(
        name="Paper", default="office-70gsm", search=_search_presets,
        description="A paper preset name ([paper] preset)")
    model: EnumProperty(
        name="Model", default="hybrid",
        items=[("hybrid", "Crumpling", "The crumpling model of Schreck et al. 2015: "
                                       "flat and curved regions, singular vertices"),
               ("elastic", "Elastic", "Plain FEM on a fixed mesh (tears, cloth-like)")])
    max_edge: FloatProperty(
        name="Max edge", default=0.0, min=0.0, unit="LENGTH", precision=4,
        description="Simulation mesh resolution; 0: min(width, height) / 16")
    substeps: IntProperty(name="Substeps", default=4, min=1, max=1024)
    seed: IntProperty(name="Seed", default=1, min=0)
    sound: BoolProperty(
        name="Sound", default=False,
        description="Write [sound]: the simulation stores sound events and the "
                    "soundtrack comes back as a sound strip")
    refine: EnumProperty(
        name="Refine", default="auto",
        items=[("auto", "Auto", "Curved regions refined along their rulings"),
               ("off", "Off", "Exactly the simulated mesh")],
        description="crumple export --refine")
    directory: StringProperty(
        name="Folder", subtype="DIR_PATH", default="//crumple",
        description="The scene folder: scene.toml, animation.gltf and out/")
    # The background job's state, shown in the panel.
    running: BoolProperty(default=False, options={"SKIP_SAVE"})
    progress: FloatProperty(name="Progress", default=0.0, min=0.0, max=100.0,
                            subtype="PERCENTAGE", options={"SKIP_SAVE"})
    status: StringProperty(name="Status", default="", options={"SKIP_SAVE"})


class CrumpleObjectSettings(bpy.types.PropertyGroup):
    role: EnumProperty(
        name="Role", default="NONE",
        items=[("NONE", "None", "Not part of the crumple scene"),
               ("HANDLE", "Handle", "A finger holding the sheet where it touches "
                                    "the sheet at the first frame"),
               ("COLLIDER", "Collider", "A solid the sheet stays outside of")])
    tangent_control: BoolProperty(
        name="Tangent control", default=False,
        description="The handle's rotation also turns the sheet's tangent plane")
    collider_shape: EnumProperty(
        name="Shape", default="MESH",
        items=[("MESH", "Mesh", "The object's triangles, moving with it"),
               ("BOX", "Box", "A box of the object's dimensions, moving with it"),
               ("SPHERE", "Sphere", "A sphere of half the object's largest "
                                    "dimension, centred on its origin"),
               ("PLANE", "Plane", "The infinite plane of the object's local XY "
                                  "at the first frame; the solid is behind local +Z")])


class CrumpleBoneSettings(bpy.types.PropertyGroup):
    is_handle: BoolProperty(name="Handle", default=False,
                            description="The bone's head holds the sheet")
    tangent_control: BoolProperty(
        name="Tangent control", default=False,
        description="The bone's rotation also turns the sheet's tangent plane")


CLASSES = (CrumplePreferences, CrumpleSceneSettings, CrumpleObjectSettings,
           CrumpleBoneSettings)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.crumple = PointerProperty(type=CrumpleSceneSettings)
    bpy.types.Object.crumple = PointerProperty(type=CrumpleObjectSettings)
    bpy.types.PoseBone.crumple = PointerProperty(type=CrumpleBoneSettings)


def unregister():
    del bpy.types.PoseBone.crumple
    del bpy.types.Object.crumple
    del bpy.types.Scene.crumple
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
