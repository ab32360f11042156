"""The Properties editor panels: Scene > Crumple (the shot and the job),
Object > Crumple (an object's role) and Bone > Crumple (a bone as a handle)."""

import bpy

from . import job, operators


class CRUMPLE_PT_scene(bpy.types.Panel):
    bl_label = "Crumple"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "scene"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.crumple
        layout.use_property_split = True
        col = layout.column()
        col.prop(settings, "sheet")
        sheet = settings.sheet
        if sheet is not None:
            dims = sheet.dimensions
            col.label(text="Size: %.1f x %.1f cm" % (dims.x * 100.0, dims.y * 100.0))
        col.prop(settings, "paper_preset")
        col.prop(settings, "model")
        col.prop(settings, "max_edge")
        col.prop(settings, "substeps")
        col.prop(settings, "seed")
        col.prop(settings, "sound")
        col.prop(settings, "refine")
        col.prop(settings, "directory")
        handles = [o.name for o in context.scene.objects if o.crumple.role == "HANDLE"]
        colliders = [o.name for o in context.scene.objects if o.crumple.role == "COLLIDER"]
        layout.label(text="Handles: %s" % (", ".join(sorted(handles)) or "none (Object > Crumple)"))
        layout.label(text="Colliders: %d" % len(colliders))
        layout.operator("crumple.add_colliders")
        if job.find_crumple(context) is None:
            layout.label(text="crumple not found: set it in the add-on preferences",
                         icon="ERROR")
        col = layout.column(align=True)
        col.operator("crumple.write_scene", icon="FILE_TICK")
        col.operator("crumple.simulate", icon="PLAY")
        col.operator("crumple.import_result", icon="IMPORT")
        if operators._current is not None:
            row = layout.row()
            row.prop(settings, "progress", slider=True, text=settings.status)
            row.operator("crumple.cancel", icon="CANCEL")
        elif settings.status:
            layout.label(text=settings.status)


class CRUMPLE_PT_object(bpy.types.Panel):
    bl_label = "Crumple"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        return context.object is not None

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        obj = context.object
        if obj == context.scene.crumple.sheet:
            layout.label(text="This is the crumple sheet")
            return
        layout.prop(obj.crumple, "role")
        if obj.crumple.role == "HANDLE":
            layout.prop(obj.crumple, "tangent_control")
        elif obj.crumple.role == "COLLIDER":
            layout.prop(obj.crumple, "collider_shape")


class CRUMPLE_PT_bone(bpy.types.Panel):
    bl_label = "Crumple"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "bone"

    @classmethod
    def poll(cls, context):
        return context.object and context.object.type == "ARMATURE" and context.bone

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        bone = context.object.pose.bones.get(context.bone.name)
        if bone is None:
            return
        layout.prop(bone.crumple, "is_handle")
        if bone.crumple.is_handle:
            layout.prop(bone.crumple, "tangent_control")


CLASSES = (CRUMPLE_PT_scene, CRUMPLE_PT_object, CRUMPLE_PT_bone)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
