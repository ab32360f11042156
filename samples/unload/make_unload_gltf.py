#!/usr/bin/env python3
"""Writes samples/unload/unload.gltf: the handle curves of the unload sample
(paper Fig. 18, bottom row: "the creation of a singularity ... we get the same
effect of the sheet straightening when the constrained points at the back are
unloaded ... the singular vertex is persistent in the model even if the
surface is totally unloaded").

glTF 2.0, Y-up, metres, seconds; keys every 1/48 s (every frame at 24 fps and
every half frame), sampled from eased (C2 smootherstep) analytic motions.

The sheet: 10 cm x 10 cm, standing upright in the XY plane facing the camera
(+Z), bottom edge at y = 5 cm, centred on the Y axis: pattern u along world
+X, v along world +Y. Four handles hold the corners, each with tangent-plane
control:

    CornerTL (u=0, v=10)   CornerTR (u=10, v=10)    top: held throughout
    CornerBL (u=0, v=0)    CornerBR (u=10, v=0)     bottom: released (the
                                                    scene sets release_time)

Motion (times in s), the first-singularity experiment turned by 90 degrees,
then unloaded:
  0.00-0.25  rest.
  0.25-1.25  the top and bottom sides move 10 % closer (0.5 cm each); their
             tangent planes turn by gamma = 2 sqrt(delta) (up to 36 degrees,
             the end slope of a sine arch of extra length delta) so that the
             sheet bows towards the camera. Rotation about X: -gamma at the
             top, +gamma at the bottom.
  1.50-2.50  the top border's corners move 0.5 cm each towards each other
             (10 % of the border) and turn towards the camera by the same rule
             (rotation about the corner's local in-sheet Y axis): the arch
             cannot bend along this direction smoothly, a singular point
             appears near the top border.
  2.50-4.25  every node holds its pose. The scene releases the bottom handles
             at 2.75 s: the sheet hangs from the top corners and, in ~1.5 s,
             straightens (gravity pulls it down in its plane, the bow
             relaxes) while the singular vertex stays.

Run it to regenerate the file (the committed file is its output):
    python3 samples/unload/make_unload_gltf.py [OUT.gltf]
"""
import base64
import json
import math
import os
import struct
import sys

# ---- geometry and timing (metres, seconds, radians) ----
W = 0.10              # sheet side (u and v)
Y0 = 0.05             # height of the bottom edge
SQUEEZE = 0.10        # the top and bottom sides come 10 % closer
PINCH = 0.10          # then the top border is compressed by 10 %
T_SQUEEZE = (0.25, 1.25)
T_PINCH = (1.50, 2.50)
T_RELEASE = 2.75      # the scene's release_time of the bottom handles
T_END = 4.25
KEYS_PER_SECOND = 48

# (node name, u, v) in metres on the pattern
CORNERS = [("CornerBL", 0.0, 0.0), ("CornerBR", W, 0.0),
           ("CornerTL", 0.0, W), ("CornerTR", W, W)]


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
    left = u < W / 2.0
    top = v > W / 2.0
    d1 = SQUEEZE * ramp(t, T_SQUEEZE)
    d2 = PINCH * ramp(t, T_PINCH) if top else 0.0
    x = u - W / 2.0
    y = v - W / 2.0
    # The top and bottom sides move towards each other (y); the top border's
    # corners towards each other (x).
    y -= math.copysign(W * d1 / 2.0, y)
    x -= math.copysign(W * d2 / 2.0, x)
    gamma = 2.0 * math.sqrt(d1)  # arch across Y: turn the in-sheet direction towards +Z
    psi = 2.0 * math.sqrt(d2)    # arch along the top border, towards +Z as well
    q = qaxis((1.0, 0.0, 0.0), -gamma if top else gamma)
    q = qmul(q, qaxis((0.0, 1.0, 0.0), -psi if left else psi))
    return (x, Y0 + W / 2.0 + y, 0.0), q


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
    return check_no_stretch(times, tracks_, pattern, (W, W),
                            ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)))


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "unload.gltf")
    times, tr = tracks()
    check(times, tr)
    write_gltf(path, "crumple samples/unload/make_unload_gltf.py", times, tr)


if __name__ == "__main__":
    main()
