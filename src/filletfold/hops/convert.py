"""Rhino geometry into and out of filletfold for the Hops components (needs ``rhino3dm``).

Nothing here computes geometry: :func:`mesh_from_rhino` reads a ``rhino3dm.Mesh`` into a
:class:`~filletfold.mesh.polymesh.PolyMesh` (the library cleans it as any input), and
:func:`round_outputs` and :func:`pattern_outputs` turn a :class:`~filletfold.design.Design`
into ``rhino3dm`` objects with :mod:`filletfold.export.rhino` -- the same patch meshes and
curves as ``folded.3dm`` and ``pattern.3dm``.

A Rhino mesh holds its polygons (n-gons, ``Mesh.Ngons``) as an overlay on triangles and quads;
``rhino3dm`` (8.x) reads the triangles and quads and does not give the n-gons, so an n-gon
arrives as its triangles, which the library's cleaning merges back into one polygon (coplanar
neighbours within ``coplanar_deg``, as for any input): a planar n-gon gives the design of the
polygon.
"""

from __future__ import annotations

import numpy as np

from ..errors import MeshReadError
from ..export.mesh3d import KIND_ORDER
from ..export.rhino import MAKING_LAYERS, crease_runs, patch_meshes, path_curve, pattern_paths
from ..mesh.polymesh import PolyMesh
from ..surface.patch import patch_kind

__all__ = ["KIND_ORDER", "branch", "mesh_from_rhino", "pattern_outputs", "round_outputs"]


def branch(k: int) -> str:
    """The Grasshopper path of branch ``k`` of a tree: ``{k}``."""
    return f"{{{k}}}"


def mesh_from_rhino(obj, name: str = "Mesh") -> PolyMesh:
    """The polygons of a decoded ``rhino3dm.Mesh`` (double-precision vertices where it has
    them) as a :class:`PolyMesh`: a triangle of Rhino's (its last two corners the same) has
    three corners, a quad four.

    Raises
    ------
    MeshReadError
        Naming the input ``name``: not a mesh (or not decodable), no faces, a face with a
        corner outside the vertices, or a coordinate that is not finite.
    """
    import rhino3dm

    if not isinstance(obj, rhino3dm.Mesh):
        what = "nothing decodable" if obj is None else type(obj).__name__
        raise MeshReadError(f"{name}: expected a Rhino mesh, got {what}")
    points = obj.Vertices.ToPoint3dArray()
    vertices = np.array([(p.X, p.Y, p.Z) for p in points], dtype=np.float64).reshape(-1, 3)
    n = len(vertices)
    faces = []
    for f in range(len(obj.Faces)):
        a, b, c, d = obj.Faces[f]
        corners = (a, b, c) if c == d else (a, b, c, d)
        bad = [i for i in corners if not 0 <= i < n]
        if bad:
            raise MeshReadError(
                f"{name}: face {f} uses vertex {bad[0]}, the mesh has {n} vertices", face=f
            )
        faces.append(np.array(corners, dtype=np.int64))
    if not faces:
        raise MeshReadError(f"{name}: the mesh has no faces")
    finite = np.isfinite(vertices).all(axis=1)
    if not finite.all():
        v = int(np.flatnonzero(~finite)[0])
        raise MeshReadError(f"{name}: vertex {v} has a coordinate that is not a number", vertex=v)
    return PolyMesh(vertices, faces)


def _curves(r, runs) -> list:
    return [path_curve(r, points, closed, spline) for points, closed, spline in runs]


def round_outputs(design) -> dict:
    """The *Round* component's outputs of ``design``, in the mesh's own units.

    Returns
    -------
    dict
        ``folded``: a tree, one branch per patch kind (``{0}`` cones, ``{1}`` cylinders,
        ``{2}`` conical fillets, ``{3}`` face pieces: :data:`KIND_ORDER`), a mesh per patch;
        ``names``: the same tree of the patches' names (``"cone 3"``, as in ``design.fold``);
        ``mountain``, ``valley``: the folded creases, one curve per run; ``pattern``: the flat
        layout (z = 0) as a tree, ``{0}`` cuts, ``{1}`` mountain, ``{2}`` valley creases;
        ``status``: each mesh vertex's status; ``summary``: the design's summary.
    """
    import rhino3dm as r

    pattern = design.pattern
    folded: dict = {}
    names: dict = {}
    for name, mesh in patch_meshes(r, pattern):
        kind = patch_kind(name, "patch")
        k = KIND_ORDER.index(kind) if kind in KIND_ORDER else len(KIND_ORDER)
        folded.setdefault(branch(k), []).append(mesh)
        names.setdefault(branch(k), []).append(str(name))
    order = sorted(folded, key=lambda key: int(key[1:-1]))
    v3 = pattern.vertices_3d
    v2 = np.c_[pattern.vertices_2d, np.zeros(len(pattern.vertices_2d))]
    runs = crease_runs(pattern, ("CUT", "MOUNTAIN", "VALLEY"))  # chained once, drawn twice
    flat = {
        branch(k): _curves(r, ((v2[i], c, s) for i, s, c in runs[layer]))
        for k, layer in enumerate(("CUT", "MOUNTAIN", "VALLEY"))
    }  # the layout has no tabs: pattern_paths' CUT, MOUNTAIN and VALLEY runs
    return {
        "folded": {key: folded[key] for key in order},
        "names": {key: names[key] for key in order},
        "mountain": _curves(r, ((v3[i], c, s) for i, s, c in runs["MOUNTAIN"])),
        "valley": _curves(r, ((v3[i], c, s) for i, s, c in runs["VALLEY"])),
        "pattern": flat,
        "status": list(design.vertices.status),
        "summary": design.summary(),
    }


def pattern_outputs(design) -> dict:
    """The *Pattern* component's outputs of ``design``: what ``pattern.3dm`` holds, in the
    drawing's units (``design.params.units``, every coordinate times ``design.params.scale``).

    Returns
    -------
    dict
        ``cut``, ``mountain``, ``valley``, ``tab`` (the tab hinges): curves of the layers of
        ``pattern.3dm`` (``CUT`` with the tabs' cut outlines); ``relief``, ``kerf_front``,
        ``kerf_back``: a sheet material's reliefs and grooves (empty without one that is
        relieved or kerfed); ``sheets``: each sheet's outline,
        a closed polyline (none without sheets); ``label_points`` and ``labels``: where each
        label is and its text; ``units``: the drawing unit (``""``: none); ``summary``.
    """
    import rhino3dm as r

    p = design.params
    scale = float(p.scale or 1.0)
    layers: dict = {
        name: [] for name in ("CUT", "MOUNTAIN", "VALLEY", "TAB", *MAKING_LAYERS.values())
    }
    for layer, points, closed, spline in pattern_paths(design.pattern, scale):
        layers[layer].append(path_curve(r, points, closed, spline))
    ann = design.pattern.annotations
    sheets = []
    for x0, y0, x1, y1 in (np.asarray(ann.sheets, dtype=float).reshape(-1, 4) * scale).tolist():
        corners = np.array([[x0, y0, 0], [x1, y0, 0], [x1, y1, 0], [x0, y1, 0]], dtype=float)
        sheets.append(path_curve(r, corners, True, False))
    label_points, labels = [], []
    for label in ann.labels:
        x, y = (np.asarray(label.position, dtype=np.float64).reshape(2) * scale).tolist()
        label_points.append(r.Point3d(x, y, 0.0))
        labels.append(str(label.text))
    return {
        "cut": layers["CUT"],
        "mountain": layers["MOUNTAIN"],
        "valley": layers["VALLEY"],
        "tab": layers["TAB"],
        "relief": layers["RELIEF"],
        "kerf_front": layers["KERF_FRONT"],
        "kerf_back": layers["KERF_BACK"],
        "sheets": sheets,
        "label_points": label_points,
        "labels": labels,
        "units": p.units or "",
        "summary": design.summary(),
    }
