"""The apex stage's result: what the vertices came to, for the surface and the layout."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..rounding.edges import EdgeRounding
from .batch import ApexWork
from .rescue import Rescue
from .solve import VertexResult


@dataclass
class VertexSolution:
    """The apex stage's result.

    Attributes
    ----------
    rounding : EdgeRounding
        The radii used (smaller where vertices were rescued, unrounded around sharp ones).
    centres : (n_faces, 3) float
    frames : list of VertexFrame
    classified : VertexResult
        The classification before any apex (of the frames as they are now).
    res : VertexResult
        The final per-vertex results.
    solved : list of (VertexFrame, apex or None, developed apex or None)
    kept : set of int
        The vertices whose results were taken over from an earlier design.
    rescue : Rescue
    cuts : dict
        The samples each vertex's solves added (:func:`~filletfold.vertex.solve.solve_apices`).
    needs : dict
        Each cone's sampling needs, measured here and used once by the module stage.
    ring_closed : list of bool
        Whether each vertex's ring is closed (kept apart: the layout reads it after the frames
        may be released).
    work : ApexWork
        The apex solver's work in this design (vertices taken over from an earlier design
        cost none).
    """

    rounding: EdgeRounding
    centres: np.ndarray
    frames: list | None
    classified: VertexResult | None
    res: VertexResult
    solved: list | None
    kept: set
    rescue: Rescue
    cuts: dict
    needs: dict
    ring_closed: list
    work: ApexWork = field(default_factory=ApexWork)
