"""Which way is up: the axis a mesh stands on, for its pictures and the app's view.

A mesh file does not say which axis is up: scans and character models are mostly y-up (the
glTF convention, and most OBJ and PLY files), CAD parts and 3D-printing files z-up. A model is
usually made standing on its feet, so the up axis is taken to be the one of +x, +y, +z along
which the mesh, put down on its lowest side, stands: the centre of its surface's area lies
over its footprint (the convex hull of the points within :data:`FOOT` of its size of the
lowest one), and the farthest inside it (the widest margin) decides. When it stands on none of
the three, the file format's convention decides (:data:`CONVENTION`; z when unknown).

Of 19 public meshes whose up is clear from a picture (the common 3D test models, and the
corpus's scans from geometry-central, meshio, pymeshlab and pymeshfix: 14 y-up, 4 z-up, one
flat figure standing along y), it finds 17 standing and suzanne.obj, which stands on no side
(its chin), by the OBJ convention; woody.obj, the flat figure, it lays down (z).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import shapely

__all__ = ["AXES", "CONVENTION", "FOOT", "stand_margins", "up_axis"]

#: The axes a mesh may stand along, as written (``--up``).
AXES = ("x", "y", "z")
#: Points within this share of the mesh's size of its lowest point are its footprint.
FOOT = 0.02
#: The up axis of a file format by its suffix, for a mesh that stands on no side (z else).
CONVENTION = {".obj": "y", ".ply": "y", ".gltf": "y", ".glb": "y", ".stl": "z", ".off": "z"}


def stand_margins(vertices: np.ndarray, centres: np.ndarray, areas: np.ndarray) -> np.ndarray:
    """How well a mesh stands along +x, +y and +z: for each, the distance of the centre of
    its surface's area from the border of its footprint (over the size; negative: outside).

    Parameters
    ----------
    vertices : (n, 3) float
    centres : (f, 3) float
        Each face's centre.
    areas : (f,) float
        Each face's area.

    Returns
    -------
    (3,) float
        -inf where the mesh has no extent.
    """
    v = np.asarray(vertices, dtype=np.float64)
    out = np.full(3, -np.inf)
    size = float(np.ptp(v, axis=0).max(initial=0.0)) if len(v) else 0.0
    total = float(np.sum(areas))
    if not (size > 0 and total > 0):
        return out
    centre = (np.asarray(centres, dtype=np.float64) * np.asarray(areas)[:, None]).sum(0) / total
    for a in range(3):
        across = [b for b in range(3) if b != a]
        foot = v[v[:, a] <= v[:, a].min() + FOOT * size][:, across]
        hull = shapely.MultiPoint(foot).convex_hull
        at = shapely.Point(centre[across])
        if isinstance(hull, shapely.Polygon) and hull.contains(at):
            out[a] = hull.exterior.distance(at) / size
        else:
            out[a] = -hull.distance(at) / size
    return out


def up_axis(vertices, centres, areas, source: str = "") -> tuple[str, str]:
    """The up axis of a mesh (``"x"``, ``"y"`` or ``"z"``) and why.

    Parameters
    ----------
    vertices, centres, areas
        See :func:`stand_margins`.
    source : str
        The file the mesh came from (its suffix gives the convention), or a built-in name.

    Returns
    -------
    axis : str
    why : str
        ``"it stands on its -y side"``, or the convention used.
    """
    margin = stand_margins(vertices, centres, areas)
    best = max((2, 1, 0), key=lambda a: margin[a])  # z first on a tie
    if margin[best] > 0:
        return AXES[best], f"it stands on its -{AXES[best]} side"
    suffix = Path(source).suffix.lower()
    axis = CONVENTION.get(suffix, "z")
    kind = f"the {suffix[1:].upper()} convention" if suffix in CONVENTION else "the default"
    return axis, f"it stands on no side: {kind}"
