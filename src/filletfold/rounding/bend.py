"""A sheet material's bend floor on the fillets: no cylinder tighter than the material bends.

A material (:mod:`filletfold.materials`) bends no tighter than its least inner radius; on the
design's surface (the sheet's middle) that is the *bend floor*
(:meth:`~filletfold.materials.Material.bend_floor_mm`). A fillet's radius is a length of the
mesh, the floor one of the sheet: they meet at the design's size (millimetres per mesh unit).

* :func:`hold_floor` raises the fillets below the floor to it, as far as each edge's limit
  (:func:`~filletfold.rounding.edges.radius_limits`) allows, and names the edges it cannot;
* :func:`least_size_factor` is how much larger the design must be drawn for every fillet to
  hold the floor (the error's "least size");
* :func:`floor_size` is the least size (mm) at which the fillets as they are hold it: the
  default size grows to it (:func:`~filletfold.layout.arrange.default_size`).
"""

from __future__ import annotations

import numpy as np

from ..mesh.polymesh import PolyMesh
from .edges import edge_dihedral, shrink_broken

__all__ = ["floor_size", "hold_floor", "least_size_factor"]

#: Relative round-off allowed below the floor (a raised radius may come back a few ulps short).
FLOOR_RTOL = 1e-9


def hold_floor(
    mesh: PolyMesh, radius: np.ndarray, floor: float, *, share: float = 0.9
) -> tuple[np.ndarray, np.ndarray]:
    """Every rounded edge's radius raised to at least ``floor`` (mesh units) where its limit
    allows.

    Parameters
    ----------
    mesh : PolyMesh
    radius : (n_edges,) float
        Fitted radii (0: an edge not rounded, which stays so).
    floor : float
    share : float
        Of an edge's limit a radius may use (as :func:`~filletfold.rounding.edges.clamp_radii`).

    Returns
    -------
    radius : (n_edges,) float
    short : (n_edges,) bool
        Rounded edges that stay below the floor: their limit is below it.
    """
    r = np.asarray(radius, dtype=float)
    rounded = r > 0
    raised = np.where(rounded & (r < floor), floor, r)
    gamma, _ = edge_dihedral(mesh)
    fitted = shrink_broken(mesh, raised, gamma, share=share)
    short = rounded & (fitted < floor * (1 - FLOOR_RTOL))
    return fitted, short


def least_size_factor(
    mesh: PolyMesh, radius: np.ndarray, floor: float, *, share: float = 0.9
) -> float:
    """The least factor ``k >= 1`` by which the design must be drawn larger for every rounded
    edge to hold ``floor`` (mesh units at the present size): at ``k`` times the size the
    floor is ``floor / k`` mesh units. Found by doubling then bisection on
    :func:`hold_floor` (a few dozen evaluations)."""

    def holds(k: float) -> bool:
        return not hold_floor(mesh, radius, floor / k, share=share)[1].any()

    lo, hi = 1.0, 2.0
    if holds(lo):
        return 1.0
    while not holds(hi):
        lo, hi = hi, 2 * hi
        if hi > 1e12:
            return float("inf")
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if holds(mid) else (mid, hi)
        if hi - lo < 1e-4 * hi:
            break
    return hi


def floor_size(extent: float, floor_mm: float, radius: np.ndarray) -> float | None:
    """The least size (mm, of the largest side ``extent`` mesh units) at which every rounded
    edge of radius ``radius`` (mesh units) is at least ``floor_mm``; None without a rounded
    edge or without a floor."""
    r = np.asarray(radius, dtype=float)
    r = r[r > 0]
    if not len(r) or floor_mm <= 0 or not extent > 0:
        return None
    return float(extent * floor_mm / r.min())
