"""The vertices' state that the apex stage, the rescue and the sharp vertices share.

The apex stage of the pipeline solves every vertex's apex, then the rescue
(:func:`~filletfold.vertex.rescue.rescue_vertices`) shrinks the radii around infeasible
vertices and the sharp vertices (:func:`~filletfold.vertex.sharpen.sharpen_vertices`) unround
the edges between cone-less ones; both classify and solve the affected vertices again. They
read and update the same things -- the rounding, the face piece centres, the frames, the
results, the apices -- which :class:`VertexState` holds, instead of a dozen arguments each.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..mesh.polymesh import PolyMesh
from ..rounding.edges import EdgeRounding, round_edges, shrink_broken
from .batch import ApexWork
from .solve import VertexResult


@dataclass
class VertexState:
    """The vertices of one design while their apices are found; updated in place.

    Attributes
    ----------
    mesh : PolyMesh
    rounding : EdgeRounding
        The current radii (the rescue and the sharp vertices replace it).
    centres : (n_faces, 3) float
        The face piece centres of ``rounding``.
    frames : list of VertexFrame
        By vertex; the frames of vertices classified again are replaced in place (the old
        one freed at once: a scan's frames take hundreds of MB).
    res : VertexResult
        The per-vertex results.
    depths : (n_vertices,) float
    face_centres : callable
        ``face_centres(mesh, rounding, sharp) -> (n_faces, 3)``
        (:func:`~filletfold.surface.centres.face_piece_centres`, given by the pipeline: this
        room comes before the surface's).
    flat_deg, floor, min_width : float
        What :func:`~filletfold.rounding.edges.round_edges` takes: the coplanar tolerance,
        and the narrowest fillet kept, relative and absolute.
    size : float
        The mesh's size (:func:`~filletfold.mesh.polymesh.mesh_size`).
    classified : VertexResult or None
        The classification before any apex (what a later design reuses): updated alike at
        the vertices classified again.
    apices : dict
        Vertex -> (apex, developed apex) of the cones solved
        (:func:`~filletfold.vertex.solve.solve_apices`).
    cuts : dict
        The samples each vertex's solves added: a vertex solved again starts with its own.
    progress : callable or None
        ``progress(stage, done, total)``.
    work : ApexWork
        The apex solver's work over every solve of this state (counts).
    bend_floor : float
        The sheet material's bend floor (mesh units; 0: none): :meth:`reround` makes a fillet
        under it a crease (radius 0), so no change of radii (the rescue's halvings) leaves one.
    """

    mesh: PolyMesh
    rounding: EdgeRounding
    centres: np.ndarray
    frames: list
    res: VertexResult
    depths: np.ndarray
    face_centres: Callable
    flat_deg: float
    floor: float
    min_width: float
    size: float
    classified: VertexResult | None = None
    apices: dict = field(default_factory=dict)
    cuts: dict = field(default_factory=dict)
    progress: Any = None
    work: ApexWork = field(default_factory=ApexWork)
    bend_floor: float = 0.0

    def sharp_frames(self) -> np.ndarray:
        """(n_vertices,) bool: the vertices whose frames are built sharp."""
        return np.array([f.sharp for f in self.frames], dtype=bool)

    def reround(
        self, radius: np.ndarray, sharp: np.ndarray | None = None
    ) -> tuple[np.ndarray, EdgeRounding, np.ndarray]:
        """The rounding of new radii and its face piece centres (the state unchanged).

        Parameters
        ----------
        radius : (n_edges,) float
        sharp : (n_vertices,) bool, optional
            The sharp vertices, whose edges to cones are conical fillets (default: the
            vertices whose frames are built sharp).

        Returns
        -------
        radius : (n_edges,) float
            ``radius`` with the radii that would break an obtuse corner shrunk
            (:func:`~filletfold.rounding.edges.shrink_broken`).
        rounding : EdgeRounding
        centres : (n_faces, 3) float
        """
        mesh = self.mesh
        radius = shrink_broken(mesh, radius, self.rounding.half_angle)
        if self.bend_floor > 0:  # a fillet the sheet cannot bend is a crease
            radius = np.where(radius < self.bend_floor * (1 - 1e-9), 0.0, radius)
        rounding = round_edges(
            mesh, radius, flat_deg=self.flat_deg, floor=self.floor, min_width=self.min_width
        )
        if sharp is None and self.frames:
            sharp = self.sharp_frames()
        return radius, rounding, self.face_centres(mesh, rounding, sharp)
