"""Sharp vertices in the pipeline: no holes, conical fillets that hold every invariant."""

from __future__ import annotations

import json

import numpy as np
import pytest

import filletfold
from filletfold.cli import main
from filletfold.errors import ParameterError
from filletfold.vertex.sharpen import SHARP_KINDS, edge_treatments, parse_sharp

from ..conftest import design_of

#: Built-in examples with vertices that take no cone.
WITH_HOLES = ["torus", "l-prism", "blob", "saddle-patch", "open-box", "tent", "miura"]


def holes(d):
    c = d.certificate["holes"]
    notches = int(c.detail.split(" holes and ")[1].split()[0])
    return int(c.value), notches


@pytest.mark.parametrize("name", WITH_HOLES)
def test_every_example_is_closed_by_default_and_has_holes_without(name):
    before, after = design_of(name, sharp="none"), design_of(name)
    assert sum(holes(before)) > 0, "the example has vertices without a cone"
    assert holes(after) == (0, 0)
    assert after.certificate.ok, "\n".join(after.certificate.summary())
    assert set(after.vertices.treatment) <= {"cone", "sharp"}
    assert "hole" in before.vertices.treatment
    # every vertex with a cone before keeps it (sharp neighbours only taper its sides)
    cones = [u for u, t in enumerate(before.vertices.treatment) if t == "cone"]
    kept = sum(after.vertices.treatment[u] == "cone" for u in cones)
    assert kept >= 0.8 * len(cones)


def fillet_edge_lengths(d):
    """(k,) flat and (k,) folded length of every pattern edge of a fillet face."""
    p = d.pattern
    patch = np.array([x.kind for x in p.face_patch])
    ef = p.edge_faces
    on = (patch[ef[:, 0]] == "fillet") | (patch[np.maximum(ef[:, 1], 0)] == "fillet")
    e = p.edges[on]
    l2 = np.linalg.norm(p.vertices_2d[e[:, 0]] - p.vertices_2d[e[:, 1]], axis=1)
    l3 = np.linalg.norm(p.vertices_3d[e[:, 0]] - p.vertices_3d[e[:, 1]], axis=1)
    return l2, l3


def join_angles(d, kind):
    """(k,) folded dihedral (degrees) across every pattern edge between a ``kind`` patch
    (``fillet`` or ``cylinder``) and a face piece: 0 for exact tangency, the sampling's error
    otherwise."""
    p = d.pattern
    patch = np.array([x.kind for x in p.face_patch])
    ef = p.edge_faces
    inner = np.flatnonzero((ef >= 0).all(axis=1))
    a, b = patch[ef[inner, 0]], patch[ef[inner, 1]]
    joins = inner[((a == kind) & (b == "face")) | ((a == "face") & (b == kind))]
    assert (p.edge_assignment[joins] == "F").all()
    v3 = p.vertices_3d

    def normal(f):
        q = v3[list(p.faces[f])]
        n = sum(np.cross(q[k] - q[0], q[k + 1] - q[0]) for k in range(1, len(q) - 1))
        return n / np.linalg.norm(n)

    return np.array(
        [np.degrees(np.arccos(np.clip(normal(ef[e, 0]) @ normal(ef[e, 1]), -1, 1))) for e in joins]
    )


@pytest.mark.parametrize("name", ["l-prism", "blob", "open-box", "tent"])
def test_conical_fillets_hold_the_invariants(name):
    """Fillet points on their cones (certificate), the joins between fillets and faces as
    tangent as the sampling allows (within 1.5 times the arc step of 1.5 degrees), and the
    fillets' edges contract."""
    d = design_of(name)
    assert d.certificate["on fillets"].ok and d.certificate["on fillets"].value < 1e-12
    angles = join_angles(d, "fillet")
    assert len(angles) and angles.max() <= 1.5 * 1.5
    l2, l3 = fillet_edge_lengths(d)
    assert (l3 <= l2 + 1e-12 * d.certificate.size).all()


def test_fillet_face_joins_become_tangent_under_refinement():
    """The kink across a fillet-face join is the sampling's: it halves as the samples
    double (the construction itself is tangent continuous)."""
    worst = []
    for n in (9, 17, 33):
        d = filletfold.round_mesh("l-prism", samples=n, arc_step=0, chord_tol=0, tabs=False)
        worst.append(join_angles(d, "fillet").max())
    ratio = np.array(worst[:-1]) / np.array(worst[1:])
    assert (ratio > 1.8).all(), worst


def test_fillet_mismatch_converges_under_refinement():
    """The chords of the fillets' triangles and the crease on them: the largest 2D - 3D
    length difference falls with order 2 or more as the arcs get more samples."""
    worst = []
    for n in (9, 17, 33):
        d = filletfold.round_mesh("l-prism", samples=n, arc_step=0, chord_tol=0, tabs=False)
        l2, l3 = fillet_edge_lengths(d)
        worst.append(float(np.max(l2 - l3)))
    ratio = np.array(worst[:-1]) / np.array(worst[1:])
    assert (ratio > 3.5).all(), worst


def test_treatments_in_the_report(tmp_path):
    out = tmp_path / "lp"
    assert main(["round", "l-prism", "-o", str(out), "-q", "--report-tables"]) == 0
    report = json.loads((out / "report.json").read_text())
    vt = [v["treatment"] for v in report["vertices"]]
    et = [e["treatment"] for e in report["edges"]]
    assert vt.count("sharp") == 2 and vt.count("hole") == 0
    sharp = {u for u, t in enumerate(vt) if t == "sharp"}
    for e, t in zip(report["edges"], et, strict=True):
        ends = set(e["vertices"]) & sharp
        if t == "cone":
            assert len(ends) == 1 and e["radius"] > 0
        if t == "cylinder":
            assert not ends
    assert "cone" in et
    assert report["parameters"]["sharp"] == "saddle,infeasible,boundary"
    obj = (out / "folded.obj").read_text()
    assert "g fillet_" in obj


def test_sharp_none_is_the_old_behaviour_and_kinds_choose(tmp_path):
    d = design_of("open-box", sharp="saddle")  # boundary vertices not kept: notches
    assert holes(d)[1] > 0
    assert set(d.vertices.treatment) == {"cone", "hole"}
    d = design_of("open-box", sharp="boundary")
    assert holes(d) == (0, 0)


def test_parse_sharp():
    assert parse_sharp("none") == frozenset()
    assert parse_sharp("all") == frozenset(SHARP_KINDS)
    assert parse_sharp("saddle, boundary") == {"saddle", "boundary"}
    with pytest.raises(ParameterError, match="unknown kind 'sadle'"):
        parse_sharp("sadle")


def test_a_bad_kind_is_a_one_line_error(tmp_path, capsys):
    assert main(["round", "torus", "-o", str(tmp_path / "t"), "--sharp", "holes"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unknown kind 'holes'" in err[0]
    assert not (tmp_path / "t").exists()


def test_material_loss_keeps_one_sheet():
    """With --material-loss the default leaves boundary vertices out: the developable Miura
    sheet still folds from one uncut piece (its boundary keeps today's notches)."""
    d = filletfold.round_mesh("miura", material_loss=True, tabs=False)
    assert d.layout == "sheet" and d.pattern.n_pieces == 1
    assert d.params.sharp == "saddle,infeasible"
    assert "sharp" not in d.vertices.treatment or all(
        d.vertices.kind[u] != "boundary" for u, t in enumerate(d.vertices.treatment) if t == "sharp"
    )


def test_edge_treatments_of_a_mesh_without_sharp_vertices():
    d = design_of("cube")
    t = edge_treatments(d.mesh, d.rounding, d.vertices.treatment)
    assert set(t) == {"cylinder"}


@pytest.mark.parametrize("name", ["torus", "l-prism", "blob", "saddle-patch", "cube"])
def test_saddles_are_found_before_the_frames_as_the_classification_finds_them(name):
    """saddle_vertices (mesh and radii alone) marks exactly the vertices classify_vertices
    calls saddles from their frames."""
    from filletfold.mesh import load_mesh
    from filletfold.rounding.edges import round_edges
    from filletfold.vertex.solve import VertexResult, classify_vertices, saddle_vertices

    pm = load_mesh(name)[0]
    rounding = round_edges(pm, np.full(pm.n_edges, 0.1 * pm.mean_edge_length))
    res = VertexResult.empty(pm.n_vertices)
    classify_vertices(pm, rounding, res)
    found = saddle_vertices(pm, rounding)
    assert found.tolist() == [s == "saddle" for s in res.status]
    assert found.any() == (name != "cube")
    flat = round_edges(pm, np.zeros(pm.n_edges))  # no rounded edge: no saddle, only "sharp"
    assert not saddle_vertices(pm, flat).any()


def test_each_frame_is_built_once_when_saddles_are_made_sharp(monkeypatch):
    """The saddles are sharp before the frames are built: every vertex is classified once
    before the apices (none again for its neighbours), and a saddle whose edges all end at
    saddles (so are all left unrounded) is still reported as a saddle kept sharp."""
    import filletfold.pipeline as pipeline

    counts = []
    real = pipeline.classify_vertices

    def counting(mesh, rounding, res, vertices=None, *args, **kwargs):
        counts.append(mesh.n_vertices if vertices is None else len(vertices))
        return real(mesh, rounding, res, vertices, *args, **kwargs)

    monkeypatch.setattr(pipeline, "classify_vertices", counting)
    d = filletfold.round_mesh("torus")
    assert counts == [d.mesh.n_vertices]
    saddles = [u for u, s in enumerate(d.vertices.status) if s == "saddle"]
    assert len(saddles) == 24
    ends = d.mesh.edges
    lone = [u for u in saddles if (d.rounding.radius[(ends == u).any(axis=1)] == 0).all()]
    assert lone, "the torus has saddles whose edges are all left unrounded"
    for u in saddles:
        assert d.vertices.treatment[u] == "sharp"
        assert d.vertices.reason[u].startswith("saddle vertex: no plane through it")
        assert d.vertices.reason[u].endswith("; kept sharp (its corner, no hole)")
    assert d.certificate.ok
