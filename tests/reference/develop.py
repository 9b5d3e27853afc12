"""Flat development of a polyhedral surface (unfolding across edges, breadth first)."""

from __future__ import annotations

import numpy as np

from filletfold.errors import MeshError
from filletfold.mesh.polymesh import PolyMesh
from filletfold.vertex.frame import face_frame, to_chart


def develop_faces(mesh: PolyMesh, *, check: bool = True, rtol: float = 1e-9) -> list[np.ndarray]:
    """Unfold every face into one plane, gluing neighbours along shared edges.

    Parameters
    ----------
    mesh : PolyMesh
        A connected surface; for a consistent result it must be developable (angle sum 2 pi at
        every interior vertex) and simply connected.
    check : bool
        Verify that every shared edge, and every vertex, lands at one place.
    rtol : float
        Tolerance of that check, relative to the mean edge length.

    Returns
    -------
    list of (k, 2) float
        The 2D corners of each face, in face order (counter-clockwise).

    Raises
    ------
    MeshError
        When ``check`` and the faces do not fit together (the surface is not developable), or
        the surface is not connected.
    """
    placed: dict[int, np.ndarray] = {}
    # face 0 in its own chart
    frame = face_frame(mesh, 0, mesh.vertices[mesh.faces[0][0]])
    placed[0] = to_chart(frame, mesh.vertices[mesh.faces[0]])
    queue = [0]
    while queue:
        f = queue.pop(0)
        face = mesh.faces[f]
        for j in range(len(face)):
            a, b = int(face[j]), int(face[(j + 1) % len(face)])
            g = int(mesh.halfedge_face[mesh.halfedge(b, a)]) if mesh.halfedge(b, a) >= 0 else -1
            if g < 0 or g in placed:
                continue
            # chart of g, then the rigid motion that puts its edge (b, a) on f's edge (a, b)
            gf = mesh.faces[g]
            fr = face_frame(mesh, g, mesh.vertices[gf[0]])
            local = to_chart(fr, mesh.vertices[gf])
            ia, ib = int(np.nonzero(gf == a)[0][0]), int(np.nonzero(gf == b)[0][0])
            pa, pb = placed[f][j], placed[f][(j + 1) % len(face)]
            qa, qb = local[ia], local[ib]
            ang = np.arctan2(*(pb - pa)[::-1]) - np.arctan2(*(qb - qa)[::-1])
            rot = np.array([[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]])
            placed[g] = (local - qa) @ rot.T + pa
            queue.append(g)
    if len(placed) != mesh.n_faces:
        raise MeshError("the surface is not connected: it has no single development")
    out = [placed[f] for f in range(mesh.n_faces)]
    if check:
        tol = rtol * mesh.mean_edge_length
        pos: dict[int, np.ndarray] = {}
        for f, face in enumerate(mesh.faces):
            for k, vtx in enumerate(face):
                p = out[f][k]
                if int(vtx) in pos and np.linalg.norm(pos[int(vtx)] - p) > tol:
                    raise MeshError(
                        f"the surface is not developable: vertex {int(vtx)} unfolds to two "
                        f"places {np.linalg.norm(pos[int(vtx)] - p):.3g} apart",
                        vertex=int(vtx),
                    )
                pos.setdefault(int(vtx), p)
    return out
