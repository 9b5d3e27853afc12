"""Wavefront OBJ export of the folded form, one group per surface patch."""

from __future__ import annotations

import math
import re

import numpy as np

from ..arrays import run_next, run_starts
from ..surface.pattern import CreasePattern, FaceRows
from ..surface.validate import validated_faces
from ..tolerances import tol
from .fold import face_arrays, file_creator
from .svg import _format_all

__all__ = [
    "OBJ_RTOL",
    "WELD_RTOL",
    "folded_obj",
    "obj_group_name",
    "vertex_normal_3d",
    "weld_vertices",
]

#: Vertices closer than this share of the folded form's size are welded (OBJ, PLY and STL).
WELD_RTOL = 1e-9
#: Decimals of a vertex normal's components (at least).
_NORMAL_DECIMALS = 9
#: The OBJ's coordinates are written to this share of the folded form's size (bounding-box
#: diagonal), as fixed decimals: the weld tolerance; the folded form's own error (its chords'
#: 2D - 3D mismatch, the solvers' tolerances) is larger.
OBJ_RTOL = 1e-9


def obj_group_name(patch) -> str:
    """OBJ group name of a patch: whitespace runs replaced by ``_`` (``"cone 3"`` -> ``cone_3``)."""
    name = re.sub(r"\s+", "_", str(patch).strip())
    return name or "patch"


#: Whitespace next to the NUL that :func:`_group_names` puts between names.
_SPACE_AROUND_NUL = re.compile(r"\s*\0\s*")
_SPACES = re.compile(r"\s+")


def _group_names(patches: list[str]) -> list[str]:
    """:func:`obj_group_name` of every patch, all names in one text (NUL between them)."""
    joined = "\0".join(patches)
    if not patches or joined.count("\0") != len(patches) - 1:  # none, or a name with a NUL
        return list(map(obj_group_name, patches))
    names = _SPACES.sub("_", _SPACE_AROUND_NUL.sub("\0", joined).strip()).split("\0")
    return [name or "patch" for name in names]


def weld_vertices(points: np.ndarray, rtol: float = WELD_RTOL) -> tuple[np.ndarray, np.ndarray]:
    """Merge points that coincide up to ``rtol`` times the points' bounding-box diagonal.

    Parameters
    ----------
    points : (n, 3) float
    rtol : float

    Returns
    -------
    unique : (u, 3) float
        One point per group, the first of the group in input order, groups in order of their
        first point.
    inverse : (n,) int
        The group of each input point: ``unique[inverse]`` is within the tolerance of
        ``points``.
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(p) == 0:
        return p.copy(), np.zeros(0, dtype=np.int64)
    size = float(np.linalg.norm(np.ptp(p, axis=0)))
    step = rtol * size if size > 0 else 1.0
    key = np.round((p - p.min(axis=0)) / step).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")  # groups in order of their first point
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return p[first[order]], rank[inverse.ravel()]


def vertex_normal_3d(vertices_3d: np.ndarray, faces: list) -> np.ndarray:
    """Area-weighted vertex normals of the folded form.

    Parameters
    ----------
    vertices_3d : (n, 3) float
    faces : list of (k,) int

    Returns
    -------
    (n, 3) float
        Unit normals: the normalised sum of the (area-scaled) Newell normals of the incident
        faces; ``(0, 0, 1)`` for a vertex in no face or where the sum vanishes.
    """
    acc = np.zeros((len(vertices_3d), 3))
    if len(faces):
        flat, start = face_arrays(faces)
        flat = flat.astype(np.int64, copy=False)
        size = np.diff(start)
        p = vertices_3d[flat]
        p = p - np.repeat(np.add.reduceat(p, start[:-1], axis=0) / size[:, None], size, axis=0)
        nxt = run_next(start)
        area_normal = 0.5 * np.add.reduceat(np.cross(p, p[nxt]), start[:-1], axis=0)
        np.add.at(acc, flat, np.repeat(area_normal, size, axis=0))
    norm = np.linalg.norm(acc, axis=1)
    scale = norm.max() if len(norm) else 0.0
    ok = norm > tol.area * scale if scale > 0 else np.zeros(len(norm), dtype=bool)
    out = np.tile([0.0, 0.0, 1.0], (len(acc), 1))
    out[ok] = acc[ok] / norm[ok, None]
    return out


def folded_obj(pattern: CreasePattern, *, vertex_normals: bool = False) -> str:
    """The folded form as a Wavefront OBJ document.

    The pattern's vertices that fold onto one point (within :data:`WELD_RTOL` of the folded
    form's size: the two sides of every seam) are one OBJ vertex, so the surface is closed
    where the pieces are glued (a viewer shades it smooth across the seams) and each point is
    written once. Vertices are in order of their first pattern vertex (``v x y z``, 3D
    positions to :data:`OBJ_RTOL` of the size). Faces are polygons as in the pattern (not
    triangulated), 1-based, grouped as ``g <patch>`` with one group per patch name: groups in
    order of the patch's first face, faces in pattern order within a group.

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.surface.validate.validate_pattern`.
    vertex_normals : bool
        Also write ``vn`` lines (see :func:`vertex_normal_3d`, of the welded surface), one per
        vertex, referenced as ``f a//a b//b ...``.

    Returns
    -------
    str
        The OBJ text, ending with a newline. Same input, same bytes.

    Raises
    ------
    ExportError
        When the pattern is inconsistent.
    """
    return _folded_obj(pattern, validated_faces(pattern), vertex_normals=vertex_normals)


def obj_decimals(points: np.ndarray) -> int:
    """Decimals of the OBJ's coordinates: those that resolve :data:`OBJ_RTOL` of the points'
    bounding-box diagonal (at least 0; 12 for a single point or none)."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    size = float(np.linalg.norm(np.ptp(p, axis=0))) if len(p) else 0.0
    if not (size > 0 and math.isfinite(size)):
        return 12
    return max(0, math.ceil(-math.log10(OBJ_RTOL * size) - 1e-9))


def _xyz_lines(tag: str, xyz: np.ndarray, decimals: int) -> str:
    """``"<tag> x y z\\n"`` per row of ``xyz`` (n, 3), numbers with ``decimals`` fixed
    decimals, trailing zeros stripped (``-0`` written as ``0``), as the SVG writes its
    numbers (:func:`~filletfold.export.svg._format_all`)."""
    xyz = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
    cols = [_format_all(xyz[:, k], decimals) for k in range(3)]
    return "".join(f"{tag} {x} {y} {z}\n" for x, y, z in zip(*cols, strict=True))


def _folded_obj(pattern: CreasePattern, faces, *, vertex_normals: bool = False) -> str:
    """:func:`folded_obj` of a pattern already checked (``faces`` from
    :func:`~filletfold.surface.validate.validated_faces`)."""
    flat, start = faces
    v3, inverse = weld_vertices(pattern.vertices_3d)
    flat = inverse[flat]
    patches = dict.fromkeys(pattern.face_patch)  # in order of their first face
    head = (
        f"# {file_creator()}: folded form\n"
        f"# {len(v3)} vertices, {len(pattern.faces)} faces, {len(patches)} patches\n"
    )
    decimals = obj_decimals(v3)
    parts = [head, _xyz_lines("v", v3, decimals)]
    if vertex_normals:
        normals = vertex_normal_3d(v3, FaceRows(flat, start))
        parts.append(_xyz_lines("vn", normals, max(decimals, _NORMAL_DECIMALS)))
    # groups in order of their first face; faces in pattern order within a group
    group_id: dict[str, int] = {}
    for p, name in zip(patches, _group_names(list(map(str, patches))), strict=True):
        patches[p] = group_id.setdefault(name, len(group_id))
    group = np.fromiter(
        map(patches.__getitem__, pattern.face_patch), dtype=np.int64, count=len(pattern.face_patch)
    )
    order = np.argsort(group, kind="stable")
    size = np.diff(start)[order]
    first = run_starts(size)
    corner = np.repeat(start[:-1][order] - first[:-1], size) + np.arange(first[-1])
    ids = flat[corner] + 1
    if vertex_normals:
        ids = np.repeat(ids, 2)
    spec = " %d//%d" if vertex_normals else " %d"
    face_line = {k: "f" + spec * k + "\n" for k in set(size.tolist())}
    lines = [face_line[k] for k in size.tolist()]
    ends = np.flatnonzero(np.diff(group[order], append=len(group_id))).tolist()
    template = [
        "g " + name.replace("%", "%%") + "\n" + "".join(lines[a + 1 : b + 1])
        for name, a, b in zip(group_id, [-1, *ends[:-1]], ends, strict=True)
    ]
    parts.append("".join(template) % tuple(ids.tolist()))
    return "".join(parts)
