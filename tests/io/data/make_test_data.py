#!/usr/bin/env python3
"""Writes the hand-made animation files used by tests/io (run from anywhere).

Every file holds the SAME scene, stated in crumple's world frame (Y-up,
metres, seconds):

  Handle  root node; position keys t = 0, 1, 2 s: (0,0,0), (0.1,0.2,0),
          (0.3,0.2,0.1); rotation keys about +Y: 0, 40, 100 degrees.
  Parent  root node; t = 0, 2 s: position (0,0.1,0) -> (0.2,0.1,0),
          rotation about +Y 0 -> 90 degrees, uniform scale 1 -> 1.5.
  Child   under Parent, static local offset (0.05, 0, 0).
  Static  root node, position (-0.1, 0.05, 0.2), 45 degrees about +X.
  Camera  root node at (0, 0.3, 0.6) looking down -Z, +Y up;
          vertical fov 0.6 rad, aspect 1.5.
  Sheet   root node at (0, 0.01, 0) holding a 0.2 x 0.3 quad in its XZ plane.

Formats:
  anim.gltf          glTF 2.0, JSON with a base64 data-URI buffer
  anim.glb           glTF 2.0 binary
  anim_zup_cm.dae    COLLADA, <unit meter="0.01"/>, <up_axis>Z_UP</up_axis>
  anim_zup_cm.fbx    ASCII FBX 7.4, UnitScaleFactor 1 (cm), Z up (Blender/Max
                     axes: Up +Z, Front -Y, Coord +X), TimeMode 24 fps
  anim_yup_m.fbx     ASCII FBX 7.4, UnitScaleFactor 100 (m), Y up, TimeMode
                     default (assimp: 1 tick per second)
Z-up files state every local frame in the file's axes (what a Z-up DCC
writes): a rotation about world +Y is a rotation about file +Z.

Error and corner cases:
  nan.glb            anim.glb with a NaN in Handle's second position key
  nan.dae            anim_zup_cm.dae with "nan" in Handle's translate keys
  malformed.gltf     truncated JSON (assimp finds no reader for it)
  broken.gltf        valid JSON, but an accessor names a missing buffer view
  malformed.fbx      FBX with an unterminated scope
  shifted.fbx        keys at 0.5 s and 1.5 s and no take LocalStart/LocalStop
  ticks0.fbx         TimeMode custom with CustomFrameRate 0
"""
import base64
import json
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
KTIME = 46186158000  # FBX ticks per second

HANDLE_T = [0.0, 1.0, 2.0]
HANDLE_P = [(0.0, 0.0, 0.0), (0.1, 0.2, 0.0), (0.3, 0.2, 0.1)]
HANDLE_YDEG = [0.0, 40.0, 100.0]
PARENT_T = [0.0, 2.0]
PARENT_P = [(0.0, 0.1, 0.0), (0.2, 0.1, 0.0)]
PARENT_YDEG = [0.0, 90.0]
PARENT_S = [1.0, 1.5]
CHILD_OFFSET = (0.05, 0.0, 0.0)
STATIC_P = (-0.1, 0.05, 0.2)
STATIC_XDEG = 45.0
CAMERA_P = (0.0, 0.3, 0.6)
CAMERA_YFOV = 0.6
CAMERA_ASPECT = 1.5
SHEET_P = (0.0, 0.01, 0.0)
SHEET_V = [(-0.1, 0.0, -0.15), (0.1, 0.0, -0.15), (0.1, 0.0, 0.15), (-0.1, 0.0, 0.15)]
SHEET_TRI = [(0, 2, 1), (0, 3, 2)]


def quat_y(deg):  # glTF order x, y, z, w
    h = math.radians(deg) / 2
    return (0.0, math.sin(h), 0.0, math.cos(h))


def quat_x(deg):
    h = math.radians(deg) / 2
    return (math.sin(h), 0.0, 0.0, math.cos(h))


def g(v):
    return repr(float(v))


# ---------------------------------------------------------------- glTF / glb
def gltf_document(nan_key=False):
    blob = bytearray()
    views, accessors = [], []

    def add(floats, comp, type_, count, minmax=None, target=None, fmt="f"):
        while len(blob) % 4:
            blob.append(0)
        off = len(blob)
        blob.extend(struct.pack("<%d%s" % (len(floats), fmt), *floats))
        view = {"buffer": 0, "byteOffset": off, "byteLength": len(blob) - off}
        if target:
            view["target"] = target
        views.append(view)
        acc = {"bufferView": len(views) - 1, "componentType": comp, "count": count, "type": type_}
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    def flat(rows):
        return [x for r in rows for x in r]

    def mm(rows):
        cols = list(zip(*rows))
        return [min(c) for c in cols], [max(c) for c in cols]

    t3 = add(HANDLE_T, 5126, "SCALAR", 3, ([0.0], [2.0]))
    t2 = add(PARENT_T, 5126, "SCALAR", 2, ([0.0], [2.0]))
    hp = list(HANDLE_P)
    if nan_key:
        hp[1] = (float("nan"), 0.2, 0.0)
    h_pos = add(flat(hp), 5126, "VEC3", 3)
    h_rot = add(flat([quat_y(d) for d in HANDLE_YDEG]), 5126, "VEC4", 3)
    p_pos = add(flat(PARENT_P), 5126, "VEC3", 2)
    p_rot = add(flat([quat_y(d) for d in PARENT_YDEG]), 5126, "VEC4", 2)
    p_scl = add(flat([(s, s, s) for s in PARENT_S]), 5126, "VEC3", 2)
    m_pos = add(flat(SHEET_V), 5126, "VEC3", 4, mm(SHEET_V), 34962)
    m_idx = add(flat(SHEET_TRI), 5123, "SCALAR", 6, None, 34963, fmt="H")

    doc = {
        "asset": {"version": "2.0", "generator": "crumple tests/io/data/make_test_data.py"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 3, 4, 5]}],
        "nodes": [
            {"name": "Handle"},
            {"name": "Parent", "translation": list(PARENT_P[0]), "children": [2]},
            {"name": "Child", "translation": list(CHILD_OFFSET)},
            {"name": "Static", "translation": list(STATIC_P), "rotation": list(quat_x(STATIC_XDEG))},
            {"name": "Camera", "translation": list(CAMERA_P), "camera": 0},
            {"name": "Sheet", "translation": list(SHEET_P), "mesh": 0},
        ],
        "cameras": [{"type": "perspective", "perspective": {
            "yfov": CAMERA_YFOV, "aspectRatio": CAMERA_ASPECT, "znear": 0.01, "zfar": 100.0}}],
        "meshes": [{"name": "SheetMesh", "primitives": [{"attributes": {"POSITION": m_pos},
                                                          "indices": m_idx, "mode": 4}]}],
        "animations": [{
            "name": "Take",
            "samplers": [
                {"input": t3, "output": h_pos, "interpolation": "LINEAR"},
                {"input": t3, "output": h_rot, "interpolation": "LINEAR"},
                {"input": t2, "output": p_pos, "interpolation": "LINEAR"},
                {"input": t2, "output": p_rot, "interpolation": "LINEAR"},
                {"input": t2, "output": p_scl, "interpolation": "LINEAR"},
            ],
            "channels": [
                {"sampler": 0, "target": {"node": 0, "path": "translation"}},
                {"sampler": 1, "target": {"node": 0, "path": "rotation"}},
                {"sampler": 2, "target": {"node": 1, "path": "translation"}},
                {"sampler": 3, "target": {"node": 1, "path": "rotation"}},
                {"sampler": 4, "target": {"node": 1, "path": "scale"}},
            ],
        }],
        "bufferViews": views,
        "accessors": accessors,
    }
    return doc, bytes(blob)


def write_gltf():
    doc, blob = gltf_document()
    doc["buffers"] = [{"byteLength": len(blob),
                       "uri": "data:application/octet-stream;base64," +
                              base64.b64encode(blob).decode("ascii")}]
    with open(os.path.join(HERE, "anim.gltf"), "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


def write_glb(name, nan_key=False):
    doc, blob = gltf_document(nan_key)
    doc["buffers"] = [{"byteLength": len(blob)}]
    js = json.dumps(doc, separators=(",", ":")).encode("ascii")
    js += b" " * ((4 - len(js) % 4) % 4)
    blob += b"\0" * ((4 - len(blob) % 4) % 4)
    total = 12 + 8 + len(js) + 8 + len(blob)
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, total))
        f.write(struct.pack("<I4s", len(js), b"JSON") + js)
        f.write(struct.pack("<I4s", len(blob), b"BIN\0") + blob)


# ----------------------------------------------------------- Z-up file frame
# crumple (x, y, z) -> Z-up file (x, -z, y); lengths in file units.
def zup(p, scale):
    x, y, z = p
    return (x * scale, -z * scale, y * scale)


# ------------------------------------------------------------------- COLLADA
def write_dae(name, nan_key=False):
    cm = 100.0
    hp = [zup(p, cm) for p in HANDLE_P]
    hp_text = " ".join(g(c) for p in hp for c in p)
    if nan_key:
        vals = hp_text.split(" ")
        vals[3] = "nan"
        hp_text = " ".join(vals)
    pp = [zup(p, cm) for p in PARENT_P]

    def src(id_, values, stride, params):
        n = len(values) if isinstance(values, list) else None
        text = " ".join(g(v) for v in values) if isinstance(values, list) else values
        count = n if n is not None else len(text.split())
        ps = "".join('<param name="%s" type="float"/>' % p for p in params)
        return ('<source id="%s"><float_array id="%s-array" count="%d">%s</float_array>'
                '<technique_common><accessor source="#%s-array" count="%d" stride="%d">%s'
                '</accessor></technique_common></source>'
                % (id_, id_, count, text, id_, count // stride, stride, ps))

    def interp(id_, n):
        return ('<source id="%s"><Name_array id="%s-array" count="%d">%s</Name_array>'
                '<technique_common><accessor source="#%s-array" count="%d" stride="1">'
                '<param name="INTERPOLATION" type="name"/></accessor></technique_common></source>'
                % (id_, id_, n, " ".join(["LINEAR"] * n), id_, n))

    def anim(id_, times, out_src, target):
        n = len(times)
        return ('<animation id="%s">%s%s%s<sampler id="%s-sampler">'
                '<input semantic="INPUT" source="#%s-in"/><input semantic="OUTPUT" source="#%s-out"/>'
                '<input semantic="INTERPOLATION" source="#%s-interp"/></sampler>'
                '<channel source="#%s-sampler" target="%s"/></animation>\n'
                % (id_, src(id_ + "-in", times, 1, ["TIME"]), out_src, interp(id_ + "-interp", n),
                   id_, id_, id_, id_, id_, target))

    anims = ""
    anims += anim("handle-T", HANDLE_T, src("handle-T-out", hp_text, 3, "XYZ"), "handle_node/translate")
    anims += anim("handle-R", HANDLE_T, src("handle-R-out", HANDLE_YDEG, 1, ["ANGLE"]),
                  "handle_node/rotZ.ANGLE")
    anims += anim("parent-T", PARENT_T, src("parent-T-out", [c for p in pp for c in p], 3, "XYZ"),
                  "parent_node/translate")
    anims += anim("parent-R", PARENT_T, src("parent-R-out", PARENT_YDEG, 1, ["ANGLE"]),
                  "parent_node/rotZ.ANGLE")
    anims += anim("parent-S", PARENT_T,
                  src("parent-S-out", [s for s in PARENT_S for _ in range(3)], 3, "XYZ"),
                  "parent_node/scale")

    sv = [zup(v, cm) for v in SHEET_V]
    pos = " ".join(g(c) for v in sv for c in v)
    tris = " ".join(str(i) for t in SHEET_TRI for i in t)
    deg = math.degrees(CAMERA_YFOV)

    def vec(p):
        return " ".join(g(c) for c in p)

    text = f"""<?xml version="1.0" encoding="utf-8"?>
<!-- Generated by crumple tests/io/data/make_test_data.py: the test scene in centimetres, Z up. -->
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset>
    <contributor><authoring_tool>crumple make_test_data.py</authoring_tool></contributor>
    <created>2024-01-01T00:00:00</created>
    <modified>2024-01-01T00:00:00</modified>
    <unit name="centimeter" meter="0.01"/>
    <up_axis>Z_UP</up_axis>
  </asset>
  <library_cameras>
    <camera id="cam0" name="CameraData">
      <optics><technique_common><perspective>
        <yfov>{g(deg)}</yfov><aspect_ratio>{g(CAMERA_ASPECT)}</aspect_ratio><znear>1</znear><zfar>10000</zfar>
      </perspective></technique_common></optics>
    </camera>
  </library_cameras>
  <library_geometries>
    <geometry id="sheet-mesh" name="SheetMesh">
      <mesh>
        <source id="sheet-pos"><float_array id="sheet-pos-array" count="12">{pos}</float_array>
          <technique_common><accessor source="#sheet-pos-array" count="4" stride="3">
            <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
          </accessor></technique_common></source>
        <vertices id="sheet-vtx"><input semantic="POSITION" source="#sheet-pos"/></vertices>
        <triangles count="2"><input semantic="VERTEX" source="#sheet-vtx" offset="0"/><p>{tris}</p></triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_animations>
{anims}  </library_animations>
  <library_visual_scenes>
    <visual_scene id="scene" name="scene">
      <node id="handle_node" name="Handle" type="NODE">
        <translate sid="translate">0 0 0</translate>
        <rotate sid="rotZ">0 0 1 0</rotate>
      </node>
      <node id="parent_node" name="Parent" type="NODE">
        <translate sid="translate">{vec(pp[0])}</translate>
        <rotate sid="rotZ">0 0 1 0</rotate>
        <scale sid="scale">1 1 1</scale>
        <node id="child_node" name="Child" type="NODE">
          <translate sid="translate">{vec(zup(CHILD_OFFSET, cm))}</translate>
        </node>
      </node>
      <node id="static_node" name="Static" type="NODE">
        <translate sid="translate">{vec(zup(STATIC_P, cm))}</translate>
        <rotate sid="rotX">1 0 0 {g(STATIC_XDEG)}</rotate>
      </node>
      <node id="camera_node" name="Camera" type="NODE">
        <translate sid="translate">{vec(zup(CAMERA_P, cm))}</translate>
        <rotate sid="rotX">1 0 0 90</rotate>
        <instance_camera url="#cam0"/>
      </node>
      <node id="sheet_node" name="Sheet" type="NODE">
        <translate sid="translate">{vec(zup(SHEET_P, cm))}</translate>
        <instance_geometry url="#sheet-mesh"/>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
"""
    with open(os.path.join(HERE, name), "w") as f:
        f.write(text)


# ----------------------------------------------------------------------- FBX
class Fbx:
    def __init__(self):
        self.objects = []
        self.connections = []
        self.next_id = 1000

    def id(self):
        self.next_id += 1
        return self.next_id

    def model(self, name, kind, parent, t=(0, 0, 0), r=(0, 0, 0), s=(1, 1, 1)):
        i = self.id()
        self.objects.append(
            f'\tModel: {i}, "Model::{name}", "{kind}" {{\n\t\tVersion: 232\n\t\tProperties70:  {{\n'
            f'\t\t\tP: "Lcl Translation", "Lcl Translation", "", "A",{g(t[0])},{g(t[1])},{g(t[2])}\n'
            f'\t\t\tP: "Lcl Rotation", "Lcl Rotation", "", "A",{g(r[0])},{g(r[1])},{g(r[2])}\n'
            f'\t\t\tP: "Lcl Scaling", "Lcl Scaling", "", "A",{g(s[0])},{g(s[1])},{g(s[2])}\n'
            f'\t\t}}\n\t\tShading: Y\n\t\tCulling: "CullingOff"\n\t}}\n')
        self.connections.append(f'\tC: "OO",{i},{parent}\n')
        return i

    def curves(self, layer, model, prop, short, times, xyz):
        """xyz: list of (x, y, z) per key."""
        node = self.id()
        first = xyz[0]
        self.objects.append(
            f'\tAnimationCurveNode: {node}, "AnimCurveNode::{short}", "" {{\n\t\tProperties70:  {{\n'
            f'\t\t\tP: "d|X", "Number", "", "A",{g(first[0])}\n'
            f'\t\t\tP: "d|Y", "Number", "", "A",{g(first[1])}\n'
            f'\t\t\tP: "d|Z", "Number", "", "A",{g(first[2])}\n\t\t}}\n\t}}\n')
        self.connections.append(f'\tC: "OO",{node},{layer}\n')
        self.connections.append(f'\tC: "OP",{node},{model}, "{prop}"\n')
        for axis, comp in (("X", 0), ("Y", 1), ("Z", 2)):
            c = self.id()
            kt = ",".join(str(int(round(t * KTIME))) for t in times)
            kv = ",".join(v if isinstance(v, str) else g(v) for v in (k[comp] for k in xyz))
            n = len(times)
            self.objects.append(
                f'\tAnimationCurve: {c}, "AnimCurve::", "" {{\n\t\tDefault: 0\n\t\tKeyVer: 4008\n'
                f'\t\tKeyTime: *{n} {{\n\t\t\ta: {kt}\n\t\t}}\n'
                f'\t\tKeyValueFloat: *{n} {{\n\t\t\ta: {kv}\n\t\t}}\n'
                # 0x4004: linear interpolation, constant tangent mode.
                f'\t\tKeyAttrFlags: *1 {{\n\t\t\ta: 16388\n\t\t}}\n'
                f'\t\tKeyAttrDataFloat: *4 {{\n\t\t\ta: 0,0,0,0\n\t\t}}\n'
                f'\t\tKeyAttrRefCount: *1 {{\n\t\t\ta: {n}\n\t\t}}\n\t}}\n')
            self.connections.append(f'\tC: "OP",{c},{node}, "d|{axis}"\n')

    def text(self, settings, take=None):
        props = "".join(f'\t\tP: "{k}", {v}\n' for k, v in settings)
        take_text = ""
        if take is not None:
            stack, layer, start, stop = take
            local = ""
            if start is not None:
                local = (f'\t\tProperties70:  {{\n'
                         f'\t\t\tP: "LocalStart", "KTime", "Time", "",{int(round(start * KTIME))}\n'
                         f'\t\t\tP: "LocalStop", "KTime", "Time", "",{int(round(stop * KTIME))}\n'
                         f'\t\t}}\n')
            take_text = (f'\tAnimationStack: {stack}, "AnimStack::Take 001", "" {{\n{local}\t}}\n'
                         f'\tAnimationLayer: {layer}, "AnimLayer::BaseLayer", "" {{\n\t}}\n')
        return ("; FBX 7.4.0 project file\n"
                "; Generated by crumple tests/io/data/make_test_data.py (hand-built ASCII FBX).\n"
                "FBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n\tFBXVersion: 7400\n"
                '\tCreator: "crumple make_test_data.py"\n}\n'
                f"GlobalSettings:  {{\n\tVersion: 1000\n\tProperties70:  {{\n{props}\t}}\n}}\n"
                "Objects:  {\n" + take_text + "".join(self.objects) + "}\n"
                "Connections:  {\n" + "".join(self.connections) + "}\n")


def fbx_settings(up, up_sign, front, front_sign, coord, coord_sign, unit, time_mode, custom=-1.0):
    return [
        ("UpAxis", f'"int", "Integer", "",{up}'),
        ("UpAxisSign", f'"int", "Integer", "",{up_sign}'),
        ("FrontAxis", f'"int", "Integer", "",{front}'),
        ("FrontAxisSign", f'"int", "Integer", "",{front_sign}'),
        ("CoordAxis", f'"int", "Integer", "",{coord}'),
        ("CoordAxisSign", f'"int", "Integer", "",{coord_sign}'),
        ("OriginalUpAxis", f'"int", "Integer", "",{up}'),
        ("OriginalUpAxisSign", f'"int", "Integer", "",{up_sign}'),
        ("UnitScaleFactor", f'"double", "Number", "",{g(unit)}'),
        ("OriginalUnitScaleFactor", f'"double", "Number", "",{g(unit)}'),
        ("TimeMode", f'"enum", "", "",{time_mode}'),
        ("CustomFrameRate", f'"double", "Number", "",{g(custom)}'),
    ]


def write_fbx(name, zup_frame):
    """zup_frame: True = Z up, cm (UnitScaleFactor 1); False = Y up, m (100)."""
    fb = Fbx()
    stack, layer = fb.id(), fb.id()
    fb.connections.append(f'\tC: "OO",{layer},{stack}\n')
    if zup_frame:
        scale = 100.0  # file units are cm

        def P(p):
            return zup(p, scale)

        def yrot(d):  # rotation about world +Y = about file +Z
            return (0.0, 0.0, d)

        settings = fbx_settings(2, 1, 1, -1, 0, 1, 1.0, 11)
        # FBX cameras look down local +X with +Y up: +X -> file +Y (world -Z),
        # +Y -> file +Z (world +Y).
        cam_rot = (90.0, 0.0, 90.0)
        static_rot = (STATIC_XDEG, 0.0, 0.0)
    else:
        scale = 1.0  # file units are m

        def P(p):
            return tuple(c * scale for c in p)

        def yrot(d):
            return (0.0, d, 0.0)

        settings = fbx_settings(1, 1, 2, 1, 0, 1, 100.0, 0)
        cam_rot = (0.0, 90.0, 0.0)  # +X -> world -Z
        static_rot = (STATIC_XDEG, 0.0, 0.0)

    handle = fb.model("Handle", "Null", 0)
    fb.curves(layer, handle, "Lcl Translation", "T", HANDLE_T, [P(p) for p in HANDLE_P])
    fb.curves(layer, handle, "Lcl Rotation", "R", HANDLE_T, [yrot(d) for d in HANDLE_YDEG])
    parent = fb.model("Parent", "Null", 0, t=P(PARENT_P[0]))
    fb.curves(layer, parent, "Lcl Translation", "T", PARENT_T, [P(p) for p in PARENT_P])
    fb.curves(layer, parent, "Lcl Rotation", "R", PARENT_T, [yrot(d) for d in PARENT_YDEG])
    fb.curves(layer, parent, "Lcl Scaling", "S", PARENT_T, [(s, s, s) for s in PARENT_S])
    fb.model("Child", "Null", parent, t=P(CHILD_OFFSET))
    fb.model("Static", "Null", 0, t=P(STATIC_P), r=static_rot)

    cam = fb.model("Camera", "Camera", 0, t=P(CAMERA_P), r=cam_rot)
    attr = fb.id()
    hfov = math.degrees(2 * math.atan(CAMERA_ASPECT * math.tan(CAMERA_YFOV / 2)))
    fb.objects.append(
        f'\tNodeAttribute: {attr}, "NodeAttribute::Camera", "Camera" {{\n\t\tProperties70:  {{\n'
        f'\t\t\tP: "AspectWidth", "double", "Number", "",1920\n'
        f'\t\t\tP: "AspectHeight", "double", "Number", "",1280\n'
        f'\t\t\tP: "FieldOfView", "FieldOfView", "", "A",{g(hfov)}\n'
        f'\t\t}}\n\t\tTypeFlags: "Camera"\n\t\tGeometryVersion: 124\n\t}}\n')
    fb.connections.append(f'\tC: "OO",{attr},{cam}\n')

    sheet = fb.model("Sheet", "Mesh", 0, t=P(SHEET_P))
    geo = fb.id()
    verts = ",".join(g(c) for v in SHEET_V for c in P(v))
    fb.objects.append(
        f'\tGeometry: {geo}, "Geometry::SheetMesh", "Mesh" {{\n'
        f'\t\tVertices: *12 {{\n\t\t\ta: {verts}\n\t\t}}\n'
        f'\t\tPolygonVertexIndex: *4 {{\n\t\t\ta: 0,3,2,-2\n\t\t}}\n'
        f'\t\tGeometryVersion: 124\n\t}}\n')
    fb.connections.append(f'\tC: "OO",{geo},{sheet}\n')

    with open(os.path.join(HERE, name), "w") as f:
        f.write(fb.text(settings, (stack, layer, 0.0, 2.0)))


def write_fbx_single(name, times, values, time_mode, custom, local_range):
    """One node "Handle" with position keys only (Y up, m)."""
    fb = Fbx()
    stack, layer = fb.id(), fb.id()
    fb.connections.append(f'\tC: "OO",{layer},{stack}\n')
    handle = fb.model("Handle", "Null", 0)
    fb.curves(layer, handle, "Lcl Translation", "T", times, values)
    settings = fbx_settings(1, 1, 2, 1, 0, 1, 100.0, time_mode, custom)
    start, stop = local_range if local_range else (None, None)
    with open(os.path.join(HERE, name), "w") as f:
        f.write(fb.text(settings, (stack, layer, start, stop)))


def main():
    write_gltf()
    write_glb("anim.glb")
    write_glb("nan.glb", nan_key=True)
    write_dae("anim_zup_cm.dae")
    write_dae("nan.dae", nan_key=True)
    write_fbx("anim_zup_cm.fbx", True)
    write_fbx("anim_yup_m.fbx", False)
    write_fbx_single("shifted.fbx", [0.5, 1.5], [(0, 0, 0), (1, 0, 0)], 0, -1.0, None)
    write_fbx_single("ticks0.fbx", [0.0, 1.0], [(0, 0, 0), (1, 0, 0)], 14, 0.0, (0.0, 1.0))
    with open(os.path.join(HERE, "malformed.gltf"), "w") as f:
        f.write('{"asset": {"version": "2.0"}, "nodes": [{"name": "Handle"\n')
    with open(os.path.join(HERE, "broken.gltf"), "w") as f:
        f.write('{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],\n'
                ' "nodes": [{"name": "Sheet", "mesh": 0}],\n'
                ' "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],\n'
                ' "accessors": [{"bufferView": 7, "componentType": 5126, "count": 3,'
                ' "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]}]}\n')
    with open(os.path.join(HERE, "malformed.fbx"), "w") as f:
        f.write("; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n\tFBXVersion: 7400\n"
                "Objects:  {\n\tModel: 1, \"Model::Handle\", \"Null\" {\n")


if __name__ == "__main__":
    main()
