"""Batched dense validation of apices (:func:`~filletfold.vertex.apex.validate_apices`).

Every vertex's check must be the same as a straightforward one-vertex validation: the
reference below is the per-vertex implementation the batched one replaced, kept here only.
"""

from __future__ import annotations

import numpy as np
import pytest

import filletfold
from filletfold.tolerances import tol
from filletfold.vertex.apex import KINDS, ApexCheck, validate_apex, validate_apices

from ..conftest import design_of

EXAMPLES = ["icosahedron", "cube", "dimpled-cube", "l-prism", "torus", "blob", "conical-dome"]


def _reference_validate(frame, V, v, sigma, n_samples=65, centres=None) -> ApexCheck:
    """One vertex on its own (the former ``validate_apex``)."""
    sa = frame.arrays
    k = len(sa.arc)
    scale = float(sa.length.mean())
    eps = tol.validate * scale
    side, first, last, s, C, N = sa.samples(n_samples)
    vi = np.einsum("kij,j->ki", sa.Q, v) + sa.t
    d = V - C
    num = (vi[side, 0] - s) ** 2 + vi[side, 1] ** 2 - np.einsum("ij,ij->i", d, d)
    dn = vi[:, 1] - np.einsum("ij,ij->i", V - sa.M, sa.R)
    valid = dn > 0
    l = 0.5 * num / np.where(valid, dn, 1.0)[side]
    nonint = sigma * np.einsum("ij,ij->i", d, N)
    l_min = _reference_refined_min(sa, V, l, s, first, vi=vi, dn=dn)
    nonint_min = _reference_refined_min(sa, V, nonint, s, first, sigma=sigma)
    # the curved crease's fold: across F(s) the cone leaves along V - F and the cylinder along
    # -R, both made normal to F'(s) = C'(s) + l'(s) R, with l' = num' / (2 dn) and
    # num' = -2 (v_x - s) + 2 (V - C) . C'; their angle is at least tol.fold
    r = np.where(sa.radius[side] > 0, sa.radius[side], 1.0)
    dC = sa.kappa[side, None] * (
        -np.sin(s / r)[:, None] * sa.N0[side] + np.cos(s / r)[:, None] * sa.B[side]
    )
    dnum = -2 * (vi[side, 0] - s) + 2 * np.einsum("ij,ij->i", d, dC)
    dF = dC + (0.5 * dnum / np.where(valid, dn, 1.0)[side])[:, None] * sa.R[side]
    u = dF / np.linalg.norm(dF, axis=1)[:, None]
    cone = d - l[:, None] * sa.R[side]
    cone -= np.einsum("ij,ij->i", cone, u)[:, None] * u
    cyl = -sa.R[side] + np.einsum("ij,ij->i", sa.R[side], u)[:, None] * u
    norm = np.linalg.norm(cyl, axis=1)
    cyl /= np.where(norm > 0, norm, 1.0)[:, None]
    crease = np.cos(tol.fold) * nonint - np.sin(tol.fold) * np.einsum("ij,ij->i", cone, cyl)
    measured = valid[side] & (sa.radius[side] > 0) & ~sa.conical[side]
    crease = np.minimum.reduceat(np.where(measured, crease, np.inf), first)
    checks = np.stack(
        [
            dn,
            np.where(valid, l_min, -np.inf),
            np.where(
                valid,
                np.minimum(frame.lmax_start - l[first], frame.lmax_end - l[last]),
                -np.inf,
            ),
            nonint_min,
            crease,
        ],
        axis=1,
    )
    slack = [checks.ravel()]
    failing = []
    strict = np.array([True, False, False, True, True])
    bad = np.where(strict, checks < eps, checks < -eps)
    names = ("patch", "l_min", "l_max", "nonint", "crease")
    for i, c in zip(*np.nonzero(bad), strict=True):
        failing.append(f"{KINDS[names[c]]} at edge {sa.edge[i]}")
    nf = len(frame.ring.faces)
    n = sa.face_normal
    face_val = sigma * np.einsum("ij,ij->i", V - frame.T_end[:nf], n)
    slack.append(face_val)
    nxt = (np.arange(nf) + 1) % k
    p0 = C[last[:nf]] + l[last[:nf], None] * sa.R[:nf]
    p1 = C[first[nxt]] + l[first[nxt], None] * sa.R[nxt]
    dvec = p1 - p0
    length = np.linalg.norm(dvec, axis=1)
    dvec = dvec / np.where(length > eps, length, 1.0)[:, None]
    side_t = np.einsum("ij,ij->i", np.cross(dvec, frame.T_end[:nf] - p0), n)
    # the fold: the apex's foot on the face, its distance from the crease line (positive on
    # the far side from T), and the angle atan2(height, distance) of the cone triangle
    rel = V - p0
    foot = rel - np.einsum("ij,ij->i", rel, n)[:, None] * n
    side_v = np.einsum("ij,ij->i", np.cross(dvec, foot), n)
    w = -np.sign(side_t) * side_v
    fold_val = np.cos(tol.fold) * face_val - np.sin(tol.fold) * w
    fold_val = np.where(length > eps, fold_val, np.inf)
    slack.append(fold_val[length > eps])
    centre_val = np.full(nf, np.inf)
    if centres is not None:
        side_c = np.einsum("ij,ij->i", np.cross(dvec, centres[frame.ring.faces] - p0), n)
        centre_val = np.where(side_t != 0, -side_c * np.sign(side_t), np.abs(side_c))
        centre_val = np.where(length > eps, centre_val, np.inf)
        slack.append(centre_val[length > eps])
    for i, f in enumerate(frame.ring.faces):
        if face_val[i] < eps:
            failing.append(f"{KINDS['face']} at face {int(f)}")
        if centre_val[i] < eps:
            failing.append(f"{KINDS['centre']} on face {int(f)}")
        if fold_val[i] < eps:
            failing.append(f"{KINDS['fold']} at face {int(f)}")
    return ApexCheck(not failing, float(np.min(np.concatenate(slack))), failing)


def _reference_refined_min(sa, V, values, s, first, *, vi=None, dn=None, sigma=1):
    """Smallest value per side of one vertex: its smallest sample, refined by Newton steps."""
    ends = np.append(first[1:], len(values))
    best = np.minimum.reduceat(values, first)
    r, arc = sa.radius, sa.arc
    ok = r > 0
    if not ok.any():
        return best
    side = np.repeat(np.arange(len(first)), ends - first)
    hit = np.flatnonzero(values == best[side])
    arg = hit[np.unique(side[hit], return_index=True)[1]]
    t = s[arg].copy()
    rr = np.where(ok, r, 1.0)
    P = np.einsum("ij,ij->i", V - sa.O, sa.N0)
    Q = np.einsum("ij,ij->i", V - sa.O, sa.B)
    for _ in range(4):
        c, sn = np.cos(t / rr), np.sin(t / rr)
        if vi is not None:
            d1 = -2 * (vi[:, 0] - t) + 2 * sa.kappa * (-P * sn + Q * c)
            d2 = 2 + 2 * sa.kappa / rr * (-P * c - Q * sn)
        else:
            d1 = sigma / rr * (-P * sn + Q * c)
            d2 = sigma / rr**2 * (-P * c - Q * sn)
        step = np.where(d2 > 0, d1 / np.where(d2 > 0, d2, 1.0), 0.0)
        t = np.clip(t - step, 0.0, arc)
    i = np.arange(len(first))
    C = sa.base(i, t)
    if vi is not None:
        dv = V - C
        num = (vi[:, 0] - t) ** 2 + vi[:, 1] ** 2 - np.einsum("ij,ij->i", dv, dv)
        val = 0.5 * num / np.where(dn > 0, dn, 1.0)
    else:
        val = sigma * np.einsum("ij,ij->i", V - C, sa.normal(i, t))
    return np.where(ok, np.minimum(best, val), best)


def _cases(name):
    """Frames, centres and the solved (V, v, sigma) of every vertex with a cone (with holes:
    the reference has no conical fillets)."""
    d = design_of(name, sharp="none")
    res = d.vertices
    us = [u for u in range(d.mesh.n_vertices) if res.status[u] == "ok"]
    frames = [d.stages.frames[u] for u in us]
    V = np.array([res.apex[u] for u in us])
    v = np.array([res.apex_developed[u] for u in us])
    sigma = np.array([int(res.sigma[u]) for u in us])
    return frames, d.stages.centres, V, v, sigma


def _perturbed(frames, V, v, sigma, how, seed):
    """Apices moved so that various conditions fail."""
    rng = np.random.default_rng(seed)
    scale = np.array([f.arrays.length.mean() for f in frames])[:, None]
    U = np.array([f.U for f in frames])
    if how == "jitter":  # small moves: some conditions just fail, most hold
        return V + 0.02 * scale * rng.normal(size=V.shape), v + 0.01 * scale * rng.normal(
            size=v.shape
        )
    if how == "far":  # large moves of both apices
        return V + 0.5 * scale * rng.normal(size=V.shape), v + 0.3 * scale * rng.normal(
            size=v.shape
        )
    if how == "mirror":  # the apex through the vertex, to the wrong side of the faces
        return 2 * U - V, v
    if how == "deep":  # far along the axis: crease lengths beyond l_max
        return U + 3 * (V - U), v
    raise ValueError(how)


def _assert_same(got, want):
    assert len(got) == len(want)
    for g, w in zip(got, want, strict=True):
        assert g.ok == w.ok
        assert g.failing == w.failing
        # bit for bit here; a hair of rounding allowed (margins are in units of edges ~1)
        np.testing.assert_allclose(g.margin, w.margin, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("name", EXAMPLES)
@pytest.mark.parametrize("with_centres", [False, True])
def test_solved_apices_match_reference(name, with_centres):
    frames, centres, V, v, sigma = _cases(name)
    centres = centres if with_centres else None
    got = validate_apices(frames, V, v, sigma, centres=centres)
    want = [
        _reference_validate(f, V[j], v[j], sigma[j], centres=centres) for j, f in enumerate(frames)
    ]
    _assert_same(got, want)
    assert all(c.ok for c in want)  # solved apices pass the dense validation
    # the one-vertex wrapper and a reversed batch give the same checks
    assert validate_apex(frames[0], V[0], v[0], sigma[0], centres=centres) == want[0]
    _assert_same(validate_apices(frames[::-1], V[::-1], v[::-1], sigma[::-1], centres=centres),
                 want[::-1])  # fmt: skip


@pytest.mark.parametrize(
    "n_samples",
    [9, pytest.param(65, marks=pytest.mark.slow)],  # 65: 3 s of reference checks
)
def test_perturbed_apices_match_reference(n_samples):
    """Apices that fail every kind of condition; the failing lists, in order, and margins."""
    seen = set()
    for name in EXAMPLES:
        frames, centres, V, v, sigma = _cases(name)
        for seed, how in enumerate(["jitter", "far", "mirror", "deep"]):
            Vp, vp = _perturbed(frames, V, v, sigma, how, seed)
            for c in (None, centres):
                got = validate_apices(frames, Vp, vp, sigma, n_samples, centres=c)
                want = [
                    _reference_validate(f, Vp[j], vp[j], sigma[j], n_samples, centres=c)
                    for j, f in enumerate(frames)
                ]
                _assert_same(got, want)
                for w in want:
                    seen.update(k for k, text in KINDS.items() for f in w.failing
                                if f.startswith(text))  # fmt: skip
    assert seen == set(KINDS) - {"chord"}  # the chord plane is only sampled in the solve


def test_mixed_batch_of_meshes():
    """Vertices of different meshes in one batch (no centres: they are per mesh)."""
    frames, V, v, sigma = [], [], [], []
    for seed, name in enumerate(EXAMPLES):
        f, _, V_, v_, s_ = _cases(name)
        V_, v_ = _perturbed(f, V_, v_, s_, "jitter", 10 + seed)
        frames += f
        V.append(V_), v.append(v_), sigma.append(s_)
    V, v, sigma = np.concatenate(V), np.concatenate(v), np.concatenate(sigma)
    got = validate_apices(frames, V, v, sigma)
    _assert_same(got, [_reference_validate(f, V[j], v[j], sigma[j]) for j, f in enumerate(frames)])
    assert any(not c.ok for c in got) and any(c.ok for c in got)


def test_empty_batch():
    assert validate_apices([], np.zeros((0, 3)), np.zeros((0, 2)), []) == []


def test_cuts_are_the_worst_points_and_a_retry_with_them_holds_there():
    """The first attempt on blob leaves ``l < 0`` between the samples at many vertices: each
    cut is a point of its side where the failing condition is at its worst (no sample of 257
    is lower), and solving again with the cuts as samples meets ``l >= m`` there."""
    from filletfold.vertex.apex import crease_length
    from filletfold.vertex.batch import solve_apex_batch
    from filletfold.vertex.solve import ATTEMPTS, apex_problems

    d = design_of("blob", sharp="none")
    probs = apex_problems(d.mesh, d.rounding, d.stages.depths)
    cons = [p.constraints(*ATTEMPTS[0]) for p in probs]
    sols = solve_apex_batch(cons, [p.target for p in probs], [p.starts for p in probs])
    solved = [(p, s) for p, s in zip(probs, sols, strict=True) if s.ok and not p.closed]
    checks = validate_apices(
        [p.frame for p, _ in solved], [s.apex for _, s in solved], [p.v for p, _ in solved],
        [p.sigma for p, _ in solved],
    )  # fmt: skip
    cut = [(p, s, c) for (p, s), c in zip(solved, checks, strict=True) if len(c.cuts)]
    assert len(cut) > 10  # the case this is for
    retried = []
    for p, sol, check in cut:
        assert not check.ok
        for side, s_cut in check.cuts:
            side = int(side)
            arc = p.frame.arrays.arc[side]
            l_cut, _ = crease_length(p.frame, side, sol.apex, p.v, np.array([s_cut]))
            l_all, _ = crease_length(p.frame, side, sol.apex, p.v, np.linspace(0, arc, 257))
            if l_cut[0] < 0:  # an l >= 0 cut: its worst point
                assert l_cut[0] <= l_all.min() + 1e-12
        p.extra = check.cuts
        retried.append((p, p.constraints(*ATTEMPTS[0])))
    again = solve_apex_batch(
        [c for _, c in retried], [p.target for p, _ in retried], [p.starts for p, _ in retried]
    )
    held = 0
    for (p, c), sol in zip(retried, again, strict=True):
        if sol.ok:
            n_cut = len(p.extra)
            n_samples = len(c.quad_s) - 3 * len(p.frame.sides)  # l >= m rows, cuts last
            rows = c.values(sol.x)[n_samples - n_cut : n_samples]
            assert (rows >= -1e-9).all()
            held += 1
    assert held > 0.9 * len(retried)


def test_constraints_of_many_vertices_are_those_of_each_alone():
    """build_constraints_many with mixed sample counts, shortened creases, extra samples and
    open and closed developments gives every vertex exactly its own build_constraints."""
    import dataclasses

    from filletfold.vertex.apex import build_constraints, build_constraints_many
    from filletfold.vertex.solve import apex_problems

    problems = []
    for name, kwargs in (("blob", {}), ("torus", {}), ("miura", {"material_loss": True})):
        d = filletfold.round_mesh(name, tabs=False, layout="modules", **kwargs)
        problems += apex_problems(d.mesh, d.rounding, d.stages.depths)
    assert any(p.closed for p in problems) and not all(p.closed for p in problems)
    rng = np.random.default_rng(1)
    args = []
    for i, p in enumerate(problems):
        if i % 3 == 1:
            p.shrink = rng.uniform(0.5, 1.0, size=(len(p.frame.sides), 2))
        if i % 4 == 2:
            side = rng.integers(0, len(p.frame.sides), size=2)
            p.extra = np.stack([side, rng.uniform(0, 1, 2) * p.frame.arrays.arc[side]], axis=1)
        args.append(p.constraint_args([9, 33, 5][i % 3], [1.0, 2.0][i % 2]))
    many = build_constraints_many(*map(list, zip(*args, strict=True)))
    assert len(many) == len(args)
    for a, got in zip(args, many, strict=True):
        want = build_constraints(*a)
        for f in dataclasses.fields(want):
            x, y = getattr(got, f.name), getattr(want, f.name)
            if isinstance(y, np.ndarray):
                assert np.array_equal(x, y), f.name
            else:
                assert x == y, f.name
