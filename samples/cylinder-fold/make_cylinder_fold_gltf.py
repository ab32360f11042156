#!/usr/bin/env python3
"""Writes samples/cylinder-fold/cylinder-fold.gltf: the handle curves of the
cylinder-fold sample (paper Fig. 1: "Interactive folding of a virtual sheet of
paper, after a cylindrical wrap"; Sec. 7.3: "after smoothly wrapping the sheet
into a cylindrical shape, a second bending is applied orthogonally to the
cylinder axis. The resulting shape exhibits sharp singularities").

glTF 2.0, Y-up, metres, seconds; keys every 1/48 s (every frame at 24 fps and
every half frame), sampled from eased (C2 smootherstep) analytic motions, so
the linear interpolation between keys is smooth to the eye.

The sheet: 10 cm x 10 cm, lying flat at y = 10 cm, centred on the Y axis,
pattern u along world +X, v along world -Z (front edge v = 0 at z = +5 cm,
nearest the camera). Four handles hold the corners, each with tangent-plane
control (the node's rotation turns the corner's two neighbour vertices):

    CornerFL (u=0, v=0)    CornerFR (u=10, v=0)     front, z = +5 cm
    CornerBL (u=0, v=10)   CornerBR (u=10, v=10)    back,  z = -5 cm

Motion (times in s):
  0.00-0.25  rest.
  0.25-1.75  wrap: the left and right edges (u = 0 and u = 10) roll up and
             towards each other. At wrap angle phi the cross-section is a
             circular arc of length 10 cm, radius 10/phi, whose bottom line
             (u = 5) stays at y = 10 cm; each corner sits on the arc and its
             tangent plane turns with it (rotation about Z by the arc angle,
             +-phi/2). phi grows from 0 to 240 degrees: a "C"-shaped tube,
             open at the top, axis along Z, radius 2.39 cm.
  1.75-2.25  hold the cylinder.
  2.25-3.75  bend orthogonally to the cylinder axis: the two ends of the tube
             (z = +-5 cm) turn about the X axis by +-beta (beta up to 15
             degrees) as rigid cross-sections, so that the tube's bottom line
             becomes a circular arc of length 10 cm bulging down (the ends
             rise). The open top of the tube, where the held edges are, is on
             the inside of the bend: the edges' corners come 20 % closer
             (10 cm -> 8.0 cm). A cylinder cannot bend along its axis without
             stretching, so the compressed top must buckle: singular points
             (d-cones) form along the held edges.
  3.75-4.25  hold the final pose.

Run it to regenerate the file (the committed file is its output):
    python3 samples/cylinder-fold/make_cylinder_fold_gltf.py [OUT.gltf]
samples/paper-types runs the same motion (make_paper_types_gltf.py imports
this script's write()).
"""
import base64
import json
import math
import os
import struct
import sys

# ---- geometry and timing (metres, seconds, radians) ----
W = 0.10                 # sheet width (u, across the cylinder)
L = 0.10                 # sheet height (v, along the cylinder axis)
Y0 = 0.10                # height of the flat sheet and of the tube's bottom line
PHI = math.radians(240)  # final wrap angle of the cross-section
BETA = math.radians(15)  # final half-angle of the axis bend
T_WRAP = (0.25, 1.75)
T_BEND = (2.25, 3.75)
T_END = 4.25
KEYS_PER_SECOND = 48

# (node name, u, v) in metres on the pattern
CORNERS = [("CornerFL", 0.0, 0.0), ("CornerFR", W, 0.0),
           ("CornerBL", 0.0, L), ("CornerBR", W, L)]


# ---- small helpers (stdlib only) ----
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
        "buffers": [{
            "byteLength": len(blob),
            "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode(),
        }],
        "bufferViews": views,
        "accessors": accessors,
    }
    with open(path, "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


def check_no_stretch(times, tracks_, pattern, size, axes, patch=0.01):
    """Asserts that the handles never pull the sheet longer than its pattern:
    no two held points get farther apart than on the pattern. Held points are
    each handle's vertex and, for tangent-plane control, its neighbours, taken
    here `patch` metres away along the pattern axes (1 cm: coarser than any
    mesh the samples run on), carried rigidly by the node's rotation.
    pattern: {node: (u, v)} in metres; size: (width, height); axes: the world
    directions of the pattern's u and v at the first frame (every node starts
    with the identity rotation). Returns the worst ratio."""
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


# ---- the motion ----
def corner_pose(u, v, t):
    """World position and rotation of the handle at pattern point (u, v)."""
    phi = PHI * ramp(t, T_WRAP)
    beta = BETA * ramp(t, T_BEND)
    # Cross-section: an arc of length W and angle phi, bottom (u = W/2) at the origin.
    if phi < 1e-9:
        alpha, d = 0.0, (u - W / 2.0, 0.0, 0.0)
    else:
        r = W / phi
        alpha = (u - W / 2.0) / r
        d = (r * math.sin(alpha), r * (1.0 - math.cos(alpha)), 0.0)
    # Axis bend: the bottom line becomes an arc of length L and angle 2 beta,
    # centre above; the end at z = s L/2 turns about X by -s beta.
    s = 1.0 if v < L / 2.0 else -1.0
    if beta < 1e-9:
        b = (0.0, Y0, s * L / 2.0)
    else:
        rb = L / (2.0 * beta)
        b = (0.0, Y0 + rb * (1.0 - math.cos(beta)), s * rb * math.sin(beta))
    q_end = qaxis((1.0, 0.0, 0.0), -s * beta)
    p = qrot(q_end, d)
    position = (b[0] + p[0], b[1] + p[1], b[2] + p[2])
    rotation = qmul(q_end, qaxis((0.0, 0.0, 1.0), alpha))
    return position, rotation


def tracks():
    times = [k / KEYS_PER_SECOND for k in range(int(round(T_END * KEYS_PER_SECOND)) + 1)]
    out = []
    for name, u, v in CORNERS:
        poses = [corner_pose(u, v, t) for t in times]
        out.append((name, [p for p, _ in poses], [q for _, q in poses]))
    return times, out


def check(times, tracks_):
    """No two held points ever get farther apart than on the pattern."""
    pattern = {name: (u, v) for name, u, v in CORNERS}
    return check_no_stretch(times, tracks_, pattern, (W, L),
                            ((1.0, 0.0, 0.0), (0.0, 0.0, -1.0)))


def write(path, generator="crumple samples/cylinder-fold/make_cylinder_fold_gltf.py"):
    times, tr = tracks()
    check(times, tr)
    write_gltf(path, generator, times, tr)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    write(sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "cylinder-fold.gltf"))


if __name__ == "__main__":
    main()
