"""Face piece centres: the point of each face that every straight crease on it stays short of."""

from __future__ import annotations

import numpy as np
import shapely

from ..arrays import run_owners
from ..errors import MeshError
from ..mesh.polymesh import PolyMesh
from ..rounding.edges import EdgeRounding
from ..tolerances import tol


def face_piece_centres(
    mesh: PolyMesh, rounding: EdgeRounding, sharp: np.ndarray | None = None
) -> np.ndarray:
    """Centre of every flat face piece, from which the whole piece is visible.

    The face piece of a face is bounded by the tangent lines of its edges (the edge itself for a
    boundary or flat edge); its corners are the crossing points T. Each vertex's share of the
    piece is cut off by straight segments from the edge midpoints to this centre, so the centre
    must see the whole piece: it is the centroid of the piece's kernel (the piece itself when
    convex).

    A rounded edge with one ``sharp`` end is a conical fillet (its radius grows from 0 at the
    sharp end, through the cylinder's at the midpoint, to twice that at the other end): its
    line on the face runs from the sharp vertex through the midpoint's tangent point, so
    beside the other end it reaches twice as far into the face as a cylinder's tangent line
    (a thin face beside a sharp vertex: a centre taken for the cylinder lay beyond the fillet,
    and the face share of the vertex at the wide end crossed itself).

    Parameters
    ----------
    mesh : PolyMesh
    rounding : EdgeRounding
    sharp : (n_vertices,) bool, optional
        The sharp vertices (none when not given).

    Returns
    -------
    centre : (n_faces, 3) float

    Raises
    ------
    MeshError
        If a face piece is not star-shaped (no point sees all of it).
    """
    half = 0.5 * rounding.strip_width
    start = np.asarray(mesh.face_start)
    face_of = run_owners(np.diff(start))
    nxt = np.arange(len(face_of)) + 1
    nxt[start[1:] - 1] = start[:-1]  # the half-edge after the last one of a face is its first
    p = mesh.vertices[mesh.halfedge_from]
    u = p[nxt] - p
    u /= np.linalg.norm(u, axis=1)[:, None]
    n = mesh.face_normal[face_of]
    base = p + half[mesh.halfedge_edge][:, None] * np.cross(n, u)  # a point of each tangent line
    # face coordinates: origin at the first corner, e1 along the first edge
    origin = p[start[:-1]]
    e1 = u[start[:-1]]
    e2 = np.cross(mesh.face_normal, e1)
    frame = (start, face_of, nxt, mesh.halfedge_prev, origin, e1, e2)
    centre, starred = _centres(base, u, frame)
    if sharp is not None:  # conical fillets: the line from the sharp end through the midpoint's
        e = mesh.halfedge_edge
        a, b = sharp[mesh.halfedge_from], sharp[mesh.halfedge_to]
        cone = (a != b) & (rounding.radius[e] > 0) & (half[e] > 0)
        if cone.any():
            mid = 0.5 * (p[cone] + p[nxt][cone]) + half[e[cone], None] * np.cross(n[cone], u[cone])
            tip = np.where(a[cone, None], p[cone], p[nxt][cone])  # the sharp end
            line = np.where(a[cone, None], mid - tip, tip - mid)  # from the half-edge's start
            base, u = base.copy(), u.copy()
            base[cone] = mid
            u[cone] = line / np.linalg.norm(line, axis=1)[:, None]
            coned, ok = _centres(base, u, frame)
            # where the conical lines leave no point that sees the whole piece, the tangent
            # lines' centre stays (as before the sharp vertices were known)
            centre = np.where(ok[:, None], coned, centre)
            starred |= ok
    if not starred.all():
        fi = int(np.flatnonzero(~starred)[0])
        raise MeshError(
            f"face {fi} is not star-shaped after rounding: no point of it sees the whole "
            "face piece; split it into convex polygons or use a smaller radius",
            face=fi,
        )
    return origin + centre[:, :1] * e1 + centre[:, 1:] * e2


def _centres(base: np.ndarray, u: np.ndarray, frame) -> tuple[np.ndarray, np.ndarray]:
    """Each face piece's centre (face coordinates, (n_faces, 2)) for the lines through
    ``base`` along ``u`` (one per half-edge), and whether it is star-shaped ((n_faces,) bool;
    where not, the centre is meaningless)."""
    start, face_of, nxt, prev, origin, e1, e2 = frame
    # corner of half-edge h: the lines of the previous half-edge and of h cross at T
    delta = base - base[prev]
    cos = np.einsum("ij,ij->i", u[prev], u)
    sin2 = 1 - cos**2
    parallel = sin2 < 1e-24  # a straight corner between unrounded edges: T is the corner
    z = (np.einsum("ij,ij->i", u[prev], delta) - cos * np.einsum("ij,ij->i", u, delta)) / (
        np.where(parallel, 1.0, sin2)
    )
    T = np.where(parallel[:, None], base, base[prev] + z[:, None] * u[prev])
    rel = T - origin[face_of]
    xy = np.stack(
        [np.einsum("ij,ij->i", rel, e1[face_of]), np.einsum("ij,ij->i", rel, e2[face_of])], axis=1
    )
    # convex pieces: the polygon centroid (shoelace); the others: the kernel's centroid
    x, y = xy[:, 0], xy[:, 1]
    xn, yn = x[nxt], y[nxt]
    cross = x * yn - xn * y
    area = np.add.reduceat(cross, start[:-1]) / 2
    cx = np.add.reduceat((x + xn) * cross, start[:-1]) / (6 * np.where(area != 0, area, 1))
    cy = np.add.reduceat((y + yn) * cross, start[:-1]) / (6 * np.where(area != 0, area, 1))
    d = xy[nxt] - xy
    turn = d[:, 0] * d[nxt][:, 1] - d[:, 1] * d[nxt][:, 0]
    convex = (np.minimum.reduceat(turn, start[:-1]) >= 0) & (area > 0)
    centre = np.stack([cx, cy], axis=1)
    starred = convex.copy()
    for fi in np.nonzero(~convex)[0]:
        c = _kernel_centroid(xy[start[fi] : start[fi + 1]])
        if c is not None:
            centre[fi], starred[fi] = c, True
    return centre, starred


def _kernel_centroid(xy: np.ndarray) -> np.ndarray | None:
    """Centroid of the kernel of a counter-clockwise polygon (k, 2), or None if it is empty.

    (Convex pieces do not come here: :func:`face_piece_centres` takes their centroid.)
    """
    poly = shapely.Polygon(xy)
    size = float(np.ptp(xy, axis=0).max()) * 4 + 1.0
    kernel = poly if poly.is_valid else shapely.convex_hull(poly)
    for a, b in zip(xy, np.roll(xy, -1, axis=0), strict=True):
        t = b - a
        nrm = np.array([-t[1], t[0]]) / np.linalg.norm(t) * size  # left of a -> b is inside
        t = t / np.linalg.norm(t) * size
        half = shapely.Polygon([a - t, b + t, b + t + nrm, a - t + nrm])
        kernel = kernel.intersection(half)
    if kernel.is_empty or kernel.area <= tol.roundoff * poly.area:
        return None
    c = kernel.centroid
    return np.array([c.x, c.y])
