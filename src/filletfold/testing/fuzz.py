"""Reproducible robustness cases for :func:`filletfold.round_mesh`, and a runner for them.

A case is a base mesh with one or two *mutations* of the kind users' meshes have (scans, CAD
STL exports, quad meshes from Rhino or COMPAS, triangle soups), given either as arrays or as a
file's bytes, or a file that is not a mesh at all (*garbage*).

Base meshes: convex hulls of 8-300 random points (``hull-37``), the built-in examples of at
most :data:`MAX_EXAMPLE_FACES` faces (``cube``), open height-field grids of quads or triangles
(``grid-quad-5x7``, ``grid-tri-4x6``) and tori of quads (``torus-9x5``).

Mutation kinds (:data:`ARRAY_KINDS`), each changing the arrays:

* ``scale-1e-6``, ``scale-1e6``: every coordinate multiplied by the factor;
* ``translate-1e6``: moved 1e6 away from the origin;
* ``flip``: a random subset of faces reversed;
* ``soup``: every face given its own vertices (as STL stores them);
* ``holes``: some faces removed;
* ``bumps``: vertices moved along their normals by up to 30 % of the mean edge length;
* ``quantise``: coordinates rounded to an integer grid (the mesh 20-2000 units across);
* ``float32``: coordinates rounded to float32 and back;
* ``dup-faces``: some faces repeated (some reversed, from another first corner);
* ``zero-area``: zero-area faces: a sliver closing a T-junction on an edge, or a triangle on
  an edge whose third vertex is a copy of one of its ends;
* ``dup-vertex``: a vertex duplicated at the same place, some of its faces using the copy;
* ``collapse-edge``: an edge's end moved onto its other end (the faces kept as they are);
* ``nonmanifold-vertex``: a rotated copy of the mesh touching it at one vertex;
* ``nonmanifold-edge``: a rotated copy sharing an edge with it, or a fin face on an edge;
* ``nonplanar-quads``: coplanar triangle pairs merged into quads, then every vertex lifted
  along its normal by 0.05-2 % of the local edge length (so no quad is planar any more);
* ``quads``: coplanar triangle pairs merged into quads (polygons, not triangles).

File kinds (:data:`FILE_KINDS`) write the (possibly mutated) mesh as a valid ``obj``, ``off``,
``ply`` (ASCII), ``ply-binary``, ``stl`` (binary, float32) or ``stl-ascii`` file (sometimes
with an upper-case suffix, as CAD exports have). Garbage kinds (:data:`GARBAGE_KINDS`):
``random-bytes``, ``truncated`` (OBJ, OFF, PLY or STL text cut short), ``nan`` (a NaN or
infinite coordinate), ``index-out-of-range``, ``empty-file`` (empty, blank or comments only),
``points-lines`` (an OBJ with only ``v``, ``p`` and ``l`` records) and ``stl-bad-count`` (a
binary STL whose triangle count disagrees with its size). Every garbage file but a truncated
OBJ or ASCII STL (which can still be a valid, smaller mesh) must be refused
(:attr:`FuzzCase.garbage`).

Case ``i`` of seed ``s`` depends only on ``(s, i)``: the first 300 cases of a 2000-case run
are the 300 cases of a 300-case run, and a case is rebuilt from its name alone
(:func:`case_by_name`).
"""

from __future__ import annotations

import hashlib
import importlib
import re
import signal
import struct
import tempfile
import threading
import time
import traceback
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

import numpy as np
from scipy.spatial import ConvexHull

#: Built-in examples with more faces than this are not used as base meshes.
MAX_EXAMPLE_FACES = 400

ARRAY_KINDS = (
    "scale-1e-6",
    "scale-1e6",
    "translate-1e6",
    "flip",
    "soup",
    "holes",
    "bumps",
    "quantise",
    "float32",
    "dup-faces",
    "zero-area",
    "dup-vertex",
    "collapse-edge",
    "nonmanifold-vertex",
    "nonmanifold-edge",
    "nonplanar-quads",
    "quads",
)
FILE_KINDS = ("obj", "off", "ply", "ply-binary", "stl", "stl-ascii")
GARBAGE_KINDS = (
    "random-bytes",
    "truncated",
    "nan",
    "index-out-of-range",
    "empty-file",
    "points-lines",
    "stl-bad-count",
)
#: Every kind, in the order reports list them.
KINDS = ARRAY_KINDS + FILE_KINDS + GARBAGE_KINDS
#: What a run can end in: a design, a one-line :class:`~filletfold.errors.FilletfoldError`, one
#: whose message has several lines (a defect), any other exception (a defect), or no answer
#: within the time allowed (a defect).
OUTCOMES = ("design", "error", "error-multiline", "traceback", "timeout")

_NAME = re.compile(r"^(?P<base>[^/]+)/(?P<kind>[^#]+)#(?P<index>\d+)(?:@(?P<seed>\d+))?$")


# ------------------------------------------------------------------------------------- cases
@dataclass(eq=False)
class FuzzCase:
    """One robustness case.

    Attributes
    ----------
    name : str
        ``BASE/KIND#INDEX`` (``@SEED`` appended for a seed other than 0), e.g.
        ``hull-37/scale-1e-6#0012`` or ``cube/flip+stl#0040@3``: unique in a run, and enough
        to rebuild the case (:func:`case_by_name`).
    kind : str
        The mutation kinds applied, in order, joined by ``+`` (``"flip+holes"``, ``"soup+stl"``,
        ``"nan"``); see :attr:`kinds`.
    base : str
        The base mesh (``hull-37``, ``cube``, ``grid-tri-4x6``, ``torus-9x5``).
    index, seed : int
        Where the case comes from: ``fuzz_case(index, seed)``.
    vertices : (n, 3) float64 or None
        The mesh of an array case.
    faces : list of (k,) int64 or None
        Its polygons (0-based; ``k >= 3`` unless a mutation made them otherwise).
    file : tuple of (str, bytes) or None
        A file case's suffix (``".obj"``, ``".STL"``...) and contents.
    garbage : bool
        A file that must be refused with an error naming it.
    """

    name: str
    kind: str
    base: str
    index: int
    seed: int
    vertices: np.ndarray | None = None
    faces: list[np.ndarray] | None = None
    file: tuple[str, bytes] | None = None
    garbage: bool = False

    @property
    def kinds(self) -> tuple[str, ...]:
        """The mutation kinds, one per element of :attr:`kind`."""
        return tuple(self.kind.split("+"))

    @property
    def file_name(self) -> str | None:
        """The name a file case is written under (its case name made safe, then its suffix)."""
        if self.file is None:
            return None
        return re.sub(r"[^A-Za-z0-9._-]+", "_", self.name) + self.file[0]

    def digest(self) -> str:
        """SHA-256 of everything the case holds (to compare cases made twice).

        Returns
        -------
        str
            64 hexadecimal digits.
        """
        h = hashlib.sha256()
        for text in (self.name, self.kind, self.base, str(self.index), str(self.seed)):
            h.update(text.encode() + b"\0")
        h.update(b"garbage" if self.garbage else b"fine")
        if self.vertices is not None:
            h.update(np.ascontiguousarray(self.vertices, dtype=np.float64).tobytes())
        for f in self.faces or ():
            a = np.ascontiguousarray(f, dtype=np.int64)
            h.update(struct.pack("<q", len(a)) + a.tobytes())
        if self.file is not None:
            h.update(self.file[0].encode() + b"\0" + self.file[1])
        return h.hexdigest()


def fuzz_cases(n: int, seed: int = 0) -> list[FuzzCase]:
    """The first ``n`` cases of ``seed``.

    Parameters
    ----------
    n : int
        Number of cases.
    seed : int
        Non-negative seed; case ``i`` depends only on ``(seed, i)``.

    Returns
    -------
    list of FuzzCase
        ``[fuzz_case(i, seed) for i in range(n)]``.
    """
    return [fuzz_case(i, seed) for i in range(n)]


def fuzz_case(index: int, seed: int = 0) -> FuzzCase:
    """Case ``index`` of ``seed`` (deterministic).

    Parameters
    ----------
    index, seed : int
        Non-negative.

    Returns
    -------
    FuzzCase
    """
    if index < 0 or seed < 0:
        raise ValueError(f"index and seed must be non-negative, got {index} and {seed}")
    rng = np.random.default_rng([seed, index])
    base, v, faces = _base_mesh(rng)
    tag = f"#{index:04d}" + (f"@{seed}" if seed else "")
    u = rng.random()
    if u < 0.2:  # a file that is not a mesh
        kind = GARBAGE_KINDS[rng.integers(len(GARBAGE_KINDS))]
        suffix, data, garbage = _GARBAGE[kind](v, faces, rng)
        return FuzzCase(
            f"{base}/{kind}{tag}", kind, base, index, seed, file=(suffix, data), garbage=garbage
        )
    as_file = u < 0.4  # a valid file of the mesh, mutated once or not at all
    n_mutations = int(rng.integers(0, 2)) if as_file else int(rng.integers(1, 3))
    kinds: list[str] = []
    for _ in range(n_mutations):
        choices = _choices(kinds, v, faces)
        k = choices[rng.integers(len(choices))]
        v, faces = _MUTATIONS[k](v, faces, rng)
        kinds.append(k)
    if as_file:
        fmt = FILE_KINDS[rng.integers(len(FILE_KINDS))]
        kinds.append(fmt)
        kind = "+".join(kinds)
        return FuzzCase(
            f"{base}/{kind}{tag}", kind, base, index, seed, file=_file_of(fmt, v, faces, rng)
        )
    kind = "+".join(kinds)
    return FuzzCase(f"{base}/{kind}{tag}", kind, base, index, seed, vertices=v, faces=faces)


def case_by_name(name: str) -> FuzzCase:
    """Rebuild a case from its name.

    Parameters
    ----------
    name : str
        A :attr:`FuzzCase.name`, e.g. ``"hull-37/scale-1e-6#0012"``.

    Returns
    -------
    FuzzCase

    Raises
    ------
    ValueError
        The name is not of the form ``BASE/KIND#INDEX[@SEED]``, or the case of that index and
        seed has another name (made by another version of this module).
    """
    m = _NAME.match(name.strip())
    if m is None:
        raise ValueError(f"{name!r} is not a case name (BASE/KIND#INDEX[@SEED])")
    case = fuzz_case(int(m["index"]), int(m["seed"] or 0))
    if case.name != name.strip():
        raise ValueError(f"case {m['index']} of seed {m['seed'] or 0} is {case.name}, not {name}")
    return case


# ------------------------------------------------------------------------------- base meshes
Mesh = tuple[np.ndarray, list[np.ndarray]]


def _base_mesh(rng: np.random.Generator) -> tuple[str, np.ndarray, list[np.ndarray]]:
    u = rng.random()
    if u < 0.4:
        name, v, f = _hull(rng)
    elif u < 0.65:
        names = _example_names()
        name = names[rng.integers(len(names))]
        v, f = _example(name)
        v, f = v.copy(), [a.copy() for a in f]
    elif u < 0.9:
        name, v, f = _grid(rng)
    else:
        name, v, f = _torus(rng)
    return name, np.asarray(v, dtype=np.float64), [np.asarray(a, dtype=np.int64) for a in f]


def _hull(rng) -> tuple[str, np.ndarray, list[np.ndarray]]:
    """Convex hull of 8-300 random points (log-uniform count; at most 100 on a sphere, where
    every point is on the hull), outward triangles."""
    n = round(np.exp(rng.uniform(np.log(8), np.log(300))))
    shape = int(rng.integers(6))
    if shape == 0:  # on a sphere every point is a hull vertex: at most ~200 faces
        n = min(n, 100)
    p = rng.normal(size=(n, 3))
    if shape == 0:  # on a sphere: every point on the hull
        p /= np.linalg.norm(p, axis=1)[:, None]
    elif shape == 1:  # in a ball
        p *= (rng.random(n) ** (1 / 3) / np.linalg.norm(p, axis=1))[:, None]
    elif shape == 2:  # in a cube
        p = rng.uniform(-1, 1, size=(n, 3))
    elif shape == 4:  # flat
        p *= np.array([1.0, 1.0, rng.uniform(0.05, 0.3)])
    elif shape == 5:  # needle
        p *= np.array([1.0, rng.uniform(0.1, 0.3), rng.uniform(0.1, 0.3)])
    hull = ConvexHull(p)
    used = np.unique(hull.simplices)
    new = -np.ones(n, dtype=np.int64)
    new[used] = np.arange(len(used))
    tri = hull.simplices
    a, b, c = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    outward = np.einsum("ij,ij->i", np.cross(b - a, c - a), hull.equations[:, :3]) > 0
    tri = np.where(outward[:, None], tri, tri[:, ::-1])
    faces = list(new[tri])
    return f"hull-{n}", p[used], faces


@cache
def _example_names() -> tuple[str, ...]:
    from filletfold.mesh import example_names

    return tuple(n for n in example_names() if len(_example(n)[1]) <= MAX_EXAMPLE_FACES)


@cache
def _example(name: str) -> Mesh:
    from filletfold.mesh import example_mesh

    v, f = example_mesh(name)
    return np.asarray(v, dtype=np.float64), [np.asarray(a, dtype=np.int64) for a in f]


def _grid(rng) -> tuple[str, np.ndarray, list[np.ndarray]]:
    """An open height field on a grid: planar quads, or triangles (flat pairs or not)."""
    tri = bool(rng.random() < 0.5)
    nx, ny = (int(k) for k in rng.integers(2, 10, size=2))
    while tri and nx * ny > 64:
        nx, ny = max(2, nx - 1), max(2, ny - 1)
    x = np.concatenate([[0.0], np.cumsum(rng.uniform(0.6, 1.4, nx))])
    y = np.concatenate([[0.0], np.cumsum(rng.uniform(0.6, 1.4, ny))])
    a = rng.uniform(0.1, 1.2, 4)
    k = rng.uniform(0.2, 1.0, 4)
    ph = rng.uniform(0, 2 * np.pi, 4)
    if not tri or rng.random() < 0.5:  # translational surface z = g(x) + h(y): planar quads
        z = (a[0] * np.sin(k[0] * x + ph[0]) + 0.05 * a[1] * x**2)[:, None] + (
            a[2] * np.sin(k[2] * y + ph[2]) - 0.05 * a[3] * y**2
        )[None, :]
    else:
        z = a[0] * np.sin(k[0] * x[:, None] + ph[0]) * np.cos(k[1] * y[None, :] + ph[1])
        z = z + 0.1 * a[2] * x[:, None] * y[None, :] / (1 + x[-1])
    X, Y = np.meshgrid(x, y, indexing="ij")
    v = np.stack([X.ravel(), Y.ravel(), z.ravel()], axis=1)
    idx = np.arange(len(v)).reshape(nx + 1, ny + 1)
    faces = []
    for i in range(nx):
        for j in range(ny):
            q = np.array([idx[i, j], idx[i + 1, j], idx[i + 1, j + 1], idx[i, j + 1]])
            if not tri:
                faces.append(q)
            elif rng.random() < 0.5:
                faces += [q[[0, 1, 2]], q[[0, 2, 3]]]
            else:
                faces += [q[[0, 1, 3]], q[[1, 2, 3]]]
    return f"grid-{'tri' if tri else 'quad'}-{nx}x{ny}", v, faces


def _torus(rng) -> tuple[str, np.ndarray, list[np.ndarray]]:
    """A torus of revolution in planar quads (trapezoids), outward."""
    na, nb = int(rng.integers(6, 17)), int(rng.integers(4, 11))
    while na * nb > 96:
        na -= 1
    big, small = rng.uniform(1.5, 3.0), rng.uniform(0.4, 1.0)
    t = 2 * np.pi * np.arange(na) / na
    s = 2 * np.pi * np.arange(nb) / nb
    T, S = np.meshgrid(t, s, indexing="ij")
    ring = big + small * np.cos(S)
    v = np.stack([ring * np.cos(T), ring * np.sin(T), small * np.sin(S)], axis=-1).reshape(-1, 3)
    faces = []
    for i in range(na):
        for j in range(nb):
            i1, j1 = (i + 1) % na, (j + 1) % nb
            faces.append(np.array([i * nb + j, i * nb + j1, i1 * nb + j1, i1 * nb + j]))
    if _signed_volume(v, faces) < 0:
        faces = [f[::-1].copy() for f in faces]
    return f"torus-{na}x{nb}", v, faces


# -------------------------------------------------------------------------- mesh helpers
def _signed_volume(v: np.ndarray, faces: list[np.ndarray]) -> float:
    p = v - v.mean(axis=0)
    tris = np.array([[f[0], f[j], f[j + 1]] for f in faces for j in range(1, len(f) - 1)])
    a, b, c = p[tris[:, 0]], p[tris[:, 1]], p[tris[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum()) / 6.0


def _newell(v: np.ndarray, f: np.ndarray) -> np.ndarray:
    p = v[f]
    return np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0)


def _face_normals(v: np.ndarray, faces: list[np.ndarray]) -> np.ndarray:
    """(m, 3) Newell vectors of the faces (twice their vector areas)."""
    out = np.zeros((len(faces), 3))
    sizes = np.array([len(f) for f in faces])
    for k in np.unique(sizes).tolist():
        rows = np.flatnonzero(sizes == k)
        p = v[np.array([faces[i] for i in rows])]  # (r, k, 3)
        out[rows] = np.cross(p, np.roll(p, -1, axis=1)).sum(axis=1)
    return out


def _vertex_normals(v: np.ndarray, faces: list[np.ndarray]) -> np.ndarray:
    """(n, 3) unit area-weighted vertex normals (zero where a vertex has no face)."""
    out = np.zeros_like(v)
    fn = _face_normals(v, faces)
    for f, n in zip(faces, fn, strict=True):
        out[f] += n
    norm = np.linalg.norm(out, axis=1)
    ok = norm > 0
    out[ok] /= norm[ok][:, None]
    return out


def _mean_edge(v: np.ndarray, faces: list[np.ndarray]) -> float:
    lengths = [np.linalg.norm(v[np.roll(f, -1)] - v[f], axis=1) for f in faces]
    m = float(np.concatenate(lengths).mean()) if lengths else 0.0
    return m if m > 0 else 1.0


def _halfedges(faces: list[np.ndarray]) -> dict[tuple[int, int], int]:
    """Directed edge ``(a, b)`` -> the (last) face that has it."""
    out = {}
    for i, f in enumerate(faces):
        f = f.tolist()
        for a, b in zip(f, f[1:] + f[:1], strict=True):
            out[(a, b)] = i
    return out


def _interior_edges(faces: list[np.ndarray]) -> list[tuple[int, int, int, int]]:
    """``(a, b, face with a->b, face with b->a)`` for every consistently shared edge."""
    he = _halfedges(faces)
    return [(a, b, fa, he[(b, a)]) for (a, b), fa in sorted(he.items()) if a < b and (b, a) in he]


def _coplanar_pairs(v, faces, rng, cos_min: float = 1 - 1e-12) -> list[tuple[int, int, int, int]]:
    """A random maximal matching of triangle pairs that share an edge and lie in one plane."""
    edges = [e for e in _interior_edges(faces) if len(faces[e[2]]) == 3 == len(faces[e[3]])]
    if not edges:
        return []
    fn = _face_normals(v, faces)
    fa, fb = np.array([e[2] for e in edges]), np.array([e[3] for e in edges])
    la, lb = np.linalg.norm(fn[fa], axis=1), np.linalg.norm(fn[fb], axis=1)
    flat = (la > 0) & (lb > 0) & (np.einsum("ij,ij->i", fn[fa], fn[fb]) >= cos_min * la * lb)
    edges = [e for e, ok in zip(edges, flat.tolist(), strict=True) if ok]
    used: set[int] = set()
    pairs = []
    for e in rng.permutation(len(edges)).tolist():
        a, b, fa, fb = edges[e]
        if fa not in used and fb not in used:
            used.update((fa, fb))
            pairs.append((a, b, fa, fb))
    return pairs


def _merge_pairs(faces: list[np.ndarray], pairs) -> list[np.ndarray]:
    """Merge each pair of triangles (sharing edge a-b) into the quad around it."""
    merged, out = {}, []
    for a, b, fa, fb in pairs:
        c = int(next(x for x in faces[fa].tolist() if x not in (a, b)))
        d = int(next(x for x in faces[fb].tolist() if x not in (a, b)))
        merged[fa] = np.array([a, d, b, c], dtype=np.int64)  # fa has a->b: a, (d), b, c
        merged[fb] = None
    for i, f in enumerate(faces):
        if i in merged:
            if merged[i] is not None:
                out.append(merged[i])
        else:
            out.append(f)
    return out


def _has_quads(v, faces) -> bool:
    if any(len(f) >= 4 for f in faces):
        return True
    return bool(_coplanar_pairs(v, faces, np.random.default_rng(0)))


# -------------------------------------------------------------------------------- mutations
def _scale(factor: float):
    def mutate(v, faces, rng):
        return v * factor, faces

    return mutate


def _translate(v, faces, rng):
    d = rng.normal(size=3)
    return v + 1e6 * d / np.linalg.norm(d), faces


def _flip(v, faces, rng):
    p = rng.uniform(0.1, 0.9)
    return v, [f[::-1].copy() if rng.random() < p else f for f in faces]


def _soup(v, faces, rng):
    out_v, out_f, k = [], [], 0
    for f in faces:
        out_v.append(v[f])
        out_f.append(np.arange(k, k + len(f), dtype=np.int64))
        k += len(f)
    return np.concatenate(out_v), out_f


def _holes(v, faces, rng):
    k = max(1, round(rng.uniform(0, 0.15) * len(faces)))
    k = min(k, len(faces) - 2)
    drop = set(rng.choice(len(faces), size=k, replace=False).tolist()) if k > 0 else set()
    return v, [f for i, f in enumerate(faces) if i not in drop]


def _bumps(v, faces, rng):
    n = _vertex_normals(v, faces)
    amp = rng.uniform(0.01, 0.3) * _mean_edge(v, faces)
    moved = rng.random(len(v)) < rng.uniform(0.3, 1.0)
    return v + n * (amp * rng.uniform(-1, 1, len(v)) * moved)[:, None], faces


def _quantise(v, faces, rng):
    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0))) or 1.0
    units = np.exp(rng.uniform(np.log(20), np.log(2000)))
    return np.round(v * (units / diag)), faces


def _float32(v, faces, rng):
    return v.astype(np.float32).astype(np.float64), faces


def _dup_faces(v, faces, rng):
    out = list(faces)
    for _ in range(int(rng.integers(1, max(2, len(faces) // 20 + 1)))):
        f = faces[rng.integers(len(faces))]
        f = np.roll(f, int(rng.integers(len(f))))
        if rng.random() < 0.5:
            f = f[::-1]
        out.insert(int(rng.integers(len(out) + 1)), f.copy())
    return v, out


def _zero_area(v, faces, rng):
    out = list(faces)
    for _ in range(int(rng.integers(1, 4))):
        edges = _interior_edges(out)
        if edges and rng.random() < 0.6:  # a T-junction on edge a-b closed by a sliver
            a, b, fa, _ = edges[rng.integers(len(edges))]
            m = len(v)
            v = np.vstack([v, v[a] + rng.uniform(0.2, 0.8) * (v[b] - v[a])])
            f = out[fa].tolist()
            j = f.index(a)
            out[fa] = np.array([*f[: j + 1], m, *f[j + 1 :]], dtype=np.int64)
            out.insert(int(rng.integers(len(out) + 1)), np.array([a, b, m], dtype=np.int64))
        else:  # a triangle on an edge, its third vertex a copy of one end
            f = out[rng.integers(len(out))]
            j = int(rng.integers(len(f)))
            a, b = int(f[j]), int(f[(j + 1) % len(f)])
            v = np.vstack([v, v[b]])
            out.insert(int(rng.integers(len(out) + 1)), np.array([b, a, len(v) - 1]))
    return v, out


def _dup_vertex(v, faces, rng):
    out = list(faces)
    for _ in range(int(rng.integers(1, 4))):
        u = int(rng.choice(np.unique(np.concatenate(out))))
        copy = len(v)
        v = np.vstack([v, v[u]])
        users = [i for i, f in enumerate(out) if u in f]
        share = rng.uniform(0, 1)  # 0: the copy is left unreferenced
        for i in users:
            if rng.random() < share:
                out[i] = np.where(out[i] == u, copy, out[i])
    return v, out


def _collapse_edge(v, faces, rng):
    v = v.copy()
    for _ in range(int(rng.integers(1, 4))):
        f = faces[rng.integers(len(faces))]
        j = int(rng.integers(len(f)))
        a, b = int(f[j]), int(f[(j + 1) % len(f)])
        if rng.random() < 0.5:
            v[b] = v[a]
        else:
            v[a] = v[b] = 0.5 * (v[a] + v[b])
    return v, faces


def _rotate_half_turn(v: np.ndarray, point: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Rotate points by 180 degrees about the line through ``point`` along unit ``axis``."""
    d = v - point
    return point + 2 * (d @ axis)[:, None] * axis - d


def _join_copy(v, faces, copy_v, shared: dict[int, int]):
    """The mesh and a copy of it (vertices ``copy_v``), copy vertex ``i`` replaced by
    ``shared[i]`` of the original where given."""
    n = len(v)
    index = np.arange(n, 2 * n, dtype=np.int64)
    for i, j in shared.items():
        index[i] = j
    keep = np.ones(n, dtype=bool)
    keep[list(shared)] = False
    # compact the copy's vertices
    remap = np.cumsum(keep) - 1 + n
    index = np.where(keep, remap, index)
    return np.vstack([v, copy_v[keep]]), list(faces) + [index[f] for f in faces]


def _nonmanifold_vertex(v, faces, rng):
    d = rng.normal(size=3)
    d /= np.linalg.norm(d)
    used = np.unique(np.concatenate(faces))
    u = int(used[np.argmax(v[used] @ d)])
    w = np.cross(d, rng.normal(size=3))
    w /= np.linalg.norm(w)
    copy_v = _rotate_half_turn(v, v[u], w)
    shared = {u: u} if rng.random() < 0.5 else {}  # else two coincident vertices
    return _join_copy(v, faces, copy_v, shared)


def _nonmanifold_edge(v, faces, rng):
    edges = _interior_edges(faces)
    if not edges:  # a fin on any edge
        f = faces[rng.integers(len(faces))]
        edges = [(int(f[0]), int(f[1]), 0, 0)]
    order = rng.permutation(len(edges))
    if rng.random() < 0.6:  # a copy turned a half turn about an edge of the hull
        used = np.unique(np.concatenate(faces))
        scale = float(np.abs(v[used]).max()) or 1.0
        for e in order[:200]:
            a, b = edges[e][:2]
            t = v[b] - v[a]
            if np.linalg.norm(t) == 0:
                continue
            t = t / np.linalg.norm(t)
            q = v[used] - v[a]
            q = q - (q @ t)[:, None] * t
            far = np.linalg.norm(q, axis=1) > 1e-9 * scale
            ang = np.sort(np.arctan2(q[far] @ _perp(t)[1], q[far] @ _perp(t)[0]))
            if len(ang) == 0:
                continue
            gaps = np.diff(np.concatenate([ang, [ang[0] + 2 * np.pi]]))
            g = int(np.argmax(gaps))
            if gaps[g] < np.pi + 1e-3:
                continue  # a-b is not an edge of the convex hull
            copy_v = _rotate_half_turn(v, v[a], t)
            shared = {a: a, b: b} if rng.random() < 0.5 else {}
            return _join_copy(v, faces, copy_v, shared)
    a, b = edges[order[0]][:2]
    n = _vertex_normals(v, faces)
    up = n[a] + n[b]
    if np.linalg.norm(up) == 0:
        up = _perp(v[b] - v[a])[0]
    length = float(np.linalg.norm(v[b] - v[a])) or _mean_edge(v, faces)
    tip = 0.5 * (v[a] + v[b]) + rng.uniform(0.3, 1.0) * length * up / np.linalg.norm(up)
    return np.vstack([v, tip]), [*faces, np.array([a, b, len(v)], dtype=np.int64)]


def _perp(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors orthogonal to ``t`` and to each other."""
    t = t / np.linalg.norm(t)
    x = np.cross(t, [1.0, 0.0, 0.0] if abs(t[0]) < 0.9 else [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    return x, np.cross(t, x)


def _quads(v, faces, rng):
    return v, _merge_pairs(faces, _coplanar_pairs(v, faces, rng))


def _nonplanar_quads(v, faces, rng):
    v, faces = _quads(v, faces, rng)
    n = _vertex_normals(v, faces)
    local = np.zeros(len(v))
    count = np.zeros(len(v))
    for f in faces:
        le = np.linalg.norm(v[np.roll(f, -1)] - v[f], axis=1)
        np.add.at(local, f, le)
        np.add.at(count, f, 1)
    local = np.where(count > 0, local / np.maximum(count, 1), 0.0)
    frac = np.exp(rng.uniform(np.log(5e-4), np.log(2e-2)))
    sign = rng.choice([-1.0, 1.0], size=len(v))
    return v + n * (frac * local * sign)[:, None], faces


_MUTATIONS: dict[str, Callable] = {
    "scale-1e-6": _scale(1e-6),
    "scale-1e6": _scale(1e6),
    "translate-1e6": _translate,
    "flip": _flip,
    "soup": _soup,
    "holes": _holes,
    "bumps": _bumps,
    "quantise": _quantise,
    "float32": _float32,
    "dup-faces": _dup_faces,
    "zero-area": _zero_area,
    "dup-vertex": _dup_vertex,
    "collapse-edge": _collapse_edge,
    "nonmanifold-vertex": _nonmanifold_vertex,
    "nonmanifold-edge": _nonmanifold_edge,
    "nonplanar-quads": _nonplanar_quads,
    "quads": _quads,
}


def _choices(done: list[str], v, faces) -> list[str]:
    """The mutations that may follow the mutations ``done`` on this mesh."""
    out = []
    for kind in ARRAY_KINDS:
        if kind in done or (kind.startswith("scale") and any(k.startswith("scale") for k in done)):
            continue
        if kind in ("quads", "nonplanar-quads") and ({"quads", "nonplanar-quads"} & set(done)):
            continue
        if kind == "holes" and len(faces) <= 3:
            continue
        out.append(kind)
    if "quads" in out and not _has_quads(v, faces):
        out = [k for k in out if k not in ("quads", "nonplanar-quads")]
    return out


# ------------------------------------------------------------------------------------ files
def _triangles(v, faces) -> list[np.ndarray]:
    """Every polygon ear-clipped into triangles (fan when clipping gets stuck)."""
    out = []
    for f in faces:
        f = np.asarray(f, dtype=np.int64)
        if len(f) <= 3:
            out.append(f)
            continue
        n = _newell(v, f)
        if np.linalg.norm(n) == 0:
            out += [f[[0, j, j + 1]] for j in range(1, len(f) - 1)]
            continue
        x, y = _perp(n)
        p2 = np.stack([v[f] @ x, v[f] @ y], axis=1)
        ring = list(range(len(f)))
        tris = []
        while len(ring) > 3:
            for k in range(len(ring)):
                i, j, m = ring[k - 1], ring[k], ring[(k + 1) % len(ring)]
                a, b, c = p2[i], p2[j], p2[m]
                if _cross2(b - a, c - b) <= 0:
                    continue
                if any(_inside(p2[r], a, b, c) for r in ring if r not in (i, j, m)):
                    continue
                tris.append(f[[i, j, m]])
                ring.pop(k)
                break
            else:
                break
        if len(ring) > 3:  # stuck (self-touching or degenerate): fan the rest
            tris += [f[[ring[0], ring[j], ring[j + 1]]] for j in range(1, len(ring) - 1)]
        else:
            tris.append(f[ring])
        out += tris
    return out


def _cross2(a, b) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _inside(p, a, b, c) -> bool:
    return _cross2(b - a, p - a) >= 0 and _cross2(c - b, p - b) >= 0 and _cross2(a - c, p - c) >= 0


def _coord_text(v: np.ndarray) -> list[list[str]]:
    return [[repr(float(x)) for x in row] for row in v]


def _obj_text(coords: list[list[str]], faces: list[list[str]]) -> bytes:
    lines = ["# filletfold fuzz case"]
    lines += ["v " + " ".join(c) for c in coords]
    lines += ["f " + " ".join(f) for f in faces]
    return ("\n".join(lines) + "\n").encode()


def _off_text(coords: list[list[str]], faces: list[list[str]]) -> bytes:
    lines = ["OFF", f"{len(coords)} {len(faces)} 0"]
    lines += [" ".join(c) for c in coords]
    lines += [f"{len(f)} " + " ".join(f) for f in faces]
    return ("\n".join(lines) + "\n").encode()


def _ply_text(coords: list[list[str]], faces: list[list[str]]) -> bytes:
    lines = [
        "ply",
        "format ascii 1.0",
        f"element vertex {len(coords)}",
        "property double x",
        "property double y",
        "property double z",
        f"element face {len(faces)}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    lines += [" ".join(c) for c in coords]
    lines += [f"{len(f)} " + " ".join(f) for f in faces]
    return ("\n".join(lines) + "\n").encode()


def _stl_ascii_text(coords: list[list[str]], tris: list[np.ndarray]) -> bytes:
    lines = ["solid fuzz"]
    for t in tris:
        lines += ["  facet normal 0 0 0", "    outer loop"]
        lines += ["      vertex " + " ".join(coords[int(i)]) for i in t]
        lines += ["    endloop", "  endfacet"]
    lines.append("endsolid fuzz")
    return ("\n".join(lines) + "\n").encode()


def _stl_binary(v: np.ndarray, tris: list[np.ndarray]) -> bytes:
    head = b"filletfold fuzz case".ljust(80, b" ")
    rec = np.zeros(len(tris), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    if tris:
        t = np.array(tris, dtype=np.int64)
        p = v[t]
        n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        norm = np.linalg.norm(n, axis=1)
        n[norm > 0] /= norm[norm > 0][:, None]
        rec["n"], rec["v"] = n, p
    return head + struct.pack("<I", len(tris)) + rec.tobytes()


def _ply_binary(v: np.ndarray, faces: list[np.ndarray], double: bool) -> bytes:
    typ = "double" if double else "float"
    head = "\n".join(
        [
            "ply",
            "format binary_little_endian 1.0",
            f"element vertex {len(v)}",
            f"property {typ} x",
            f"property {typ} y",
            f"property {typ} z",
            f"element face {len(faces)}",
            "property list uchar int vertex_indices",
            "end_header",
        ]
    )
    body = np.ascontiguousarray(v, dtype="<f8" if double else "<f4").tobytes()
    body += b"".join(struct.pack(f"<B{len(f)}i", len(f), *map(int, f)) for f in faces)
    return (head + "\n").encode() + body


def _index_text(faces, one_based: bool) -> list[list[str]]:
    k = 1 if one_based else 0
    return [[str(int(i) + k) for i in f] for f in faces]


def _suffix(ext: str, rng) -> str:
    return ext.upper() if rng.random() < 0.2 else ext


def _file_of(fmt: str, v, faces, rng) -> tuple[str, bytes]:
    """A valid file of the mesh in format ``fmt`` (one of :data:`FILE_KINDS`)."""
    if fmt == "obj":
        return _suffix(".obj", rng), _obj_text(_coord_text(v), _index_text(faces, True))
    if fmt == "off":
        return _suffix(".off", rng), _off_text(_coord_text(v), _index_text(faces, False))
    tris = _triangles(v, faces)
    if fmt == "ply":
        return _suffix(".ply", rng), _ply_text(_coord_text(v), _index_text(tris, False))
    if fmt == "ply-binary":
        return _suffix(".ply", rng), _ply_binary(v, tris, bool(rng.random() < 0.5))
    if fmt == "stl":
        return _suffix(".stl", rng), _stl_binary(v, tris)
    return _suffix(".stl", rng), _stl_ascii_text(_coord_text(v), tris)


def _random_bytes(v, faces, rng):
    size = int(np.exp(rng.uniform(0, np.log(4096))))
    ext = (".obj", ".off", ".ply", ".stl")[rng.integers(4)]
    return _suffix(ext, rng), rng.integers(0, 256, size, dtype=np.uint8).tobytes(), True


def _truncated(v, faces, rng):
    fmt = ("obj", "off", "ply", "stl-ascii")[rng.integers(4)]
    _, data = _file_of(fmt, v, faces, rng)
    last = data.rstrip(b"\n").rfind(b"\n") + 1  # start of the last line: it is always lost
    cut = int(rng.integers(int(0.1 * len(data)), max(last, int(0.1 * len(data)) + 1)))
    ext = ".stl" if fmt == "stl-ascii" else "." + fmt
    # an OBJ or ASCII STL cut short can still be a (smaller) valid mesh; OFF and PLY say
    # how many elements they have
    return _suffix(ext, rng), data[:cut], fmt in ("off", "ply")


def _nan(v, faces, rng):
    fmt = ("obj", "off", "ply", "stl-ascii")[rng.integers(4)]
    coords = _coord_text(v)
    used = np.unique(np.concatenate(faces))
    tokens = ("nan", "NaN", "inf", "-inf", "1e999", "-nan")
    for _ in range(int(rng.integers(1, 4))):
        coords[int(rng.choice(used))][int(rng.integers(3))] = tokens[rng.integers(len(tokens))]
    if fmt == "obj":
        return _suffix(".obj", rng), _obj_text(coords, _index_text(faces, True)), True
    if fmt == "off":
        return _suffix(".off", rng), _off_text(coords, _index_text(faces, False)), True
    tris = _triangles(v, faces)
    if fmt == "ply":
        return _suffix(".ply", rng), _ply_text(coords, _index_text(tris, False)), True
    return _suffix(".stl", rng), _stl_ascii_text(coords, tris), True


def _index_out_of_range(v, faces, rng):
    fmt = ("obj", "off", "ply")[rng.integers(3)]
    n = len(v)
    one = fmt == "obj"
    listed = faces if fmt != "ply" else _triangles(v, faces)
    idx = _index_text(listed, one)
    f = int(rng.integers(len(idx)))
    j = int(rng.integers(len(idx[f])))
    bad = int(rng.integers(0, 3))
    if one:
        choices = (n + 1 + bad, 0, -(n + 1 + bad))
    else:
        choices = (n + bad, -1 - bad, n + 1000)
    idx[f][j] = str(choices[rng.integers(3)])
    writer = {"obj": _obj_text, "off": _off_text, "ply": _ply_text}[fmt]
    return _suffix("." + fmt, rng), writer(_coord_text(v), idx), True


def _empty_file(v, faces, rng):
    ext = (".obj", ".off", ".ply", ".stl")[rng.integers(4)]
    data = (b"", b"\n", b"   \n\n", b"# nothing here\n")[rng.integers(4)]
    return _suffix(ext, rng), data, True


def _points_lines(v, faces, rng):
    lines = ["# points and lines, no faces"] + ["v " + " ".join(c) for c in _coord_text(v)]
    for f in faces:
        f1 = [str(int(i) + 1) for i in f]
        lines.append(("p " if rng.random() < 0.3 else "l ") + " ".join(f1))
    return _suffix(".obj", rng), ("\n".join(lines) + "\n").encode(), True


def _stl_bad_count(v, faces, rng):
    data = bytearray(_stl_binary(v, _triangles(v, faces)))
    count = struct.unpack_from("<I", data, 80)[0]
    choice = int(rng.integers(4))
    if choice == 0:
        wrong = count + int(rng.integers(1, 6))
    elif choice == 1:
        wrong = count - int(rng.integers(1, count + 1))
    else:
        wrong = (0, 2**32 - 1)[choice - 2]
    if wrong == count:
        wrong = count + 1
    struct.pack_into("<I", data, 80, wrong)
    return _suffix(".stl", rng), bytes(data), True


_GARBAGE: dict[str, Callable] = {
    "random-bytes": _random_bytes,
    "truncated": _truncated,
    "nan": _nan,
    "index-out-of-range": _index_out_of_range,
    "empty-file": _empty_file,
    "points-lines": _points_lines,
    "stl-bad-count": _stl_bad_count,
}


# ----------------------------------------------------------------------------------- running
@dataclass
class Outcome:
    """What :func:`run_case` saw.

    Attributes
    ----------
    name, kind : str
        The case's :attr:`FuzzCase.name` and :attr:`FuzzCase.kind`.
    outcome : str
        One of :data:`OUTCOMES`.
    message : str
        The error's message (``"error"``, ``"error-multiline"``), or the last line of the
        traceback (``"traceback"``, ``"timeout"``); empty for a design.
    error_type : str
        The exception's class name (empty for a design).
    traceback : str
        The formatted traceback of a ``"traceback"`` (or ``"timeout"``); empty otherwise.
    where : str
        Where a ``"traceback"`` was raised: ``file:line in function`` of the innermost
        filletfold frame, then ``-> file:line in function`` of the raising frame when that is
        in another package.
    stage : str
        ``"round"`` or, for an exception raised while certifying a design, ``"certify"``.
    certified : bool or None
        For a design: whether ``filletfold.check.certify_design`` accepted it; None when that
        function does not exist (or there is no design).
    failed_checks : tuple of str
        Names of the certificate's failing checks.
    seconds : float
        Wall time of ``round_mesh`` (reading the file included).
    certify_seconds : float
        Wall time of the certificate.
    file : str or None
        The path a file case was written to.
    names_file : bool or None
        For an error of a file case: whether its message names the file.
    garbage : bool
        The case's :attr:`FuzzCase.garbage`.
    warnings : tuple of str
        Distinct warnings raised during the run (``Category: message``).
    n_faces : int or None
        Faces of the cleaned mesh, for a design.
    """

    name: str
    kind: str
    outcome: str
    message: str = ""
    error_type: str = ""
    traceback: str = ""
    where: str = ""
    stage: str = "round"
    certified: bool | None = None
    failed_checks: tuple[str, ...] = ()
    seconds: float = 0.0
    certify_seconds: float = 0.0
    file: str | None = None
    names_file: bool | None = None
    garbage: bool = False
    warnings: tuple[str, ...] = field(default_factory=tuple)
    n_faces: int | None = None

    @property
    def kinds(self) -> tuple[str, ...]:
        return tuple(self.kind.split("+"))

    @property
    def defect(self) -> bool:
        """A traceback, a time-out, a multi-line error, a design failing its certificate, or a
        garbage file not refused or refused with an error that does not name it."""
        return (
            self.outcome in ("traceback", "timeout", "error-multiline")
            or self.certified is False
            or (self.garbage and (self.outcome == "design" or self.names_file is False))
        )


class _Timeout(Exception):
    pass


def certifier() -> Callable | None:
    """``filletfold.check.certify_design`` when that module exists, else None."""
    try:
        module = importlib.import_module("filletfold.check")
    except ModuleNotFoundError as exc:
        if exc.name not in ("filletfold.check", "filletfold"):
            raise
        return None
    return getattr(module, "certify_design", None)


def failed_checks(certificate) -> tuple[str, ...]:
    """Names of a certificate's failing checks.

    ``certificate.checks`` may be a mapping of name to a bool or to an object with ``ok`` (or
    ``passed``), or a sequence of such objects (named by ``name``) or of ``(name, ok, ...)``
    tuples.
    """
    checks = getattr(certificate, "checks", None)
    if checks is None:
        return ()
    items = checks.items() if isinstance(checks, Mapping) else enumerate(checks)
    out = []
    for key, check in items:
        name, ok = key, check
        if isinstance(check, tuple) and check and isinstance(check[0], str):
            name, ok = check[0], (check[1] if len(check) > 1 else None)
        elif not isinstance(check, bool | np.bool_):
            name = getattr(check, "name", key)
            ok = getattr(check, "ok", getattr(check, "passed", None))
        if ok is not None and not bool(ok):
            out.append(str(name))
    return tuple(out)


def _innermost(exc: BaseException) -> str:
    """``file:line in function`` of the innermost filletfold frame of a traceback, followed by
    ``-> file:line in function`` of the frame that raised when that is another one (numpy's,
    shapely's...); paths from the package or ``site-packages`` on."""

    def where(frame) -> str:
        path = frame.filename.replace("\\", "/")
        for marker in ("site-packages/", "/src/"):
            if marker in path:
                path = path[path.rfind(marker) + len(marker) :]
                break
        return f"{path}:{frame.lineno} in {frame.name}"

    frames = traceback.extract_tb(exc.__traceback__)
    if not frames:
        return ""
    ours = [
        f
        for f in frames
        if "filletfold" in f.filename.replace("\\", "/").split("/site-packages/")[-1]
        and "/testing/" not in f.filename.replace("\\", "/")
    ]
    raised = where(frames[-1])
    if not ours or ours[-1] is frames[-1]:
        return raised
    return f"{where(ours[-1])} -> {raised}"


def run_case(case: FuzzCase, tmpdir=None, *, timeout: float | None = None, **round_kwargs):
    """Run one case through :func:`filletfold.round_mesh` and say how it ended.

    Parameters
    ----------
    case : FuzzCase
    tmpdir : str or Path, optional
        Where a file case is written (a fresh temporary folder, removed after, when None).
    timeout : float, optional
        Seconds after which the run is interrupted (outcome ``"timeout"``); only in the main
        thread of a POSIX process, else ignored. Not passed to ``round_mesh``.
    **round_kwargs
        Passed to ``round_mesh`` (its defaults when none).

    Returns
    -------
    Outcome
    """
    if case.file is not None and tmpdir is None:
        with tempfile.TemporaryDirectory(prefix="filletfold-fuzz-") as folder:
            return run_case(case, folder, timeout=timeout, **round_kwargs)
    from filletfold.errors import FilletfoldError

    out = Outcome(case.name, case.kind, "design", garbage=case.garbage)
    if case.file is not None:
        path = Path(tmpdir) / case.file_name
        path.write_bytes(case.file[1])
        source = str(path)
        out.file = source
    else:
        source = (np.array(case.vertices, dtype=np.float64), [f.copy() for f in case.faces])
    alarm = (
        timeout is not None
        and hasattr(signal, "setitimer")
        and threading.current_thread() is threading.main_thread()
    )
    if alarm:

        def _ring(signum, frame):
            raise _Timeout(f"no answer within {timeout:g} s")

        previous = signal.signal(signal.SIGALRM, _ring)
        signal.setitimer(signal.ITIMER_REAL, timeout)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            _round_and_certify(out, source, round_kwargs)
        except _Timeout as exc:
            out.outcome, out.error_type, out.message = "timeout", "Timeout", str(exc)
            out.traceback = traceback.format_exc()
            out.where = _innermost(exc)
        except FilletfoldError as exc:
            out.message = str(exc)
            out.error_type = type(exc).__name__
            multiline = "\n" in out.message or "\r" in out.message
            out.outcome = "error-multiline" if multiline else "error"
            if out.stage == "certify":  # the certificate's own error is not a refusal
                out.outcome = "traceback"
                out.traceback = traceback.format_exc()
                out.where = _innermost(exc)
            elif case.file is not None:
                out.names_file = Path(source).name in out.message
        except Exception as exc:
            out.outcome, out.error_type = "traceback", type(exc).__name__
            out.traceback = traceback.format_exc()
            out.message = out.traceback.strip().splitlines()[-1]
            out.where = _innermost(exc)
        finally:
            if alarm:
                signal.setitimer(signal.ITIMER_REAL, 0)
                signal.signal(signal.SIGALRM, previous)
    out.warnings = tuple(dict.fromkeys(f"{w.category.__name__}: {w.message}" for w in caught))
    return out


def _round_and_certify(out: Outcome, source, round_kwargs: dict) -> None:
    """Round ``source`` and certify the design, filling ``out`` (exceptions pass through)."""
    import filletfold

    t = time.perf_counter()
    try:
        design = filletfold.round_mesh(source, **round_kwargs)
    finally:
        out.seconds = time.perf_counter() - t
    out.n_faces = int(design.mesh.n_faces)
    certificate = design.certificate  # round_mesh certifies its design (certify=True)
    if certificate is None:
        certify = certifier()
        if certify is None:
            return
        out.stage = "certify"
        t = time.perf_counter()
        try:
            certificate = certify(design)
        finally:
            out.certify_seconds = time.perf_counter() - t
    else:
        out.certify_seconds = float(design.timings.get("certificate", 0.0))
    out.certified = bool(certificate.ok)
    out.failed_checks = failed_checks(certificate)
    out.stage = "round"
