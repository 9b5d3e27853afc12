"""Rhino ``.3dm`` files of the crease pattern and of the folded form, through ``rhino3dm``.

Needs the ``rhino`` extra (``pip install 'filletfold[rhino]'``, i.e. ``rhino3dm>=8``); without
it the format ``3dm`` is refused in one line, and ``--format all`` leaves it out.

``pattern.3dm`` -- the flat layout, in the plane z = 0, on these layers:

===========  =============================================================================
layer        content
===========  =============================================================================
``CUT``      ``B`` edges (piece borders and cuts) and the cut part of each glue-tab outline
``MOUNTAIN`` ``M`` edges
``VALLEY``   ``V`` edges
``TAB``      the tab hinges (the fold between a tab and its piece), one line each
``LABEL``    the labels (part numbers, seam labels) as text dots, named by their kind
``RELIEF``   with a sheet material that is relieved: the reliefs' outlines (cut through)
``KERF_*``   with a kerfed sheet material: the grooves, ``KERF_FRONT`` and ``KERF_BACK``
===========  =============================================================================

Edges of one layer are chained end to end and cut into runs exactly as in the DXF
(:func:`~filletfold.export.paths.edge_chains`, :func:`~filletfold.export.paths.chain_runs`):
a smooth run (a sampled curved crease) is one degree-3 NURBS curve that passes through its
samples (the interpolation the DXF's splines use), a run of two points a line, any other run
a polyline.

``folded.3dm`` -- the folded form: one mesh per patch (named as in ``design.fold``, e.g.
``"cone 3"``) on a layer per patch kind -- ``CONE``, ``CYLINDER``, ``FILLET`` (conical fillets),
``FACE`` -- with double-precision vertices and Rhino's vertex normals, and the creases (the
same runs, through the folded points) on ``MOUNTAIN`` and ``VALLEY``.

Both files carry the model unit of ``units`` (``mm``, ``cm``, ``m``, ``in``; unitless is Rhino's
"no unit system") and every coordinate is multiplied by ``scale``, the folded form's too, so
the two files overlay at the same size. Written as Rhino 7 files (Rhino 7 and 8 open them).
Layer and object ids are fixed (derived from the file and the object's number) and the file's
creation and edit dates are written as 2000-01-01 00:00:00, so the same input gives the same
bytes.
"""

from __future__ import annotations

import base64
import struct
import uuid
import zlib

import numpy as np

from ..errors import ExportError, ParameterError
from ..surface.patch import patch_kind
from ..surface.pattern import CreasePattern
from ..surface.validate import validated_faces
from ..units import check_units
from .dxf import check_scale
from .mesh3d import kinds_present
from .palette import ASSIGNMENT_COLOR, KERF_COLOR, LABEL_COLOR, TAB_HINGE_COLOR
from .paths import chain_runs, edge_chains, edge_layer_masks, tab_cut_paths
from .png import PATCH_COLOR

__all__ = [
    "FOLDED_CREASE_LAYERS",
    "MAKING_LAYERS",
    "PATTERN_LAYERS",
    "RHINO_UNITS",
    "folded_3dm",
    "kind_layer",
    "patch_meshes",
    "path_curve",
    "pattern_3dm",
    "pattern_paths",
    "require_rhino3dm",
]

#: Rhino ``UnitSystem`` member of each drawing unit (``""``: unitless).
RHINO_UNITS = {"": "None", "mm": "Millimeters", "cm": "Centimeters", "m": "Meters", "in": "Inches"}
#: Layers of ``pattern.3dm`` and their colours, in the order they are created.
PATTERN_LAYERS = {
    "CUT": ASSIGNMENT_COLOR["B"],
    "MOUNTAIN": ASSIGNMENT_COLOR["M"],
    "VALLEY": ASSIGNMENT_COLOR["V"],
    "TAB": TAB_HINGE_COLOR,
    "LABEL": LABEL_COLOR,
}
#: Layers of a sheet material's making paths (:mod:`~filletfold.layout.making`) in
#: ``pattern.3dm``, after :data:`PATTERN_LAYERS` where a design has them, and their colours.
MAKING_LAYERS = {"relief": "RELIEF", "kerf-front": "KERF_FRONT", "kerf-back": "KERF_BACK"}
MAKING_COLORS = {"relief": ASSIGNMENT_COLOR["B"], **KERF_COLOR}
#: Crease layers of ``folded.3dm`` (after its patch layers) and their colours.
FOLDED_CREASE_LAYERS = {"MOUNTAIN": ASSIGNMENT_COLOR["M"], "VALLEY": ASSIGNMENT_COLOR["V"]}
#: The Rhino file version written.
RHINO_VERSION = 7
#: Namespace of the fixed layer and object ids.
_ID_NAMESPACE = uuid.UUID("5c1f0a5e-6d1e-4f0d-9a8e-f111e7f01d00")
#: openNURBS chunk type codes: the properties table and its revision history (created / last
#: edited dates).
_TCODE_PROPERTIES_TABLE = 0x10000014
_TCODE_REVISION_HISTORY = 0x20008021
#: 2000-01-01 00:00:00 as openNURBS writes a time: sec, min, hour, mday, mon, year - 1900,
#: wday (a Saturday), yday.
_FIXED_TIME = struct.pack("<8i", 0, 0, 0, 1, 0, 100, 6, 0)


def require_rhino3dm():
    """Import ``rhino3dm``, or raise a one-line :class:`ParameterError` saying how to get it."""
    try:
        import rhino3dm
    except ImportError:
        raise ParameterError(
            "format 3dm needs rhino3dm: pip install 'filletfold[rhino]'", name="format"
        ) from None
    return rhino3dm


def kind_layer(kind: str) -> str:
    """The ``folded.3dm`` layer of a patch kind: its name in capitals (``"cone"`` -> ``CONE``)."""
    return kind.upper()


def _rgba(colour) -> tuple[int, int, int, int]:
    """``"#rrggbb"`` or an RGB triple in 0..1 as Rhino's (r, g, b, a) bytes."""
    if isinstance(colour, str):
        rgb = [int(colour[i : i + 2], 16) for i in (1, 3, 5)]
    else:
        rgb = [round(255 * c) for c in colour]
    return (*rgb, 255)


class _Model:
    """A ``File3dm`` being filled: layers by name, objects with fixed ids."""

    def __init__(self, rhino3dm, name: str, units: str, layers: dict):
        self.r = rhino3dm
        self.name = name
        self.file = rhino3dm.File3dm()
        self.file.Settings.ModelUnitSystem = getattr(rhino3dm.UnitSystem, RHINO_UNITS[units])
        self.layer = {}
        for layer_name, colour in layers.items():
            layer = rhino3dm.Layer()
            layer.Name = layer_name
            layer.Color = _rgba(colour)
            layer.Id = self._id(f"layer {layer_name}")
            self.layer[layer_name] = self.file.Layers.Add(layer)
        self.count = 0

    def _id(self, what: str) -> uuid.UUID:
        return uuid.uuid5(_ID_NAMESPACE, f"{self.name} {what}")

    def attributes(self, layer: str, name: str = ""):
        attr = self.r.ObjectAttributes()
        attr.LayerIndex = self.layer[layer]
        attr.Id = self._id(f"object {self.count}")
        if name:
            attr.Name = name
        self.count += 1
        return attr

    def add_path(self, points: np.ndarray, closed: bool, layer: str, spline: bool) -> None:
        """One run (:func:`path_curve`) on ``layer``."""
        self.file.Objects.AddCurve(
            path_curve(self.r, points, closed, spline), self.attributes(layer)
        )

    def encode(self) -> bytes:
        options = self.r.File3dmWriteOptions()
        options.Version = RHINO_VERSION
        return _fixed_dates(base64.b64decode(self.file.Encode(options)))


def path_curve(r, points: np.ndarray, closed: bool, spline: bool):
    """One run of the 3dm files as a ``rhino3dm`` curve: a degree-3 curve through ``points``
    (k, 3) with ``spline``, else a line (two points) or a polyline (closed: back to its first
    point). ``r`` is the ``rhino3dm`` module."""
    if spline:
        return _interpolating_curve(r, np.asarray(points, dtype=np.float64))
    pts = [r.Point3d(x, y, z) for x, y, z in np.asarray(points, dtype=float).tolist()]
    if len(pts) == 2 and not closed:
        return r.LineCurve(pts[0], pts[1])
    return r.PolylineCurve([*pts, pts[0]] if closed else pts)


def _interpolating_curve(r, points: np.ndarray):
    """The degree-3 NURBS curve through ``points`` (k, 3): ezdxf's CAD-style interpolation
    (chord-length parameters, the points at its distinct knots) with end tangents estimated
    from the first and last three points, so that a sampled arc's curve keeps to the arc at its
    ends too (on a circle sampled every 4.5 degrees: within 1.8e-6 r of it, against 3e-4 r
    with free ends)."""
    from ezdxf.math import Vec3, estimate_tangents, fit_points_to_cad_cv

    fit = [Vec3(*map(float, p)) for p in points]
    tangents = estimate_tangents(fit, method="3-points")
    spline = fit_points_to_cad_cv(fit, tangents=[tangents[0], tangents[-1]])
    control = np.asarray(spline.control_points, dtype=np.float64)
    knots = np.asarray(spline.knots(), dtype=np.float64)
    curve = r.NurbsCurve(3, False, spline.order, len(control))
    for i, p in enumerate(control.tolist()):
        curve.Points[i] = r.Point4d(p[0], p[1], p[2], 1.0)
    for i, k in enumerate(knots[1:-1].tolist()):  # openNURBS omits the two outer knots
        curve.Knots[i] = k
    return curve


def _fixed_dates(data: bytes) -> bytes:
    """The 3dm ``data`` with its created and last-edited times set to :data:`_FIXED_TIME`.

    openNURBS writes the current time into the properties table's revision history (a chunk
    with a CRC32 of its contents); here both times are replaced and the CRC is recomputed.
    """
    out = bytearray(data)
    table = _find_chunk(out, 32, len(out), _TCODE_PROPERTIES_TABLE)
    if table is None:
        raise ExportError("3dm writer: no properties table in rhino3dm's file")
    start, length = table
    chunk = _find_chunk(out, start, start + length, _TCODE_REVISION_HISTORY)
    if chunk is None:
        raise ExportError("3dm writer: no revision history in rhino3dm's file")
    start, length = chunk
    body = start + length - 4  # the CRC32 closes the chunk
    at = start + 1  # after the chunk version byte: created by, created, edited by, edited
    for _ in range(2):
        (chars,) = struct.unpack_from("<I", out, at)
        at += 4 + 2 * chars
        if at + len(_FIXED_TIME) > body:
            raise ExportError("3dm writer: unexpected revision history in rhino3dm's file")
        out[at : at + len(_FIXED_TIME)] = _FIXED_TIME
        at += len(_FIXED_TIME)
    struct.pack_into("<I", out, body, zlib.crc32(bytes(out[start:body])))
    return bytes(out)


def _find_chunk(data, start: int, end: int, typecode: int) -> tuple[int, int] | None:
    """``(offset of its contents, length)`` of the first chunk of ``typecode`` among the chunks
    from ``start`` to ``end`` of a 3dm (version 5 or later: 4-byte type code, 8-byte length;
    a short chunk, type code bit 31 set, holds a value instead of contents)."""
    at = start
    while at + 12 <= end:
        code, value = struct.unpack_from("<Iq", data, at)
        if code == typecode:
            return at + 12, value
        at += 12 + (0 if code & 0x80000000 else value)
    return None


def _index_runs(v2: np.ndarray, chain: np.ndarray, closed: bool):
    """:func:`~filletfold.export.paths.chain_runs` of the chain's 2D points, each run as the
    pattern vertices it passes (a run's points are rows of the chain's points)."""
    pts = np.ascontiguousarray(v2[chain])
    where: dict[bytes, int] = {}
    for i, row in enumerate(pts):
        where.setdefault(row.tobytes(), int(chain[i]))
    out = []
    for run, spline, run_closed in chain_runs(pts, closed):
        rows = np.ascontiguousarray(run, dtype=np.float64)
        out.append((np.array([where[r.tobytes()] for r in rows]), spline, run_closed))
    return out


def crease_runs(pattern: CreasePattern, layers=("MOUNTAIN", "VALLEY")):
    """The runs the 3dm files draw, per layer of :func:`~filletfold.export.paths.edge_layer_masks`.

    Parameters
    ----------
    pattern : CreasePattern
    layers : iterable of str
        Which of ``"CUT"``, ``"MOUNTAIN"``, ``"VALLEY"``.

    Returns
    -------
    dict of str to list of ((k,) int, bool, bool)
        Per layer, each run's pattern vertices, whether it is a smooth curve, and whether it is
        closed (a polyline back to its first vertex; a closed smooth run repeats its first).
    """
    masks = edge_layer_masks(pattern)
    out = {}
    for layer in layers:
        runs = []
        for chain, closed in edge_chains(pattern.edges, masks[layer]):
            runs += _index_runs(pattern.vertices_2d, chain, closed)
        out[layer] = runs
    return out


def _check(units: str, scale: float):
    rhino3dm = require_rhino3dm()
    check_units(units, unitless=True)
    return rhino3dm, check_scale(scale)


def pattern_3dm(pattern: CreasePattern, *, units: str = "", scale: float = 1.0) -> bytes:
    """The flat crease pattern as a Rhino ``.3dm`` file (see the module docstring).

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.surface.validate.validate_pattern`; its tabs, hinges
        and labels are drawn when present.
    units : str
        The model unit: ``""`` (none), ``"mm"``, ``"cm"``, ``"m"`` or ``"in"``.
    scale : float
        Model units per pattern length unit.

    Returns
    -------
    bytes
        Same input, same bytes.

    Raises
    ------
    ParameterError
        Without rhino3dm, for an unknown unit or a scale that is not a positive number.
    ExportError
        When the pattern is inconsistent.
    """
    rhino3dm, scale = _check(units, scale)
    validated_faces(pattern)
    return _pattern_3dm(rhino3dm, pattern, units, scale)


def pattern_paths(pattern: CreasePattern, scale: float = 1.0):
    """The runs ``pattern.3dm`` draws, in its order: ``(layer, points (k, 3), closed, spline)``
    for the ``CUT`` runs and the tabs' cut outlines, the ``MOUNTAIN`` and ``VALLEY`` runs and
    the ``TAB`` hinges, in the plane z = 0, times ``scale`` (the labels are not among them)."""
    v = np.c_[pattern.vertices_2d * scale, np.zeros(len(pattern.vertices_2d))]
    ann = pattern.annotations
    for layer, runs in crease_runs(pattern, ("CUT", "MOUNTAIN", "VALLEY")).items():
        for ids, spline, closed in runs:
            yield layer, v[ids], closed, spline
        if layer == "CUT":
            for pts, closed in tab_cut_paths(ann):
                p = np.asarray(pts, dtype=np.float64).reshape(-1, 2) * scale
                yield "CUT", np.c_[p, np.zeros(len(p))], closed, False
    for hinge in ann.tab_hinges:
        h = np.asarray(hinge, dtype=np.float64).reshape(2, 2) * scale
        yield "TAB", np.c_[h, np.zeros(2)], False, False
    for m in ann.making:  # a sheet material's reliefs and kerf grooves
        p = np.asarray(m.points, dtype=np.float64).reshape(-1, 2) * scale
        yield MAKING_LAYERS[m.kind], np.c_[p, np.zeros(len(p))], m.closed, False


def _pattern_3dm(rhino3dm, pattern: CreasePattern, units: str, scale: float) -> bytes:
    layers = dict(PATTERN_LAYERS)
    kinds = {m.kind for m in pattern.annotations.making}
    for kind, colour in MAKING_COLORS.items():  # only the layers a material's making draws
        if kind in kinds:
            layers[MAKING_LAYERS[kind]] = colour
    model = _Model(rhino3dm, "pattern.3dm", units, layers)
    ann = pattern.annotations
    for layer, points, closed, spline in pattern_paths(pattern, scale):
        model.add_path(points, closed, layer, spline)
    for label in ann.labels:
        x, y = (np.asarray(label.position, dtype=np.float64).reshape(2) * scale).tolist()
        at = rhino3dm.Point3d(x, y, 0.0)
        model.file.Objects.AddTextDot(str(label.text), at, model.attributes("LABEL", label.kind))
    return model.encode()


def folded_3dm(pattern: CreasePattern, *, units: str = "", scale: float = 1.0) -> bytes:
    """The folded form as a Rhino ``.3dm`` file: a mesh per patch, creases as curves.

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.surface.validate.validate_pattern`.
    units : str
        The model unit: ``""`` (none), ``"mm"``, ``"cm"``, ``"m"`` or ``"in"``.
    scale : float
        Model units per pattern length unit (the folded form is scaled as the pattern is).

    Returns
    -------
    bytes
        Same input, same bytes.

    Raises
    ------
    ParameterError
        Without rhino3dm, for an unknown unit or a scale that is not a positive number.
    ExportError
        When the pattern is inconsistent.
    """
    rhino3dm, scale = _check(units, scale)
    validated_faces(pattern)
    return _folded_3dm(rhino3dm, pattern, units, scale)


def _folded_3dm(rhino3dm, pattern: CreasePattern, units: str, scale: float) -> bytes:
    kinds = kinds_present(pattern.face_patch)
    layers = {kind_layer(k): PATCH_COLOR.get(k, (0.8, 0.8, 0.8)) for k in kinds}
    model = _Model(rhino3dm, "folded.3dm", units, {**layers, **FOLDED_CREASE_LAYERS})
    for name, mesh in patch_meshes(rhino3dm, pattern, scale):
        attr = model.attributes(kind_layer(patch_kind(name, "patch")), str(name))
        model.file.Objects.AddMesh(mesh, attr)
    v3 = pattern.vertices_3d * scale
    for layer, runs in crease_runs(pattern).items():
        for ids, spline, closed in runs:
            model.add_path(v3[ids], closed, layer, spline)
    return model.encode()


def patch_meshes(rhino3dm, pattern: CreasePattern, scale: float = 1.0):
    """The folded form's patches as ``rhino3dm`` meshes, as ``folded.3dm`` holds them:
    ``(patch name, Mesh)`` per patch in the order of their first face, with double-precision
    vertices times ``scale`` and Rhino's vertex normals; triangles and quads stay as they are
    (Rhino's mesh faces), larger polygons are split into triangles."""
    from .mesh3d import folded_triangles

    v3 = pattern.vertices_3d * scale
    patches = dict.fromkeys(pattern.face_patch)
    for k, name in enumerate(patches):
        patches[name] = k
    face_patch = np.fromiter(
        map(patches.__getitem__, pattern.face_patch), np.int64, len(pattern.face_patch)
    )
    flat, start = validated_faces(pattern)
    sizes = np.diff(start)
    tris, tri_face = folded_triangles(pattern)
    tris = tris[sizes[tri_face] > 4]
    tri_patch = face_patch[tri_face[sizes[tri_face] > 4]]
    small = np.flatnonzero(sizes <= 4)
    small = small[np.argsort(face_patch[small], kind="stable")]
    tri_order = np.argsort(tri_patch, kind="stable")
    tris, tri_patch = tris[tri_order], tri_patch[tri_order]
    n = len(patches)
    small_at = np.searchsorted(face_patch[small], np.arange(n + 1))
    tri_at = np.searchsorted(tri_patch, np.arange(n + 1))
    for k, name in enumerate(patches):
        corners = [flat[start[f] : start[f + 1]] for f in small[small_at[k] : small_at[k + 1]]]
        corners += list(tris[tri_at[k] : tri_at[k + 1]])
        used, local = np.unique(np.concatenate(corners), return_inverse=True)
        mesh = rhino3dm.Mesh()
        for x, y, z in v3[used].tolist():
            mesh.Vertices.AddPoint3d(x, y, z)  # double precision
        local = local.tolist()
        at = 0
        for c in corners:
            mesh.Faces.AddFace(*local[at : at + len(c)])
            at += len(c)
        mesh.Normals.ComputeNormals()
        yield name, mesh
