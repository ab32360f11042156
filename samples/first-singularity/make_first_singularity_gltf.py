#!/usr/bin/env python3
"""Writes samples/first-singularity/first-singularity.gltf: the handle curves
of the first-singularity sample, the validation experiment of the paper's
Sec. 7.1 and Fig. 17: "we moved the two opposite sides of an undamaged square
sheet of paper closer to each other by a factor 10%. Then we applied an
orthogonal constraint on one of the borders until a singular point appeared."

glTF 2.0, Y-up, metres, seconds; keys every 1/48 s (every frame at 24 fps and
every half frame), sampled from eased (C2 smootherstep) analytic motions.

The sheet: 10 cm x 10 cm (L_paper = 10 cm, as in the paper's validation),
standing upright in the XY plane facing the camera (+Z), bottom edge at
y = 5 cm, centred on the Y axis: pattern u along world +X, v along world +Y.
Upright, gravity acts in the sheet's plane and does not bend it, so the bow
below is the one the handles ask for (a 10 cm sheet of 70 g/m^2 paper lying
horizontally sags under its own weight as much as it bows: w L^3 / B ~ 2.7).
Four handles hold the corners, each with tangent-plane control:

    CornerTL (u=0, v=10)   CornerTR (u=10, v=10)    top,    y = 15 cm
    CornerBL (u=0, v=0)    CornerBR (u=10, v=0)     bottom, y = 5 cm

The left side (u = 0: BL, TL) and the right side (u = 10: BR, TR) are the
two held opposite sides; the left side is also the border that gets the
orthogonal constraint.

Motion (times in s):
  0.00-0.25  rest.
  0.25-1.50  the two sides move 10 % closer: each 0.5 cm towards the middle
             (1 cm in total). So that the sheet bows towards the camera as a
             smooth arch, the held sides' tangent planes turn by
             gamma = 2 sqrt(delta) (delta the compression fraction, up to 0.1:
             gamma = 36 degrees), the end slope of the sine-shaped arch whose
             extra length is delta (pinned ends: w = A sin(pi x / L),
             delta ~ (pi A / 2 L)^2). Rotation about Y, -gamma on the left,
             +gamma on the right.
  1.50-1.75  hold the arch.
  1.75-3.25  orthogonal constraint on the left border: its two corners move
             towards each other along it (Y), 0.5 cm each, 10 % of the
             border, and the border's tangent turns towards the camera by the
             same rule (rotation about the corner's local in-sheet X axis,
             after the arch's). The arch is curved across this direction, so
             it cannot bend along it smoothly: a singular point (d-cone)
             appears near the left border.
  3.25-4.00  hold the end pose.

Run it to regenerate the file (the committed file is its output):
    python3 samples/first-singularity/make_first_singularity_gltf.py [OUT.gltf]
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
SQUEEZE = 0.10        # the two held sides come 10 % closer
PINCH = 0.10          # then the left border is compressed by 10 %
T_SQUEEZE = (0.25, 1.50)
T_PINCH = (1.75, 3.25)
T_END = 4.00
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
    bottom = v < W / 2.0
    d1 = SQUEEZE * ramp(t, T_SQUEEZE)
    d2 = PINCH * ramp(t, T_PINCH) if left else 0.0
    x = u - W / 2.0
    y = v - W / 2.0
    # The sides move towards each other (x); the left border's corners towards
    # each other (y).
    x -= math.copysign(W * d1 / 2.0, x)
    y -= math.copysign(W * d2 / 2.0, y)
    gamma = 2.0 * math.sqrt(d1)  # arch across X: turn the in-sheet direction towards +Z
    psi = 2.0 * math.sqrt(d2)    # arch along the left border, towards +Z as well
    q = qaxis((0.0, 1.0, 0.0), -gamma if left else gamma)
    q = qmul(q, qaxis((1.0, 0.0, 0.0), psi if bottom else -psi))
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
    path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "first-singularity.gltf")
    times, tr = tracks()
    check(times, tr)
    write_gltf(path, "crumple samples/first-singularity/make_first_singularity_gltf.py",
               times, tr)


if __name__ == "__main__":
    main()
