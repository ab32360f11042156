"""Writes docs/images/blender-panel.png: Blender's window with the add-on's
Scene > Crumple panel after a simulation of the test's cylinder-fold shot
(the paper at frame 70 in its structure colours), drawn in a real window (run by scripts/blender-addon-screenshot.sh under Xvfb):

    blender --factory-startup --python tests/blender/panel_screenshot.py -- \\
        --zip ZIP --crumple BIN --work DIR --out PNG
"""

import argparse
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_addon import build_scene  # noqa: E402


def arrange():
    """The Properties editor on the Scene tab, the 3D view on the paper."""
    window = bpy.context.window_manager.windows[0]
    areas = {a.type: a for a in window.screen.areas}
    areas["PROPERTIES"].spaces.active.context = "SCENE"
    space = areas["VIEW_3D"].spaces.active
    space.clip_start = 0.001
    space.shading.color_type = "VERTEX"  # "Attribute": the structure colours
    space.region_3d.view_location = (0.0, 0.0, 0.115)
    space.region_3d.view_distance = 0.30
    for area in window.screen.areas:
        area.tag_redraw()


def shoot(args):
    window = bpy.context.window_manager.windows[0]
    with bpy.context.temp_override(window=window):
        bpy.ops.screen.screenshot(filepath=args.out)
    print("panel screenshot: %s (%d x %d)" % (args.out, window.width, window.height))
    bpy.ops.wm.quit_blender()


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    parser = argparse.ArgumentParser(prog="panel_screenshot.py")
    for name in ("--zip", "--crumple", "--work", "--out"):
        parser.add_argument(name, required=True)
    args = parser.parse_args(argv)
    bpy.context.preferences.view.show_splash = False
    bpy.ops.preferences.addon_install(filepath=args.zip, overwrite=True)
    bpy.ops.preferences.addon_enable(module="crumple_blender")
    bpy.context.preferences.addons["crumple_blender"].preferences.crumple_path = args.crumple
    scene = build_scene(os.path.join(args.work, "scene"))
    bpy.ops.crumple.simulate(synchronous=True)
    scene.frame_set(70)
    bpy.context.view_layer.objects.active = bpy.data.objects["Paper (crumple)"]
    bpy.app.timers.register(arrange, first_interval=1.0)
    bpy.app.timers.register(lambda: shoot(args), first_interval=4.0)


main()
