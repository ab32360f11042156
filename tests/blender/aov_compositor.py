"""Open a crumple AOV EXR in Blender's compositor, headless, and check it.

    blender -b --factory-startup -noaudio --python-exit-code 1 \\
        --python tests/blender/aov_compositor.py -- FRAME.exr EXPECT.txt OUTDIR

FRAME.exr: a frame rendered with `crumple render --aov ...`. EXPECT.txt:
what crumple reads from it (tests/blender/exr_probe), one line per check:
    size W H                   the image's size
    pass NAME CHANNELS         the Image node offers pass NAME
    pixel NAME X Y V0 [V1 ...] the pass's value at pixel (X, Y), rows top to bottom
The file is loaded into an Image node of the compositor, which must read it
as a multi-layer EXR and offer every pass. For each pass, the compositor
sends it to the Composite output of a render (an empty scene, Cycles at one
sample: the compositor runs with a render) written as a float EXR into
OUTDIR, which Blender loads back to read the pixels (in background mode the
Viewer node's image is not filled). Exit status 1 on any mismatch.
"""
import os
import sys

import bpy


def fail(message):
    print("FAIL: " + message, file=sys.stderr)
    sys.exit(1)


def read_expectations(path):
    size, passes, pixels = None, {}, []
    with open(path) as f:
        for line in f:
            words = line.split()
            if not words:
                continue
            if words[0] == "size":
                size = (int(words[1]), int(words[2]))
            elif words[0] == "pass":
                passes[words[1]] = int(words[2])
            elif words[0] == "pixel":
                pixels.append((words[1], int(words[2]), int(words[3]), [float(v) for v in words[4:]]))
            else:
                fail("bad expectation line: " + line.strip())
    if size is None:
        fail("no size line in " + path)
    return size, passes, pixels


def compositor(scene, image, width, height):
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 1
    scene.cycles.use_denoising = False  # Debian's Blender has no OpenImageDenoise
    scene.cycles.device = "CPU"
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.use_nodes = True
    tree = scene.node_tree
    for node in list(tree.nodes):
        tree.nodes.remove(node)
    source = tree.nodes.new("CompositorNodeImage")
    source.image = image
    composite = tree.nodes.new("CompositorNodeComposite")
    return tree, source, composite


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    if len(argv) != 3:
        fail("usage: ... -- FRAME.exr EXPECT.txt OUTDIR")
    exr, expect, outdir = argv
    (width, height), passes, pixels = read_expectations(expect)

    image = bpy.data.images.load(exr)
    scene = bpy.context.scene
    tree, source, composite = compositor(scene, image, width, height)
    offered = {s.name: s for s in source.outputs if s.enabled}
    print("Blender %s: Image node passes: %s" % (bpy.app.version_string, ", ".join(sorted(offered))))
    for name in sorted(passes):
        if name not in offered:
            fail("pass %s missing (offered: %s)" % (name, ", ".join(sorted(offered))))

    # The passes above come from the file's layers; once the compositor has
    # read it, Blender also calls the image what it is.
    results = {}
    for name in sorted(passes):
        for link in list(tree.links):
            tree.links.remove(link)
        tree.links.new(offered[name], composite.inputs[0])
        scene.render.filepath = os.path.join(outdir, "blender_%s.exr" % name)
        bpy.ops.render.render(write_still=True)
        result = bpy.data.images.load(scene.render.filepath)
        if tuple(result.size) != (width, height):
            fail("pass %s comes out %s, the image is %dx%d" % (name, tuple(result.size), width, height))
        results[name] = result
    if image.type != "MULTILAYER":
        fail("Blender reads %s as %s, not a multi-layer EXR" % (exr, image.type))

    for name, x, y, values in pixels:
        result = results[name]
        i = ((height - 1 - y) * width + x) * 4  # Blender's rows run bottom to top
        px = result.pixels[i:i + 4]
        # A one-channel pass comes out grey (the value in R, G and B).
        for k, expected in enumerate(values):
            tolerance = 1e-6 * max(1.0, abs(expected))
            if abs(px[k] - expected) > tolerance:
                fail("pass %s pixel (%d, %d) channel %d: Blender reads %.9g, crumple wrote %.9g"
                     % (name, x, y, k, px[k], expected))
        print("pass %s pixel (%d, %d): %s ok" % (name, x, y, ", ".join("%.6g" % v for v in values)))
    print("OK: %d passes, %d pixels, as crumple wrote them" % (len(passes), len(pixels)))


main()
