"""Typed errors raised at filletfold's public boundary.

Every error a user can trigger derives from :class:`FilletfoldError`, so front ends catch one
type and print its message; nothing below it should surface as a traceback.
"""

from __future__ import annotations


class FilletfoldError(Exception):
    """Base class of every error filletfold raises on bad input or impossible requests."""


class MeshError(FilletfoldError):
    """The input mesh cannot be read or is not a valid polyhedral surface.

    Attributes
    ----------
    vertex, edge, face : int or tuple or None
        The element the error is about, when there is one (indices into the mesh as read).
    """

    def __init__(self, message: str, *, vertex=None, edge=None, face=None):
        super().__init__(message)
        self.vertex = vertex
        self.edge = edge
        self.face = face


class MeshReadError(MeshError):
    """The file is missing, unreadable, empty, or of an unsupported format."""


class ParameterError(FilletfoldError):
    """A parameter is out of its valid range (radius too large, negative depth, NaN...).

    Attributes
    ----------
    name : str
        The parameter's name as the user spelled it (``radius``, ``depth``...).
    edge : int or None
        The edge the value is about, for per-edge limits.
    """

    def __init__(self, message: str, *, name: str | None = None, edge: int | None = None):
        super().__init__(message)
        self.name = name
        self.edge = edge


class SolverError(FilletfoldError):
    """A numerical stage failed in a way that cannot be reported per vertex."""

    def __init__(self, message: str, *, vertex: int | None = None):
        super().__init__(message)
        self.vertex = vertex


class ExportError(FilletfoldError):
    """An output could not be written (nothing is left half-written when this is raised)."""
