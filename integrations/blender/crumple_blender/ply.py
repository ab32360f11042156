"""Reads the binary little-endian PLY frames `crumple export --format ply`
writes (docs/EXPORT.md "PLY"): vertices x y z u v (s t), faces as a list of
vertex indices with an int `region` each."""

import struct

_TYPES = {"char": "b", "uchar": "B", "short": "h", "ushort": "H", "int": "i",
          "uint": "I", "float": "f", "double": "d", "int8": "b", "uint8": "B",
          "int16": "h", "uint16": "H", "int32": "i", "uint32": "I",
          "float32": "f", "float64": "d"}


class PlyFrame:
    def __init__(self):
        self.positions = []   # (x, y, z), metres, Y up
        self.uvs = []         # (u, v) per vertex
        self.faces = []       # (a, b, c, ...) vertex indices
        self.regions = []     # region id per face (or empty)


def _header(data, path):
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise ValueError("%s: not a PLY file" % path)
    body = data.index(b"\n", end) + 1
    elements = []  # (name, count, [(property, type or (count type, item type))])
    for raw in data[:end].decode("ascii").splitlines():
        words = raw.split()
        if not words:
            continue
        if words[0] == "format" and words[1] != "binary_little_endian":
            raise ValueError("%s: %s PLY, want binary_little_endian" % (path, words[1]))
        if words[0] == "element":
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property":
            if words[1] == "list":
                elements[-1][2].append((words[4], (_TYPES[words[2]], _TYPES[words[3]])))
            else:
                elements[-1][2].append((words[2], _TYPES[words[1]]))
    return elements, body


def read(path):
    with open(path, "rb") as f:
        data = f.read()
    elements, pos = _header(data, path)
    frame = PlyFrame()
    for name, count, props in elements:
        if all(isinstance(t, str) for _, t in props):
            fmt = "<" + "".join(t for _, t in props)
            size = struct.calcsize(fmt)
            rows = list(struct.iter_unpack(fmt, data[pos:pos + size * count]))
            pos += size * count
            cols = {p: i for i, (p, _) in enumerate(props)}
            if name == "vertex":
                frame.positions = [(r[cols["x"]], r[cols["y"]], r[cols["z"]]) for r in rows]
                if "u" in cols:
                    frame.uvs = [(r[cols["u"]], r[cols["v"]]) for r in rows]
            continue
        pos = _read_faces(data, pos, count, props, frame)
    return frame


def _read_faces(data, pos, count, props, frame):
    """A face element: its list property and scalars (region) in any order."""
    for _ in range(count):
        for prop, kind in props:
            if isinstance(kind, tuple):
                n = struct.unpack_from("<" + kind[0], data, pos)[0]
                pos += struct.calcsize(kind[0])
                frame.faces.append(struct.unpack_from("<%d%s" % (n, kind[1]), data, pos))
                pos += n * struct.calcsize(kind[1])
            else:
                value = struct.unpack_from("<" + kind, data, pos)[0]
                pos += struct.calcsize(kind)
                if prop == "region":
                    frame.regions.append(value)
    return pos
