# SPDX-License-Identifier: MIT
"""Blender add-on: import hair grooms as curve objects, one POLY spline per strand.

Formats (the same files Follicle reads and writes; facts in docs/blender.md):
  - Cem Yuksel's HAIR (.hair): 128-byte little-endian header "HAIR", hair count, point count,
    array flags (segments 1, points 2, thickness 4, transparency 8, colours 16), default segments,
    thickness, transparency, colour and an 88-byte info string; then the arrays in that order.
  - AMD TressFX 4 (.tfx): 160-byte little-endian header (float version, strand count, vertices
    per strand, byte offsets of positions / strand UVs / vertex UVs / strand thickness / vertex
    colours, 32 reserved uints); positions are float4 (x, y, z, inverse mass).

Pure Python: the struct and array modules plus the Blender API (no numpy). The readers
(read_cyhair, read_tfx) also work outside Blender.

Use from File > Import, or from a script:
    bpy.ops.import_curve.follicle_hair(filepath="groom.hair", units='CM', axis='Y_UP')
    bpy.ops.import_curve.follicle_tfx(filepath="groom.tfx", units='CM')
    follicle_grooms.import_groom(bpy.context, "groom.hair", units='CM')  # returns the object
"""

import array
import os
import struct
import sys

bl_info = {
    "name": "Follicle grooms (.hair, .tfx)",
    "author": "Follicle contributors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "File > Import > Cem Yuksel Hair (.hair) / AMD TressFX (.tfx)",
    "description": "Import hair grooms as curve objects, one poly spline per strand",
    "category": "Import-Export",
}

# Metres per file unit for the `units` option.
UNIT_METRES = {"M": 1.0, "DM": 0.1, "CM": 0.01, "MM": 0.001}


class GroomFormatError(ValueError):
    """A malformed, truncated or inconsistent groom file; the message names the file."""


class Groom:
    """A groom as read from a file, in the file's own unit and axes.

    sizes: points per strand; points: flat x, y, z floats (3 per point); radius: one radius per
    point in file units (None when the file has no thickness); notes: what was read or ignored."""

    def __init__(self, fmt, sizes, points, radius=None, notes=()):
        self.format = fmt
        self.sizes = sizes
        self.points = points
        self.radius = radius
        self.notes = list(notes)

    @property
    def num_strands(self):
        return len(self.sizes)

    @property
    def num_points(self):
        return len(self.points) // 3


def _floats(data, offset, count, path, what):
    """`count` little-endian float32 values of `data` at byte `offset`."""
    end = offset + 4 * count
    if offset < 0 or end > len(data):
        raise GroomFormatError(
            "%s: truncated: %s need %d bytes at offset %d, the file has %d"
            % (path, what, 4 * count, offset, len(data)))
    a = array.array("f")
    a.frombytes(data[offset:end])
    if sys.byteorder == "big":
        a.byteswap()
    return a


def _check_finite(values, path, what):
    for i, v in enumerate(values):
        if v != v or v in (float("inf"), float("-inf")):
            raise GroomFormatError("%s: %s %d is not finite (%r)" % (path, what, i, v))


def read_cyhair(path):
    """Reads a Cem Yuksel .hair file; raises GroomFormatError naming the file on bad input."""
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < 4 or data[:4] != b"HAIR":
        raise GroomFormatError('%s: not a .hair file: expected the signature "HAIR"' % path)
    if len(data) < 128:
        raise GroomFormatError("%s: truncated: the header needs 128 bytes, the file has %d"
                               % (path, len(data)))
    (hair_count, point_count, flags, default_segments, default_thickness, _default_transparency,
     _r, _g, _b) = struct.unpack_from("<IIIIff3f", data, 4)
    info = data[40:128].split(b"\0", 1)[0].decode("latin-1")
    if flags & ~31:
        raise GroomFormatError("%s: unknown array flags 0x%x (expected bits 0..4)" % (path, flags))
    if not flags & 2:
        raise GroomFormatError("%s: file has no points array" % path)
    pos = 128
    if flags & 1:
        end = pos + 2 * hair_count
        if end > len(data):
            raise GroomFormatError("%s: truncated: segments need %d bytes at offset %d, the file "
                                   "has %d" % (path, 2 * hair_count, pos, len(data)))
        seg = array.array("H")
        seg.frombytes(data[pos:end])
        if sys.byteorder == "big":
            seg.byteswap()
        sizes = [s + 1 for s in seg]
        pos = end
    else:
        sizes = [default_segments + 1] * hair_count
    if sum(sizes) != point_count:
        raise GroomFormatError("%s: segment counts describe %d points but the header says %d"
                               % (path, sum(sizes), point_count))
    points = _floats(data, pos, 3 * point_count, path, "points")
    pos += 12 * point_count
    _check_finite(points, path, "point coordinate")
    notes = ['info: "%s"' % info] if info else []
    radius = None
    if flags & 4:
        thickness = _floats(data, pos, point_count, path, "thickness")
        pos += 4 * point_count
        radius = array.array("f", (0.5 * t for t in thickness))
    else:  # like Follicle: writers leave cyHairFile's default of 1 here, rarely a real width
        notes.append("no thickness array (header default %g not applied)" % default_thickness)
    if flags & 8:
        pos += 4 * point_count
        notes.append("transparency ignored")
    if flags & 16:
        pos += 12 * point_count
        notes.append("colours ignored")
    if pos != len(data):
        if pos > len(data):
            raise GroomFormatError("%s: truncated: the arrays need %d bytes, the file has %d"
                                   % (path, pos, len(data)))
        raise GroomFormatError("%s: %d unexpected trailing bytes after the arrays (the header "
                               "counts %d points)" % (path, len(data) - pos, point_count))
    return Groom("hair", sizes, points, radius, notes)


def read_tfx(path):
    """Reads an AMD TressFX 4 .tfx file; raises GroomFormatError naming the file on bad input."""
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < 160:
        raise GroomFormatError("%s: truncated: the TressFX header needs 160 bytes, the file has %d"
                               % (path, len(data)))
    (version, strands, verts, off_pos, _off_suv, _off_vuv, off_thick,
     _off_col) = struct.unpack_from("<fIIIIIII", data, 0)
    if not (1.0 <= version <= 100.0):
        raise GroomFormatError("%s: not a TressFX file: version %r (expected 4.0)"
                               % (path, version))
    if verts < 2 or verts > 64 or verts & (verts - 1):
        raise GroomFormatError("%s: vertices per strand %d is not a power of two in [2, 64]"
                               % (path, verts))
    if strands == 0:
        raise GroomFormatError("%s: file has no strands" % path)
    if off_pos < 160:
        raise GroomFormatError("%s: position offset %d lies inside the 160-byte header"
                               % (path, off_pos))
    n = strands * verts
    xyzw = _floats(data, off_pos, 4 * n, path, "positions")
    _check_finite(xyzw, path, "position")
    points = array.array("f", bytes(12 * n))
    points[0::3] = xyzw[0::4]
    points[1::3] = xyzw[1::4]
    points[2::3] = xyzw[2::4]
    radius = None
    notes = ["version %g, %d vertices per strand" % (version, verts)]
    if off_thick:
        if off_thick < 160:
            raise GroomFormatError("%s: thickness offset %d lies inside the 160-byte header"
                                   % (path, off_thick))
        thick = _floats(data, off_thick, strands, path, "strand thickness")
        radius = array.array("f", (0.5 * thick[i // verts] for i in range(n)))
    return Groom("tfx", [verts] * strands, points, radius, notes)


def read_groom(path):
    """Reads .hair or .tfx by extension (falls back to the "HAIR" signature)."""
    ext = os.path.splitext(path)[1].lower()
    if ext == ".tfx":
        return read_tfx(path)
    if ext == ".hair":
        return read_cyhair(path)
    with open(path, "rb") as f:
        if f.read(4) == b"HAIR":
            return read_cyhair(path)
    raise GroomFormatError("%s: unknown groom file type '%s': expected .hair or .tfx" % (path, ext))


def to_blender_points(groom, units="M", scale=1.0, axis="Y_UP"):
    """The groom's points as flat x, y, z, w floats in Blender coordinates: file units times
    UNIT_METRES[units] times `scale`; axis 'Y_UP' maps a Y-up file to Blender's Z-up world as
    Blender's OBJ and glTF importers do ((x, y, z) -> (x, -z, y)); 'Z_UP' keeps the axes."""
    k = UNIT_METRES[units] * scale
    p = groom.points
    n = groom.num_points
    out = array.array("f", bytes(16 * n))
    out[0::4] = array.array("f", (k * v for v in p[0::3]))
    if axis == "Y_UP":
        out[1::4] = array.array("f", (-k * v for v in p[2::3]))
        out[2::4] = array.array("f", (k * v for v in p[1::3]))
    elif axis == "Z_UP":
        out[1::4] = array.array("f", (k * v for v in p[1::3]))
        out[2::4] = array.array("f", (k * v for v in p[2::3]))
    else:
        raise ValueError("axis must be 'Y_UP' or 'Z_UP', got %r" % (axis,))
    out[3::4] = array.array("f", [1.0]) * n
    return out


try:
    import bpy
    from bpy.props import BoolProperty, EnumProperty, FloatProperty, StringProperty
    from bpy_extras.io_utils import ImportHelper
except ImportError:  # the readers above work without Blender
    bpy = None


def import_groom(context, filepath, units="M", scale=1.0, axis="Y_UP", use_radius=True,
                 bevel=False, name=None):
    """Imports a .hair or .tfx file as a new curve object linked to the active collection and
    returns it. The object's custom properties record the format, counts and unit."""
    groom = read_groom(filepath)
    co = to_blender_points(groom, units, scale, axis)
    name = name or os.path.splitext(os.path.basename(filepath))[0]
    cu = bpy.data.curves.new(name, type="CURVE")
    cu.dimensions = "3D"
    k = UNIT_METRES[units] * scale
    radius = groom.radius if use_radius else None
    begin = 0
    for n in groom.sizes:
        sp = cu.splines.new("POLY")
        if n > 1:
            sp.points.add(n - 1)
        sp.points.foreach_set("co", co[4 * begin:4 * (begin + n)])
        if radius is not None:
            sp.points.foreach_set("radius", array.array("f", (k * r for r in
                                                              radius[begin:begin + n])))
        begin += n
    if bevel:
        # Point radii are absolute (Blender units) when the file has thickness, so a bevel depth
        # of 1 makes tubes of the true thickness; without thickness every radius is 1 and the
        # tubes get a typical hair radius of 40 um (times `scale`).
        cu.bevel_depth = 1.0 if radius is not None else 40e-6 * scale
        cu.bevel_resolution = 0
    obj = bpy.data.objects.new(name, cu)
    obj["follicle_format"] = groom.format
    obj["follicle_strands"] = groom.num_strands
    obj["follicle_points"] = groom.num_points
    obj["follicle_units"] = units
    obj["follicle_axis"] = axis
    obj["follicle_source"] = filepath
    context.collection.objects.link(obj)
    for o in context.selected_objects:
        o.select_set(False)
    obj.select_set(True)
    context.view_layer.objects.active = obj
    return obj


if bpy is not None:

    class _ImportGroomBase(ImportHelper):
        units: EnumProperty(
            name="File Units",
            description="Length unit of the coordinates in the file (Blender works in metres)",
            items=(("M", "Metres", "1 file unit = 1 m (no scaling)"),
                   ("DM", "Decimetres", "1 file unit = 0.1 m"),
                   ("CM", "Centimetres", "1 file unit = 0.01 m"),
                   ("MM", "Millimetres", "1 file unit = 0.001 m")),
            default="M")
        scale: FloatProperty(
            name="Scale", description="Extra uniform scale applied after the unit conversion",
            default=1.0, min=1e-6, max=1e6, soft_min=1e-3, soft_max=1e3)
        axis: EnumProperty(
            name="Up Axis",
            description="Up axis of the file. Y Up converts to Blender's Z up like the OBJ and "
                        "glTF importers: (x, y, z) -> (x, -z, y)",
            items=(("Y_UP", "Y Up", "The file is Y-up (Follicle, TressFX, most hair data)"),
                   ("Z_UP", "Z Up", "Keep the file's axes")),
            default="Y_UP")
        use_radius: BoolProperty(
            name="Thickness as Radius",
            description="Set each point's radius to half the file's thickness (Blender units)",
            default=True)
        bevel: BoolProperty(
            name="Tubes",
            description="Give the curve a bevel so strands render as tubes of their thickness "
                        "(heavy for large grooms)",
            default=False)

        def execute(self, context):
            try:
                obj = import_groom(context, self.filepath, units=self.units, scale=self.scale,
                                   axis=self.axis, use_radius=self.use_radius, bevel=self.bevel)
            except (OSError, GroomFormatError) as e:
                self.report({"ERROR"}, str(e))
                return {"CANCELLED"}
            self.report({"INFO"}, "Imported %s: %d strands, %d points"
                        % (obj.name, obj["follicle_strands"], obj["follicle_points"]))
            return {"FINISHED"}

    class IMPORT_CURVE_OT_follicle_hair(bpy.types.Operator, _ImportGroomBase):
        """Import a Cem Yuksel .hair groom as a curve object (one poly spline per strand)"""
        bl_idname = "import_curve.follicle_hair"
        bl_label = "Import Cem Yuksel Hair"
        bl_options = {"REGISTER", "UNDO", "PRESET"}
        filename_ext = ".hair"
        filter_glob: StringProperty(default="*.hair", options={"HIDDEN"})

    class IMPORT_CURVE_OT_follicle_tfx(bpy.types.Operator, _ImportGroomBase):
        """Import an AMD TressFX .tfx groom as a curve object (one poly spline per strand)"""
        bl_idname = "import_curve.follicle_tfx"
        bl_label = "Import AMD TressFX"
        bl_options = {"REGISTER", "UNDO", "PRESET"}
        filename_ext = ".tfx"
        filter_glob: StringProperty(default="*.tfx", options={"HIDDEN"})

    def menu_func_hair(self, context):
        self.layout.operator(IMPORT_CURVE_OT_follicle_hair.bl_idname,
                             text="Cem Yuksel Hair (.hair)")

    def menu_func_tfx(self, context):
        self.layout.operator(IMPORT_CURVE_OT_follicle_tfx.bl_idname, text="AMD TressFX (.tfx)")

    _classes = (IMPORT_CURVE_OT_follicle_hair, IMPORT_CURVE_OT_follicle_tfx)


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.TOPBAR_MT_file_import.append(menu_func_hair)
    bpy.types.TOPBAR_MT_file_import.append(menu_func_tfx)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(menu_func_tfx)
    bpy.types.TOPBAR_MT_file_import.remove(menu_func_hair)
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)


if __name__ == "__main__":  # run from Blender's text editor: register without installing
    register()
