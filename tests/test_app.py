"""The browser app: its GUI-free session, its scene arrays, and the server answering HTTP."""

from __future__ import annotations

import io
import json
import socket
import time
import urllib.request
import zipfile

import numpy as np
import pytest
from numpy.testing import assert_allclose

from filletfold.app import session as session_mod
from filletfold.app.session import AppSession, nearest_vertex_to_ray
from filletfold.app.view import scene_arrays, triangulate_polygon
from filletfold.cli import main
from filletfold.errors import MeshReadError, ParameterError

TETRA_OBJ = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
ZIP_NAMES = {"design.fold", "report.json", "folded.obj", "pattern.svg", "pattern.dxf"}


@pytest.fixture(scope="module")
def cube_session():
    s = AppSession()
    s.load("cube")
    return s


def test_load_example_and_recompute():
    s = AppSession()
    design = s.load("cube")
    assert s.name == "cube" and s.design is design and s.design_id == 1
    assert design.status_counts()["ok"] == 8
    s.set_params(radius="5%", samples=8)
    again = s.recompute()
    assert again is s.design and s.design_id == 2
    assert again.params.radius == "5%" and again.params.samples == 8


def test_older_request_never_replaces_a_newer_result():
    s = AppSession()
    s.load("cube")
    old = s.begin()  # e.g. a slow compute started before the user moved the slider again
    s.set_params(radius="5%")
    new = s.begin()
    assert new.id > old.id
    assert s.commit(new, s.compute(new))
    newest = s.design
    assert not s.commit(old, s.compute(old))  # finishes last, is dropped
    assert s.design is newest and s.design_id == new.id
    assert s.design.params.radius == "5%"


def test_bad_upload_keeps_the_design_and_reports_the_readers_error():
    s = AppSession()
    design = s.load("cube")
    with pytest.raises(MeshReadError, match=r"bad\.obj: line 1: vertex needs 3 coordinates"):
        s.load("bad.obj", b"v 1 2\nf 1 2 3\n")
    assert s.design is design and s.name == "cube"
    with pytest.raises(MeshReadError, match=r"mesh\.txt: unsupported file type"):
        s.load("mesh.txt", TETRA_OBJ)
    with pytest.raises(MeshReadError, match="no built-in example"):
        s.load("no-such-example")
    assert s.design is design


def test_upload_over_the_size_cap_is_refused(monkeypatch):
    monkeypatch.setattr(session_mod, "UPLOAD_LIMIT_BYTES", 64)
    s = AppSession()
    design = s.load("cube")
    with pytest.raises(MeshReadError, match=r"big\.obj: the file is .* MB; the app accepts"):
        s.load("big.obj", TETRA_OBJ + b"# padding\n" * 10)
    assert s.design is design


def test_upload_cap_is_50_mb():
    assert session_mod.UPLOAD_LIMIT_BYTES == 50 * 1024 * 1024


def test_good_upload_replaces_mesh_and_clears_vertex_depths():
    s = AppSession()
    s.load("cube")
    s.set_vertex_depth(5, 0.2)
    design = s.load("tetra.obj", TETRA_OBJ)
    assert s.name == "tetra.obj" and design.source == "tetra.obj"
    assert len(design.mesh.vertices) == 4 and s.vertex_depth == {}


def test_failed_recompute_keeps_the_design(cube_session):
    s = AppSession()
    design = s.load("cube")
    s.set_params(samples=2)
    with pytest.raises(ParameterError, match="samples"):
        s.recompute()
    assert s.design is design


def test_parameter_and_vertex_validation(cube_session):
    with pytest.raises(ParameterError, match="unknown parameter 'colour'"):
        cube_session.set_params(colour=1)
    with pytest.raises(ParameterError, match=r"vertex 8 does not exist \(0\.\.7\)"):
        cube_session.set_vertex_depth(8, 0.1)
    with pytest.raises(ParameterError, match="vertex -1 does not exist"):
        cube_session.vertex_info(-1)
    with pytest.raises(ParameterError, match="no design"):
        AppSession().vertex_info(0)


def test_vertex_depth_changes_only_that_vertex():
    s = AppSession()
    s.load("cube")
    s.set_vertex_depth(3, 0.2)
    s.recompute()
    report = s.design.report()
    assert report["vertices"][3]["depth_requested"] == pytest.approx(0.2)
    default = report["vertices"][0]["depth_requested"]
    assert default == pytest.approx(0.3)  # 30% of the unit cube's edges
    info = s.vertex_info(3)
    assert info["depth_requested"] == pytest.approx(0.2) and info["override"] == 0.2
    assert info["status"] == "ok" and len(info["normal"]) == 3 and len(info["apex"]) == 3
    assert info["margin"] is not None
    s.set_vertex_depth(3, None)
    s.recompute()
    assert s.vertex_info(3)["depth_requested"] == pytest.approx(default)
    json.dumps(info)  # plain values only


def test_export_zip_holds_the_files_and_they_parse(cube_session):
    data = cube_session.export_zip()
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        names = set(zf.namelist())
        assert ZIP_NAMES <= names
        fold = json.loads(zf.read("design.fold"))
        report = json.loads(zf.read("report.json"))
        obj = zf.read("folded.obj").decode()
        svg = zf.read("pattern.svg").decode()
        dxf = zf.read("pattern.dxf").decode()
    assert fold["file_spec"] == 1.2 and len(fold["vertices_coords"]) > 0
    assert report["status_counts"]["ok"] == 8 and report["source"] == "cube"
    assert "\nv " in obj and "\nf " in obj
    assert svg.lstrip().startswith("<") and "<svg" in svg
    assert "SECTION" in dxf and "EOF" in dxf


def test_nearest_vertex_to_ray():
    points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    assert nearest_vertex_to_ray(points, (1, 0, 5), (0, 0, -1)) == 1
    assert nearest_vertex_to_ray(points, (0, 1.1, -5), (0, 0, 2)) == 2
    assert nearest_vertex_to_ray(np.zeros((0, 3)), (0, 0, 0), (1, 0, 0)) == -1


def _area(p):
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


@pytest.mark.parametrize(
    "poly",
    [
        [[0, 0], [1, 0], [1, 1], [0, 1]],
        [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]],  # L shape, not convex
        [[0, 0], [3, 0], [3, 3], [2, 1], [1, 1], [0, 3]],
    ],
)
def test_triangulation_covers_the_polygon(poly):
    p = np.array(poly, dtype=float)
    tris = triangulate_polygon(p)
    assert tris.shape == (len(p) - 2, 3)
    areas = [_area(p[t]) for t in tris]
    assert min(areas) > 0
    assert_allclose(sum(areas), _area(p), rtol=1e-12)


def test_scene_arrays_match_the_pattern(cube_session):
    design = cube_session.design
    arrays = scene_arrays(design)
    n_tri = sum(len(f) - 2 for f in design.pattern.faces)
    assert sum(len(t) for _, t in arrays.folded.values()) == n_tri
    assert set(arrays.folded) == {"cone", "cylinder", "face"}
    for kind, (v, t) in arrays.flat.items():
        assert t.max() < len(v)
        assert_allclose(v[:, 2], v[0, 2], atol=0)  # the pattern lies flat
        assert v[:, 0].min() > design.pattern.vertices_3d[:, 0].max()  # beside the model
        assert len(arrays.folded[kind][0]) == len(v)
    assert arrays.folded_creases["M"].shape[1:] == (2, 3)
    assert arrays.vertex_points.shape == (8, 3) and arrays.vertex_colors.shape == (8, 3)


def test_cli_app_with_unknown_mesh_exits_2(capsys):
    assert main(["app", "no-such-mesh"]) == 2
    assert "no built-in example" in capsys.readouterr().err


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _wait_for(predicate, timeout=10.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.05)
    return False


def test_server_answers_and_stops():
    pytest.importorskip("viser")
    from filletfold.app import run_app

    port = _free_port()
    app = run_app("cube", host="127.0.0.1", port=port)
    try:
        assert app.url == f"http://127.0.0.1:{port}"

        def page():
            try:
                with urllib.request.urlopen(app.url + "/", timeout=2) as r:
                    return r.status, r.headers.get("content-type", ""), r.read()
            except OSError:
                return None

        assert _wait_for(lambda: page() is not None)
        status, ctype, body = page()
        assert status == 200 and "text/html" in ctype and b"<html" in body.lower()

        # a slider change recomputes in the worker; the status says when it is done
        first = app.session.design_id
        app.session.set_params(radius="5%")
        app.request_update()
        assert _wait_for(lambda: app.session.design_id > first and "computing" not in app.status)
        assert app.status.startswith("**cube**")

        # a bad upload shows the reader's error and keeps the design
        design = app.session.design
        app.request_load("bad.obj", b"v 1 2\nf 1 2 3\n")
        assert _wait_for(lambda: "error" in app.status)
        assert "bad.obj: line 1" in app.status and app.session.design is design
    finally:
        app.stop()
    with pytest.raises(OSError):
        urllib.request.urlopen(app.url + "/", timeout=2)
