"""crumple for Blender: mark a plane as the sheet and empties or bones as
handles, write a crumple scene folder, simulate it in the background and
bring the paper back as an animated mesh with its soundtrack
(docs/BLENDER.md).

Modules:
  properties    the settings stored in the .blend (scene, object, pose bone)
                and the add-on preferences (where crumple is)
  scene_writer  scene.toml and the handles' glTF animation
  job           crumple runs as child processes, PROGRESS lines parsed
  ply           the reader of `crumple export --format ply` frames
  importer      per-frame meshes, materials, the frame-change handler, sound
  operators     what the buttons do
  panel         the Properties editor panels
"""

bl_info = {
    "name": "crumple",
    "author": "crumple developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Scene > Crumple; Object > Crumple; Bone > Crumple",
    "description": "Simulate paper held by animated empties or bones with crumple",
    "category": "Animation",
}

import bpy

MIN_BLENDER = (3, 4, 0)

if bpy.app.version >= MIN_BLENDER:
    from . import importer, operators, panel, properties


def register():
    # Refused on an older Blender: its API lacks what the add-on uses
    # (StringProperty search, color attributes).
    if bpy.app.version < MIN_BLENDER:
        raise RuntimeError(
            "crumple needs Blender %d.%d or newer; this is Blender %s"
            % (MIN_BLENDER[0], MIN_BLENDER[1], bpy.app.version_string))
    properties.register()
    operators.register()
    panel.register()
    importer.register()


def unregister():
    importer.unregister()
    panel.unregister()
    operators.unregister()
    properties.unregister()
