"""Typed errors raised at filletfold's public boundary.

Every error a user can trigger derives from :class:`FilletfoldError`, so front ends catch one
type and print its message; nothing below it should surface as a traceback.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools


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


class InternalError(FilletfoldError):
    """A stage of the pipeline failed in a way no check foresaw (a bug, or an input that
    defeats a geometric library): the message names the stage and, where known, the element;
    the original exception is its ``__cause__`` (the command line shows it with ``--debug``).

    Attributes
    ----------
    stage : str
    element : str or None
        ``"vertex 12"``, ``"face 3"``, ...
    """

    def __init__(self, message: str, *, stage: str, element: str | None = None):
        super().__init__(message)
        self.stage = stage
        self.element = element


def one_line(exc: BaseException, limit: int = 300) -> str:
    """``Type: message`` of an exception on one line (its first line, cut at ``limit``)."""
    text = str(exc).strip().splitlines()
    first = text[0] if text else ""
    out = f"{type(exc).__name__}: {first}" if first else type(exc).__name__
    return out if len(out) <= limit else out[: limit - 3] + "..."


#: The stage of the pipeline running now, for the message of an unforeseen failure.
_STAGE: contextvars.ContextVar = contextvars.ContextVar("filletfold_stage", default="design")


#: Who is told of each new stage (:func:`watching_stages`), or None.
_WATCH: contextvars.ContextVar = contextvars.ContextVar("filletfold_stage_watch", default=None)


def stage(name: str) -> None:
    """Say which stage of the pipeline runs from here on; the memory the stages before freed
    goes back to the system first (:func:`filletfold.memory.release_memory`)."""
    from .memory import release_memory

    release_memory()
    _STAGE.set(name)
    watch = _WATCH.get()
    if watch is not None:
        watch(name)


@contextlib.contextmanager
def watching_stages(callback):
    """Within the block, ``callback(name)`` is called whenever a stage begins
    (:func:`stage`): a front end's log of the pipeline."""
    token = _WATCH.set(callback)
    try:
        yield
    finally:
        _WATCH.reset(token)


def named_stages(first: str):
    """Decorate a pipeline function: an exception that is not a :class:`FilletfoldError`
    becomes an :class:`InternalError` naming the stage it happened in (see :func:`stage`),
    with the original as its cause."""

    def decorate(func):
        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            token = _STAGE.set(first)
            try:
                return func(*args, **kwargs)
            except FilletfoldError:
                raise
            except Exception as exc:  # anything else is a failure no check foresaw
                if is_callers(exc):
                    raise
                stage = _STAGE.get()
                raise InternalError(
                    f"{stage} failed: {one_line(exc)} (run with --debug for the traceback)",
                    stage=stage,
                ) from exc
            finally:
                _STAGE.reset(token)

        return wrapper

    return decorate


def callers_progress(progress):
    """``progress`` wrapped so that what it raises (a front end stopping a computation) is
    marked as the caller's own and passes through :func:`named_stages` unchanged."""
    if progress is None:
        return None

    def call(*args):
        try:
            return progress(*args)
        except Exception as exc:
            exc._filletfold_callers = True
            raise

    return call


def is_callers(exc: BaseException) -> bool:
    """Whether ``exc`` came from the caller's progress callback (:func:`callers_progress`)."""
    return bool(getattr(exc, "_filletfold_callers", False))
