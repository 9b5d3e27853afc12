"""Wavefront OBJ export of the folded form, one group per surface patch."""

from __future__ import annotations

import re

import numpy as np

from ..pattern import CreasePattern
from ..tolerances import tol
from .fold import file_creator, validate_pattern

__all__ = ["folded_obj", "obj_group_name", "vertex_normal_3d"]


def obj_group_name(patch: str) -> str:
    """OBJ group name of a patch: whitespace runs replaced by ``_`` (``"cone 3"`` -> ``cone_3``)."""
    name = re.sub(r"\s+", "_", patch.strip())
    return name or "patch"


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
    for f in faces:
        idx = np.asarray(f, dtype=np.int64)
        p = vertices_3d[idx]
        p = p - p.mean(axis=0)
        area_normal = 0.5 * np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0)
        np.add.at(acc, idx, area_normal)
    norm = np.linalg.norm(acc, axis=1)
    scale = norm.max() if len(norm) else 0.0
    ok = norm > tol.area * scale if scale > 0 else np.zeros(len(norm), dtype=bool)
    out = np.tile([0.0, 0.0, 1.0], (len(acc), 1))
    out[ok] = acc[ok] / norm[ok, None]
    return out


def _num(x: float) -> str:
    """12 significant digits, ``-0`` written as ``0``."""
    s = f"{x:.12g}"
    return "0" if s in ("-0", "0") else s


def folded_obj(pattern: CreasePattern, *, vertex_normals: bool = False) -> str:
    """The folded form as a Wavefront OBJ document.

    Vertices are written in pattern order (``v x y z``, 3D positions). Faces are polygons as in
    the pattern (not triangulated), 1-based, grouped as ``g <patch>`` with one group per patch
    name: groups in order of the patch's first face, faces in pattern order within a group.

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.export.fold.validate_pattern`.
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
    validate_pattern(pattern)
    v3 = pattern.vertices_3d
    lines = [
        f"# {file_creator()}: folded form",
        f"# {len(v3)} vertices, {len(pattern.faces)} faces, {len(set(pattern.face_patch))} patches",
    ]
    lines.extend(f"v {_num(a)} {_num(b)} {_num(c)}" for a, b, c in v3)
    if vertex_normals:
        vn = vertex_normal_3d(v3, pattern.faces)
        lines.extend(f"vn {_num(a)} {_num(b)} {_num(c)}" for a, b, c in vn)

    groups: dict[str, list[int]] = {}
    for i, patch in enumerate(pattern.face_patch):
        groups.setdefault(obj_group_name(patch), []).append(i)
    for name, face_ids in groups.items():
        lines.append(f"g {name}")
        for i in face_ids:
            ids = [int(k) + 1 for k in pattern.faces[i]]
            if vertex_normals:
                lines.append("f " + " ".join(f"{k}//{k}" for k in ids))
            else:
                lines.append("f " + " ".join(str(k) for k in ids))
    return "\n".join(lines) + "\n"
