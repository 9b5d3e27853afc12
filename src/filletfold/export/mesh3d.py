"""The folded form as a triangle mesh: glTF binary (GLB), PLY and STL, written through trimesh.

* ``folded.glb`` -- a glTF 2.0 scene with one mesh (and one node) per patch kind present
  (``cone``, ``cylinder``, ``fillet``, ``face``, in that order), each with its own PBR material
  named after the kind and coloured as in the preview picture
  (:data:`~filletfold.export.png.PATCH_COLOR`), double sided, not metallic. Vertices are split
  between patches, so each patch is shaded smooth (area-weighted vertex normals of its own
  faces) and the creases between patches stay sharp. glTF is y-up: the design's z axis is
  written as +y (``(x, y, z) -> (x, z, -y)``, a rotation, so faces keep their winding).
* ``folded.ply`` -- binary PLY of the whole folded surface, vertices welded where they coincide
  (the two sides of a seam become one vertex), one colour per face (its patch kind's).
* ``folded.stl`` -- binary STL of the same welded triangles (STL has no colour).

PLY and STL keep the design's own axes (z up), as ``folded.obj`` does.
Polygons are triangulated in the flat layout, where they are simple and counter-clockwise
(:func:`~filletfold.surface.triangulate.triangulate_faces`); every triangle is front-facing in
3D as its polygon is. Same pattern, same bytes.

Size: as in ``folded.3dm``, one pattern unit is ``scale`` drawing units of ``units``
(:func:`length_factor`). PLY and STL coordinates are the design's times ``scale``, in
``units``; the PLY names its unit in a header comment (``comment units mm``; none when
unitless), STL cannot. glTF lengths are metres by its specification, so with a unit the GLB
holds the true size in metres (the design's times ``scale`` times the unit in metres:
``--units mm --scale 200`` multiplies by 0.2); unitless, the design's times ``scale``, one
drawing unit read as one metre. Welding and normals are computed before scaling, so they do
not depend on it.
"""

from __future__ import annotations

import io

import numpy as np

from ..surface.patch import patch_kind
from ..surface.pattern import CreasePattern, FaceRows
from ..surface.triangulate import triangulate_faces
from ..surface.validate import validated_faces
from ..units import MM_PER_UNIT, check_units
from .dxf import check_scale
from .obj import vertex_normal_3d, weld_vertices
from .png import PATCH_COLOR

__all__ = [
    "KIND_ORDER",
    "folded_glb",
    "folded_ply",
    "folded_stl",
    "folded_triangles",
    "length_factor",
    "weld_vertices",
]

#: Patch kinds in the order their meshes are written (others follow, sorted by name).
KIND_ORDER = ("cone", "cylinder", "fillet", "face")
#: Colour (RGB, 0..1) of a patch of a kind :data:`PATCH_COLOR` does not know.
_OTHER_COLOR = (0.8, 0.8, 0.8)
#: glTF is y-up: the design's (x, y, z) is written as (x, z, -y).
Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
#: Millimetres per glTF length unit (the metre, by the glTF 2.0 specification).
GLTF_MM_PER_UNIT = 1000.0


def length_factor(units: str = "", scale: float = 1.0, *, gltf: bool = False) -> float:
    """What the design's coordinates are multiplied by in a 3D file.

    Parameters
    ----------
    units : str
        The drawing unit: ``""`` (unitless), ``"mm"``, ``"cm"``, ``"m"`` or ``"in"``.
    scale : float
        Drawing units per pattern length unit (positive).
    gltf : bool
        For glTF, whose unit is the metre: with ``units``, convert the drawing units to metres.

    Returns
    -------
    float
        ``scale``; for glTF with a unit, ``scale * MM_PER_UNIT[units] / 1000`` (``"mm"``,
        ``200`` -> ``0.2``).

    Raises
    ------
    ParameterError
        For an unknown unit or a scale that is not a positive number.
    """
    check_units(units, unitless=True)
    scale = check_scale(scale)
    if gltf and units:
        return scale * (MM_PER_UNIT[units] / GLTF_MM_PER_UNIT)
    return scale


def kinds_present(face_patch) -> list[str]:
    """The patch kinds of ``face_patch`` (a list of patch names), in :data:`KIND_ORDER`, then
    any others sorted by name."""
    kinds = {patch_kind(p, "patch") for p in dict.fromkeys(face_patch)}
    return [k for k in KIND_ORDER if k in kinds] + sorted(kinds - set(KIND_ORDER))


def folded_triangles(pattern: CreasePattern) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of the pattern's faces (their corners are pattern vertices).

    Parameters
    ----------
    pattern : CreasePattern

    Returns
    -------
    triangles : (t, 3) int
        Counter-clockwise in 2D, so front-facing in 3D; a face of ``k`` corners gives
        ``k - 2`` triangles.
    face : (t,) int
        The face each triangle comes from (non-decreasing).
    """
    return triangulate_faces(pattern.vertices_2d, pattern.faces)


def _kind_meshes(pattern: CreasePattern) -> list[tuple[str, np.ndarray, np.ndarray, np.ndarray]]:
    """Per patch kind present: ``(kind, vertices (u, 3), triangles (t, 3), normals (u, 3))``
    with the vertices split between patches (one copy of a pattern vertex per patch)."""
    tris, face = folded_triangles(pattern)
    patches = dict.fromkeys(pattern.face_patch)
    for k, name in enumerate(patches):
        patches[name] = k
    face_patch = np.fromiter(
        map(patches.__getitem__, pattern.face_patch), np.int64, len(pattern.face_patch)
    )
    patch_kinds = np.array([patch_kind(p, "patch") for p in patches] or [""])
    tri_kind = patch_kinds[face_patch[face]] if len(face) else np.zeros(0, dtype=str)
    n = len(pattern.vertices_3d)
    out = []
    for kind in kinds_present(pattern.face_patch):
        sel = np.flatnonzero(tri_kind == kind)
        t = tris[sel]
        key = face_patch[face[sel]][:, None] * n + t  # one vertex per (patch, pattern vertex)
        uniq, local = np.unique(key.ravel(), return_inverse=True)
        v = pattern.vertices_3d[uniq % n]
        local = local.reshape(-1, 3)
        normals = vertex_normal_3d(v, FaceRows.of_sizes(local.ravel(), np.full(len(local), 3)))
        out.append((kind, v, local, normals))
    return out


def _rgba(kind: str) -> list[int]:
    """The colour of a patch kind as RGBA bytes."""
    rgb = PATCH_COLOR.get(kind, _OTHER_COLOR)
    return [round(255 * c) for c in rgb] + [255]


def folded_glb(pattern: CreasePattern, *, units: str = "", scale: float = 1.0) -> bytes:
    """The folded form as a glTF 2.0 binary file (see the module docstring).

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.surface.validate.validate_pattern`.
    units : str
        The drawing unit: ``""`` (unitless), ``"mm"``, ``"cm"``, ``"m"`` or ``"in"``; with a
        unit the coordinates are converted to metres, glTF's unit.
    scale : float
        Drawing units per pattern length unit.

    Returns
    -------
    bytes
        The GLB, coordinates the design's times :func:`length_factor` ``(units, scale,
        gltf=True)``; same input, same bytes.

    Raises
    ------
    ParameterError
        For an unknown unit or a scale that is not a positive number.
    ExportError
        When the pattern is inconsistent.
    """
    factor = length_factor(units, scale, gltf=True)
    validated_faces(pattern)
    return _folded_glb(pattern, factor)


def _folded_glb(pattern: CreasePattern, factor: float = 1.0) -> bytes:
    """:func:`folded_glb` of a pattern already checked, coordinates times ``factor``."""
    import trimesh
    from trimesh.exchange.gltf import export_glb
    from trimesh.visual.material import PBRMaterial

    scene = trimesh.Scene()
    for kind, v, t, normals in _kind_meshes(pattern):
        material = PBRMaterial(
            name=kind,
            baseColorFactor=_rgba(kind),
            metallicFactor=0.0,
            roughnessFactor=0.8,
            doubleSided=True,
        )
        mesh = trimesh.Trimesh(
            vertices=(v * factor) @ Y_UP.T,
            faces=t,
            vertex_normals=normals @ Y_UP.T,
            visual=trimesh.visual.TextureVisuals(material=material),
            process=False,
        )
        scene.add_geometry(mesh, geom_name=kind, node_name=kind)
    return export_glb(scene, include_normals=True)


def _welded(pattern: CreasePattern, factor: float = 1.0):
    """The folded surface as one trimesh, vertices welded (:func:`weld_vertices`) and then
    multiplied by ``factor``, one face colour per patch kind."""
    import trimesh

    tris, face = folded_triangles(pattern)
    v, inverse = weld_vertices(pattern.vertices_3d)
    colours = np.array([_rgba(patch_kind(p, "patch")) for p in pattern.face_patch], dtype=np.uint8)
    return trimesh.Trimesh(
        vertices=v * factor,
        faces=inverse[tris].reshape(-1, 3),
        face_colors=colours[face].reshape(-1, 4),
        process=False,
    )


def folded_ply(pattern: CreasePattern, *, units: str = "", scale: float = 1.0) -> bytes:
    """The folded form as a binary PLY (welded vertices, a colour per face).

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.surface.validate.validate_pattern`.
    units : str
        The drawing unit, ``""`` (unitless), ``"mm"``, ``"cm"``, ``"m"`` or ``"in"``: named in
        a header comment (``comment units mm``) unless unitless.
    scale : float
        Drawing units per pattern length unit: the coordinates are the design's times it.

    Returns
    -------
    bytes
        Same input, same bytes.

    Raises
    ------
    ParameterError
        For an unknown unit or a scale that is not a positive number.
    ExportError
        When the pattern is inconsistent.
    """
    factor = length_factor(units, scale)
    validated_faces(pattern)
    return _folded_ply(pattern, units, factor)


def _folded_ply(pattern: CreasePattern, units: str = "", factor: float = 1.0) -> bytes:
    """:func:`folded_ply` of a pattern already checked, coordinates times ``factor``."""
    from trimesh.exchange.ply import export_ply

    data = export_ply(_welded(pattern, factor), encoding="binary", include_attributes=False)
    if not units:
        return data
    # a comment may stand anywhere in the header after the format line
    at = data.index(b"\n", data.index(b"\nformat ") + 1) + 1
    return data[:at] + f"comment units {units}\n".encode("ascii") + data[at:]


def folded_stl(pattern: CreasePattern, *, scale: float = 1.0) -> bytes:
    """The folded form as a binary STL (the welded triangles of :func:`folded_ply`).

    Parameters
    ----------
    pattern : CreasePattern
        Checked with :func:`~filletfold.surface.validate.validate_pattern`.
    scale : float
        Drawing units per pattern length unit: the coordinates are the design's times it (STL
        has no field for the unit).

    Returns
    -------
    bytes
        Same input, same bytes.

    Raises
    ------
    ParameterError
        For a scale that is not a positive number.
    ExportError
        When the pattern is inconsistent.
    """
    factor = length_factor("", scale)
    validated_faces(pattern)
    return _folded_stl(pattern, factor)


def _folded_stl(pattern: CreasePattern, factor: float = 1.0) -> bytes:
    """:func:`folded_stl` of a pattern already checked, coordinates times ``factor``."""
    from trimesh.exchange.stl import export_stl

    buffer = io.BytesIO(export_stl(_welded(pattern, factor)))
    return buffer.getvalue()
