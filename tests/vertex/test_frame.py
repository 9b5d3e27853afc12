"""Batched vertex frames (``vertex_frames``) against a straightforward per-vertex build."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from filletfold.errors import MeshError
from filletfold.mesh import example_mesh, example_names, load_mesh
from filletfold.mesh.polymesh import PolyMesh, VertexRing
from filletfold.rounding.edges import round_edges
from filletfold.vertex.frame import (
    Side,
    VertexFrame,
    _line_crossings,
    vertex_frame,
    vertex_frames,
)

from ..conftest import random_convex

ATOL = 1e-12  # on lengths divided by the mesh's mean edge length


# ---------------------------------------------------------------- per-vertex reference
# A plain, one-vertex-at-a-time build (the formulas of sec. 2.1, 2.4 written out with scalar
# numpy calls); it shares no code with the batched builder beyond the data classes.


def _rigid(linear, t):
    m = np.eye(3)
    m[:2, :2] = linear
    m[:2, 2] = t
    return m


def _invert(m):
    q = m[:2, :2].T
    return _rigid(q, -q @ m[:2, 2])


def _face_frame(mesh, f, origin):
    n = mesh.face_normal[f]
    face = mesh.faces[f]
    d = mesh.vertices[face[1]] - mesh.vertices[face[0]]
    e1 = d / np.linalg.norm(d)
    return np.stack([origin, e1, np.cross(n, e1)])


def _side(mesh, rounding, u, e, n_prev, n_next):
    a, b = mesh.edges[e]
    other = b if a == u else a
    d = mesh.vertices[u] - mesh.vertices[other]
    length = float(np.linalg.norm(d))
    R = d / length
    M = 0.5 * (mesh.vertices[u] + mesh.vertices[other])
    common = {"edge": int(e), "R": R, "M": M, "length": length}
    if n_prev is None or n_next is None:
        return Side(rounded=False, **common)
    r = float(rounding.radius[e])
    if r <= 0:
        return Side(rounded=True, O=M, N0=n_prev, B=np.cross(R, n_prev), **common)
    B = np.cross(R, n_prev)  # across the edge, turned toward the next face's normal
    B *= np.sign(B @ n_next)
    return Side(
        rounded=True,
        radius=r,
        gamma=float(rounding.half_angle[e]),
        arc=float(rounding.arc_length[e]),
        kappa=int(rounding.kappa[e]),
        O=rounding.axis_point[e],
        N0=n_prev,
        B=B,
        **common,
    )


def _point(side, s):
    if not side.rounded:
        return side.M
    if side.radius == 0:
        return side.O + 0.0 * side.N0
    t = s / side.radius
    return side.O + side.kappa * side.radius * (np.cos(t) * side.N0 + np.sin(t) * side.B)


def _tangent(side, s):
    if side.radius == 0:
        return np.cross(side.R, side.N0)
    t = s / side.radius
    return side.kappa * (-np.sin(t) * side.N0 + np.cos(t) * side.B)


def _gluing(side, frame, s):
    tan = _tangent(side, s)
    if side.radius == 0:  # a flat or sharp side meets each face along its own line
        tan = np.cross(side.R, np.cross(frame[1], frame[2]))
    lin = np.array([[tan @ frame[1], side.R @ frame[1]], [tan @ frame[2], side.R @ frame[2]]])
    q = _point(side, s) - frame[0]
    p = np.array([q @ frame[1], q @ frame[2]])
    return _rigid(lin, p - lin @ np.array([s, 0.0]))


def _crossing(p1, d1, p2, d2):
    delta = p2 - p1
    c = float(d1 @ d2)
    a, b = float(d1 @ delta), float(d2 @ delta)
    det = 1.0 - c * c
    if det < 1e-12:
        z, *_ = np.linalg.lstsq(np.stack([d1, -d2], axis=1), delta, rcond=None)
        return float(z[0]), float(z[1])
    return (a - c * b) / det, (c * a - b) / det


def reference_frame(mesh, rounding, u, start_edge=None) -> VertexFrame:
    """The frame of vertex ``u``, built side by side and face by face."""
    ring = mesh.vertex_ring(u)
    if ring.closed and start_edge is not None:
        hit = np.nonzero(ring.edges == start_edge)[0]
        if len(hit):
            k = int(hit[0])
            ring = VertexRing(
                vertex=ring.vertex,
                edges=np.roll(ring.edges, -k),
                faces=np.roll(ring.faces, -k),
                neighbors=np.roll(ring.neighbors, -k),
                closed=True,
            )
    U = mesh.vertices[u]
    nf, ne = len(ring.faces), len(ring.edges)
    normals = mesh.face_normal[ring.faces]
    sides = []
    for i, e in enumerate(ring.edges):
        prev = normals[i - 1] if (ring.closed or i > 0) else None
        nxt = normals[i] if (ring.closed or i < nf) else None
        sides.append(_side(mesh, rounding, u, int(e), prev, nxt))
    frames = [_face_frame(mesh, int(f), U) for f in ring.faces]
    angles = mesh.corner_angles()
    corner = np.array([angles[mesh.halfedge(u, int(q))] for q in ring.neighbors[:nf]])
    lmax_start, lmax_end = np.full(ne, np.nan), np.full(ne, np.nan)
    T_start, T_end = np.full((ne, 3), np.nan), np.full((ne, 3), np.nan)
    for i in range(nf):
        j = (i + 1) % ne
        s1, s2 = sides[i], sides[j]
        p1, p2 = _point(s1, s1.arc), _point(s2, 0.0)
        z1, z2 = _crossing(p1, s1.R, p2, s2.R)
        lmax_end[i], lmax_start[j] = z1, z2
        T_end[i], T_start[j] = p1 + z1 * s1.R, p2 + z2 * s2.R
    cyl_map, face_map, rho = [None] * ne, [None] * nf, None
    if ring.closed:
        current = np.eye(3)
        for i in range(ne):
            cyl_map[i] = current @ _gluing(sides[i], frames[(i - 1) % nf], 0.0)
            current = cyl_map[i] @ _invert(_gluing(sides[i], frames[i], sides[i].arc))
            face_map[i] = current
        rho = current
    else:
        face_map[0] = np.eye(3)
        for i in range(1, ne - 1):
            cyl_map[i] = face_map[i - 1] @ _gluing(sides[i], frames[i - 1], 0.0)
            face_map[i] = cyl_map[i] @ _invert(_gluing(sides[i], frames[i], sides[i].arc))
    return VertexFrame(
        vertex=u,
        ring=ring,
        U=U,
        sides=sides,
        face_frames=frames,
        cyl_map=cyl_map,
        face_map=face_map,
        rho=rho,
        lmax_start=lmax_start,
        lmax_end=lmax_end,
        T_start=T_start,
        T_end=T_end,
        corner_angle=corner,
    )


# ---------------------------------------------------------------- comparison


def _close(a, b, atol, what):
    if a is None or b is None:
        assert a is None and b is None, what
        return
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape, what
    assert np.array_equal(np.isnan(a), np.isnan(b)), what
    ok = ~np.isnan(a)
    assert np.all(np.abs(a[ok] - b[ok]) <= atol), (what, np.abs(a[ok] - b[ok]).max())


def assert_same_frame(got: VertexFrame, ref: VertexFrame, scale: float):
    """Every field equal within ``ATOL`` (lengths in units of ``scale``)."""
    tol = ATOL * scale
    u = ref.vertex
    assert got.vertex == u
    for name in ("edges", "faces", "neighbors"):
        assert np.array_equal(getattr(got.ring, name), getattr(ref.ring, name)), (u, name)
    assert got.ring.vertex == ref.ring.vertex and got.ring.closed == ref.ring.closed
    _close(got.U, ref.U, 0, (u, "U"))
    assert got.n_sides == ref.n_sides
    for i, (a, b) in enumerate(zip(got.sides, ref.sides, strict=True)):
        what = (u, "side", i)
        assert (a.edge, a.rounded, a.kappa, a.flat) == (b.edge, b.rounded, b.kappa, b.flat), what
        assert type(a.edge) is int and type(a.kappa) is int, what
        for f in ("R", "N0", "B", "gamma"):
            _close(getattr(a, f), getattr(b, f), ATOL, (*what, f))
        for f in ("M", "O", "length", "radius", "arc"):
            _close(getattr(a, f), getattr(b, f), tol, (*what, f))
    assert len(got.face_frames) == len(ref.face_frames)
    for i, (a, b) in enumerate(zip(got.face_frames, ref.face_frames, strict=True)):
        _close(a[0], b[0], tol, (u, "face origin", i))
        _close(a[1:], b[1:], ATOL, (u, "face axes", i))
    for name in ("cyl_map", "face_map"):
        ga, ra = getattr(got, name), getattr(ref, name)
        assert len(ga) == len(ra), (u, name)
        for i, (a, b) in enumerate(zip(ga, ra, strict=True)):
            if a is None or b is None:
                assert a is None and b is None, (u, name, i)
                continue
            _close(a[:, :2], b[:, :2], ATOL, (u, name, i, "linear"))
            _close(a[:, 2], b[:, 2], tol, (u, name, i, "translation"))
    if ref.rho is None:
        assert got.rho is None
    else:
        _close(got.rho[:, :2], ref.rho[:, :2], ATOL, (u, "rho"))
        _close(got.rho[:, 2], ref.rho[:, 2], tol, (u, "rho"))
    for name in ("lmax_start", "lmax_end", "T_start", "T_end"):
        _close(getattr(got, name), getattr(ref, name), tol, (u, name))
    _close(got.corner_angle, ref.corner_angle, ATOL, (u, "corner_angle"))
    if got.ring.closed:
        assert "arrays" in got.__dict__, u  # filled in by the batch
        pre = got.arrays
        del got.__dict__["arrays"]
        built = got.arrays  # the property, from the Side objects
        for name in ("edge", "kappa"):
            assert np.array_equal(getattr(pre, name), getattr(built, name)), (u, name)
        assert pre.edge.dtype == built.edge.dtype and pre.kappa.dtype == built.kappa.dtype
        for name in ("R", "M", "O", "N0", "B", "radius", "arc", "length", "Q", "t"):
            _close(getattr(pre, name), getattr(built, name), 0, (u, "arrays", name))
        _close(pre.face_normal, built.face_normal, 0, (u, "arrays face_normal"))
    else:
        assert "arrays" not in got.__dict__


def check_mesh(mesh, rounding, vertices=None, start_edges=None):
    if vertices is None:
        vertices = list(range(mesh.n_vertices))
    got = vertex_frames(mesh, rounding, vertices, start_edges)
    assert len(got) == len(vertices)
    starts = [None] * len(vertices) if start_edges is None else start_edges
    scale = mesh.mean_edge_length
    for frame, u, e in zip(got, vertices, starts, strict=True):
        assert_same_frame(frame, reference_frame(mesh, rounding, u, e), scale)
    return got


def _mesh(name):
    return load_mesh(name)[0]


def _rounding(mesh, share=0.1):
    return round_edges(mesh, share * mesh.mean_edge_length)


# ---------------------------------------------------------------- tests


@pytest.mark.parametrize("name", example_names())
def test_every_example_matches_the_per_vertex_build(name):
    m = _mesh(name)
    check_mesh(m, _rounding(m))


@pytest.mark.parametrize("name", ["open-box", "tent", "saddle-patch", "miura"])
def test_open_meshes_have_boundary_sides(name):
    m = _mesh(name)
    frames = check_mesh(m, _rounding(m))
    open_frames = [f for f in frames if not f.ring.closed]
    assert open_frames
    for f in open_frames:
        assert not f.sides[0].rounded and not f.sides[-1].rounded
        assert f.cyl_map[0] is None and f.cyl_map[-1] is None
        assert f.rho is None and np.isnan(f.lmax_start[0]) and np.isnan(f.lmax_end[-1])
        assert np.array_equal(f.face_map[0], np.eye(3))


@pytest.mark.parametrize("name", ["icosahedron", "blob", "torus", "miura", "l-prism"])
def test_random_start_edges(name):
    m = _mesh(name)
    rd = _rounding(m)
    rng = np.random.default_rng(7)
    verts = list(rng.permutation(m.n_vertices))
    verts += verts[:5]  # repeated vertices, with other start edges
    starts = []
    for u in verts:
        ring = m.vertex_ring(int(u))
        pick = rng.integers(4)
        starts.append(
            None if pick == 0 else int(rng.integers(m.n_edges)) if pick == 1 else
            int(rng.choice(ring.edges))
        )  # fmt: skip
    check_mesh(m, rd, verts, starts)


def _split_cube():
    """A unit cube whose faces are split into triangles: 6 flat diagonals (+ 1 flat quad pair)."""
    v, faces = example_mesh("cube")
    tris = [t for f in faces for t in ([f[0], f[1], f[2]], [f[0], f[2], f[3]])]
    return PolyMesh(v, tris)


def test_flat_edges():
    m = _split_cube()
    rd = _rounding(m)
    flat = (rd.radius == 0) & ~m.is_boundary_edge
    assert flat.sum() == 6
    frames = check_mesh(m, rd)
    assert any(s.flat for f in frames for s in f.sides)
    # and with start edges on the flat diagonals
    starts = [int(next((e for e in f.ring.edges if flat[e]), f.ring.edges[-1])) for f in frames]
    check_mesh(m, rd, list(range(m.n_vertices)), starts)


def test_flat_open_sheet_with_straight_corners():
    """A flat 3x3 grid of quads, cut into triangles on one side, two quads merged into a hexagon.

    Every interior edge is flat (nothing is rounded); the hexagon has two corners of pi, where
    consecutive sides' lines are the same line (the least-squares fallback).
    """
    xs, ys = np.meshgrid(np.arange(4.0), np.arange(4.0), indexing="ij")
    v = np.stack([xs.ravel(), ys.ravel(), np.zeros(16)], axis=1)
    faces = [[8, 12, 13, 14, 10, 9]]
    for i in range(3):
        for j in range(3):
            a, b, c, d = 4 * i + j, 4 * (i + 1) + j, 4 * (i + 1) + j + 1, 4 * i + j + 1
            if i < 2:
                faces += [[a, b, c], [a, c, d]] if i == 0 else [[a, b, c, d]]
            elif j == 2:
                faces.append([a, b, c, d])
    m = PolyMesh(v, faces)
    rd = _rounding(m)
    assert np.all(rd.radius == 0)
    frames = check_mesh(m, rd)
    assert np.isclose(np.concatenate([f.corner_angle for f in frames]), np.pi).sum() == 2


def test_cube_with_an_edge_midpoint_vertex():
    """A vertex of valence 2 on a rounded edge: its two sides' lines coincide on both faces."""
    v, _ = example_mesh("cube")
    v = np.vstack([v, 0.5 * (v[0] + v[1])])
    faces = [[0, 8, 1, 3, 2], [0, 2, 6, 4], [0, 4, 5, 1, 8], [1, 5, 7, 3], [2, 3, 7, 6]]
    m = PolyMesh(v, [*faces, [4, 6, 7, 5]])
    rd = round_edges(m, 0.1)
    frames = check_mesh(m, rd)
    mid = frames[8]
    assert mid.n_sides == 2 and np.allclose(mid.corner_angle, np.pi)
    assert np.allclose(mid.lmax_start, 0.25) and np.allclose(mid.lmax_end, 0.25)


def test_line_crossings_parallel_fallback_matches_lstsq():
    rng = np.random.default_rng(3)
    d1 = rng.normal(size=(40, 3))
    d1 /= np.linalg.norm(d1, axis=1)[:, None]
    tilt = rng.normal(size=(40, 3)) * np.repeat([0.0, 1e-9, 1e-3, 0.5], 10)[:, None]
    d2 = d1 * np.where(np.arange(40) % 2, 1.0, -1.0)[:, None] + tilt
    d2 /= np.linalg.norm(d2, axis=1)[:, None]
    p1, p2 = rng.normal(size=(40, 3)), rng.normal(size=(40, 3))
    z1, z2 = _line_crossings(p1, d1, p2, d2)
    for k in range(40):
        r1, r2 = _crossing(p1[k], d1[k], p2[k], d2[k])
        scale = max(1.0, abs(r1), abs(r2))  # up to 1e9 where the lines are nearly parallel
        assert abs(z1[k] - r1) <= 1e-14 * scale and abs(z2[k] - r2) <= 1e-14 * scale, k


def test_vertex_frame_is_one_vertex_of_the_batch():
    m = _mesh("house")
    rd = _rounding(m)
    for u in range(m.n_vertices):
        e = int(m.vertex_ring(u).edges[-1])
        assert_same_frame(vertex_frame(m, rd, u, e), reference_frame(m, rd, u, e), 1.0)
    assert vertex_frames(m, rd, []) == []


def test_bad_vertices_raise_like_vertex_ring():
    v, faces = example_mesh("tetrahedron")
    m = PolyMesh(np.vstack([v, [[9.0, 9.0, 9.0]]]), faces)  # vertex 4 is in no face
    rd = _rounding(m)
    with pytest.raises(MeshError, match="not used by any face"):
        vertex_frames(m, rd, [0, 4])
    with pytest.raises(ValueError, match="start edges"):
        vertex_frames(m, rd, [0, 1], [None])
    # two tetrahedra sharing one vertex: a non-manifold vertex (two fans)
    w = np.vstack([v, v[1:] + np.array([3.0, 0.0, 0.0])])
    second = [np.where(f == 0, 0, f + 3) for f in faces]
    m2 = PolyMesh(w, [*faces, *second])
    with pytest.raises(MeshError, match="non-manifold vertex 0"):
        vertex_frames(m2, round_edges(m2, 0.01), [1, 0])


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 10_000), share=st.floats(0.05, 0.5))
def test_random_convex_polyhedra(seed, share):
    v, f = random_convex(seed)
    m = load_mesh((v, f))[0]
    limit = round_edges(m, 1e-6 * m.mean_edge_length).uniform_limit
    rd = round_edges(m, share * limit)
    check_mesh(m, rd)


# vertex 1377 of pyvista's ant, Loop-subdivided once (corpus2): a ring of six triangles at
# |U| = 19 with a sliver (edges 0.18, 0.18, 0.0048), the centre vertex 4
ANT_RING = np.array(
    [
        [-15.666474015737453, -9.186267662506397, -7.37952590531504],
        [-15.41260411693401, -8.942165355341332, -7.382787227610319],
        [-15.366250038146973, -8.856375217437744, -7.255250096321106],
        [-14.99500024318695, -8.48912525177002, -7.25837504863739],
        [-15.65375006198883, -9.262125253677368, -7.387375056743622],
        [-15.778749823570251, -9.37850022315979, -7.440249979496002],
        [-15.775000095367432, -9.381250262260437, -7.441499948501587],
    ]
)
ANT_FACES = [[2, 0, 4], [3, 4, 1], [2, 4, 3], [1, 4, 6], [4, 0, 5], [4, 5, 6]]


def test_gluing_maps_are_rigid_on_a_sliver_far_from_the_origin():
    # The face normals (Newell's sum) were taken about the origin and came out 2e-11 rad off
    # the sliver's plane; the face charts' axes then missed the tangent lines by as much, the
    # maps into the common frame were 2e-11 from orthogonal and the folded pattern edges of
    # this vertex came out 2.8e-12 longer than flat (the certificate's contraction check)
    m = PolyMesh(ANT_RING, ANT_FACES)
    rd = round_edges(m, 0.5 * round_edges(m, 1e-6 * m.mean_edge_length).uniform_limit)
    frame = vertex_frame(m, rd, 4)
    assert frame.ring.closed
    for f, axes in zip(frame.ring.faces, frame.face_frames, strict=True):
        assert np.abs(axes[1:] @ m.face_normal[f]).max() < 1e-15
    maps = frame.cyl_maps[frame.rounded]
    lin = maps[:, :2, :2]
    off = np.abs(lin.transpose(0, 2, 1) @ lin - np.eye(2)).max()
    assert off < 1e-14  # was 2e-11
    rho = frame.rho[:2, :2]
    assert np.abs(rho.T @ rho - np.eye(2)).max() < 1e-14


# ---- conical sides (a sharp neighbour): docs/method.md, "Sharp vertices and conical fillets"


def _sharp_case(name, seed):
    m = load_mesh(name)[0]
    rd = round_edges(m, 0.08 * m.mean_edge_length)
    rng = np.random.default_rng(seed)
    sharp = rng.random(m.n_vertices) < 0.3
    return m, rd, sharp


@pytest.mark.parametrize("name", ["cube", "icosahedron", "random-convex", "dimpled-cube"])
def test_conical_sides_chain_their_fillets_gluing_maps(name):
    """With sharp neighbours, rho is the chain of the fillets' and cylinders' gluing maps
    (the chain of tests/rounding/test_tapered.py), T lies on both faces' lines, and the
    frames of vertices with no sharp neighbour are unchanged."""
    from ..rounding.test_tapered import Chart, chain

    m, rd, sharp = _sharp_case(name, 3)
    verts = list(range(m.n_vertices))
    plain = vertex_frames(m, rd, verts)
    frames = vertex_frames(m, rd, verts, sharp=sharp)
    n_conical = 0
    for f0, f in zip(plain, frames, strict=True):
        cone = f.arrays.conical
        n_conical += int(cone.sum())
        if sharp[f.vertex]:
            assert not cone.any()  # a sharp vertex's own sides stay as they are
        want = sharp[f.ring.neighbors] & (f.arrays.radius > 0) & ~sharp[f.vertex]
        np.testing.assert_array_equal(cone, want)
        if not cone.any():
            np.testing.assert_array_equal(f.rho, f0.rho)
            continue
        _, rho = chain(f0, [Chart(s, bool(c)) for s, c in zip(f0.sides, cone, strict=True)])
        np.testing.assert_allclose(f.rho, rho, atol=1e-13)
        for i in range(len(f.ring.faces)):
            j = (i + 1) % len(f.sides)
            C, R, _, _ = f.arrays.chart(np.array([i, j]), np.array([f.arrays.arc[i], 0.0]))
            # T_end of side i on its end ruling, T_start of side j on its start ruling
            for T, c, r, z in ((f.T_end[i], C[0], R[0], f.lmax_end[i]),
                               (f.T_start[j], C[1], R[1], f.lmax_start[j])):  # fmt: skip
                np.testing.assert_allclose(T, c + z * r, atol=1e-12)
            np.testing.assert_allclose(f.T_end[i], f.T_start[j], atol=1e-10)
    assert n_conical > 0


def test_row_maps_read_eq1_on_a_fillet_as_on_a_cylinder():
    """crease_numerator / crease_denominator through the per-row charts are the ruled eq. (1)
    of rounding.tapered, on cylinders and fillets alike."""
    from filletfold.rounding.tapered import crease_height_ruled
    from filletfold.vertex.crease import chart_apex, crease_denominator, crease_numerator

    m, rd, sharp = _sharp_case("icosahedron", 5)
    frames = vertex_frames(m, rd, list(range(m.n_vertices)), sharp=sharp)
    rng = np.random.default_rng(0)
    checked = 0
    for f in frames:
        sa = f.arrays
        side = np.repeat(np.arange(len(sa.arc)), 5)
        s = sa.arc[side] * rng.random(len(side))
        V = f.U + 0.3 * rng.standard_normal(3)
        v = 0.1 * rng.standard_normal(2)
        C, R, c, r = sa.chart(side, s)
        vi = chart_apex(sa.Q[side], sa.t[side], v)
        _, num_w, dn_w = crease_height_ruled(V, vi, C, R, c, r)
        Q, t, R_row, M_row = sa.row_maps(side, s)
        v_row = chart_apex(Q, t, v)
        num = crease_numerator(V, v_row, s, C)
        dn = crease_denominator(V, v_row, M_row, R_row)
        np.testing.assert_allclose(num, num_w, atol=1e-12)
        np.testing.assert_allclose(dn, dn_w, atol=1e-12)
        checked += int(sa.conical.any())
    assert checked > 0


def test_a_fillets_surface_normal_is_the_faces_at_its_ends():
    m, rd, sharp = _sharp_case("cube", 1)
    for f in vertex_frames(m, rd, list(range(m.n_vertices)), sharp=sharp):
        sa = f.arrays
        k = np.flatnonzero(sa.conical)
        if not len(k):
            continue
        n0 = sa.surface_normal(k, np.zeros(len(k)))
        n1 = sa.surface_normal(k, sa.arc[k])
        faces = np.asarray(f.ring.faces)
        np.testing.assert_allclose(n0, m.face_normal[faces[(k - 1) % len(faces)]], atol=1e-12)
        np.testing.assert_allclose(n1, m.face_normal[faces[k]], atol=1e-12)
