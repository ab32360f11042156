"""What the other modules share: the error the operators report, the change
of frame between Blender and crumple, and TOML-safe number formatting."""

from mathutils import Vector


class CrumpleError(Exception):
    """Bad input or a failed crumple run: the operators report its message
    with self.report({'ERROR'}, ...) instead of raising."""


def to_gltf(v):
    """Blender's Z-up world to crumple's (and glTF's) Y-up world, as Blender's
    glTF exporter converts it (export_yup): (x, y, z) -> (x, z, -y)."""
    return Vector((v[0], v[2], -v[1]))


def from_gltf(v):
    """crumple's Y-up world to Blender's Z-up: (x, y, z) -> (x, -z, y)."""
    return Vector((v[0], -v[2], v[1]))


def number(x):
    """A TOML float, the same text for the same value: 9 significant digits,
    no negative zero, always with a '.' or an exponent."""
    if abs(x) < 1e-12:
        x = 0.0
    text = "%.9g" % x
    if "." not in text and "e" not in text and "n" not in text:
        text += ".0"
    return text


def vector(values):
    return "[" + ", ".join(number(x) for x in values) + "]"


def string(text):
    """A TOML basic string."""
    out = []
    for ch in text:
        if ch in "\\\"":
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append("\\u%04x" % ord(ch))
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'
