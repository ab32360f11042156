"""Shared helpers of the sample generators (stdlib only): easing, quaternions,
key sampling, a glTF 2.0 writer for keyframed handle nodes (embedded base64
buffers, Y-up, metres, seconds) and for the static meshes some samples add,
the check that handles never stretch the sheet, and the command line the
generators share (write_sample: `SCRIPT [OUT.gltf]`).

Imported by samples/make_tear_gltf.py, samples/*/make_*_gltf.py and
tests/stability/scenes/make_scenes.py, each of which puts this folder on
sys.path relative to its own location (so they run from any working
directory); not a sample itself. samples/drape/make_drape_gltf.py stands
alone: scripts/reliability_table.py runs an edited copy of its source text,
where a path relative to the script would not resolve.
"""
import base64
import json
import math
import os
import struct
import sys

# The repository's root: write_sample names a script by its path from here.
REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The samples' key rate: every frame at 24 fps and every half frame.
KEYS_PER_SECOND = 48


# ---- easing and quaternions ----
def smoother(x):
    """C2 ease in/out on [0, 1] (smootherstep), clamped."""
    x = min(1.0, max(0.0, x))
    return x * x * x * (x * (6.0 * x - 15.0) + 10.0)


def ramp(t, span):
    return smoother((t - span[0]) / (span[1] - span[0]))


def qaxis(axis, angle):
    """Quaternion (x, y, z, w), glTF order, rotating by angle about axis."""
    n = math.sqrt(sum(c * c for c in axis))
    s = math.sin(angle / 2.0) / n
    return (axis[0] * s, axis[1] * s, axis[2] * s, math.cos(angle / 2.0))


def qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def qrot(q, v):
    qv, w = q[:3], q[3]
    c1 = cross(qv, v)
    c2 = cross(qv, c1)
    return tuple(v[i] + 2.0 * w * c1[i] + 2.0 * c2[i] for i in range(3))


# ---- motions and their keys ----
def squeeze_and_pinch(a, b, side, d_squeeze, d_pinch):
    """One corner of a square sheet (side metres) held at its corners, whose
    held sides come closer by the fraction d_squeeze and whose border
    through this corner is then compressed by the fraction d_pinch (0 for a
    border left alone). (a, b): the corner's offset from the sheet's centre
    across the held sides and along them. Returns (a, b, arch, pinch): the
    moved offset, each side moving half the compression, and the turns of
    the corner's tangent plane that bow the sheet as a smooth sine arch,
    2 sqrt(delta) for a compression fraction delta (the end slope of the arch
    w = A sin(pi x / L) whose extra length is delta), signed by the side
    (arch with a, pinch with b). The caller turns the tangent plane by them
    about its own axes."""
    arch = math.copysign(2.0 * math.sqrt(d_squeeze), a)
    pinch = math.copysign(2.0 * math.sqrt(d_pinch), b)
    return (a - math.copysign(side * d_squeeze / 2.0, a),
            b - math.copysign(side * d_pinch / 2.0, b), arch, pinch)


def key_times(t_end, keys_per_second=KEYS_PER_SECOND):
    """The key times from 0 to t_end (included), keys_per_second a second."""
    return [k / keys_per_second for k in range(int(round(t_end * keys_per_second)) + 1)]


def handle_tracks(handles, pose, t_end, keys_per_second=KEYS_PER_SECOND):
    """Samples every handle's pose at keys_per_second from 0 to t_end.
    handles: [(node name, u, v)]; pose(u, v, t) -> (position, rotation).
    Returns (times, [(node name, [position], [rotation])]) for write_gltf."""
    times = key_times(t_end, keys_per_second)
    out = []
    for name, u, v in handles:
        poses = [pose(u, v, t) for t in times]
        out.append((name, [p for p, _ in poses], [q for _, q in poses]))
    return times, out


def check_no_stretch(times, tracks_, pattern, size, axes, patch=0.01):
    """Asserts that the handles never pull the sheet longer than its pattern:
    no two held points get farther apart than on the pattern. Held points are
    each handle's vertex and, for tangent-plane control, its neighbours, taken
    here `patch` metres away along the pattern axes (1 cm: coarser than any
    mesh the samples run on), carried rigidly by the node's rotation.
    pattern: {node: (u, v)} in metres, or the handles [(node, u, v)];
    size: (width, height); axes: the world directions of the pattern's u and
    v at the first frame (every node starts with the identity rotation).
    Returns the worst ratio."""
    if not isinstance(pattern, dict):
        pattern = {name: (u, v) for name, u, v in pattern}
    (ux, uy, uz), (vx, vy, vz) = axes
    held = []  # (node, u, v, local offset at bind)
    for name, (u, v) in pattern.items():
        held.append((name, u, v, (0.0, 0.0, 0.0)))
        for du, dv in ((patch, 0.0), (-patch, 0.0), (0.0, patch), (0.0, -patch)):
            if -1e-9 <= u + du <= size[0] + 1e-9 and -1e-9 <= v + dv <= size[1] + 1e-9:
                held.append((name, u + du, v + dv,
                             (du * ux + dv * vx, du * uy + dv * vy, du * uz + dv * vz)))
    index = {name: i for i, (name, _, _) in enumerate(tracks_)}
    worst = 0.0
    for k, _ in enumerate(times):
        world = []
        for name, u, v, offset in held:
            _, positions, rotations = tracks_[index[name]]
            o = qrot(rotations[k], offset) if rotations is not None else offset
            world.append(tuple(p + c for p, c in zip(positions[k], o)))
        for i in range(len(held)):
            for j in range(i + 1, len(held)):
                if held[i][0] == held[j][0]:
                    continue
                d0 = math.hypot(held[i][1] - held[j][1], held[i][2] - held[j][2])
                worst = max(worst, math.dist(world[i], world[j]) / d0)
    assert worst <= 1.0 + 1e-9, "the handles stretch the sheet by %.3g %%" % (100 * (worst - 1))
    return worst


# ---- writing glTF files ----
def data_uri_buffer(blob):
    """A glTF buffer holding blob as an embedded base64 data URI."""
    return {
        "byteLength": len(blob),
        "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode(),
    }


def dump_gltf(path, gltf):
    """Writes the glTF JSON (one-space indent, final newline) to path."""
    with open(path, "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


def write_gltf(path, generator, times, tracks, camera=None):
    """tracks: [(node name, [position], [rotation quaternion] or None)].
    camera: None or (node name, yfov rad, aspect): that track's node holds a
    perspective camera (looking down its local -Z, +Y up)."""
    blob = bytearray()
    views, accessors = [], []

    def add(values, count, type_, minmax=None):
        offset = len(blob)
        blob.extend(struct.pack("<%df" % len(values), *values))
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": 4 * len(values)})
        acc = {"bufferView": len(views) - 1, "componentType": 5126, "count": count, "type": type_}
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    t_acc = add(times, len(times), "SCALAR", ([min(times)], [max(times)]))
    nodes, samplers, channels = [], [], []
    for index, (name, positions, rotations) in enumerate(tracks):
        node = {"name": name, "translation": list(positions[0])}
        if camera is not None and camera[0] == name:
            node["camera"] = 0
        samplers.append({"input": t_acc, "interpolation": "LINEAR",
                         "output": add([c for p in positions for c in p], len(positions), "VEC3")})
        channels.append({"sampler": len(samplers) - 1,
                         "target": {"node": index, "path": "translation"}})
        if rotations is not None:
            # Keep consecutive keys in one hemisphere (slerp along the short arc).
            rots = [rotations[0]]
            for q in rotations[1:]:
                rots.append(q if sum(a * b for a, b in zip(q, rots[-1])) >= 0.0
                            else tuple(-c for c in q))
            node["rotation"] = list(rots[0])
            samplers.append({"input": t_acc, "interpolation": "LINEAR",
                             "output": add([c for q in rots for c in q], len(rots), "VEC4")})
            channels.append({"sampler": len(samplers) - 1,
                             "target": {"node": index, "path": "rotation"}})
        nodes.append(node)
    gltf = {
        "asset": {"version": "2.0", "generator": generator},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "animations": [{"name": "handles", "samplers": samplers, "channels": channels}],
        **({"cameras": [{"type": "perspective", "perspective": {
            "yfov": camera[1], "aspectRatio": camera[2], "znear": 0.01, "zfar": 100.0}}]}
           if camera is not None else {}),
        "buffers": [data_uri_buffer(blob)],
        "bufferViews": views,
        "accessors": accessors,
    }
    dump_gltf(path, gltf)


def sample_path(script):
    """The script's path from the repository root, with forward slashes."""
    return os.path.relpath(os.path.abspath(script), REPO_ROOT).replace(os.sep, "/")


def write_sample(script, default_name, times, tracks, camera=None, generator=None):
    """The command line the generators share, `SCRIPT [OUT.gltf]`: writes
    the tracks (write_gltf's times, tracks and camera) to OUT.gltf, by
    default to default_name next to the script (where the committed file
    is). The generator string is "crumple " and the script's path in the
    repository unless given. Returns the path written, for the samples that
    add meshes to it."""
    here = os.path.dirname(os.path.abspath(script))
    path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, default_name)
    write_gltf(path, generator or "crumple " + sample_path(script), times, tracks, camera)
    return path


def write_sample_of(script, source, default_name):
    """write_sample for a sample that runs another sample's motion exactly:
    the tracks() of the generator `source` (a path relative to `script`'s
    folder), written next to `script`; the generator string names both
    scripts."""
    import importlib.util
    here = os.path.dirname(os.path.abspath(script))
    source = os.path.join(here, source)
    name = os.path.splitext(os.path.basename(source))[0]
    spec = importlib.util.spec_from_file_location(name, source)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return write_sample(script, default_name, *module.tracks(),
                        generator="crumple %s (%s)" % (sample_path(script), sample_path(source)))


# ---- static meshes ----
def uv_sphere(radius, segments=(48, 24)):
    """Positions, normals and counter-clockwise (seen from outside) triangle
    indices of a UV sphere centred on the origin, segments = (longitude,
    latitude)."""
    nlon, nlat = segments
    positions, normals, indices = [], [], []
    for i in range(nlat + 1):
        theta = math.pi * i / nlat               # from the top pole
        for j in range(nlon + 1):
            phi = 2.0 * math.pi * j / nlon
            nrm = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            normals.extend(nrm)
            positions.extend(radius * c for c in nrm)
    row = nlon + 1
    for i in range(nlat):
        for j in range(nlon):
            a, b = i * row + j, i * row + j + 1
            c, d = a + row, b + row
            if i > 0:
                indices.extend((a, c, b))
            if i < nlat - 1:
                indices.extend((b, c, d))
    return positions, normals, indices


def add_meshes(path, meshes):
    """Gives the glTF that write_gltf wrote at path one triangle mesh per
    entry of meshes, [(node name, positions, normals, indices, (min, max),
    translation or None)], in a second embedded buffer: positions and
    normals are flat float lists (x, y, z a vertex), indices a flat list of
    vertex triples (uint16, counter-clockwise seen from outside), (min, max)
    the positions' bounds. An existing node (an animated one) gets the mesh,
    a missing one is added as a static node at the translation (a prop needs
    a mesh node)."""
    with open(path) as f:
        gltf = json.load(f)
    blob = bytearray()
    buf = len(gltf["buffers"])
    gltf["meshes"] = []
    for name, positions, normals, indices, (lo, hi), translation in meshes:
        nv = len(positions) // 3
        first_view = len(gltf["bufferViews"])
        for values, fmt, target in ((positions, "f", 34962), (normals, "f", 34962),
                                    (indices, "H", 34963)):
            while len(blob) % 4:
                blob.append(0)
            offset = len(blob)
            blob.extend(struct.pack("<%d%s" % (len(values), fmt), *values))
            gltf["bufferViews"].append({"buffer": buf, "byteOffset": offset,
                                        "byteLength": len(blob) - offset, "target": target})
        first_acc = len(gltf["accessors"])
        gltf["accessors"].extend([
            {"bufferView": first_view, "componentType": 5126, "count": nv, "type": "VEC3",
             "min": list(lo), "max": list(hi)},
            {"bufferView": first_view + 1, "componentType": 5126, "count": nv, "type": "VEC3"},
            {"bufferView": first_view + 2, "componentType": 5123, "count": len(indices),
             "type": "SCALAR"},
        ])
        gltf["meshes"].append({"name": name, "primitives": [{
            "attributes": {"POSITION": first_acc, "NORMAL": first_acc + 1},
            "indices": first_acc + 2, "mode": 4}]})
        mesh = len(gltf["meshes"]) - 1
        node = next((n for n in gltf["nodes"] if n["name"] == name), None)
        if node is None:
            gltf["nodes"].append({"name": name, "translation": list(translation)})
            gltf["scenes"][0]["nodes"].append(len(gltf["nodes"]) - 1)
            node = gltf["nodes"][-1]
        node["mesh"] = mesh
    gltf["buffers"].append(data_uri_buffer(blob))
    dump_gltf(path, gltf)


def add_sphere_meshes(path, spheres, segments=(48, 24)):
    """add_meshes with one UV sphere (uv_sphere) per entry of spheres,
    [(node name, radius, translation or None)]."""
    meshes = []
    for name, radius, translation in spheres:
        positions, normals, indices = uv_sphere(radius, segments)
        meshes.append((name, positions, normals, indices, ([-radius] * 3, [radius] * 3),
                       translation))
    add_meshes(path, meshes)
