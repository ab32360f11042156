"""The add-on's operators. Bad input (no sheet, a handle off the sheet,
crumple not found, crumple refusing the scene) is reported with
self.report({'ERROR'}, ...), never raised."""

import os
import time

import bpy
from bpy.props import BoolProperty

from . import importer, job, scene_writer
from .common import CrumpleError

OUT = "out"              # the shot's outputs, inside the scene folder
LOG = "crumple.log"      # every command and what it said, in OUT
_current = None          # the running Job (one at a time)


def result_name(context):
    sheet = context.scene.crumple.sheet
    return "%s (crumple)" % (sheet.name if sheet else context.scene.name)


class CRUMPLE_OT_write_scene(bpy.types.Operator):
    """Write scene.toml and animation.gltf into the crumple folder"""
    bl_idname = "crumple.write_scene"
    bl_label = "Write Scene"

    def execute(self, context):
        try:
            folder, shot = scene_writer.write(context)
        except CrumpleError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self.report({"INFO"}, "Wrote %s (%d handles, frames %d-%d)"
                    % (os.path.join(folder, scene_writer.SCENE_FILE), len(shot.handles),
                       shot.first, shot.last))
        return {"FINISHED"}


class CRUMPLE_OT_simulate(bpy.types.Operator):
    """Write the scene, simulate it with crumple in the background and import
    the paper (and its sound)"""
    bl_idname = "crumple.simulate"
    bl_label = "Simulate"

    synchronous: BoolProperty(
        name="Wait", default=False, options={"HIDDEN", "SKIP_SAVE"},
        description="Block Blender until crumple is done (scripts, background mode)")

    @classmethod
    def poll(cls, context):
        return _current is None

    def execute(self, context):
        global _current
        try:
            crumple = job.require_crumple(context)
            folder, shot = scene_writer.write(context)
            out = os.path.join(folder, OUT)
            os.makedirs(out, exist_ok=True)
            for sub in ("ply", "obj"):  # no stale frames of a longer shot
                _remove_frames(os.path.join(out, sub))
        except (CrumpleError, OSError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self._out, self._first = out, shot.first
        steps = job.shot_steps(crumple, folder, out, context.scene.crumple.refine,
                               context.scene.crumple.sound)
        _current = job.Job(steps, os.path.join(out, LOG)).start()
        self._show(context)
        if self.synchronous or bpy.app.background or context.window is None:
            while _current.poll() == job.RUNNING:
                time.sleep(0.05)
            return self._finish(context)
        wm = context.window_manager
        wm.progress_begin(0, 100)
        self._timer = wm.event_timer_add(0.2, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        if _current.poll() == job.RUNNING:
            self._show(context)
            return {"PASS_THROUGH"}
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        return self._finish(context)

    def _show(self, context):
        settings = context.scene.crumple
        settings.running = _current.state == job.RUNNING
        settings.progress = _current.progress
        settings.status = "%s: %d%%" % (_current.label, round(_current.progress))
        if context.window_manager and not bpy.app.background:
            context.window_manager.progress_update(_current.progress)
        for area in (context.screen.areas if context.screen else []):
            if area.type == "PROPERTIES":
                area.tag_redraw()

    def _finish(self, context):
        global _current
        done, _current = _current, None
        settings = context.scene.crumple
        settings.running = False
        if done.state != job.DONE:
            settings.status = done.error
            self.report({"ERROR"} if done.state == job.FAILED else {"WARNING"},
                        "%s (log: %s)" % (done.error, done.log_path))
            return {"CANCELLED"}
        try:
            obj = import_outputs(context, self._out, self._first)
        except CrumpleError as e:
            settings.status = str(e)
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        settings.progress, settings.status = 100.0, "Done: %s" % obj.name
        self.report({"INFO"}, "Simulated and imported '%s'" % obj.name)
        return {"FINISHED"}


def _remove_frames(folder):
    if os.path.isdir(folder):
        for name in os.listdir(folder):
            if name[:1].isdigit() or name == "paper.mtl":
                os.remove(os.path.join(folder, name))


def import_outputs(context, out, first):
    """The paper mesh, and the sound strip when sound.wav is there; the sheet
    plane is hidden, the paper takes its place."""
    obj = importer.import_shot(context, out, result_name(context))
    wav = os.path.join(out, "sound.wav")
    if context.scene.crumple.sound and os.path.isfile(wav):
        importer.add_sound_strip(context.scene, wav, first)
    sheet = context.scene.crumple.sheet
    if sheet is not None:
        sheet.hide_set(True)
        sheet.hide_render = True
    return obj


class CRUMPLE_OT_cancel(bpy.types.Operator):
    """Stop the running crumple job"""
    bl_idname = "crumple.cancel"
    bl_label = "Cancel"

    @classmethod
    def poll(cls, context):
        return _current is not None

    def execute(self, context):
        _current.cancel()  # the simulate operator's timer then finishes
        return {"FINISHED"}


class CRUMPLE_OT_import_result(bpy.types.Operator):
    """Import the shot last simulated into the crumple folder"""
    bl_idname = "crumple.import_result"
    bl_label = "Import Result"

    def execute(self, context):
        try:
            out = os.path.join(scene_writer.scene_folder(context), OUT)
            obj = import_outputs(context, out, context.scene.frame_start)
        except CrumpleError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self.report({"INFO"}, "Imported '%s'" % obj.name)
        return {"FINISHED"}


class CRUMPLE_OT_add_colliders(bpy.types.Operator):
    """Make the selected objects colliders (meshes: mesh colliders; others: spheres)"""
    bl_idname = "crumple.add_colliders"
    bl_label = "Selected as Colliders"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        sheet = context.scene.crumple.sheet
        count = 0
        for obj in context.selected_objects:
            if obj == sheet or obj.crumple.role == "HANDLE":
                continue
            obj.crumple.role = "COLLIDER"
            obj.crumple.collider_shape = "MESH" if obj.type == "MESH" else "SPHERE"
            count += 1
        self.report({"INFO"}, "%d colliders" % count)
        return {"FINISHED"}


CLASSES = (CRUMPLE_OT_write_scene, CRUMPLE_OT_simulate, CRUMPLE_OT_cancel,
           CRUMPLE_OT_import_result, CRUMPLE_OT_add_colliders)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)


def unregister():
    global _current
    if _current is not None:
        _current.cancel()
        _current = None
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
