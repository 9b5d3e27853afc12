"""Crease patterns and designs the export tests share."""

from __future__ import annotations

import io
import math
import re

import ezdxf
import numpy as np
import pytest

import filletfold
from filletfold.export.paths import tab_cut_paths
from filletfold.surface.pattern import Annotations, CreasePattern, Label

SVG_NS = "{http://www.w3.org/2000/svg}"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


# ---------------------------------------------------------------- patterns


def arc_pattern(n: int = 40, annotated: bool = False) -> CreasePattern:
    """A half annulus in three rings (radii 1, 1.5, 2, 2.5) of ``n`` quads each.

    The arc at radius 1.5 is a mountain crease (-30 degrees), the arc at 2 a valley (+45);
    radial edges are flat, the outline is a border. Flat in 3D (the exporters do not look).
    """
    t = np.linspace(0.0, math.pi, n + 1)
    radii = (1.0, 1.5, 2.0, 2.5)
    v2 = np.vstack([np.c_[r * np.cos(t), r * np.sin(t)] for r in radii])
    v3 = np.c_[v2, np.zeros(len(v2))]
    faces, patches = [], []
    for ring, kind in enumerate(("cone 0", "cylinder 1", "face 2")):
        a, b = ring * (n + 1), (ring + 1) * (n + 1)
        for i in range(n):
            faces.append([a + i + 1, a + i, b + i, b + i + 1])
            patches.append(kind)
    base = CreasePattern(v2, v3, faces, patches, np.zeros(len(faces), dtype=int), [0])
    edges = base.edges
    lo, hi = edges[:, 0], edges[:, 1]
    ring_of = np.arange(len(v2)) // (n + 1)
    same_ring = ring_of[lo] == ring_of[hi]
    assign = np.full(len(edges), "F", dtype="<U1")
    angle = np.zeros(len(edges))
    assign[same_ring & (ring_of[lo] == 1)] = "M"
    angle[same_ring & (ring_of[lo] == 1)] = -30.0
    assign[same_ring & (ring_of[lo] == 2)] = "V"
    angle[same_ring & (ring_of[lo] == 2)] = 45.0
    assign[(base.edge_faces < 0).any(axis=1)] = "B"
    ann = Annotations()
    if annotated:
        # a trapezoid tab on the inner border segment at the right end (x from 1 to 2.5, y = 0)
        tab = np.array([[1.0, 0.0], [1.2, -0.2], [2.3, -0.2], [2.5, 0.0]])
        ann = Annotations(
            tabs=[tab],
            tab_hinges=[np.array([[1.0, 0.0], [2.5, 0.0]])],
            labels=[
                Label(np.array([0.0, 1.75]), "P1", 0.0, 0.2, "part"),
                Label(np.array([1.75, -0.1]), "7", 30.0, 0.08, "tab"),
            ],
            sheets=np.array([[-2.6, -0.3, 2.6, 2.6]]),
        )
    return CreasePattern(
        v2,
        v3,
        faces,
        patches,
        np.zeros(len(faces), dtype=int),
        [0],
        edges=edges,
        edge_assignment=assign,
        edge_fold_angle=angle,
        edge_faces=base.edge_faces,
        annotations=ann,
    )


@pytest.fixture(scope="module")
def cube():
    """The real cube design (with the tabs, labels and sheets the pipeline adds, if any)."""
    return filletfold.round_mesh("cube")


def edge_length(pattern: CreasePattern, code: str) -> float:
    e = pattern.edges[pattern.edge_assignment == code]
    return float(np.linalg.norm(np.diff(pattern.vertices_2d[e], axis=1)[:, 0], axis=1).sum())


def tab_lengths(ann: Annotations) -> tuple[float, float]:
    """(cut length of all tab outlines without hinges, total hinge length)."""
    cut = 0.0
    for p, closed in tab_cut_paths(ann):
        q = np.vstack([p, p[:1]]) if closed else p
        cut += float(np.linalg.norm(np.diff(q, axis=0), axis=1).sum())
    hinge = sum(float(np.linalg.norm(np.diff(h, axis=0))) for h in ann.tab_hinges)
    return cut, hinge


def read_dxf(text: str):
    doc = ezdxf.read(io.StringIO(text))
    auditor = doc.audit()
    assert not auditor.has_errors, [str(e) for e in auditor.errors]
    return doc


def layer_lengths(doc) -> dict:
    """Per layer: (length of polylines + spline fit polylines, list of (spline, fit) lengths)."""
    out: dict = {}
    for e in doc.modelspace():
        splines = out.setdefault(e.dxf.layer, [0.0, []])[1]
        if e.dxftype() == "LWPOLYLINE":
            p = np.array(e.get_points("xy"))
            if e.closed:
                p = np.vstack([p, p[:1]])
            out[e.dxf.layer][0] += float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
        elif e.dxftype() == "SPLINE":
            fit = np.array(e.fit_points)[:, :2]
            fit_len = float(np.linalg.norm(np.diff(fit, axis=0), axis=1).sum())
            flat = np.array(list(e.construction_tool().flattening(1e-6 * fit_len)))
            spline_len = float(np.linalg.norm(np.diff(flat, axis=0), axis=1).sum())
            out[e.dxf.layer][0] += fit_len
            splines.append((spline_len, fit_len))
        elif e.dxftype() == "LINE":
            out[e.dxf.layer][0] += float(np.linalg.norm(np.subtract(e.dxf.end, e.dxf.start)))
    return out


def layer_lengths_of(pattern: CreasePattern) -> dict[str, float]:
    """The length each cut-file layer should draw: CUT the borders and the tab outlines,
    MOUNTAIN and VALLEY their creases, TAB the tab hinges (pattern units)."""
    tab_cut, hinge = tab_lengths(pattern.annotations)
    return {
        "CUT": edge_length(pattern, "B") + tab_cut,
        "MOUNTAIN": edge_length(pattern, "M"),
        "VALLEY": edge_length(pattern, "V"),
        "TAB": hinge,
    }


def check_lengths(doc, pattern: CreasePattern, scale: float = 1.0) -> None:
    lengths = layer_lengths(doc)
    expected = layer_lengths_of(pattern)
    for layer, want in expected.items():
        got, splines = lengths.get(layer, (0.0, []))
        assert got == pytest.approx(want * scale, rel=1e-6, abs=1e-9), layer
        for spline_len, fit_len in splines:
            assert spline_len == pytest.approx(fit_len, rel=1e-3), layer


def pdf_pages(data: bytes) -> int:
    return len(re.findall(rb"/Type\s*/Page(?![a-zA-Z])", data))
