"""The browser app: its GUI-free session, its scene arrays, and the server answering HTTP."""

from __future__ import annotations

import io
import itertools
import json
import socket
import threading
import time
import urllib.request
import zipfile

import numpy as np
import pytest
from numpy.testing import assert_allclose

from filletfold.app import session as session_mod
from filletfold.app.session import AppSession, nearest_vertex_to_ray
from filletfold.app.view import SCENE_WIDTH, scene_arrays
from filletfold.check import check_folder
from filletfold.cli import main
from filletfold.errors import MeshReadError, ParameterError
from filletfold.surface.triangulate import triangulate_faces, triangulate_polygon_2d

from ..conftest import design_of

TETRA_OBJ = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
ZIP_NAMES = {
    "design.fold",
    "annotations.json",
    "simulator.fold",
    "simulator.svg",
    "report.json",
    "folded.obj",
    "pattern.svg",
    "pattern.dxf",
}


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


@pytest.mark.slow  # fast tier near its budget: in make test-slow (CI runs both)
def test_arc_step_reaches_the_design_and_its_download():
    """The arc step is a session parameter; the download (rebuilt with tabs by reuse) keeps
    the shown design's sampling."""
    s = AppSession()
    s.load("geodesic-sphere")  # arcs of about 20 degrees: the step decides their points
    s.set_params(arc_step=1.5)
    fine = len(s.recompute().pattern.faces)
    s.set_params(arc_step=5.0)
    coarse = s.recompute()
    assert coarse.params.arc_step == 5.0 and len(coarse.pattern.faces) < fine
    files = dict(s.export_files())
    fold = json.loads(files["design.fold"])
    assert json.loads(files["report.json"])["parameters"]["arc_step"] == 5.0
    cp = [len(f) for f in fold["faces_vertices"]]
    assert len(cp) >= len(coarse.pattern.faces) and len(cp) < fine


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


def test_export_zip_holds_the_files_and_they_parse(cube_session, tmp_path):
    data = cube_session.export_zip()
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        zf.extractall(tmp_path / "unzipped")
        names = set(zf.namelist())
        assert ZIP_NAMES <= names
        fold = json.loads(zf.read("design.fold"))
        annotations = json.loads(zf.read("annotations.json"))
        report = json.loads(zf.read("report.json"))
        obj = zf.read("folded.obj").decode()
        svg = zf.read("pattern.svg").decode()
        dxf = zf.read("pattern.dxf").decode()
        simulator = json.loads(zf.read("simulator.fold"))
        simulator_svg = zf.read("simulator.svg").decode()
    assert {len(f) for f in simulator["faces_vertices"]} == {3}  # triangles for the app
    assert len(simulator["vertices_coords"]) < len(fold["vertices_coords"])
    assert 'stroke="#ff0000"' in simulator_svg and 'stroke="#ff00ff"' not in simulator_svg
    assert "timings" not in report
    assert fold["file_spec"] == 1.2 and len(fold["vertices_coords"]) > 0
    assert annotations["design"]["vertices"] == len(fold["vertices_coords"])
    assert len(annotations["tabs"]) > 0  # the download has its glue tabs
    assert report["status_counts"]["ok"] == 8 and report["source"] == "cube"
    assert "\nv " in obj and "\nf " in obj
    assert svg.lstrip().startswith("<") and "<svg" in svg
    assert "SECTION" in dxf and "EOF" in dxf
    # as the CLI writes them: a summary report, the mesh's data in design.fold; they check
    assert "vertices" not in report and report["mesh_counts"]["vertices"] == 8
    assert check_folder(tmp_path / "unzipped").ok


def test_shown_design_has_no_tabs_but_the_download_does(cube_session):
    """Glue tabs are off in the live view (speed) and added for the download (reuse); the view
    shows the modules, the download is laid out in nets, as the command line's default."""
    assert cube_session.design.fabrication["tabs"] == 0
    assert cube_session.design.layout == "modules"
    files = cube_session.export_files()
    report = json.loads(files["report.json"])
    assert report["fabrication"]["tabs"] > 0
    assert "assembly.txt" in files
    assert report["source"] == "cube"
    assert report["layout"]["kind"] == "net" and report["pattern"]["pieces"] < 8


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
    tris = triangulate_polygon_2d(p)
    assert tris.shape == (len(p) - 2, 3)
    areas = [_area(p[t]) for t in tris]
    assert min(areas) > 0
    assert_allclose(sum(areas), _area(p), rtol=1e-12)


def test_triangulate_faces_covers_every_face():
    polys = [
        [[0, 0], [1, 0], [0, 1]],
        [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]],  # not convex
        [[0, 0], [1, 0], [1, 1], [0, 1]],
        [[0, 0], [3, 0], [3, 3], [2, 1], [1, 1], [0, 3]],  # not convex
        [[0, 0], [2, 0], [3, 1], [1, 2], [-1, 1]],
        [[5, 5], [6, 5], [6, 6], [5, 6]],
    ]
    points = np.vstack([np.array(q, dtype=float) for q in polys])
    starts = np.cumsum([0] + [len(q) for q in polys])
    faces = [np.arange(a, b) for a, b in itertools.pairwise(starts)]
    tris, owner = triangulate_faces(points, faces)
    assert len(tris) == sum(len(f) - 2 for f in faces) and np.all(np.diff(owner) >= 0)
    for i, f in enumerate(faces):
        mine = tris[owner == i]
        assert np.isin(mine, f).all()
        areas = [_area(points[t]) for t in mine]
        assert min(areas) > 0
        assert_allclose(sum(areas), _area(points[f]), rtol=1e-12)


@pytest.mark.parametrize("as_arrays", [False, True])
def test_triangulate_faces_is_triangulate_polygon_face_by_face(as_arrays):
    """The triangles of every face, convex or not (resch has non-convex face shares), as
    triangulate_polygon_2d gives them, face after face; faces of fewer than 3 corners give none."""
    pattern = design_of("resch").pattern
    faces = [f if as_arrays else f.tolist() for f in pattern.faces[:600]]
    faces[3:3] = [faces[3][:2], faces[7][:1]]
    tris, owner = triangulate_faces(pattern.vertices_2d, faces)
    want = [
        np.asarray(f)[triangulate_polygon_2d(pattern.vertices_2d[f])] for f in faces if len(f) > 2
    ]
    assert tris.dtype == np.int64 and np.array_equal(tris, np.vstack(want))
    sizes = np.array([len(f) for f in faces])
    assert np.array_equal(owner, np.repeat(np.arange(len(faces)), np.maximum(sizes - 2, 0)))


def test_triangulate_faces_reads_a_patterns_flat_faces_as_their_list():
    """A pattern's faces (flat arrays, read without an array per face) give the triangles and
    owners of the same faces as a list."""
    pattern = design_of("resch").pattern
    tris, owner = triangulate_faces(pattern.vertices_2d, pattern.faces)
    want_tris, want_owner = triangulate_faces(pattern.vertices_2d, list(pattern.faces))
    assert np.array_equal(tris, want_tris) and np.array_equal(owner, want_owner)
    assert tris.dtype == np.int64 and len(owner) == len(tris)


def test_scene_meshes_number_their_points_in_order():
    """Each patch kind's mesh holds the points its triangles use, in increasing order
    (numpy.unique's numbering)."""
    design = design_of("resch")
    arrays = scene_arrays(design)
    tris, owner = triangulate_faces(design.pattern.vertices_2d, design.pattern.faces)
    kinds = np.array([p.kind for p in design.pattern.face_patch])[owner]
    v3 = arrays.to_scene(design.pattern.vertices_3d)
    assert list(arrays.folded) == [k for k in ("cone", "cylinder", "face") if k in kinds]
    for kind, (v, t) in arrays.folded.items():
        used, inverse = np.unique(tris[kinds == kind], return_inverse=True)
        assert np.array_equal(t, inverse.reshape(-1, 3)) and np.array_equal(v, v3[used])
        flat_v, flat_t = arrays.flat[kind]
        assert len(flat_v) == len(used) and np.array_equal(flat_t, t)


def test_scene_arrays_match_the_pattern(cube_session):
    design = cube_session.design
    arrays = scene_arrays(design)
    n_tri = sum(len(f) - 2 for f in design.pattern.faces)
    assert sum(len(t) for _, t in arrays.folded.values()) == n_tri
    assert set(arrays.folded) == {"cone", "cylinder", "face"}
    model_right = max(v[:, 0].max() for v, _ in arrays.folded.values())
    for kind, (v, t) in arrays.flat.items():
        assert t.max() < len(v)
        assert_allclose(v[:, 2], v[0, 2], atol=0)  # the pattern lies flat
        assert v[:, 0].min() > model_right  # beside the model
        assert len(arrays.folded[kind][0]) == len(v)
    assert arrays.folded_creases["M"].shape[1:] == (2, 3)
    assert arrays.vertex_points.shape == (8, 3) and arrays.vertex_colors.shape == (8, 3)


@pytest.mark.parametrize("name", ["cube", "icosahedron", "miura"])
def test_scene_frames_model_and_pattern_in_one_box(name):
    """Every design is drawn in the same box around the origin (one camera frames all), the
    folded form and the pattern similar to the design's (pattern at most at true scale)."""
    s = AppSession()
    design = s.load(name)
    arrays = scene_arrays(design)
    points = np.vstack([v for v, _ in [*arrays.folded.values(), *arrays.flat.values()]])
    lo, hi = points.min(axis=0), points.max(axis=0)
    assert_allclose((hi - lo).max(), SCENE_WIDTH, rtol=1e-12)
    assert_allclose(0.5 * (lo + hi), 0, atol=1e-12)
    assert 0 < arrays.pattern_scale <= 1
    v3, v2 = design.pattern.vertices_3d, design.pattern.vertices_2d
    assert_allclose(arrays.vertex_points, arrays.to_scene(design.mesh.vertices))
    edges = design.pattern.edges
    e3 = np.linalg.norm(np.diff(v3[edges], axis=1), axis=-1)
    e2 = np.linalg.norm(np.diff(v2[edges], axis=1), axis=-1)
    drawn3 = np.linalg.norm(np.diff(arrays.to_scene(v3)[edges], axis=1), axis=-1)
    flat = arrays.flat_creases
    drawn2 = np.linalg.norm(np.diff(np.vstack(list(flat.values())), axis=1), axis=-1)
    assign = np.asarray(design.pattern.edge_assignment)
    order = np.concatenate([np.flatnonzero(assign == a) for a in flat])
    assert_allclose(drawn3, arrays.scale * e3, rtol=1e-9, atol=1e-12)
    assert_allclose(drawn2, arrays.scale * arrays.pattern_scale * e2[order], rtol=1e-9, atol=1e-12)


def test_recompute_and_load_report_progress():
    s = AppSession()
    calls = []
    s.load("cube", progress=lambda *a: calls.append(a))
    assert {"apices", "surface"} <= {stage for stage, _, _ in calls}
    # the cube's 8 vertices (the first design of a process also reports loading the kernel)
    assert all(0 < d <= t == 8 for stage, d, t in calls if stage in ("apices", "surface"))
    calls.clear()
    s.set_params(radius="5%")
    s.recompute(progress=lambda *a: calls.append(a))
    assert calls[-1] == ("surface", 8, 8)


def test_an_exception_from_progress_stops_the_computation_and_keeps_the_design():
    s = AppSession()
    design = s.load("cube")

    class Stop(Exception):
        pass

    def stop(stage, done, total):
        raise Stop

    s.set_params(radius="5%")
    with pytest.raises(Stop):
        s.recompute(progress=stop)
    assert s.design is design


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

    from .page import Page

    port = _free_port()
    app = run_app("cube", host="127.0.0.1", port=port)
    page = None
    try:
        assert app.url == f"http://127.0.0.1:{port}"

        def index():
            try:
                with urllib.request.urlopen(app.url + "/", timeout=2) as r:
                    return r.status, r.headers.get("content-type", ""), r.read()
            except OSError:
                return None

        assert _wait_for(lambda: index() is not None)
        status, ctype, body = index()
        assert status == 200 and "text/html" in ctype and b"<html" in body.lower()

        page = Page(app.url)  # a page of the app, without a browser
        view = app.wait_view()
        # a slider change recomputes in the worker; the status says when it is done
        first = view.session.design_id
        view.session.set_params(radius="5%")
        view.request_update()
        assert _wait_for(lambda: view.session.design_id > first and "computing" not in view.status)
        assert view.status.startswith("**cube**")

        # a bad upload shows the reader's error and keeps the design
        design = view.session.design
        view.request_load("bad.obj", b"v 1 2\nf 1 2 3\n")
        assert _wait_for(lambda: "error" in view.status)
        assert "bad.obj: line 1" in view.status and view.session.design is design

        # coarsening in the worker: the status says what it did
        view.request_load("blob")
        assert _wait_for(lambda: view.status.startswith("**blob**"))
        view.request_coarsen(120)
        assert _wait_for(lambda: "coarsened: 320 -> " in view.status)
        assert view.session.mesh.n_faces <= 120
        view.request_coarsen(None)
        assert _wait_for(lambda: "coarsened" not in view.status and "blob**" in view.status)
    finally:
        if page is not None:
            page.close()
        app.stop()
    with pytest.raises(OSError):
        urllib.request.urlopen(app.url + "/", timeout=2)


def test_server_shows_progress_stays_responsive_and_a_newer_change_supersedes(monkeypatch):
    """While the worker computes, the page shows the stage and a progress bar, the server
    answers and takes GUI changes, and a newer change stops the older computation."""
    pytest.importorskip("viser")
    from filletfold.app import run_app

    from .page import Page

    real = session_mod.round_mesh
    armed, reached, release = threading.Event(), threading.Event(), threading.Event()
    finished, first_call = [], []

    def gated_round_mesh(mesh, params, progress=None, **kw):
        def hook(stage, done, total):
            if progress is not None:
                progress(stage, done, total)  # the app's callback: updates the page
            if armed.is_set() and not release.is_set():  # hold the first report
                first_call.append((stage, done, total))
                reached.set()
                release.wait(30)

        design = real(mesh, params, progress=hook, **kw)
        finished.append(params.radius)
        return design

    monkeypatch.setattr(session_mod, "round_mesh", gated_round_mesh)
    app = run_app("cube", host="127.0.0.1", port=_free_port())
    page = None
    try:
        page = Page(app.url)  # a page of the app, without a browser
        view = app.wait_view()
        assert view.wait_drawn(1)
        assert view.progress is None and not view._progress_bar.visible
        armed.set()
        view._radius.value = 15.0  # what the slider's on_update does, from the server side
        assert reached.wait(30), "the worker did not start computing"
        # mid-computation: the stage and the bar are shown
        ((stage, done, total),) = first_call
        assert view.progress == (stage, done, total) and total == 8
        assert view.status == f"computing… {stage} {done}/{total}"
        assert view._progress_bar.visible
        assert view._progress_bar.value == pytest.approx(100 * done / total)
        # ...and the page is not frozen: the server answers and takes a newer change at once
        with urllib.request.urlopen(app.url + "/", timeout=5) as r:
            assert r.status == 200
        # setting the slider returns while the worker is still held (not released below)
        setter = threading.Thread(target=setattr, args=(view._radius, "value", 20.0))
        setter.start()
        setter.join(30)
        assert not setter.is_alive(), "the slider waited for the computation in progress"
        assert view.session.params.radius == "20.0%"
        release.set()
        assert _wait_for(lambda: view.session.design.params.radius == "20.0%", 30)
        assert view.wait_drawn(view.session.design_id)
        assert "15.0%" not in finished  # the superseded computation was stopped
        assert _wait_for(lambda: view.progress is None and not view._progress_bar.visible)
        assert view.status.startswith("**cube**")
        assert set(view.timings) == {"compute", "draw"}
    finally:
        release.set()
        if page is not None:
            page.close()
        app.stop()


def test_a_redraw_updates_the_scene_nodes_it_made_first():
    """The first draw makes the scene nodes; a new design only gives them new arrays (the
    same handles), those of the new design's scene arrays; kinds a design lacks are hidden,
    and the pattern's nodes follow the "show pattern" box."""
    pytest.importorskip("viser")
    from filletfold.app import run_app

    from .page import Page

    app = run_app("cube", host="127.0.0.1", port=_free_port())
    page = None
    try:
        page = Page(app.url)  # a page of the app, without a browser
        view = app.wait_view()
        assert view.wait_drawn(1)
        nodes = dict(view._nodes)
        view._radius.value = 15.0
        assert view.wait_idle(60) and view.session.design.params.radius == "15.0%"
        assert view._nodes == nodes and all(view._nodes[k] is v for k, v in nodes.items())
        arrays = scene_arrays(view.session.design)
        for root, parts in (("/folded", arrays.folded), ("/pattern", arrays.flat)):
            for kind, (v, f) in parts.items():
                node = view._nodes[f"{root}/{kind}"]
                assert np.array_equal(node.vertices, v.astype(np.float32))
                assert np.array_equal(node.faces, f) and node.visible
        for a, points in arrays.flat_creases.items():  # the cube has no valley creases
            node = view._nodes[f"/pattern/crease_{a}"]
            assert node.visible == (len(points) > 0)
            if len(points):
                assert np.array_equal(node.points, points.astype(np.float32))
        assert np.array_equal(view._nodes["/folded/vertices"].colors, arrays.vertex_colors)
        assert "radius 15.0%" in view.status

        view.request_load("saddle-patch")  # no cones, no mountain or valley creases
        assert view.wait_idle(60) and view.session.name == "saddle-patch"
        assert view._nodes == nodes
        arrays = scene_arrays(view.session.design)
        visible = {name for name, node in view._nodes.items() if node.visible}
        want = {f"{root}/{kind}" for root in ("/folded", "/pattern") for kind in arrays.folded}
        want |= {f"/pattern/crease_{a}" for a, p in arrays.flat_creases.items() if len(p)}
        want |= {f"/folded/crease_{a}" for a, p in arrays.folded_creases.items() if len(p)}
        assert visible == want | {"/folded/vertices"} and "/folded/cone" not in visible
        view._show_pattern.value = False
        assert not any(view._nodes[name].visible for name in want if name.startswith("/pattern"))
    finally:
        if page is not None:
            page.close()
        app.stop()


def test_export_zip_is_reproducible(cube_session):
    data = cube_session.export_zip()
    assert data == cube_session.export_zip()
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        # not dated by the clock: the same design is the same zip on any day
        assert {info.date_time for info in zf.infolist()} == {(1980, 1, 1, 0, 0, 0)}
        assert {info.external_attr >> 16 for info in zf.infolist()} == {0o644}


def test_the_download_keeps_every_parameter_of_the_shown_design():
    """The download is the shown design again with glue tabs: parameters the app has no
    slider for (chord tolerance, sharp vertices, vertex fitting) are those of the shown
    design too, not the defaults."""
    from filletfold import round_mesh

    s = AppSession()
    s.load("l-prism")
    shown = round_mesh(
        s.mesh, chord_tol=0, arc_step=0, samples=5, sharp="none", fit_vertices=False, tabs=False
    )
    shown.source = "l-prism"
    s.design = shown
    files = s.export_files()
    parameters = json.loads(files["report.json"])["parameters"]
    assert parameters == shown.params.replace(tabs=True).as_dict()  # the download has tabs
    assert parameters["chord_tol"] == 0 and parameters["sharp"] == "none"
    assert not parameters["fit_vertices"]
    assert json.loads(files["report.json"])["fabrication"]["tabs"] > 0
    fold = json.loads(files["design.fold"])
    assert len(fold["vertices_coords"]) >= len(shown.pattern.vertices_2d)


def test_coarsen_designs_the_loaded_mesh_with_fewer_triangles_and_back():
    s = AppSession()
    s.load("geodesic-sphere:level=2")  # 162 vertices, 320 triangles
    loaded = s.mesh
    s.set_vertex_depth(5, "40%")
    design = s.coarsen(120)
    assert s.loaded is loaded and s.mesh is not loaded
    assert s.coarsening.faces_before == 320 and s.coarsening.faces_after <= 120
    assert design.mesh.n_vertices == s.coarsening.vertices_after < 162
    assert s.vertex_depth == {}  # the vertices are new
    again = s.coarsen(60)  # from the loaded mesh, not from the coarse one
    assert s.coarsening.faces_before == 320 and again.mesh.n_faces <= 60
    back = s.coarsen(None)
    assert s.mesh is loaded and s.coarsening is None and back.mesh.n_vertices == 162
    s.recompute()  # a slider change after a coarsening designs the coarse mesh
    s.coarsen(80)
    n = s.mesh.n_vertices
    s.set_params(radius="5%")
    assert s.recompute().mesh.n_vertices == n


def test_coarsen_errors_keep_the_design():
    s = AppSession()
    with pytest.raises(MeshReadError, match="no mesh"):
        s.coarsen(100)
    design = s.load("cube")
    with pytest.raises(ParameterError, match="faces"):
        s.coarsen(2)
    assert s.design is design and s.coarsening is None
