"""Wavefront OBJ export of the folded form, one group per surface patch."""

from __future__ import annotations

import re

import numpy as np

from ..surface.pattern import CreasePattern
from ..surface.validate import validated_faces
from ..tolerances import tol
from .fold import face_arrays, file_creator

__all__ = ["folded_obj", "obj_group_name", "vertex_normal_3d"]


def obj_group_name(patch: str) -> str:
    """OBJ group name of a patch: whitespace runs replaced by ``_`` (``"cone 3"`` -> ``cone_3``)."""
    name = re.sub(r"\s+", "_", patch.strip())
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
        nxt = np.arange(1, len(flat) + 1)
        nxt[start[1:] - 1] = start[:-1]
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

    Vertices are written in pattern order (``v x y z``, 3D positions). Faces are polygons as in
    the pattern (not triangulated), 1-based, grouped as ``g <patch>`` with one group per patch
    name: groups in order of the patch's first face, faces in pattern order within a group.

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.surface.validate.validate_pattern`.
    vertex_normals : bool
        Also write ``vn`` lines (see :func:`vertex_normal_3d`), one per vertex, referenced as
        ``f a//a b//b ...``.

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


def _xyz_lines(tag: str, xyz: np.ndarray) -> str:
    """``"<tag> x y z\\n"`` per row of ``xyz`` (n, 3), numbers with 12 significant digits
    (``-0`` written as ``0``)."""
    return (f"{tag} %.12g %.12g %.12g\n" * len(xyz)) % tuple((xyz + 0.0).ravel().tolist())


def _folded_obj(pattern: CreasePattern, faces, *, vertex_normals: bool = False) -> str:
    """:func:`folded_obj` of a pattern already checked (``faces`` from
    :func:`~filletfold.surface.validate.validated_faces`)."""
    v3 = pattern.vertices_3d
    flat, start = faces
    patches = dict.fromkeys(pattern.face_patch)  # in order of their first face
    head = (
        f"# {file_creator()}: folded form\n"
        f"# {len(v3)} vertices, {len(pattern.faces)} faces, {len(patches)} patches\n"
    )
    parts = [head, _xyz_lines("v", v3)]
    if vertex_normals:
        parts.append(_xyz_lines("vn", vertex_normal_3d(v3, pattern.faces)))
    # groups in order of their first face; faces in pattern order within a group
    group_id: dict[str, int] = {}
    for p, name in zip(patches, _group_names(list(patches)), strict=True):
        patches[p] = group_id.setdefault(name, len(group_id))
    group = np.fromiter(
        map(patches.__getitem__, pattern.face_patch), dtype=np.int64, count=len(pattern.face_patch)
    )
    order = np.argsort(group, kind="stable")
    size = np.diff(start)[order]
    first = np.concatenate([[0], np.cumsum(size)])
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
