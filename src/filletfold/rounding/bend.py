"""A sheet material's bend floor on the fillets: no cylinder tighter than the material bends.

A material (:mod:`filletfold.materials`) bends no tighter than its least inner radius; on the
design's surface (the sheet's middle) that is the *bend floor*
(:meth:`~filletfold.materials.Material.bend_floor_mm`). A fillet's radius is a length of the
mesh, the floor one of the sheet: they meet at the design's size (millimetres per mesh unit).

* :func:`hold_floor` raises the fillets below the floor to it, as far as each edge's limit
  (:func:`~filletfold.rounding.edges.radius_limits`) allows, and names the edges it cannot;
* :func:`least_size_factor` is how much larger the design must be drawn for every fillet to
  hold the floor (the error's "least size");
* :func:`floor_size` is the least size (mm) at which the fillets as they are hold it;
* :func:`share_floor_size` the least size at which all but the tightest
  :data:`CREASE_SHARE` of the fillets' length hold it: the default size grows to it
  (:func:`~filletfold.layout.arrange.default_size`) and the fillets still under the floor
  there, whose limits do not let them be raised to it, become creases. Growing the size
  for the tightest fillet alone gave a 1,148-vertex beetle scan in card 230 m across.
"""

from __future__ import annotations

import numpy as np

from ..mesh.polymesh import PolyMesh
from .edges import edge_dihedral, shrink_broken

__all__ = ["CREASE_SHARE", "floor_size", "hold_floor", "least_size_factor", "share_floor_size"]

#: Relative round-off allowed below the floor (a raised radius may come back a few ulps short).
FLOOR_RTOL = 1e-9
#: At the default size, the share of the fillets' length (the tightest first) that may become
#: creases instead of making the object larger: public scans in card at the size it gives
#: (beetle 880 mm, cow 590 mm, spot 430 mm, suzanne 200 mm) against 79 m, 121 m, 0.9 m and
#: 2.2 m for every fillet.
CREASE_SHARE = 0.1


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


def share_floor_size(
    extent: float, floor_mm: float, radius: np.ndarray, length: np.ndarray,
    share: float = CREASE_SHARE,
) -> float | None:  # fmt: skip
    """The least size (mm, of the largest side ``extent`` mesh units) at which the rounded
    edges holding all but ``share`` of the rounded length (the tightest left out) are at
    least ``floor_mm``; None without a rounded edge or without a floor.

    Parameters
    ----------
    extent : float
    floor_mm : float
    radius : (n_edges,) float
        Mesh units (0: not rounded).
    length : (n_edges,) float
        The edges' lengths.
    share : float
        In ``[0, 1)``; 0 gives :func:`floor_size`.
    """
    r = np.asarray(radius, dtype=float)
    rounded = r > 0
    if not rounded.any() or floor_mm <= 0 or not extent > 0:
        return None
    r, w = r[rounded], np.asarray(length, dtype=float)[rounded]
    order = np.argsort(r, kind="stable")
    left = np.cumsum(w[order]) - w[order]  # the length tighter than each edge
    k = int(np.searchsorted(left, share * w.sum(), side="right")) - 1
    return float(extent * floor_mm / r[order][max(k, 0)])
