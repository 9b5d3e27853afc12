"""The validity certificate: built-in designs pass, in memory and from their files, and every
invariant fails when the data are corrupted to break it."""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import re

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from filletfold.check import (
    Certificate,
    certify,
    certify_design,
    check_folder,
    design_edges,
    file_quantum,
    memory_quantum,
)
from filletfold.cli import main
from filletfold.errors import MeshReadError
from filletfold.export.fold_read import read_fold
from filletfold.surface.pattern import CreasePattern

from .conftest import design_of

NAMES = ("icosahedron", "cube", "miura")
CHECKS = [
    "ruling isometry",
    "contraction",
    "on planes",
    "on cylinders",
    "on fillets",
    "M/V",
    "fold-angle match",
    "fold-angle range",
    "smallest fold angle",
    "facet folds",
    "edge lengths",
    "no overlap",
    "face orientation",
    "smallest edge",
    "smallest face angle",
    "holes",
]


@functools.cache
def written(name: str, tmp_root: str) -> str:
    """The folder of ``name``'s design written once (``tmp_root``: the session's tmp folder)."""
    folder = f"{tmp_root}/{name}"
    design_of(name).export(folder, formats="fold,json")
    return folder


@pytest.fixture(scope="module")
def tmp_root(tmp_path_factory) -> str:
    return str(tmp_path_factory.mktemp("check"))


def _certify(design, pattern: CreasePattern | None = None, apex=None) -> Certificate:
    apex = design.vertices.apex if apex is None else apex
    pattern = design.pattern if pattern is None else pattern
    return certify(pattern, design.mesh.vertices, design.mesh.faces, design_edges(design), apex)


def _failed(cert: Certificate) -> set[str]:
    return {c.name for c in cert.failed}


def _patch_faces(pattern, kind: str) -> np.ndarray:
    return np.array([k for k, p in enumerate(pattern.face_patch) if p.kind == kind])


def _consistent(cert: Certificate) -> None:
    """Every check's verdict is what its figure and limit say."""
    compare = {
        "<=": lambda v, lim: v <= lim,
        "<": lambda v, lim: v < lim,
        ">=": lambda v, lim: v >= lim,
        ">": lambda v, lim: v > lim,
    }
    for c in cert.checks:
        if c.limit is None:
            assert c.ok and c.relation == ""
        elif not math.isnan(c.value) and c.name not in ("ruling isometry", "no overlap"):
            assert c.ok == compare[c.relation](c.value, c.limit), c.line()


# ------------------------------------------------------------------ valid designs


@pytest.mark.parametrize("name", NAMES)
def test_designs_pass_in_memory(name):
    cert = certify_design(design_of(name))
    assert cert.ok, "\n".join(cert.summary())
    assert [c.name for c in cert.checks] == CHECKS
    assert cert.coord_quantum == memory_quantum(design_of(name).pattern) > 0
    _consistent(cert)
    assert "rounded to 12 digits" not in "\n".join(cert.summary())  # no file rounding


@pytest.mark.parametrize("name", NAMES)
def test_written_designs_pass(name, tmp_root, capsys):
    folder = written(name, tmp_root)
    cert = check_folder(folder)
    assert cert.ok, "\n".join(cert.summary())
    assert cert.coord_quantum == file_quantum(read_fold(f"{folder}/design.fold")) > 0
    _consistent(cert)
    assert main(["check", folder]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == len(CHECKS) + 1 and lines[-1].startswith("valid")
    for line, name_ in zip(lines, CHECKS, strict=False):
        assert line.startswith(name_)
        info = name_ in ("smallest face angle", "holes")
        assert (" info " if info else " ok ") in line
    contraction = lines[CHECKS.index("contraction")]
    assert "q =" in contraction and "12 digits" in contraction  # the file's rounding is said


def test_certificate_as_json(tmp_root, capsys):
    cert = check_folder(written("cube", tmp_root))
    data = cert.as_dict()
    assert list(data) == ["ok", "checks"] and data["ok"] is True
    assert list(data["checks"]) == CHECKS
    for name, entry in data["checks"].items():
        assert list(entry) == ["ok", "value", "limit", "detail"]
        if name == "on fillets":  # the cube has no conical fillet: nothing measured
            assert entry["value"] is None and entry["ok"] is True
            continue
        assert type(entry["value"]) is float and type(entry["ok"]) is bool
        assert entry["limit"] is None or type(entry["limit"]) is float
    assert json.loads(json.dumps(data, allow_nan=False)) == data
    assert data["checks"]["smallest face angle"]["limit"] is None
    assert main(["check", written("cube", tmp_root), "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == data


def test_nothing_to_measure_is_not_a_failure():
    """The Miura design with holes (``--sharp none``) has no cone and no M/V crease: those
    checks hold, with no figure."""
    cert = certify_design(design_of("miura", sharp="none"))
    for name in ("ruling isometry", "fold-angle range", "smallest fold angle"):
        assert cert[name].ok and math.isnan(cert[name].value)
    assert cert.as_dict()["checks"]["ruling isometry"]["value"] is None


# ------------------------------------------------------------------ each invariant fails


def test_ruling_isometry_fails_when_an_apex_moves_in_2d():
    d = design_of("cube")
    p = d.pattern
    cone = _patch_faces(p, "cone")[0]
    u = p.face_patch[cone].index
    apex = int(np.argmin(np.linalg.norm(p.vertices_3d - d.vertices.apex[u], axis=1)))
    v2 = p.vertices_2d.copy()
    v2[apex] += 1e-6
    cert = _certify(d, dataclasses.replace(p, vertices_2d=v2))
    assert "ruling isometry" in _failed(cert)
    assert cert["ruling isometry"].worst["patch"] == f"cone {u}"
    # without its apex, no cone face is certified
    no_apex = d.vertices.apex.copy()
    no_apex[u] = np.nan
    cert = _certify(d, apex=no_apex)
    assert _failed(cert) == {"ruling isometry"}
    assert f"vertex {u} has no apex" in cert["ruling isometry"].detail


def test_contraction_fails_when_a_piece_shrinks_in_2d():
    d = design_of("miura")
    p = d.pattern
    points = np.unique(
        np.concatenate([f for f, k in zip(p.faces, p.face_piece, strict=True) if k == 0])
    )
    v2 = p.vertices_2d.copy()
    centre = v2[points].mean(axis=0)
    v2[points] = centre + (1 - 1e-7) * (v2[points] - centre)
    cert = _certify(d, dataclasses.replace(p, vertices_2d=v2))
    assert _failed(cert) == {"contraction"}
    assert cert["contraction"].value == pytest.approx(1e-7, rel=1e-3)


def test_on_planes_fails_when_a_point_leaves_its_face():
    d = design_of("cube")
    p = d.pattern
    face = _patch_faces(p, "face")[0]
    f = p.face_patch[face].index
    v = int(p.faces[face][2])
    v3 = p.vertices_3d.copy()
    v3[v] += 1e-6 * d.mesh.face_normal[f]
    cert = _certify(d, dataclasses.replace(p, vertices_3d=v3))
    assert "on planes" in _failed(cert)
    assert cert["on planes"].worst == {"pattern_vertex": v, "mesh_face": f}


def test_on_cylinders_fails_when_a_point_leaves_its_cylinder():
    d = design_of("icosahedron")
    p = d.pattern
    face = _patch_faces(p, "cylinder")[5]
    e = p.face_patch[face].index
    v = int(p.faces[face][0])
    v3 = p.vertices_3d.copy()
    a, b = d.mesh.vertices[d.mesh.edges[e]]
    t = (b - a) / np.linalg.norm(b - a)
    radial = v3[v] - d.rounding.axis_point[e]
    radial -= (radial @ t) * t
    v3[v] += 1e-6 * radial / np.linalg.norm(radial)
    cert = _certify(d, dataclasses.replace(p, vertices_3d=v3))
    assert "on cylinders" in _failed(cert)
    assert cert["on cylinders"].worst == {"pattern_vertex": v, "mesh_edge": e}
    assert cert["on cylinders"].value == pytest.approx(1e-6 / cert.size, rel=1e-3)


def test_mv_fails_when_an_assignment_flips():
    d = design_of("icosahedron")
    p = d.pattern
    e = int(np.flatnonzero(p.edge_assignment == "M")[3])
    assign = p.edge_assignment.copy()
    assign[e] = "V"
    cert = _certify(d, dataclasses.replace(p, edge_assignment=assign))
    assert _failed(cert) == {"M/V"}
    assert cert["M/V"].value == 1 and cert["M/V"].worst == {"pattern_edge": e}
    # flipped with its angle, the written data agree but the folded form does not
    angle = p.edge_fold_angle.copy()
    angle[e] = -angle[e]
    cert = _certify(d, dataclasses.replace(p, edge_assignment=assign, edge_fold_angle=angle))
    assert _failed(cert) == {"M/V", "fold-angle match"}


@pytest.mark.parametrize(
    ("wrong", "failing"),
    [
        (lambda a: -179.9, {"fold-angle range", "fold-angle match"}),
        (lambda a: -1e-9, {"smallest fold angle", "fold-angle match"}),
        (lambda a: 1.001 * a, {"fold-angle match"}),
    ],
    ids=["folds-flat", "does-not-fold", "off-by-0.1%"],
)
def test_fold_angle_checks_fail_on_a_wrong_angle(wrong, failing):
    d = design_of("cube")
    p = d.pattern
    e = int(np.flatnonzero(p.edge_assignment == "M")[7])
    angle = p.edge_fold_angle.copy()
    angle[e] = wrong(angle[e])
    cert = _certify(d, dataclasses.replace(p, edge_fold_angle=angle))
    assert _failed(cert) == failing
    for name in failing:
        assert cert[name].worst == {"pattern_edge": e}


def _pieces_on_top(pattern) -> np.ndarray:
    """2D coordinates with piece 1 moved onto piece 0 (their centres together)."""
    v2 = pattern.vertices_2d.copy()
    points = [
        np.unique(
            np.concatenate(
                [f for f, k in zip(pattern.faces, pattern.face_piece, strict=True) if k == i]
            )
        )
        for i in (0, 1)
    ]
    v2[points[1]] += v2[points[0]].mean(axis=0) - v2[points[1]].mean(axis=0)
    return v2


def test_no_overlap_fails_when_a_piece_lies_on_another():
    d = design_of("cube")
    cert = _certify(d, dataclasses.replace(d.pattern, vertices_2d=_pieces_on_top(d.pattern)))
    assert _failed(cert) == {"no overlap"}
    assert cert["no overlap"].value > 0.01
    a, b = cert["no overlap"].worst["pattern_faces"]
    assert {d.pattern.face_piece[a], d.pattern.face_piece[b]} == {0, 1}


def test_no_overlap_fails_on_a_face_that_crosses_itself():
    d = design_of("cube")
    p = d.pattern
    faces = list(p.faces)
    k = next(int(k) for k in _patch_faces(p, "cylinder") if len(faces[k]) == 4)
    b0, b1, t1, t0 = faces[k]
    faces[k] = np.array([b0, t1, b1, t0])  # a bow tie
    cert = _certify(d, dataclasses.replace(p, faces=faces))
    assert "no overlap" in _failed(cert)
    assert "not simple polygons" in cert["no overlap"].detail


def test_face_orientation_fails_on_a_clockwise_face():
    d = design_of("cube")
    p = d.pattern
    k = int(_patch_faces(p, "face")[1])
    faces = list(p.faces)
    faces[k] = faces[k][::-1]
    cert = _certify(d, dataclasses.replace(p, faces=faces))
    assert "face orientation" in _failed(cert)
    assert cert["face orientation"].worst == {"pattern_face": k}
    assert cert["face orientation"].value < 0


def test_smallest_edge_fails_on_a_tiny_edge():
    d = design_of("cube")
    p = d.pattern
    e = int(np.flatnonzero(p.edge_assignment == "B")[0])
    a, b = p.edges[e]
    v2, v3 = p.vertices_2d.copy(), p.vertices_3d.copy()
    v2[b] = v2[a] + 1e-9 * (v2[b] - v2[a])
    v3[b] = v3[a] + 1e-9 * (v3[b] - v3[a])
    cert = _certify(d, dataclasses.replace(p, vertices_2d=v2, vertices_3d=v3))
    assert "smallest edge" in _failed(cert)
    assert cert["smallest edge"].worst == {"pattern_edge": e}


# ------------------------------------------------------------------ overlap against shapely


def _polygon(rng, k: int) -> np.ndarray:
    """A random star-shaped counter-clockwise polygon of ``k`` corners, convex or not (every
    turn round its centre under half a turn, so a simple polygon)."""
    gap = rng.uniform(1.0, 1.9, k)
    angle = np.cumsum(gap * 2 * np.pi / gap.sum())
    radius = rng.uniform(0.05, 0.3) * rng.uniform(0.4, 1.0, k)
    return rng.uniform(0, 1, 2) + radius[:, None] * np.c_[np.cos(angle), np.sin(angle)]


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 7), fan=st.booleans())
def test_overlap_agrees_with_shapely(seed, n, fan):
    """Random polygons (or a fan of triangles round a shared point, like a cone's): the
    certificate finds an overlap exactly when shapely measures one."""
    rng = np.random.default_rng(seed)
    if fan:  # triangles sharing the centre and their sides: overlapping only if turned back
        turn = np.cumsum(rng.uniform(0.1, 1.4, n + 1))
        ring = np.c_[np.cos(turn), np.sin(turn)] * rng.uniform(0.5, 1, (n + 1, 1))
        v2 = np.vstack([[0.0, 0.0], ring])
        faces = [np.array([0, i, i + 1]) for i in range(1, n + 1)]
    else:
        polys = [_polygon(rng, int(rng.integers(3, 7))) for _ in range(n)]
        v2 = np.vstack(polys)
        start = np.cumsum([0] + [len(q) for q in polys])
        faces = [np.arange(start[i], start[i + 1]) for i in range(n)]
    shapes = [shapely.Polygon(v2[f]) for f in faces]
    expected = any(
        shapes[i].intersection(shapes[j]).area > 1e-9 * min(shapes[i].area, shapes[j].area)
        for i in range(len(faces))
        for j in range(i)
    )
    pattern = CreasePattern(
        np.asarray(v2, dtype=float),
        np.c_[v2, np.zeros(len(v2))],
        faces,
        ["face 0"] * len(faces),
        np.arange(len(faces)),
        np.zeros(len(faces), dtype=np.int64),
    )
    edges = {k: np.zeros((0, 2) if k in ("vertices", "faces") else 0) for k in _edge_keys()}
    cert = certify(pattern, np.eye(3) * [1, 1, 0], [[0, 1, 2]], edges, np.full((3, 3), np.nan))
    assert cert["no overlap"].ok is not expected, cert["no overlap"].line()
    assert cert["on planes"].ok and cert["face orientation"].ok


def _edge_keys():
    return ("vertices", "faces", "radius", "half_angle", "kappa")


# ------------------------------------------------------------------ files and errors


def _rewrite_fold(folder, change) -> None:
    path = f"{folder}/design.fold"
    with open(path) as fh:
        doc = json.load(fh)
    change(doc)
    with open(path, "w") as fh:
        json.dump(doc, fh)


def test_check_exits_1_when_the_file_breaks_an_invariant(tmp_path, capsys):
    folder = tmp_path / "ico"
    design_of("icosahedron").export(folder, formats="fold,json")

    def flip(doc):  # an M crease written as a valley, with its angle: readable, but wrong
        e = doc["edges_assignment"].index("M")
        doc["edges_assignment"][e] = "V"
        doc["edges_foldAngle"][e] = -doc["edges_foldAngle"][e]

    _rewrite_fold(folder, flip)
    assert _failed(check_folder(folder)) == {"M/V", "fold-angle match"}
    assert main(["check", str(folder)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in out if " FAIL " in line] == ["M/V", "fold-angle"]
    assert out[-1].startswith("NOT VALID: 2 check(s) fail")


def _fold_arrays(doc):
    v2 = np.array(doc["vertices_coords"], dtype=float)
    v3 = np.array(doc["file_frames"][0]["vertices_coords"], dtype=float)
    return v2, v3, np.array(doc["edges_vertices"]), doc["edges_assignment"]


def _cone_facet_edge(doc):
    """An F edge between two triangles of one cone, the corner of the second triangle off
    it, and the edge's index (from the FOLD alone)."""
    _, _, ev, assign = _fold_arrays(doc)
    faces, patch = doc["faces_vertices"], doc["filletfold:faces_patch"]
    owner = {}
    for f, corners in enumerate(faces):
        for a, b in zip(corners, corners[1:] + corners[:1], strict=True):
            owner.setdefault((min(a, b), max(a, b)), []).append(f)
    for e, (a, b) in enumerate(ev.tolist()):
        fs = owner.get((min(a, b), max(a, b)), [])
        if assign[e] != "F" or len(fs) != 2 or not str(patch[fs[0]]).startswith("cone "):
            continue
        if patch[fs[0]] == patch[fs[1]] and len(faces[fs[1]]) == 3:
            (c,) = set(faces[fs[1]]) - {a, b}
            if c not in faces[fs[0]]:
                return e, a, b, c
    raise AssertionError("no facet edge inside a cone")


def _rotate(p, a, b, deg):
    """``p`` turned by ``deg`` degrees about the line through ``a`` and ``b``."""
    k = (b - a) / np.linalg.norm(b - a)
    q = p - a
    t = math.radians(deg)
    return a + q * math.cos(t) + np.cross(k, q) * math.sin(t) + k * (k @ q) * (1 - math.cos(t))


def test_check_names_a_facet_folded_30_degrees_and_an_edge_stretched_1_percent(tmp_path, capsys):
    """Two designs broken on purpose, each read from its files alone: a cone's facet turned by
    30 degrees about its F edge (a moved folded vertex), and one pattern edge 1% longer flat
    than folded. ``filletfold check`` fails each, naming the edge."""
    folder = tmp_path / "facet"
    design_of("icosahedron").export(folder, formats="fold,json")
    with open(folder / "design.fold") as fh:
        e, a, b, c = _cone_facet_edge(json.load(fh))

    def fold_facet(doc):
        v3 = doc["file_frames"][0]["vertices_coords"]
        p = [np.array(v3[i], dtype=float) for i in (a, b, c)]
        v3[c] = _rotate(p[2], p[0], p[1], 30.0).tolist()

    _rewrite_fold(folder, fold_facet)
    cert = check_folder(folder)
    assert "facet folds" in _failed(cert)
    assert cert["facet folds"].value > 29.0, cert["facet folds"].line()
    named = dict(re.findall(r"(\d+) \(([0-9.]+) deg\)", cert["facet folds"].detail))
    assert 30.0 <= float(named[str(e)]) < 30.0 + 2 * 1.5, cert["facet folds"].line()
    assert main(["check", str(folder)]) == 1
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("facet folds"))
    assert " FAIL " in line and (f", {e} (" in line or f"edges {e} (" in line)

    folder = tmp_path / "stretch"
    design_of("icosahedron").export(folder, formats="fold,json")
    with open(folder / "design.fold") as fh:
        v2, _, ev, assign = _fold_arrays(json.load(fh))
    length = np.linalg.norm(v2[ev[:, 1]] - v2[ev[:, 0]], axis=1)
    e = int(np.flatnonzero(np.array(assign) == "F")[np.argmax(length[np.array(assign) == "F"])])
    a, b = ev[e]

    def stretch(doc):
        p = np.array(doc["vertices_coords"], dtype=float)
        doc["vertices_coords"][b] = (p[a] + 1.01 * (p[b] - p[a])).tolist()

    _rewrite_fold(folder, stretch)
    cert = check_folder(folder)
    assert "edge lengths" in _failed(cert)
    named = dict(re.findall(r"(\d+) \(([0-9.e-]+)\)", cert["edge lengths"].detail))
    assert float(named[str(e)]) == pytest.approx(0.01 / 1.01, rel=0.02), cert["edge lengths"].line()
    assert main(["check", str(folder)]) == 1
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("edge lengths"))
    assert " FAIL " in line and (f", {e} (" in line or f"edges {e} (" in line)


def test_a_crease_inside_a_cone_must_end_on_an_unrounded_edge():
    """The ruling to an edge left sharp is a crease inside its cone (an icosahedron vertex
    with one edge unrounded); written as a crease anywhere else in a cone, it fails."""
    d = design_of("icosahedron", radius=0.1)
    p = d.pattern
    inner = np.flatnonzero((p.edge_assignment == "F") & (p.edge_faces >= 0).all(axis=1))
    fa, fb = p.edge_faces[inner].T
    patch = np.array([str(x) for x in p.face_patch])
    in_cone = (patch[fa] == patch[fb]) & np.char.startswith(patch[fa], "cone ")
    e = int(inner[in_cone][0])
    assign, angle = p.edge_assignment.copy(), p.edge_fold_angle.copy()
    assign[e], angle[e] = "M", -1.0  # a crease the cone does not have
    cert = _certify(d, dataclasses.replace(p, edge_assignment=assign, edge_fold_angle=angle))
    assert "facet folds" in _failed(cert)
    assert cert["facet folds"].worst["pattern_edge"] == e
    assert "not a ruling to an unrounded edge" in cert["facet folds"].detail


def test_check_finds_overlapping_pieces_in_the_file(tmp_path):
    folder = tmp_path / "cube"
    d = design_of("cube")
    d.export(folder, formats="fold,json")
    v2 = _pieces_on_top(d.pattern)
    _rewrite_fold(folder, lambda doc: doc.update(vertices_coords=v2.tolist()))
    assert _failed(check_folder(folder)) == {"no overlap"}


def _error_line(args, capsys) -> str:
    assert main(args) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert captured.out == "" and "\n" not in err and err.startswith("error: ")
    assert "Traceback" not in err
    return err


def test_missing_or_unreadable_input_exits_2_with_one_line(tmp_path, tmp_root, capsys):
    missing = tmp_path / "no-such-design-folder-with-a-long-name-that-a-console-would-wrap"
    assert str(missing) in _error_line(["check", str(missing)], capsys)
    with pytest.raises(MeshReadError, match="no such folder"):
        check_folder(missing)
    folder = tmp_path / "partial"
    folder.mkdir()
    (folder / "design.fold").write_text((tmp_path / "x").as_posix())
    assert "report.json: no such file" in _error_line(["check", str(folder)], capsys)
    (folder / "report.json").write_text("{}")
    assert "design.fold: not a FOLD file" in _error_line(["check", str(folder)], capsys)
    cube, ico = written("cube", tmp_root), written("icosahedron", tmp_root)
    (folder / "design.fold").write_text(open(f"{cube}/design.fold").read())
    assert "report.json: not a filletfold report" in _error_line(["check", str(folder)], capsys)
    (folder / "design.fold").write_text(open(f"{ico}/design.fold").read())  # another design's
    (folder / "report.json").write_text(open(f"{cube}/report.json").read())
    err = _error_line(["check", str(folder)], capsys)
    assert "does not match report.json" in err and "12 vertices, 30 edges and 20 faces" in err
    (folder / "report.json").write_text("[1, 2")
    assert "report.json: not a report (invalid JSON" in _error_line(["check", str(folder)], capsys)


def test_the_mesh_comes_from_the_fold_or_from_the_report_tables(tmp_path, capsys):
    """design.fold holds the mesh's per-element data; a folder whose FOLD lacks it (written
    before it had it) is checked from the tables of report.json; with neither, one line."""
    d = design_of("icosahedron", radius=0.1)
    d.export(tmp_path / "ref", formats="fold,json")
    ref = check_folder(tmp_path / "ref")
    folder = tmp_path / "tables"
    d.export(folder, formats="fold,json", tables=True)
    _rewrite_fold(
        folder,
        lambda doc: [doc.pop(k) for k in list(doc) if k.startswith("filletfold:mesh_")],
    )
    again = check_folder(folder)
    assert again.ok and [c.name for c in again.checks] == [c.name for c in ref.checks]
    # the FOLD's mesh has 12 digits, the report's tables 17: the same to rounding
    a, b = (np.array([c.value for c in x.checks], dtype=float) for x in (again, ref))
    np.testing.assert_allclose(a, b, rtol=1e-6, atol=1e-11)
    plain = tmp_path / "plain"
    d.export(plain, formats="fold,json")
    _rewrite_fold(plain, lambda doc: doc.pop("filletfold:mesh_vertices_coords"))
    err = _error_line(["check", str(plain)], capsys)
    assert "has no mesh data and report.json no tables" in err
    short = tmp_path / "short"
    d.export(short, formats="fold,json")
    _rewrite_fold(short, lambda doc: doc["filletfold:mesh_edges_radius"].pop())
    err = _error_line(["check", str(short)], capsys)
    assert "design.fold: not filletfold's mesh data (malformed" in err


def test_a_radius_changed_in_the_fold_fails_the_cylinders(tmp_path):
    """The mesh's data in design.fold is measured, not trusted: a cylinder whose radius the
    file gives 1% larger than its points lie at fails "on cylinders"."""
    folder = tmp_path / "ico"
    design_of("icosahedron", radius=0.1).export(folder, formats="fold,json")

    def grow(doc):
        r = doc["filletfold:mesh_edges_radius"]
        r[3] *= 1.01

    _rewrite_fold(folder, grow)
    cert = check_folder(folder)
    assert "on cylinders" in _failed(cert)
    assert "cylinder 3" in cert["on cylinders"].detail


@pytest.mark.parametrize("name", ["report.json", "design.fold", "annotations.json"])
def test_a_file_nested_too_deeply_is_a_named_error(tmp_path, capsys, name):
    """JSON nested past Python's recursion limit in any file ``check`` reads is one line naming
    the file, never a RecursionError (issue 30)."""
    folder = tmp_path / "deep"
    design_of("icosahedron").export(folder, formats="fold,json")
    (folder / name).write_text('{"a": ' + "[" * 100_000 + "]" * 100_000 + "}")
    err = _error_line(["check", str(folder)], capsys)
    assert name in err and "nested too deeply" in err, err
