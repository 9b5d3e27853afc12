"""The typed errors of :mod:`filletfold.errors`: one-line messages, stages named in unforeseen
failures, the caller's own exceptions passed through, and errors naming their element."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import filletfold
from filletfold import errors
from filletfold.errors import (
    ExportError,
    FilletfoldError,
    InternalError,
    MeshError,
    MeshReadError,
    ParameterError,
    SolverError,
    callers_progress,
    is_callers,
    named_stages,
    one_line,
)

TETRA = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
TETRA_FACES = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]


# ---------------------------------------------------------------- one_line


@settings(max_examples=100, deadline=None)
@given(st.text(), st.integers(10, 400))
def test_one_line_is_one_line_within_its_limit(message, limit):
    out = one_line(ValueError(message), limit)
    assert "\n" not in out and "\r" not in out
    assert len(out) <= limit
    assert out.startswith("ValueError"[: limit - 3])


@settings(max_examples=100, deadline=None)
@given(st.text(st.characters(blacklist_categories=("Cc", "Zl", "Zp", "Zs")), min_size=1))
def test_one_line_keeps_a_short_first_line_whole(first):
    exc = RuntimeError(first + "\nsecond line\nthird line")
    out = one_line(exc, limit=10_000)
    assert out == f"RuntimeError: {first}"


def test_one_line_cuts_at_the_limit():
    exc = KeyError("x" * 50)
    whole = one_line(exc, limit=1000)
    assert one_line(exc, limit=len(whole)) == whole  # exactly at the limit: whole
    cut = one_line(exc, limit=len(whole) - 1)
    assert len(cut) == len(whole) - 1 and cut.endswith("...")
    assert whole.startswith(cut[:-3])
    assert len(one_line(ValueError("y" * 1000))) == 300  # the default limit


def test_one_line_of_an_empty_message_is_the_type():
    assert one_line(ValueError()) == "ValueError"
    assert one_line(ValueError("  \n  ")) == "ValueError"
    assert one_line(MeshError("\n  face 3 is bad\n more")) == "MeshError: face 3 is bad"


# ---------------------------------------------------------------- named_stages


@named_stages("first stage")
def pipeline(fail_at: str | None, exc: BaseException):
    if fail_at == "first stage":
        raise exc
    errors.stage("second stage")
    if fail_at == "second stage":
        raise exc
    return "done"


@pytest.mark.parametrize("where", ["first stage", "second stage"])
def test_an_unforeseen_failure_names_its_stage(where):
    original = ZeroDivisionError("division by zero\nin a deep place")
    with pytest.raises(InternalError) as info:
        pipeline(where, original)
    err = info.value
    assert isinstance(err, FilletfoldError)
    assert err.stage == where and err.element is None
    assert str(err).startswith(f"{where} failed: ZeroDivisionError: division by zero")
    assert "\n" not in str(err) and "--debug" in str(err)
    assert err.__cause__ is original


@pytest.mark.parametrize(
    "exc", [ParameterError("radius must be positive", name="radius"), MeshError("face 2")]
)
def test_filletfold_errors_pass_through_unchanged(exc):
    with pytest.raises(type(exc)) as info:
        pipeline("second stage", exc)
    assert info.value is exc


def test_base_exceptions_pass_through_unchanged():
    exc = KeyboardInterrupt()
    with pytest.raises(KeyboardInterrupt) as info:
        pipeline("first stage", exc)
    assert info.value is exc


def test_the_stage_is_restored_after_a_call():
    assert pipeline(None, ValueError()) == "done"

    @named_stages("outer")
    def outer():
        pipeline(None, ValueError())  # sets its own stages, then restores "outer"
        raise TypeError("after the inner call")

    with pytest.raises(InternalError) as info:
        outer()
    assert info.value.stage == "outer"


def test_named_stages_keeps_the_function_name_and_result():
    @named_stages("x")
    def documented(a, b=2):
        """Docs."""
        return a + b

    assert documented.__name__ == "documented" and documented.__doc__ == "Docs."
    assert documented(1, b=5) == 6


# ---------------------------------------------------------------- the caller's exceptions


def test_callers_progress_marks_what_the_callback_raises():
    assert callers_progress(None) is None
    seen = []
    wrapped = callers_progress(lambda *args: seen.append(args) or "returned")
    assert wrapped("stage", 1, 2) == "returned" and seen == [("stage", 1, 2)]

    class Stop(Exception):
        pass

    def stop(*args):
        raise Stop("the user pressed stop")

    with pytest.raises(Stop) as info:
        callers_progress(stop)("stage", 0, 1)
    assert is_callers(info.value)
    assert not is_callers(Stop("raised elsewhere")) and not is_callers(ValueError())


def test_the_callers_exception_passes_through_named_stages():
    class Stop(Exception):
        pass

    def stop(*args):
        raise Stop

    progress = callers_progress(stop)

    @named_stages("solving")
    def compute():
        progress("solving", 0, 10)

    with pytest.raises(Stop):  # not an InternalError
        compute()


def test_round_mesh_lets_the_progress_callbacks_exception_through():
    class Stop(Exception):
        pass

    calls = []

    def progress(stage, done, total):
        calls.append(stage)
        raise Stop(stage)

    with pytest.raises(Stop):
        filletfold.round_mesh("cube", progress=progress)
    assert len(calls) == 1


# ---------------------------------------------------------------- the error classes


def test_the_error_classes_and_their_elements():
    for cls in (MeshError, MeshReadError, ParameterError, SolverError, ExportError):
        assert issubclass(cls, FilletfoldError) and str(cls("the message")) == "the message"
    assert issubclass(MeshReadError, MeshError)
    mesh = MeshError("m", vertex=3, edge=(1, 2), face=4)
    assert (mesh.vertex, mesh.edge, mesh.face) == (3, (1, 2), 4)
    bare = MeshReadError("r")
    assert (bare.vertex, bare.edge, bare.face) == (None, None, None)
    param = ParameterError("p", name="depth", edge=7)
    assert (param.name, param.edge) == ("depth", 7)
    assert ParameterError("p").name is None and SolverError("s").vertex is None
    assert SolverError("s", vertex=5).vertex == 5
    internal = InternalError("i", stage="layout", element="vertex 2")
    assert (internal.stage, internal.element) == ("layout", "vertex 2")


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"radius": -1.0}, "radius"),
        ({"depth": float("nan")}, "depth"),
        ({"samples": 2}, "samples"),
        ({"layout": "bogus"}, "layout"),
        ({"sheet": "A9"}, "sheet"),
    ],
)
def test_a_parameter_error_names_the_parameter(kwargs, name):
    with pytest.raises(ParameterError) as info:
        filletfold.round_mesh("cube", **kwargs)
    assert info.value.name == name
    assert name in str(info.value) and "\n" not in str(info.value)


def test_a_per_edge_limit_names_the_edge():
    with pytest.raises(ParameterError) as info:
        filletfold.round_mesh("cube", radius="80%", clamp=False)
    err = info.value
    assert err.name == "radius" and err.edge is not None
    assert f"edge {err.edge}" in str(err)


def test_a_mesh_error_names_the_face_or_edge():
    bad_index = [*TETRA_FACES[:3], [1, 2, 7]]
    with pytest.raises(MeshError) as info:
        filletfold.load_mesh((TETRA, bad_index), strict=True)
    assert info.value.face == 3 and "face 3" in str(info.value)

    fin = np.vstack([TETRA, [[1.0, 1.0, 1.0]]])
    with pytest.raises(MeshError) as info:
        filletfold.load_mesh((fin, [*TETRA_FACES, [0, 1, 4]]), strict=True)
    edge = info.value.edge
    assert edge is not None and str(tuple(edge)) in str(info.value)


def test_a_read_error_names_the_file(tmp_path):
    path = tmp_path / "broken.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nf 1 2 3 x\n")
    with pytest.raises(MeshReadError) as info:
        filletfold.load_mesh(str(path))
    assert str(path) in str(info.value) and "\n" not in str(info.value)
