"""Render a crumple frame with Blender's Cycles (CPU) for bench_render.

    blender -b --factory-startup -noaudio --python bench/cycles/render_cycles.py -- \
        --scene SCENE.json --out OUT.exr --spp N --threads T --timing TIMING.json \
        [--max-bounces B] [--seed S]

SCENE.json is written by bench/bench_render.cpp (its writeSceneJson has the
fields); the OBJ files and the texture it names are relative to its folder.
The scene is built in crumple's own world coordinates (Y up): Cycles does not
care which axis is up, and a Blender camera, like a glTF one, looks down its
local -Z with +Y up, so positions and the camera quaternion are used verbatim.

Outputs
- OUT.exr: Blender's own EXR of the render result (RGBA, full float,
  uncompressed), linear scene radiance, alpha = pixel coverage.
- OUT.rgbaf (OUT with its extension replaced): the same pixels as raw floats,
  for readers without an EXR library: the 4 bytes b"RGBF", uint32 width,
  uint32 height (little-endian), then width * height * 4 float32 RGBA, rows
  top to bottom. Parsed from the EXR above by read_exr() below (Blender's
  Python here has no numpy, and loading the EXR back through
  bpy.data.images would add Blender's alpha handling between us and the file).
- TIMING.json: wall and CPU time (user + system, all threads) of
  bpy.ops.render.render() (scene sync, BVH build, shader compilation and
  path tracing; no file writing), the render
  time Blender itself prints ("Time:" of its last status line, 10 ms
  resolution), and every setting used.

Alpha: Cycles' render result, and so the EXR, is premultiplied linear RGBA
(RGB = sum of radiance over the pixel's samples / samples, alpha = the
fraction of camera samples that hit something) with film_transparent, as
crumple's EmbreeRenderer output is: the two compare directly.

Equivalence with crumple's model (src/render/include/crumple/render/view.hpp),
MEASURED with bench/cycles/calibrate.py on Blender 3.4.1 (a white Lambertian
plane, albedo 1, facing each light; the camera sees the radiance at its
centre). crumple: a light of intensity I gives such a plane radiance I
(irradiance pi I). Measured in Cycles (all ratios measured/predicted 1.0000
after the factors below, the large close area light 0.9999):
- sun: strength S (W/m^2) gives radiance S / pi: S = pi I
  (SUN_STRENGTH_PER_I). With a disc (angle = angular diameter, as crumple's
  `angle`), Cycles spreads S over the disc's solid angle, so a facing plane
  gets S (1 + cos(angle / 2)) / 2 (0.99750 S measured at 0.2 rad): the
  strength is divided by that factor, crumple's irradiance being pi I at
  any angle.
- point (radius 0: Blender's default 0.25 m is a sphere light): power P
  (W) gives at distance d radiance P / (4 pi^2 d^2): P = 4 pi^2 I
  (POINT_POWER_PER_I; radiant intensity P / (4 pi) = pi I).
- area (rectangle, spread 180 deg = Lambertian, one-sided): power P on area
  A emits radiance P / (4 A), NOT the P / (pi A) of a Lambertian emitter of
  flux P (measured 0.7854 = pi / 4 of crumple's value with P = pi^2 I);
  crumple's emitter radiance pi I / A needs P = 4 pi I (AREA_POWER_PER_I;
  checked on a 0.2 x 0.3 m light 2 m away and a 2 x 1 m light 0.5 m away
  against the exact rectangle form factor).
- world: background colour c, strength s is a uniform radiance c s
  (WORLD_STRENGTH_PER_RADIANCE = 1): a plane under it shows exactly c s.
- paper material: front lit a (1 - T), lit from behind a T, back side with
  the back colour: all exact.
- bounces: Cycles' max_bounces = 0 is direct light only (a point light at
  the centre of a closed box of albedo 0.5: 0.49985 against the analytic
  direct-only 0.5; 0.6475 at 1, 0.7154 at 2), the same count as crumple's
  maxBounces (0 = direct light only, N = N diffuse bounces after the first
  hit). So max_bounces = diffuse_bounces = transmission_bounces = crumple's
  maxBounces, not maxBounces + 1 (confirmed on the drape frame: the two
  renderers' references differ by 0.10-0.15 % RMSE with equal counts at
  maxBounces 0, 1 and 4, while Cycles at 1 against crumple at 0 would be
  16 % brighter on the paper).
"""

import json
import math
import os
import re
import resource
import struct
import sys
import tempfile
import time

import bpy
from mathutils import Matrix, Quaternion, Vector

# --- Blender light units per crumple intensity (see the module docstring) ---
# Measured by calibrate.py (measured / predicted printed there: 1.0000).
SUN_STRENGTH_PER_I = math.pi
POINT_POWER_PER_I = 4.0 * math.pi ** 2
AREA_POWER_PER_I = 4.0 * math.pi
WORLD_STRENGTH_PER_RADIANCE = 1.0


# The options after Blender's '--': option -> (key in the options, type of
# its value, default).
OPTIONS = {
    "--scene": ("scene", str, None),
    "--out": ("out", str, None),
    "--spp": ("spp", int, 16),
    "--threads": ("threads", int, 1),
    "--timing": ("timing", str, None),
    "--max-bounces": ("max_bounces", int, None),
    "--seed": ("seed", int, None),
}


def parse_args(argv):
    """The options after Blender's '--' (OPTIONS), each followed by its
    value; --scene and --out are required."""
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    opts = {key: default for key, _, default in OPTIONS.values()}
    for i in range(0, len(args), 2):
        option = args[i]
        if i + 1 >= len(args):
            raise SystemExit("render_cycles.py: %s needs a value" % option)
        if option not in OPTIONS:
            raise SystemExit("render_cycles.py: unknown option " + option)
        key, type_, _ = OPTIONS[option]
        opts[key] = type_(args[i + 1])
    if not opts["scene"] or not opts["out"]:
        raise SystemExit("render_cycles.py: --scene and --out are required")
    return opts


# --- Input ----------------------------------------------------------------

def read_obj(path):
    """A triangle OBJ as written by bench_render: v, vt, vn and f a/b/c
    (vt and vn optional). Returns positions, faces (vertex index triples),
    and per-corner uv and normal lists (None when absent)."""
    positions, uvs, normals = [], [], []
    faces, face_uv, face_n = [], [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                positions.append(tuple(float(x) for x in parts[1:4]))
            elif parts[0] == "vt":
                uvs.append((float(parts[1]), float(parts[2])))
            elif parts[0] == "vn":
                normals.append(tuple(float(x) for x in parts[1:4]))
            elif parts[0] == "f":
                vs, ts, ns = [], [], []
                for corner in parts[1:]:
                    idx = corner.split("/")
                    vs.append(int(idx[0]) - 1)
                    ts.append(int(idx[1]) - 1 if len(idx) > 1 and idx[1] else None)
                    ns.append(int(idx[2]) - 1 if len(idx) > 2 and idx[2] else None)
                faces.append(vs)
                face_uv.append(ts)
                face_n.append(ns)
    corner_uv = None
    if uvs and all(t is not None for ts in face_uv for t in ts):
        corner_uv = [uvs[t] for ts in face_uv for t in ts]
    corner_n = None
    if normals and all(n is not None for ns in face_n for n in ns):
        corner_n = [normals[n] for ns in face_n for n in ns]
    return positions, faces, corner_uv, corner_n


def make_mesh_object(name, obj_path, material):
    """A mesh object from an OBJ, in world coordinates as given. Per-corner
    normals become Blender custom split normals (Cycles then shades with
    exactly those, interpolated over the triangle); without them the faces
    are flat. Per-corner uvs go to the UV map "UVMap"."""
    positions, faces, corner_uv, corner_n = read_obj(obj_path)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(positions, [], faces)
    if corner_uv is not None:
        layer = mesh.uv_layers.new(name="UVMap")
        flat = [c for uv in corner_uv for c in uv]
        layer.data.foreach_set("uv", flat)
    if corner_n is not None:
        mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
        mesh.use_auto_smooth = True
        mesh.auto_smooth_angle = math.pi  # the custom normals decide
        mesh.normals_split_custom_set(corner_n)
    else:
        mesh.polygons.foreach_set("use_smooth", [False] * len(mesh.polygons))
    mesh.update()
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    # No shadow-terminator tricks: crumple offsets nothing either.
    obj.cycles.shadow_terminator_offset = 0.0
    obj.cycles.shadow_terminator_geometry_offset = 0.0
    bpy.context.scene.collection.objects.link(obj)
    return obj


def read_raw_rgbaf(path):
    """A raw float texture (b"RGBF", width, height, float32 RGBA rows top to
    bottom): returns width, height and the floats rows BOTTOM to top, as
    Blender stores image pixels."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"RGBF":
        raise SystemExit("render_cycles.py: %s is not an RGBF raw image" % path)
    w, h = struct.unpack_from("<II", data, 4)
    row = w * 4
    floats = struct.unpack_from("<%df" % (w * h * 4), data, 12)
    flipped = []
    for y in range(h - 1, -1, -1):
        flipped.extend(floats[y * row:(y + 1) * row])
    return w, h, flipped


# --- Materials --------------------------------------------------------------

def diffuse_material(name, color):
    """Opaque Lambertian (Diffuse BSDF with roughness 0 is Lambert; Cycles'
    diffuse is two-sided)."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (color[0], color[1], color[2], 1.0)
    bsdf.inputs["Roughness"].default_value = 0.0
    nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def paper_material(paper, base_dir):
    """crumple's PaperLook: albedo a = texture * (front or back colour);
    Diffuse BSDF a (1 - T) + Translucent BSDF a T; texture alpha < 0.5 cuts
    (Transparent BSDF: no paper for camera, shadow and bounce rays alike).

    The texture is given as linear floats (paper.rgbaf: each sRGB texel
    decoded by crumple's srgb8ToLinear) in a float image with colour space
    "Linear" and alpha "Channel Packed", so that Cycles' bilinear filter
    (texel centres at (i + 0.5) / width, repeat) mixes decoded texels, exactly
    as GL_SRGB8_ALPHA8 + GL_LINEAR does (sampleTexture), and colour and
    alpha are filtered independently as in sampleTexture (straight alpha).
    An 8-bit sRGB image would be filtered in sRGB space and decoded after."""
    mat = bpy.data.materials.new("paper")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    n = nt.nodes
    link = nt.links.new

    tex = n.new("ShaderNodeTexImage")
    raw = os.path.join(base_dir, paper["textureRaw"])
    w, h, pixels = read_raw_rgbaf(raw)
    img = bpy.data.images.new("paper", w, h, alpha=True, float_buffer=True)
    img.colorspace_settings.name = "Linear"
    img.alpha_mode = "CHANNEL_PACKED"
    img.pixels.foreach_set(pixels)
    img.pack()  # keep the pixels as given (no file behind this image)
    tex.image = img
    tex.interpolation = "Linear"
    tex.extension = "REPEAT"
    tex.projection = "FLAT"
    uv = n.new("ShaderNodeUVMap")
    uv.uv_map = "UVMap"
    link(uv.outputs["UV"], tex.inputs["Vector"])

    # Front/back colour by the geometric side the ray hits (Backfacing = 1
    # on the back; Blender's front is counter-clockwise, as crumple's).
    geom = n.new("ShaderNodeNewGeometry")
    side = n.new("ShaderNodeMixRGB")
    side.blend_type = "MIX"
    side.use_clamp = False
    link(geom.outputs["Backfacing"], side.inputs["Fac"])
    fc, bc = paper["frontColor"], paper["backColor"]
    side.inputs["Color1"].default_value = (fc[0], fc[1], fc[2], 1.0)
    side.inputs["Color2"].default_value = (bc[0], bc[1], bc[2], 1.0)

    albedo = n.new("ShaderNodeMixRGB")
    albedo.blend_type = "MULTIPLY"
    albedo.use_clamp = False
    albedo.inputs["Fac"].default_value = 1.0
    link(tex.outputs["Color"], albedo.inputs["Color1"])
    link(side.outputs["Color"], albedo.inputs["Color2"])

    t = float(paper["transmittance"])
    refl = n.new("ShaderNodeMixRGB")  # a * (1 - T)
    refl.blend_type = "MULTIPLY"
    refl.inputs["Fac"].default_value = 1.0
    link(albedo.outputs["Color"], refl.inputs["Color1"])
    refl.inputs["Color2"].default_value = (1.0 - t, 1.0 - t, 1.0 - t, 1.0)
    trans = n.new("ShaderNodeMixRGB")  # a * T
    trans.blend_type = "MULTIPLY"
    trans.inputs["Fac"].default_value = 1.0
    link(albedo.outputs["Color"], trans.inputs["Color1"])
    trans.inputs["Color2"].default_value = (t, t, t, 1.0)

    diffuse = n.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Roughness"].default_value = 0.0
    link(refl.outputs["Color"], diffuse.inputs["Color"])
    add = n.new("ShaderNodeAddShader")
    link(diffuse.outputs["BSDF"], add.inputs[0])
    if t > 0.0:
        translucent = n.new("ShaderNodeBsdfTranslucent")
        link(trans.outputs["Color"], translucent.inputs["Color"])
        link(translucent.outputs["BSDF"], add.inputs[1])

    # Alpha cut: fac = (alpha < 0.5) selects the Transparent BSDF.
    cut = n.new("ShaderNodeMath")
    cut.operation = "LESS_THAN"
    link(tex.outputs["Alpha"], cut.inputs[0])
    cut.inputs[1].default_value = 0.5
    transparent = n.new("ShaderNodeBsdfTransparent")
    transparent.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    mix = n.new("ShaderNodeMixShader")
    link(cut.outputs["Value"], mix.inputs["Fac"])
    link(add.outputs["Shader"], mix.inputs[1])
    link(transparent.outputs["BSDF"], mix.inputs[2])

    out = n.new("ShaderNodeOutputMaterial")
    link(mix.outputs["Shader"], out.inputs["Surface"])
    return mat


# --- Camera, lights, world --------------------------------------------------

def quat_from_json(q):
    """[w, x, y, z] -> mathutils Quaternion."""
    return Quaternion((q[0], q[1], q[2], q[3]))


def make_camera(cam):
    """crumple's Camera: pinhole or thin lens, vertical fov yfov."""
    data = bpy.data.cameras.new("camera")
    data.type = "PERSP"
    data.sensor_fit = "VERTICAL"
    data.sensor_height = 24.0  # mm; only the angle matters
    data.angle_y = float(cam["yfov"])
    data.clip_start = float(cam["znear"])
    data.clip_end = float(cam["zfar"])
    data.shift_x = data.shift_y = 0.0
    aperture = float(cam.get("apertureRadius", 0.0))
    if aperture > 0.0:
        # Cycles' lens radius is (lens / 1000) / (2 f-stop) m (blender
        # sync: aperturesize = 0.5 * lens * 1e-3 / fstop), a uniform disc
        # (no blades) focused on the plane at focus_distance along the axis.
        data.dof.use_dof = True
        data.dof.focus_distance = float(cam["focusDistance"])
        data.dof.aperture_fstop = (data.lens * 1e-3) / (2.0 * aperture)
        data.dof.aperture_blades = 0
        data.dof.aperture_ratio = 1.0
        data.dof.aperture_rotation = 0.0
    else:
        data.dof.use_dof = False
    obj = bpy.data.objects.new("camera", data)
    obj.location = Vector(cam["position"])
    obj.rotation_mode = "QUATERNION"
    obj.rotation_quaternion = quat_from_json(cam["rotation"])
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.scene.camera = obj
    return obj


def make_light(i, light):
    """One crumple Light as a Blender light (see the factors at the top)."""
    kind = light["kind"]
    color = light["color"]
    intensity = float(light["intensity"])
    if kind == "directional":
        data = bpy.data.lights.new("light%d" % i, "SUN")
        angle = float(light.get("angle", 0.0))  # angular diameter
        # Cycles spreads the strength S uniformly over the disc's solid angle
        # 2 pi (1 - cos(angle / 2)), so a facing plane receives
        # S (1 + cos(angle / 2)) / 2 (measured: 0.99750 of S at 0.2 rad);
        # crumple's irradiance is pi I at any angle: compensate.
        data.energy = SUN_STRENGTH_PER_I * intensity * 2.0 / (1.0 + math.cos(0.5 * angle))
        data.angle = angle
    elif kind == "point":
        data = bpy.data.lights.new("light%d" % i, "POINT")
        data.energy = POINT_POWER_PER_I * intensity
        data.shadow_soft_size = 0.0  # a true point (Blender's default is 0.25 m)
    elif kind == "area":
        data = bpy.data.lights.new("light%d" % i, "AREA")
        data.shape = "RECTANGLE"
        data.size = float(light["size"][0])
        data.size_y = float(light["size"][1])
        data.spread = math.pi  # Lambertian
        data.energy = AREA_POWER_PER_I * intensity
    else:
        raise SystemExit("render_cycles.py: unknown light kind " + kind)
    data.color = (color[0], color[1], color[2])
    data.use_shadow = True
    data.cycles.cast_shadow = True
    data.cycles.use_multiple_importance_sampling = True
    data.cycles.max_bounces = 1024
    obj = bpy.data.objects.new("light%d" % i, data)
    if kind == "directional":
        # A sun shines down its local -Z.
        d = Vector(light["direction"]).normalized()
        obj.rotation_mode = "QUATERNION"
        obj.rotation_quaternion = d.to_track_quat("-Z", "Y")
    elif kind == "point":
        obj.location = Vector(light["position"])
    else:
        # An area light emits down its local -Z, size along local X, size_y
        # along local Y. crumple: size.x along u, size.y along v, u x v = the
        # normal. So X = u, Y = -v, Z = u x (-v) = -normal.
        # (direction is authoritative; u is made perpendicular to it.)
        nrm = Vector(light["direction"]).normalized()
        u = Vector(light["u"])
        u = (u - u.dot(nrm) * nrm).normalized()
        y_axis = (-nrm).cross(u)  # = -v
        basis = Matrix((u, y_axis, -nrm)).transposed()  # columns X, Y, Z
        obj.matrix_world = Matrix.Translation(Vector(light["position"])) @ basis.to_4x4()
        # crumple's area lights are not seen by camera rays (bounce rays do
        # see them, with MIS, in both).
        obj.visible_camera = False
    bpy.context.scene.collection.objects.link(obj)
    return obj


def make_world(env):
    """Uniform environment radiance colour * intensity (seen by bounce and
    light rays; camera rays see a transparent film instead)."""
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    c = env["color"]
    bg.inputs["Color"].default_value = (c[0], c[1], c[2], 1.0)
    bg.inputs["Strength"].default_value = WORLD_STRENGTH_PER_RADIANCE * float(env["intensity"])
    # Automatic: Cycles samples the (uniform) world as a light with MIS, its
    # default and best choice; crumple samples it with the BSDF only. Same
    # expected value, different noise.
    world.cycles.sampling_method = "AUTOMATIC"
    bpy.context.scene.world = world
    return world


# --- Cycles -------------------------------------------------------------------

def setup_cycles(scene, spec, opts):
    """Cycles CPU path tracing with the settings that make it crumple's
    estimator of the same integral; returns the settings as a dict."""
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.feature_set = "SUPPORTED"
    c.shading_system = False  # SVM, not OSL
    c.samples = int(opts["spp"])
    c.use_adaptive_sampling = False
    c.time_limit = 0.0
    c.use_denoising = False
    c.use_preview_denoising = False
    c.seed = int(opts["seed"] if opts["seed"] is not None else spec.get("seed", 0))
    c.use_animated_seed = False
    # Bounces: Cycles' counts equal crumple's (the module docstring).
    bounces = int(opts["max_bounces"] if opts["max_bounces"] is not None
                  else spec.get("maxBounces", 4))
    c.max_bounces = bounces
    c.diffuse_bounces = bounces
    c.transmission_bounces = bounces  # the Translucent BSDF is a diffuse transmission
    c.glossy_bounces = 0
    c.volume_bounces = 0
    c.transparent_max_bounces = 64  # alpha cuts: pass through every layer
    c.min_light_bounces = 0
    c.min_transparent_bounces = 0
    c.caustics_reflective = False  # no glossy/refractive closures anyway
    c.caustics_refractive = False
    c.blur_glossy = 0.0
    # Unbiased: no clamping, no probabilistic light-sample culling (Cycles
    # 3.4 has no light tree: it picks one light per sample, by power).
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.light_sampling_threshold = 0.0
    # Box filter one pixel wide: each sample a uniform point of its pixel.
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.use_auto_tile = True  # default tile size 2048: one tile at 640x480
    scene.render.film_transparent = True
    scene.render.resolution_x = int(spec["camera"]["width"])
    scene.render.resolution_y = int(spec["camera"]["height"])
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    scene.render.use_border = False
    scene.render.threads_mode = "FIXED"
    scene.render.threads = int(opts["threads"])
    scene.render.use_persistent_data = False
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    scene.render.use_motion_blur = False
    scene.view_settings.view_transform = "Standard"  # irrelevant for float EXR
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    settings = {
        "blender": bpy.app.version_string,
        "device": c.device,
        "samples": c.samples,
        "use_adaptive_sampling": c.use_adaptive_sampling,
        "use_denoising": c.use_denoising,
        "seed": c.seed,
        "sampling_pattern": c.sampling_pattern,
        "max_bounces": c.max_bounces,
        "diffuse_bounces": c.diffuse_bounces,
        "transmission_bounces": c.transmission_bounces,
        "transparent_max_bounces": c.transparent_max_bounces,
        "sample_clamp_direct": c.sample_clamp_direct,
        "sample_clamp_indirect": c.sample_clamp_indirect,
        "light_sampling_threshold": c.light_sampling_threshold,
        "light_tree": "none in Blender 3.4",
        "pixel_filter_type": c.pixel_filter_type,
        "filter_width": c.filter_width,
        "tile_size": c.tile_size,
        "threads_mode": scene.render.threads_mode,
        "threads": scene.render.threads,
        "film_transparent": scene.render.film_transparent,
        "world_sampling": scene.world.cycles.sampling_method if scene.world else None,
        "resolution": [scene.render.resolution_x, scene.render.resolution_y],
        "light_units": {
            "sun_strength_per_I": SUN_STRENGTH_PER_I,
            "point_power_per_I": POINT_POWER_PER_I,
            "area_power_per_I": AREA_POWER_PER_I,
            "world_strength_per_radiance": WORLD_STRENGTH_PER_RADIANCE,
        },
    }
    return settings


def read_positions(path):
    """The v lines of an OBJ (a motion step written by bench_render)."""
    out = []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if parts and parts[0] == "v":
                out.append(tuple(float(x) for x in parts[1:4]))
    return out


def add_motion(obj, step_files, base_dir, times):
    """crumple's motion blur steps (RenderScene::sheetMotion, PropMesh::motion:
    the vertices at K times evenly over the shutter, moving linearly between
    them) as Cycles deformation motion blur: one shape key per step, its
    value keyed 1 at its own time and 0 at the others (linear keys), so that
    the evaluated mesh at any time of the shutter is the steps' piecewise
    linear interpolation, exactly crumple's. Cycles samples the object at
    2^motion_steps + 1 times evenly over the shutter and interpolates
    linearly between them: enough that those times include every one of
    crumple's when K - 1 is a power of two (K = 2: 3 times, the motion
    linear between the two ends)."""
    mesh = obj.data
    obj.shape_key_add(name="Basis", from_mix=False)
    keys = []
    for k, name in enumerate(step_files):
        positions = read_positions(os.path.join(base_dir, name))
        if len(positions) != len(mesh.vertices):
            raise SystemExit("render_cycles.py: %s has %d vertices, its mesh %d"
                             % (name, len(positions), len(mesh.vertices)))
        key = obj.shape_key_add(name="step%d" % k, from_mix=False)
        key.data.foreach_set("co", [c for p in positions for c in p])
        keys.append(key)
    for k, key in enumerate(keys):
        for j, t in enumerate(times):
            key.value = 1.0 if j == k else 0.0
            key.keyframe_insert("value", frame=t)
    for fcurve in mesh.shape_keys.animation_data.action.fcurves:
        for point in fcurve.keyframe_points:
            point.interpolation = "LINEAR"
    obj.cycles.use_motion_blur = True
    obj.cycles.use_deform_motion = True
    obj.cycles.motion_steps = max(1, math.ceil(math.log2(max(1, len(step_files) - 1))))


def setup_motion(scene, spec, objects, base_dir):
    """Motion blur as crumple's: the shutter open for shutterFrames frames,
    centred on frame 1 (Blender's frame number is only a clock here: the
    steps carry the positions), a box shutter (Cycles' default curve is
    flat); the camera, lights and the rest stand still."""
    motion = spec.get("motion")
    if not motion:
        return None
    length = float(motion["shutterFrames"])
    k = int(motion["steps"])
    times = [1.0 - 0.5 * length + length * j / (k - 1) for j in range(k)]
    if motion.get("sheet"):
        add_motion(objects["sheet"], motion["sheet"], base_dir, times)
    for i, steps in enumerate(motion.get("props") or []):
        if steps:
            add_motion(objects["prop%d" % i], steps, base_dir, times)
    scene.frame_set(1)
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = length
    scene.cycles.motion_blur_position = "CENTER"
    scene.cycles.rolling_shutter_type = "NONE"
    return {"shutter_frames": length, "steps": k, "key_times": times}


def build_scene(spec, base_dir):
    """Everything in SCENE.json into a fresh Blender scene; returns the
    scene and its mesh objects by name."""
    # --factory-startup brings a cube, a light and a camera: remove them.
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    scene = bpy.context.scene
    make_camera(spec["camera"])
    for i, light in enumerate(spec.get("lights", [])):
        make_light(i, light)
    make_world(spec["environment"])
    objects = {}
    if spec.get("paper"):
        mat = paper_material(spec["paper"], base_dir)
        objects["sheet"] = make_mesh_object(
            "sheet", os.path.join(base_dir, spec["paper"]["obj"]), mat)
    if spec.get("ground"):
        g = spec["ground"]
        make_mesh_object("ground", os.path.join(base_dir, g["obj"]),
                         diffuse_material("ground", g["color"]))
    for i, prop in enumerate(spec.get("props", [])):
        objects["prop%d" % i] = make_mesh_object(
            "prop%d" % i, os.path.join(base_dir, prop["obj"]),
            diffuse_material("prop%d" % i, prop["color"]))
    return scene, objects


# --- Output -------------------------------------------------------------------

def read_exr(path):
    """An uncompressed scanline OpenEXR (as save_exr writes it) -> width,
    height, float RGBA rows top to bottom. Handles HALF and FLOAT channels."""
    with open(path, "rb") as f:
        data = f.read()
    if struct.unpack_from("<I", data, 0)[0] != 20000630:
        raise SystemExit("render_cycles.py: %s is not an OpenEXR file" % path)
    pos = 8
    channels, compression, window = [], None, None
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        pos = end + 1
        end = data.index(b"\0", pos)
        typ = data[pos:end].decode()
        pos = end + 1
        size = struct.unpack_from("<i", data, pos)[0]
        pos += 4
        value = data[pos:pos + size]
        pos += size
        if name == "channels":
            p = 0
            while value[p] != 0:
                e = value.index(b"\0", p)
                cname = value[p:e].decode()
                ptype = struct.unpack_from("<i", value, e + 1)[0]
                channels.append((cname, ptype))
                p = e + 1 + 16
        elif name == "compression":
            compression = value[0]
        elif name == "dataWindow":
            window = struct.unpack_from("<4i", value, 0)
    pos += 1
    if compression != 0:
        raise SystemExit("render_cycles.py: %s is compressed (need exr_codec NONE)" % path)
    x0, y0, x1, y1 = window
    w, h = x1 - x0 + 1, y1 - y0 + 1
    offsets = struct.unpack_from("<%dQ" % h, data, pos)
    out = [0.0] * (w * h * 4)
    slot = {"R": 0, "G": 1, "B": 2, "A": 3}
    for off in offsets:
        y, _size = struct.unpack_from("<ii", data, off)
        p = off + 8
        row = y - y0
        for cname, ptype in channels:  # stored in channel-list order
            fmt, nbytes = ("<%de" % w, 2) if ptype == 1 else ("<%df" % w, 4)
            values = struct.unpack_from(fmt, data, p)
            p += nbytes * w
            k = slot.get(cname.split(".")[-1])
            if k is None:
                continue
            base = row * w * 4 + k
            for x in range(w):
                out[base + 4 * x] = values[x]
    if not any(c.split(".")[-1] == "A" for c, _ in channels):
        for i in range(3, len(out), 4):
            out[i] = 1.0
    return w, h, out


def write_raw(path, w, h, floats):
    """The RGBF raw format (module docstring)."""
    with open(path, "wb") as f:
        f.write(b"RGBF")
        f.write(struct.pack("<II", w, h))
        f.write(struct.pack("<%df" % len(floats), *floats))


def save_exr(scene, path):
    """The render result as an uncompressed full-float RGBA EXR (linear,
    premultiplied: Blender never applies the view transform to float EXR)."""
    s = scene.render.image_settings
    s.file_format = "OPEN_EXR"
    s.color_mode = "RGBA"
    s.color_depth = "32"
    s.exr_codec = "NONE"
    s.use_preview = False
    bpy.data.images["Render Result"].save_render(path, scene=scene)


def render_timed(scene):
    """bpy.ops.render.render() with its wall and CPU time (user + system, all
    threads: robust to other processes sharing the machine); Blender's status lines
    (stdout, C level) are captured to read the render time it prints, then
    echoed."""
    sys.stdout.flush()
    saved = os.dup(1)
    with tempfile.TemporaryFile() as cap:
        os.dup2(cap.fileno(), 1)
        try:
            r0 = resource.getrusage(resource.RUSAGE_SELF)
            t0 = time.perf_counter()
            bpy.ops.render.render(write_still=False)
            wall = time.perf_counter() - t0
            r1 = resource.getrusage(resource.RUSAGE_SELF)
            cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
        finally:
            sys.stdout.flush()
            os.dup2(saved, 1)
            os.close(saved)
        cap.seek(0)
        text = cap.read().decode("utf-8", "replace")
    sys.stdout.write(text.replace("\r", "\n"))
    blender_s = None
    for m in re.finditer(r"Time:(\d+):(\d+(?:\.\d+)?)", text):
        blender_s = int(m.group(1)) * 60 + float(m.group(2))
    return wall, cpu, blender_s


def main():
    opts = parse_args(sys.argv)
    with open(opts["scene"]) as f:
        spec = json.load(f)
    base_dir = os.path.dirname(os.path.abspath(opts["scene"]))
    t0 = time.perf_counter()
    scene, objects = build_scene(spec, base_dir)
    settings = setup_cycles(scene, spec, opts)
    settings["motion_blur"] = setup_motion(scene, spec, objects, base_dir)
    build_s = time.perf_counter() - t0
    wall, cpu, blender_s = render_timed(scene)
    out = os.path.abspath(opts["out"])
    save_exr(scene, out)
    w, h, pixels = read_exr(out)
    raw = os.path.splitext(out)[0] + ".rgbaf"
    write_raw(raw, w, h, pixels)
    timing = {
        "render_wall_s": wall,             # around bpy.ops.render.render()
        "render_cpu_s": cpu,               # CPU time (all threads) in that call
        "blender_reported_s": blender_s,   # Blender's own "Time:" (10 ms steps)
        "python_scene_build_s": build_s,   # bpy data creation before the render
        "exr": out,
        "raw": raw,
        "width": w,
        "height": h,
        "settings": settings,
    }
    if opts["timing"]:
        with open(opts["timing"], "w") as f:
            json.dump(timing, f, indent=2)
    print("render_cycles: %d spp, %d threads: %.3f s (Blender: %s s)" %
          (settings["samples"], settings["threads"], wall, blender_s))


if __name__ == "__main__":
    main()
