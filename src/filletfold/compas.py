"""COMPAS adapter: a COMPAS ``Mesh`` in, COMPAS meshes and polylines of the design out.

Needs the ``compas`` extra (``pip install 'filletfold[compas]'``, i.e. ``compas>=2``); COMPAS is
imported only when one of these functions runs, never by ``import filletfold``.

>>> from compas.datastructures import Mesh
>>> from filletfold.compas import compas_meshes, round_compas_mesh
>>> design = round_compas_mesh(Mesh.from_polyhedron(12), radius="10%")
>>> sorted(compas_meshes(design))
['cone', 'cylinder', 'face']

* :func:`mesh_from_compas` -- a COMPAS mesh as ``(vertices, faces)`` arrays (what
  :func:`~filletfold.design.round_mesh` takes; its vertices renumbered ``0..n-1`` in the order of
  COMPAS's vertex keys), :func:`mesh_to_compas` the way back;
* :func:`round_compas_mesh` -- :func:`~filletfold.design.round_mesh` of a COMPAS mesh;
* :func:`compas_meshes` -- the folded form, one COMPAS mesh per patch kind (``cone``,
  ``cylinder``, ``fillet``, ``face``), its faces the pattern's polygons with a ``"patch"``
  attribute (``"cone 3"``, as in ``design.fold``);
* :func:`compas_polylines` -- the crease pattern's edges chained into COMPAS polylines per
  assignment (``"M"``, ``"V"``, ``"B"``), flat (z = 0) or through the folded points.
"""

from __future__ import annotations

import numpy as np

from .errors import ParameterError

__all__ = [
    "compas_meshes",
    "compas_polylines",
    "mesh_from_compas",
    "mesh_to_compas",
    "round_compas_mesh",
]

#: The assignments :func:`compas_polylines` draws.
POLYLINE_ASSIGNMENTS = ("M", "V", "B")


def _compas():
    """``compas.datastructures.Mesh`` and ``compas.geometry.Polyline``, or a one-line error."""
    try:
        from compas.datastructures import Mesh
        from compas.geometry import Polyline
    except ImportError:
        raise ParameterError(
            "the COMPAS adapter needs compas: pip install 'filletfold[compas]'", name="mesh"
        ) from None
    return Mesh, Polyline


def mesh_from_compas(mesh) -> tuple[np.ndarray, list[np.ndarray]]:
    """The vertices and faces of a COMPAS mesh.

    Parameters
    ----------
    mesh : compas.datastructures.Mesh

    Returns
    -------
    vertices : (n, 3) float
        In the order of the mesh's vertex keys.
    faces : list of (k,) int
        In the order of its face keys, indices into ``vertices``.

    Raises
    ------
    ParameterError
        When ``mesh`` is not a COMPAS mesh, or compas is not installed.
    """
    Mesh, _ = _compas()
    if not isinstance(mesh, Mesh):
        raise ParameterError(
            f"mesh must be a compas.datastructures.Mesh, got {type(mesh).__name__}", name="mesh"
        )
    vertices, faces = mesh.to_vertices_and_faces()
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    return v, [np.asarray(f, dtype=np.int64) for f in faces]


def mesh_to_compas(mesh):
    """A COMPAS mesh of a filletfold mesh.

    Parameters
    ----------
    mesh : PolyMesh or (vertices, faces)
        E.g. ``design.mesh`` (the cleaned mesh the design was made from).

    Returns
    -------
    compas.datastructures.Mesh
        Vertex keys ``0..n-1`` in the order of ``vertices``, one face per face.
    """
    Mesh, _ = _compas()
    if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
        vertices, faces = mesh.vertices, mesh.faces
    else:
        vertices, faces = mesh
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    return Mesh.from_vertices_and_faces(v.tolist(), [np.asarray(f).tolist() for f in faces])


def round_compas_mesh(mesh, **options):
    """Round a COMPAS mesh: :func:`~filletfold.design.round_mesh` of :func:`mesh_from_compas`.

    Parameters
    ----------
    mesh : compas.datastructures.Mesh
    **options
        Keyword arguments of :func:`~filletfold.design.round_mesh` (``radius``, ``depth``,
        ``layout``, ...); indices in them (a radius per edge, a depth per vertex) refer to the
        cleaned mesh, ``design.mesh``.

    Returns
    -------
    Design
    """
    from .design import round_mesh

    return round_mesh(mesh_from_compas(mesh), **options)


def _pattern(design):
    """The crease pattern of a design (or a crease pattern itself)."""
    from .surface.pattern import CreasePattern

    pattern = getattr(design, "pattern", design)
    if not isinstance(pattern, CreasePattern):
        raise ParameterError(
            f"expected a Design or a CreasePattern, got {type(design).__name__}", name="design"
        )
    return pattern


def compas_meshes(design) -> dict:
    """The folded form as COMPAS meshes, one per patch kind.

    Parameters
    ----------
    design : Design or CreasePattern

    Returns
    -------
    dict of str to compas.datastructures.Mesh
        Patch kind (``"cone"``, ``"cylinder"``, ``"fillet"``, ``"face"``, those present) to the
        mesh of its faces: polygons as in the pattern (counter-clockwise from the front), folded
        (3D) vertices, each face's patch name in its ``"patch"`` attribute.
    """
    Mesh, _ = _compas()
    from .export.mesh3d import kinds_present
    from .surface.patch import patch_kind

    pattern = _pattern(design)
    kinds = [patch_kind(p, "patch") for p in pattern.face_patch]
    out = {}
    for kind in kinds_present(pattern.face_patch):
        ids = [i for i, k in enumerate(kinds) if k == kind]
        faces = [np.asarray(pattern.faces[i], dtype=np.int64) for i in ids]
        used, local = np.unique(np.concatenate(faces), return_inverse=True)
        sizes = np.cumsum([len(f) for f in faces])[:-1]
        mesh = Mesh.from_vertices_and_faces(
            pattern.vertices_3d[used].tolist(), [f.tolist() for f in np.split(local, sizes)]
        )
        for key, i in zip(mesh.faces(), ids, strict=True):
            mesh.face_attribute(key, "patch", str(pattern.face_patch[i]))
        out[kind] = mesh
    return out


def compas_polylines(design, folded: bool = False) -> dict:
    """The pattern's edges chained into COMPAS polylines, per assignment.

    Edges of one assignment are joined end to end through every vertex where exactly two of
    them meet (:func:`~filletfold.export.paths.edge_chains`, as in the cut files); a closed
    chain's polyline ends at its first point.

    Parameters
    ----------
    design : Design or CreasePattern
    folded : bool
        Through the folded (3D) points instead of the flat layout (z = 0).

    Returns
    -------
    dict of str to list of compas.geometry.Polyline
        ``"M"`` (mountain), ``"V"`` (valley) and ``"B"`` (borders and cuts).
    """
    _, Polyline = _compas()
    from .export.paths import edge_chains

    pattern = _pattern(design)
    if folded:
        points = pattern.vertices_3d
    else:
        points = np.c_[pattern.vertices_2d, np.zeros(len(pattern.vertices_2d))]
    assignment = np.asarray(pattern.edge_assignment)
    out = {}
    for code in POLYLINE_ASSIGNMENTS:
        lines = []
        for chain, closed in edge_chains(pattern.edges, assignment == code):
            ids = np.append(chain, chain[0]) if closed else chain
            lines.append(Polyline(points[ids].tolist()))
        out[code] = lines
    return out
