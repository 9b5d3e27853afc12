"""The validity certificate of a design: its invariants measured again from the pattern.

:func:`certify` takes a crease pattern and the mesh it was made from and measures, with numpy
arrays over every pattern vertex, edge and face at once:

1. ``ruling isometry`` -- every cone ruling (a side of a ``cone u`` face from the apex) is as
   long in 2D as in 3D: ``|len2D - len3D| / len <= RULING_TOL`` (every ``cone u`` face must
   have a corner at ``vertex_apex[u]``, within ``APEX_TOL`` of the design size);
2. ``contraction`` -- no pattern edge is longer folded than flat:
   ``(len3D - len2D) / len2D <= CONTRACTION_TOL``;
3. ``on planes`` -- every corner of a ``face f`` face lies in mesh face ``f``'s plane, within
   ``PLANE_TOL`` of the design size;
4. ``on cylinders`` -- every corner of a ``cylinder e`` face lies at the radius ``r`` from the
   axis of edge ``e`` (through ``O = M - kappa (r / cos gamma) unit(N_a + N_b)``, along the
   edge), within ``CYLINDER_TOL`` of the design size;
5. ``M/V`` -- every M/V edge folds the way its assignment and fold angle say: the signed angle
   between its two faces' folded normals has the written sign (count of disagreements, limit
   0), and ``fold-angle match``: it is the written angle within ``ANGLE_TOL_DEG``;
6. ``fold-angle range`` -- no crease folds flat: ``|angle| <= MAX_FOLD_DEG`` (179), or the
   mesh's sharpest dihedral where that is sharper, and ``< 180``; and ``smallest fold
   angle`` -- none is so small it is no crease at all: ``|angle| > MIN_FOLD_DEG``;
7. ``no overlap`` -- no two faces overlap in 2D by more than ``OVERLAP_TOL`` of the smaller one
   (and every face is a simple polygon); ``face orientation`` -- every face is counter-clockwise
   (positive signed area) in 2D;
8. ``smallest edge`` -- the shortest pattern edge (the shorter of its flat and folded lengths)
   is at least ``MIN_EDGE`` of the design size;

9. ``facet folds`` -- no edge the pattern marks ``F`` (inside a smooth patch, or a
   tangent-continuous join) folds by more than the design's facet limit (its arc step,
   :func:`~filletfold.surface.sampling.facet_limit`) plus what the coordinates' rounding can
   turn its faces by; and every crease inside one cone is a ruling from the apex to a mesh edge
   left unrounded (the only place a cone is not smooth);
10. ``edge lengths`` -- every pattern edge is as long folded as flat, up to what a chord
   across a bent facet loses: ``(len2D - len3D) / len2D <= 1 - sin(t/2) / (t/2)`` for a
   facet turning by twice the facet limit ``t`` (:data:`EDGE_TURNS`), plus the rounding;

and, for information, the ``smallest face angle`` in 2D (slivers). The *design size* is the
bounding-box diagonal of the folded form.

A pattern read from a file holds its coordinates rounded (:data:`FOLD_DIGITS` significant
digits): each is known to ``coord_quantum`` (:func:`file_quantum`: ``5e-12`` times the largest
coordinate), so the tolerances of 1, 2 (lengths) and 5 (angles) grow by what that rounding can
do to the figure of each edge (see :data:`LENGTH_QUANTA` and :func:`certify`).

:func:`certify_design` certifies an in-memory :class:`~filletfold.Design`; :func:`check_folder`
a folder written by ``filletfold round`` (``design.fold`` and ``report.json``).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import shapely

from .arrays import run_next, run_owners
from .check_making import kerf_check, relief_check
from .defaults import DEFAULT_ARC_STEP
from .errors import MeshReadError, ParameterError
from .export.fold import FOLD_DIGITS
from .export.fold_read import load_json, read_fold_document
from .layout.convex import BoxGrid
from .mesh.measures import dihedral_turns, newell_vectors
from .surface.patch import PATCH_KINDS, Patch
from .surface.pattern import CreasePattern, face_arrays
from .surface.sampling import chord_mismatch_bound, facet_limit
from .tolerances import tol

__all__ = [
    "ANGLE_TOL_DEG",
    "APEX_TOL",
    "CONTRACTION_TOL",
    "CYLINDER_TOL",
    "EDGE_TURNS",
    "FILE_ROUNDING",
    "LENGTH_QUANTA",
    "MAX_FOLD_DEG",
    "MIN_EDGE",
    "MIN_FOLD_DEG",
    "OVERLAP_TOL",
    "PLANE_TOL",
    "RULING_TOL",
    "Certificate",
    "Check",
    "certify",
    "certify_design",
    "check_folder",
    "file_quantum",
]

#: Largest ``|len2D - len3D| / len`` of a cone ruling (plus the file's rounding).
RULING_TOL = 1e-12
#: Largest ``(len3D - len2D) / len2D`` of a pattern edge (plus the file's rounding).
CONTRACTION_TOL = 1e-12
#: Largest distance of a face-piece corner from its mesh face's plane / design size.
PLANE_TOL = 1e-9
#: Largest ``|distance from the axis - r|`` of a cylinder corner / design size.
CYLINDER_TOL = 1e-9
#: A cone face's corner is the apex when it is this close to it (/ design size).
APEX_TOL = 1e-9
#: Corners of the folded surface this close (/ design size) are one point (``holes``).
GLUE_TOL = 1e-9
#: Largest difference between a written fold angle and the folded form's (degrees; plus the
#: file's rounding). A recomputed angle this close to 0 has no sign to disagree with.
ANGLE_TOL_DEG = 1e-6
#: No crease folds beyond this (degrees) unless the mesh has an edge as sharp (the limit is
#: then the mesh's sharpest dihedral, always below 180, which would fold the sheet flat).
MAX_FOLD_DEG = 179.0
#: A facet's side across a bent patch may be shorter folded than flat by what the chord of an
#: arc turning by this many facet limits loses (a facet turns by at most one limit from each
#: neighbour, so a side across it by at most two).
EDGE_TURNS = 2.0
#: Every crease folds by more than this (degrees): less is no crease at all.
MIN_FOLD_DEG = 1e-6
#: Largest area two faces may share in 2D, as a share of the smaller one.
OVERLAP_TOL = 1e-9
#: Shortest pattern edge / design size.
MIN_EDGE = 1e-7
#: Relative rounding of a float written with :data:`FOLD_DIGITS` significant digits.
FILE_ROUNDING = 0.5 * 10.0 ** (1 - FOLD_DIGITS)
#: Round-off of an in-memory coordinate, in units in the last place of the largest one.
ROUNDOFF_ULPS = 16
#: With every coordinate within ``q`` of its value, a 2D length is within ``2 sqrt(2) q`` and a
#: 3D length within ``2 sqrt(3) q`` of its own, so the two differ by this many ``q`` more.
LENGTH_QUANTA = 2.0 * (math.sqrt(2.0) + math.sqrt(3.0))

#: Failing elements a check names (the worst first).
FAILING_NAMED = 5
#: Convex faces of up to this many corners are told apart in numpy (separating axes).
SAT_CORNERS = 8
#: Face pairs separated per numpy block.
PAIR_CHUNK = 1 << 18
#: Faces whose neighbours are asked of the grid at once (bounds the pairs held).
QUERY_CHUNK = 1 << 13

_CONE, _CYLINDER, _FACE, _FILLET = 0, 1, 2, 3
_KINDS = {"cone": _CONE, "cylinder": _CYLINDER, "face": _FACE, "fillet": _FILLET}


@dataclass
class Check:
    """One invariant and its figure.

    Attributes
    ----------
    name : str
        ``"ruling isometry"``, ``"contraction"``, ...
    ok : bool
        Whether the invariant holds (always true for an informational figure).
    value : float
        The measured figure (NaN when there is nothing to measure).
    limit : float or None
        The limit the figure is held to (at the worst element when the limit is per element);
        None for an informational figure.
    detail : str
        What was measured, the worst element, and how the limit is made.
    relation : str
        How ``value`` must compare with ``limit``: ``"<="``, ``"<"``, ``">="`` or ``">"``
        (``""`` for an informational figure).
    worst : dict
        The worst element, e.g. ``{"pattern_edge": 17, "patch": "cone 3"}`` (empty when there
        is none).
    """

    name: str
    ok: bool
    value: float
    limit: float | None
    detail: str = ""
    relation: str = "<="
    worst: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        """``{"ok", "value", "limit", "detail"}``, JSON data (NaN and infinities as None)."""
        return {
            "ok": bool(self.ok),
            "value": _json_float(self.value),
            "limit": _json_float(self.limit),
            "detail": str(self.detail),
        }

    def line(self) -> str:
        """One printable line: name, figure, relation and limit, ``ok``/``FAIL``, detail."""
        if self.limit is None:
            figure, status = f"{_fmt(self.value):>10}", "info"
        else:
            figure = f"{_fmt(self.value):>10} {self.relation:>2} {_fmt(self.limit, 4):<9}"
            status = "ok" if self.ok else "FAIL"
        return f"{self.name:<19} {figure:<23} {status:<4}  {self.detail}"


@dataclass
class Certificate:
    """The invariants of a design, measured.

    Attributes
    ----------
    checks : list of Check
        In the order of the module's list (informational figures last).
    size : float
        The design size (bounding-box diagonal of the folded form) the tolerances refer to.
    coord_quantum : float
        The coordinates' rounding the tolerances allowed for (0 for an in-memory pattern).
    ok : bool
        Whether every invariant holds.
    """

    checks: list[Check]
    size: float = 0.0
    coord_quantum: float = 0.0

    @property
    def ok(self) -> bool:
        return all(c.ok for c in self.checks)

    def __getitem__(self, name: str) -> Check:
        for c in self.checks:
            if c.name == name:
                return c
        raise KeyError(name)

    @property
    def failed(self) -> list[Check]:
        """The checks that do not hold."""
        return [c for c in self.checks if not c.ok]

    def as_dict(self) -> dict:
        """``{"ok": bool, "checks": {name: {"ok", "value", "limit", "detail"}}}`` in check order."""
        return {"ok": self.ok, "checks": {c.name: c.as_dict() for c in self.checks}}

    def summary(self) -> list[str]:
        """Printable lines: one per check, then the verdict."""
        lines = [c.line() for c in self.checks]
        if self.ok:
            lines.append(f"valid: all {sum(c.limit is not None for c in self.checks)} checks hold")
        else:
            names = ", ".join(c.name for c in self.failed)
            lines.append(f"NOT VALID: {len(self.failed)} check(s) fail: {names}")
        return lines


def _json_float(x) -> float | None:
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def _fmt(x, digits: int = 3) -> str:
    """A figure for a summary line: integers as such, others to ``digits`` significant digits
    (``-`` for NaN: nothing measured)."""
    if x is None or not math.isfinite(float(x)):
        return "-" if x is None or math.isnan(float(x)) else f"{x}"
    x = float(x)
    if x == int(x) and abs(x) < 1e6:
        return str(int(x))
    return f"{x:.{digits}g}"


def _ratio_worst(excess_num: np.ndarray, allowed: np.ndarray) -> int:
    """The element whose figure ``excess_num`` is largest against its own limit ``allowed``
    (both (k,) non-negative; 0 / 0 counts as 0, x / 0 as infinity)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(allowed > 0, excess_num / allowed, np.where(excess_num > 0, np.inf, 0.0))
    ratio = np.where(np.isnan(ratio), np.inf, ratio)
    return int(np.argmax(ratio))


def _distinct(x: np.ndarray) -> int:
    """How many distinct values the non-negative integers ``x`` hold."""
    return int(np.count_nonzero(np.bincount(x))) if len(x) else 0


def _quantum_note(q: float, what: str, source: str) -> str:
    return f"; limit {what}, q = {q:.2g} ({source})" if q else ""


class _Data:
    """The pattern and mesh as arrays, checked for consistency, with what several checks use."""

    def __init__(
        self, pattern, mesh_vertices, mesh_faces, edges, vertex_apex, coord_quantum, quantum_source
    ):
        if not isinstance(pattern, CreasePattern):
            raise ParameterError(
                f"expected a CreasePattern, got {type(pattern).__name__}", name="pattern"
            )
        self.v2 = np.asarray(pattern.vertices_2d, dtype=np.float64)
        self.v3 = np.asarray(pattern.vertices_3d, dtype=np.float64)
        n = len(self.v2)
        if self.v2.shape != (n, 2) or self.v3.shape != (n, 3):
            raise ParameterError("pattern vertices must be (n, 2) in 2D and (n, 3) in 3D")
        for name, arr in (("vertices_2d", self.v2), ("vertices_3d", self.v3)):
            bad = np.flatnonzero(~np.isfinite(arr).all(axis=1))
            if len(bad):
                raise ParameterError(f"pattern {name}[{bad[0]}] is not finite", name=name)
        flat, start = face_arrays(pattern.faces)
        self.flat = np.asarray(flat, dtype=np.int64)
        self.start = np.asarray(start, dtype=np.int64)
        self.size_of = np.diff(self.start)
        n_faces = len(self.size_of)
        if n_faces == 0:
            raise ParameterError("the pattern has no faces")
        if self.size_of.min() < 3 or self.flat.min() < 0 or self.flat.max() >= n:
            raise ParameterError("pattern faces must list at least 3 vertex indices in range")
        self.face_of = run_owners(self.size_of)
        self.nxt = run_next(self.start)
        self.prv = np.empty_like(self.nxt)
        self.prv[self.nxt] = np.arange(len(self.nxt))
        q = float(coord_quantum)
        if not (math.isfinite(q) and q >= 0):
            raise ParameterError(f"coord_quantum must be >= 0, got {coord_quantum}")
        self.q = q
        self.q_source = quantum_source
        lo, hi = self.v3.min(axis=0), self.v3.max(axis=0)
        self.size = float(np.linalg.norm(hi - lo)) or 1.0
        self.patch = list(map(str, pattern.face_patch))
        if len(self.patch) != n_faces:
            raise ParameterError(f"pattern has {n_faces} faces but {len(self.patch)} patches")
        piece = np.asarray(pattern.face_piece, dtype=np.int64).reshape(-1)
        self.piece = piece if len(piece) == n_faces else np.full(n_faces, -1)
        self._mesh(mesh_vertices, mesh_faces, edges, vertex_apex)
        self._patches(n_faces)
        self._edges(pattern, n)

    def _mesh(self, mesh_vertices, mesh_faces, edges, vertex_apex):
        self.mv = np.asarray(mesh_vertices, dtype=np.float64).reshape(-1, 3)
        mflat, mstart = face_arrays(mesh_faces)
        mflat = np.asarray(mflat, dtype=np.int64)
        if len(mstart) < 2 or np.diff(mstart).min() < 3:
            raise ParameterError("mesh faces must list at least 3 vertices each")
        if mflat.min() < 0 or mflat.max() >= len(self.mv):
            raise ParameterError(f"mesh faces refer to a vertex outside 0..{len(self.mv) - 1}")
        self.n_mesh_faces = len(mstart) - 1
        # planes: centroid and unit Newell normal of every mesh face
        msize = np.diff(mstart)
        p = self.mv[mflat]
        centre = np.add.reduceat(p, mstart[:-1], axis=0) / msize[:, None]
        qc = p - np.repeat(centre, msize, axis=0)
        mnxt = run_next(mstart)
        normal = np.add.reduceat(np.cross(qc, qc[mnxt]), mstart[:-1], axis=0)
        with np.errstate(invalid="ignore", divide="ignore"):
            normal /= np.linalg.norm(normal, axis=1)[:, None]
        self.face_centre, self.face_normal = centre, normal
        self.mesh_flat, self.mesh_nxt = mflat, mnxt
        try:
            ev = np.asarray(edges["vertices"], dtype=np.int64).reshape(-1, 2)
            n_edges = len(ev)
            ef = np.asarray(edges["faces"], dtype=np.int64).reshape(n_edges, 2)
            r = np.asarray(edges["radius"], dtype=np.float64).reshape(n_edges)
            gamma = np.asarray(edges["half_angle"], dtype=np.float64).reshape(n_edges)
            kappa = np.asarray(edges["kappa"], dtype=np.float64).reshape(n_edges)
        except KeyError as exc:
            raise ParameterError(f"edges needs the key {exc}", name="edges") from None
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"edges arrays are malformed ({exc})", name="edges") from None
        if n_edges and (ev.min() < 0 or ev.max() >= len(self.mv)):
            raise ParameterError("edges refer to a mesh vertex out of range", name="edges")
        if n_edges and ef.max() >= self.n_mesh_faces:
            raise ParameterError("edges refer to a mesh face out of range", name="edges")
        self.n_mesh_edges = n_edges
        self.edge_vertices = ev
        # cylinder axes: O = M - kappa (r / cos gamma) unit(N_a + N_b), along the edge
        rounded = (ef >= 0).all(axis=1) & (r > 0) & (kappa != 0) & np.isfinite(gamma)
        a, b = self.mv[ev[:, 0]], self.mv[ev[:, 1]]
        direction = b - a
        with np.errstate(invalid="ignore", divide="ignore"):
            direction /= np.linalg.norm(direction, axis=1)[:, None]
            s = self.face_normal[ef[:, 0]] + self.face_normal[ef[:, 1]]
            s /= np.linalg.norm(s, axis=1)[:, None]
            axis = 0.5 * (a + b) - (np.sign(kappa) * r / np.cos(gamma))[:, None] * s
        rounded &= np.isfinite(axis).all(axis=1) & np.isfinite(direction).all(axis=1)
        self.axis_point, self.axis_dir, self.radius = axis, direction, r
        self.rounded = rounded
        # the turn of every interior edge (the half angle; NaN where undefined)
        self.half_angle = np.where((ef >= 0).all(axis=1), np.abs(gamma), np.nan)
        apex = np.asarray(vertex_apex, dtype=np.float64)
        if apex.shape != (len(self.mv), 3):
            raise ParameterError(
                f"vertex_apex must be ({len(self.mv)}, 3), got {apex.shape}", name="vertex_apex"
            )
        self.apex = apex

    def _patches(self, n_faces):
        names = dict.fromkeys(self.patch)
        limit = {
            _CONE: len(self.mv),
            _CYLINDER: self.n_mesh_edges,
            _FACE: self.n_mesh_faces,
            _FILLET: self.n_mesh_edges,
        }
        parsed = {}
        for name in names:
            try:
                patch = Patch.parse(name)
            except ValueError:
                face = self.patch.index(name)
                raise ParameterError(
                    f"pattern face {face} has patch {name!r}, not 'cone <vertex>', "
                    "'cylinder <edge>', 'fillet <edge>' or 'face <face>'",
                    name="face_patch",
                ) from None
            kind, index = _KINDS[patch.kind], patch.index
            if index >= limit[kind]:
                face = self.patch.index(name)
                raise ParameterError(
                    f"pattern face {face} is on {name!r} but there is no "
                    f"mesh {PATCH_KINDS[patch.kind]} {index} (the mesh has {limit[kind]})",
                    name="face_patch",
                )
            parsed[name] = (kind, index)
        kinds = np.array([parsed[p][0] for p in names], dtype=np.int64)
        indices = np.array([parsed[p][1] for p in names], dtype=np.int64)
        ids = {p: k for k, p in enumerate(names)}
        pid = np.fromiter(map(ids.__getitem__, self.patch), dtype=np.int64, count=n_faces)
        self.kind, self.index = kinds[pid], indices[pid]

    def _edges(self, pattern, n):
        try:
            e = np.asarray(pattern.edges, dtype=np.int64).reshape(-1, 2)
            assign = np.asarray(pattern.edge_assignment).astype(str).reshape(len(e))
            angle = np.asarray(pattern.edge_fold_angle, dtype=np.float64).reshape(len(e))
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"pattern edge arrays are malformed ({exc})") from None
        if len(e) and (e.min() < 0 or e.max() >= n):
            raise ParameterError(f"pattern edges refer to a vertex outside 0..{n - 1}")
        try:
            self.edge_faces = pattern.faces_beside_edges().reshape(len(e), 2)
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"pattern edge_faces is malformed ({exc})") from None
        self.edges, self.assign, self.angle = e, assign, angle
        self.l2 = np.linalg.norm(self.v2[e[:, 0]] - self.v2[e[:, 1]], axis=1)
        self.l3 = np.linalg.norm(self.v3[e[:, 0]] - self.v3[e[:, 1]], axis=1)
        self._keys = None
        self._newell = None

    def edge_index(self, a: int, b: int) -> int:
        """The pattern edge between vertices ``a`` and ``b`` (-1 when there is none)."""
        n = len(self.v2)
        if self._keys is None:
            key = self.edges.min(axis=1) * n + self.edges.max(axis=1)
            order = np.argsort(key)
            self._keys = key[order], order
        keys, order = self._keys
        k = min(a, b) * n + max(a, b)
        pos = int(np.searchsorted(keys, k))
        return int(order[pos]) if pos < len(keys) and keys[pos] == k else -1

    def where_face(self, f: int) -> str:
        return f"face {f} (piece {self.piece[f]}, {self.patch[f]})"


def certify(
    pattern: CreasePattern,
    mesh_vertices,
    mesh_faces,
    edges: dict,
    vertex_apex,
    *,
    coord_quantum: float = 0.0,
    quantum_source: str = f"coordinates rounded to {FOLD_DIGITS} digits",
    arc_step: float = DEFAULT_ARC_STEP,
    bend_floor: float = 0.0,
    material=None,
) -> Certificate:
    """Measure the invariants of a crease pattern against the mesh it rounds.

    Parameters
    ----------
    pattern : CreasePattern
        Its faces' ``face_patch`` name mesh vertices (``cone u``), edges (``cylinder e``) and
        faces (``face f``) of the arrays below.
    mesh_vertices : (n_vertices, 3) float
    mesh_faces : list of (k,) int, counter-clockwise seen from the front
    edges : dict of arrays
        ``vertices`` (n_edges, 2) int, ``faces`` (n_edges, 2) int (the face holding ``a -> b``
        first; -1 at a boundary), ``radius`` (n_edges,), ``half_angle`` (n_edges,) radians,
        ``kappa`` (n_edges,) +1 mountain, -1 valley, 0 not rounded.
    vertex_apex : (n_vertices, 3) float
        The cone apex of every vertex, NaN where there is none.
    coord_quantum : float
        How far each coordinate of the pattern may be from its true value (0 in memory;
        :func:`file_quantum` for a pattern read from a file). The length limits grow by
        ``LENGTH_QUANTA * coord_quantum`` per edge, the fold-angle limit by what moving every
        corner of the edge's two faces by ``sqrt(3) coord_quantum`` can turn their normals:
        ``sqrt(3) q (P_a / A_a + P_b / A_b)`` radians (``P`` perimeter, ``A`` area, in 3D).
    quantum_source : str
        Where ``coord_quantum`` comes from, for the lines of the certificate.
    arc_step : float
        The design's arc step (degrees; 0: none), which sets its facet limit
        (:func:`~filletfold.surface.sampling.facet_limit`): ``facet folds`` and ``edge lengths``.
    bend_floor : float
        The least radius a cylinder may have (mesh units): a sheet material's bend floor at
        the design's size (:meth:`~filletfold.materials.Material.bend_floor_mm`); 0 (no
        material) leaves the ``bend floor`` check out.
    material : Material, optional
        The sheet material whose floor ``bend_floor`` is: with a ``"relief"`` or ``"kerf"``
        material the ``relief`` check, with ``"kerf"`` the ``kerfs`` check
        (:mod:`~filletfold.check_making`), of the making paths of the pattern's annotations.

    Returns
    -------
    Certificate

    Raises
    ------
    ParameterError
        When the data are inconsistent: a face's patch names no element of the mesh, arrays of
        the wrong shape, coordinates that are not finite.
    """
    data = _Data(
        pattern, mesh_vertices, mesh_faces, edges, vertex_apex, coord_quantum, quantum_source
    )
    checks = [
        _ruling_isometry(data),
        _contraction(data),
        _on_planes(data),
        _on_cylinders(data),
        _on_fillets(data),
        *_fold_angles(data),
        _facet_folds(data, facet_limit(arc_step)),
        _edge_lengths(data, facet_limit(arc_step)),
        *_overlap(data),
        _smallest_edge(data),
        _smallest_face_angle(data),
        _holes(data),
    ]
    if bend_floor > 0:
        checks.append(_bend_floor(data, float(bend_floor)))
        checks += _making_checks(data, pattern, float(bend_floor), material)
    return Certificate(checks=checks, size=data.size, coord_quantum=data.q)


def _making_checks(g: _Data, pattern, floor: float, material) -> list[Check]:
    """``relief`` and ``kerfs`` of a sheet material (:mod:`~filletfold.check_making`)."""
    if material is None or material.making not in ("relief", "kerf"):
        return []
    making = list(pattern.annotations.making)
    kinds = (_CONE, _CYLINDER, _FACE, _FILLET)
    ok, value, detail, worst = relief_check(g, making, floor, kinds)
    out = [Check("relief", ok, value, 0.0, detail, "<=", worst)]
    if material.making == "kerf" and material.kerf is not None:
        mm = material.bend_floor_mm() / floor
        ok, value, detail, worst = kerf_check(g, pattern, making, material.kerf, mm, kinds)
        out.append(Check("kerfs", ok, value, 0.0, detail, "<=", worst))
    return out


def _ruling_isometry(g: _Data) -> Check:
    name = "ruling isometry"
    cone_faces = np.flatnonzero(g.kind == _CONE)
    if not len(cone_faces):
        return Check(name, True, float("nan"), RULING_TOL, "no cone in the design")
    corner = g.kind[g.face_of] == _CONE
    c = np.flatnonzero(corner)
    apex = g.apex[g.index[g.face_of[c]]]
    with np.errstate(invalid="ignore"):
        at = np.zeros(len(g.flat), dtype=bool)
        at[c] = np.linalg.norm(g.v3[g.flat[c]] - apex, axis=1) <= APEX_TOL * g.size
    has_apex = np.logical_or.reduceat(at, g.start[:-1])
    missing = cone_faces[~has_apex[cone_faces]]
    side = c[at[c] | at[g.nxt[c]]]  # the sides a -> b of cone faces from or to the apex
    a, b = g.flat[side], g.flat[g.nxt[side]]
    l2 = np.linalg.norm(g.v2[a] - g.v2[b], axis=1)
    l3 = np.linalg.norm(g.v3[a] - g.v3[b], axis=1)
    length = np.maximum(l2, l3)
    diff = np.abs(l2 - l3)
    allowed = RULING_TOL * length + LENGTH_QUANTA * g.q
    n_cones = _distinct(g.index[cone_faces])
    detail = f"{len(side)} ruling sides of {len(cone_faces)} faces on {n_cones} cones"
    if not len(side):
        value, limit, ok, worst = float("nan"), RULING_TOL, True, {}
    else:
        k = _ratio_worst(diff, allowed)
        value = float(diff[k] / length[k]) if length[k] > 0 else 0.0
        limit = float(allowed[k] / length[k]) if length[k] > 0 else RULING_TOL
        ok = bool((diff <= allowed).all())
        f = int(g.face_of[side[k]])
        e = g.edge_index(int(a[k]), int(b[k]))
        worst = {"pattern_edge": e, "pattern_face": f, "patch": g.patch[f]}
        detail += f"; worst pattern edge {e} ({g.patch[f]})"
        if g.q:
            rel = diff / np.where(length > 0, length, 1.0)
            detail += f", largest |d|/len {float(rel.max()):.2e}"
    detail += _quantum_note(g.q, f"{RULING_TOL:g} + {LENGTH_QUANTA:.2f} q / len", g.q_source)
    if len(missing):
        f = int(missing[0])
        u = int(g.index[f])
        why = "has no apex" if not np.isfinite(g.apex[u]).all() else "has no corner at its apex"
        detail += f"; {len(missing)} cone face(s) without their apex (first {g.where_face(f)}: "
        detail += f"vertex {u} {why})"
        ok = False
        worst = worst or {"pattern_face": f, "patch": g.patch[f]}
    return Check(name, ok, value, limit, detail, "<=", worst)


def _contraction(g: _Data) -> Check:
    name = "contraction"
    longer = g.l3 - g.l2
    allowed = CONTRACTION_TOL * g.l2 + LENGTH_QUANTA * g.q
    if not len(g.edges):
        return Check(name, True, float("nan"), CONTRACTION_TOL, "no pattern edge")
    k = _ratio_worst(np.maximum(longer, 0.0), allowed)
    if longer[k] <= 0:  # none longer folded: the largest relative difference
        with np.errstate(invalid="ignore", divide="ignore"):
            rel = np.where(g.l2 > 0, longer / g.l2, 0.0)
        k = int(np.argmax(rel))
    value = float(longer[k] / g.l2[k]) if g.l2[k] > 0 else (math.inf if longer[k] > 0 else 0.0)
    limit = float(allowed[k] / g.l2[k]) if g.l2[k] > 0 else CONTRACTION_TOL
    ok = bool((longer <= allowed).all())
    n_longer = int(np.count_nonzero(longer > allowed))
    e = int(k)
    detail = f"{len(g.edges)} pattern edges; worst pattern edge {e} ({g.assign[e]})"
    if n_longer:
        detail += f"; {n_longer} longer folded than flat"
    detail += _quantum_note(g.q, f"{CONTRACTION_TOL:g} + {LENGTH_QUANTA:.2f} q / len", g.q_source)
    return Check(name, ok, value, limit, detail, "<=", {"pattern_edge": e})


def _on_planes(g: _Data) -> Check:
    name = "on planes"
    c = np.flatnonzero(g.kind[g.face_of] == _FACE)
    if not len(c):
        return Check(name, True, float("nan"), PLANE_TOL, "no face piece in the design")
    f = g.index[g.face_of[c]]
    d = np.abs(np.einsum("ij,ij->i", g.v3[g.flat[c]] - g.face_centre[f], g.face_normal[f]))
    d = np.where(np.isfinite(d), d, np.inf) / g.size
    k = int(np.argmax(d))
    v, mf = int(g.flat[c[k]]), int(f[k])
    detail = (
        f"{_distinct(g.flat[c])} points of {_distinct(f)} face pieces; "
        f"worst pattern vertex {v} (face {mf}); distance / size {PLANE_TOL:g}"
    )
    worst = {"pattern_vertex": v, "mesh_face": mf}
    return Check(name, bool(d[k] <= PLANE_TOL), float(d[k]), PLANE_TOL, detail, "<=", worst)


def _on_cylinders(g: _Data) -> Check:
    name = "on cylinders"
    c = np.flatnonzero(g.kind[g.face_of] == _CYLINDER)
    if not len(c):
        return Check(name, True, float("nan"), CYLINDER_TOL, "no cylinder in the design")
    e = g.index[g.face_of[c]]
    err = _off_cylinder(g, g.v3[g.flat[c]], e)
    err = np.where(g.rounded[e] & np.isfinite(err), err, np.inf)
    k = int(np.argmax(err))
    v, me = int(g.flat[c[k]]), int(e[k])
    detail = (
        f"{_distinct(g.flat[c])} points of {_distinct(e)} cylinders; "
        f"worst pattern vertex {v} (cylinder {me}); |distance - r| / size {CYLINDER_TOL:g}"
    )
    flat = np.unique(e[~g.rounded[e]])
    if len(flat):
        detail += f"; {len(flat)} cylinder(s) on edges that are not rounded (first {flat[0]})"
    worst = {"pattern_vertex": v, "mesh_edge": me}
    ok = bool(err[k] <= CYLINDER_TOL)
    return Check(name, ok, float(err[k]), CYLINDER_TOL, detail, "<=", worst)


def _bend_floor(g: _Data, floor: float) -> Check:
    """Every cylinder of the pattern at least the material's bend floor: its radius (that of
    the mesh edge, which ``on cylinders`` measures its points against) over the floor.
    Tapering fillets narrow to their sharp corner and are not held to it (counted)."""
    name = "bend floor"
    c = np.flatnonzero(g.kind[g.face_of] == _CYLINDER)
    e = np.unique(g.index[g.face_of[c]])
    e = e[g.rounded[e]]
    tapering = _distinct(g.index[g.face_of[np.flatnonzero(g.kind[g.face_of] == _FILLET)]])
    note = f"; {tapering} tapering fillet(s) not held to it" if tapering else ""
    if not len(e):
        return Check(name, True, float("nan"), 1.0, "no cylinder in the design" + note, ">=")
    ratio = g.radius[e] / floor
    k = int(np.argmin(ratio))
    below = int((ratio < 1 - 1e-9).sum())
    detail = (
        f"{len(e)} cylinders, radius / floor {floor:.6g} (mesh units): least "
        f"{_fmt(float(ratio[k]))} at cylinder {int(e[k])}; {below} below" + note
    )
    ok = below == 0
    return Check(name, ok, float(ratio[k]), 1.0, detail, ">=", {"mesh_edge": int(e[k])})


def _off_cylinder(g: _Data, points: np.ndarray, e: np.ndarray) -> np.ndarray:
    """``|distance of points[i] from edge e[i]'s axis - its radius| / size`` (NaN stays NaN)."""
    w = points - g.axis_point[e]
    t = g.axis_dir[e]
    with np.errstate(invalid="ignore"):
        radial = w - np.einsum("ij,ij->i", w, t)[:, None] * t
        return np.abs(np.linalg.norm(radial, axis=1) - g.radius[e]) / g.size


def _on_fillets(g: _Data) -> Check:
    """Every corner of a ``fillet e`` face on the cone from the edge's sharp end (the end
    without an apex) over the edge's base circle: the ruling through it meets the midpoint
    cross-section at the radius ``r`` from the axis."""
    name = "on fillets"
    c = np.flatnonzero(g.kind[g.face_of] == _FILLET)
    if not len(c):
        return Check(name, True, float("nan"), CYLINDER_TOL, "no conical fillet in the design")
    e = g.index[g.face_of[c]]
    ends = g.edge_vertices[e]
    bare = np.isnan(g.apex[ends]).any(axis=2)  # (k, 2): the end without an apex
    one = bare.sum(axis=1) == 1
    S = g.mv[np.where(bare[:, 0], ends[:, 0], ends[:, 1])]
    P = g.v3[g.flat[c]]
    t = g.axis_dir[e]
    M = 0.5 * (g.mv[ends[:, 0]] + g.mv[ends[:, 1]])
    d = P - S
    along = np.einsum("ij,ij->i", d, t)
    at_apex = np.linalg.norm(d, axis=1) <= CYLINDER_TOL * g.size
    with np.errstate(invalid="ignore", divide="ignore"):
        X = S + (np.einsum("ij,ij->i", M - S, t) / along)[:, None] * d
    err = _off_cylinder(g, X, e)
    err = np.where(at_apex, 0.0, err)
    err = np.where(g.rounded[e] & one & np.isfinite(err), err, np.inf)
    k = int(np.argmax(err))
    v, me = int(g.flat[c[k]]), int(e[k])
    detail = (
        f"{_distinct(g.flat[c])} points of {_distinct(e)} fillets; worst pattern vertex {v} "
        f"(fillet {me}); |distance of its ruling's base point - r| / size {CYLINDER_TOL:g}"
    )
    if not one.all():
        detail += f"; fillet {int(e[~one][0])} has not exactly one end without an apex"
    worst = {"pattern_vertex": v, "mesh_edge": me}
    ok = bool(err[k] <= CYLINDER_TOL)
    return Check(name, ok, float(err[k]), CYLINDER_TOL, detail, "<=", worst)


def _borders(points: np.ndarray, flat: np.ndarray, nxt: np.ndarray, eps: float):
    """The border of a polygon surface whose corners are ``points[flat]`` (corners within
    ``eps`` of each other are one vertex; ``eps < 0``: the points as given, so that a mesh's
    vertices split apart at a non-manifold point stay apart): its edges used by one face, as
    pairs of point indices, and the number of loops they form."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    n = len(points)
    pairs = (
        cKDTree(points).query_pairs(eps, output_type="ndarray")
        if eps >= 0
        else np.zeros((0, 2), dtype=np.int64)
    )
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    n_root, root = connected_components(graph, directed=False)
    root = root.astype(np.int64)  # int32 labels: lo * n below would overflow
    first = np.zeros(n_root, dtype=np.int64)  # a point of each vertex: its first
    first[root[::-1]] = np.arange(n)[::-1]
    a, b = root[flat], root[flat[nxt]]
    keep = a != b
    lo, hi = np.minimum(a, b)[keep], np.maximum(a, b)[keep]
    key, count = np.unique(lo * n + hi, return_counts=True)
    border = key[count == 1]
    if not len(border):
        return np.zeros((0, 2), dtype=np.int64), 0
    u, w = border // n, border % n
    nodes, inv = np.unique(np.concatenate([u, w]), return_inverse=True)
    m = len(nodes)
    g = coo_matrix((np.ones(len(u)), (inv[: len(u)], inv[len(u) :])), shape=(m, m))
    # loops: the cycle rank E - V + C of the border (two loops that touch at a point, as the
    # boxes of a mesh split apart at a non-manifold vertex do, count as two)
    loops = len(u) - m + int(connected_components(g, directed=False)[0])
    return np.stack([first[u], first[w]], axis=1), loops


def _distance_to_segments(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(k,) distance of every point ``p`` (k, 3) to the nearest of the segments ``a b``."""
    d = b - a
    length2 = np.maximum(np.einsum("ij,ij->i", d, d), np.finfo(float).tiny)
    best = np.full(len(p), np.inf)
    for lo in range(0, len(a), 256):  # segments in blocks: (k, 256) at a time
        aa, dd, ll = a[lo : lo + 256], d[lo : lo + 256], length2[lo : lo + 256]
        t = np.clip(np.einsum("kij,ij->ki", p[:, None] - aa[None], dd) / ll, 0.0, 1.0)
        q = aa[None] + t[..., None] * dd[None]
        best = np.minimum(best, np.linalg.norm(p[:, None] - q, axis=2).min(axis=1))
    return best


def _holes(g: _Data) -> Check:
    """Holes and notches of the folded surface (the pattern's faces glued where their 3D
    corners coincide). Its border edges that do not run along a boundary edge of the mesh
    form closed loops (holes: at vertices without a cone that were not kept sharp,
    ``--sharp``) or arcs from the mesh's border back to it (notches: at boundary vertices not
    kept sharp). Reported with the deepest notch / size, not limited."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    eps = GLUE_TOL * g.size
    border, _ = _borders(g.v3, g.flat, g.nxt, eps)
    mesh_border, _ = _borders(g.mv, g.mesh_flat, g.mesh_nxt, -1.0)
    on = np.zeros(len(border), dtype=bool)
    depth = 0.0
    if len(mesh_border) and len(border):
        a, b = g.mv[mesh_border[:, 0]], g.mv[mesh_border[:, 1]]
        ends = np.unique(border)
        far = _distance_to_segments(g.v3[ends], a, b)
        mid = _distance_to_segments(0.5 * (g.v3[border[:, 0]] + g.v3[border[:, 1]]), a, b)
        d0, d1 = far[np.searchsorted(ends, border[:, 0])], far[np.searchsorted(ends, border[:, 1])]
        on = (d0 <= eps) & (d1 <= eps) & (mid <= eps)
        depth = float(np.max(np.maximum(d0, d1), initial=0.0)) / g.size
    off = border[~on]
    holes = notches = 0
    if len(off):
        nodes, inv = np.unique(off, return_inverse=True)
        inv = inv.reshape(-1, 2)
        m = len(nodes)
        graph = coo_matrix((np.ones(len(off)), (inv[:, 0], inv[:, 1])), shape=(m, m))
        n_comp, comp = connected_components(graph, directed=False)
        degree = np.bincount(inv.ravel(), minlength=m)
        open_comp = np.zeros(n_comp, dtype=bool)
        open_comp[comp[degree != 2]] = True
        holes, notches = int((~open_comp).sum()), int(open_comp.sum())
    detail = f"{holes} holes and {notches} notches in the folded surface's border"
    if len(mesh_border):
        detail += f"; deepest notch of the border / size {depth:.3g}"
    return Check("holes", True, float(holes), None, detail, "", {})


def _face_newell(g: _Data) -> tuple[np.ndarray, np.ndarray]:
    """(n_faces, 3) Newell vectors (twice the vector area) and (n_faces,) perimeters, in 3D."""
    p = g.v3[g.flat]
    newell = newell_vectors(p, g.start, g.nxt)
    side = np.linalg.norm(p[g.nxt] - p, axis=1)
    return newell, np.add.reduceat(side, g.start[:-1])


def _folded(g: _Data, which: np.ndarray):
    """For pattern edges ``which`` (k,): whether each has two faces, its fold angle in the
    folded form (degrees, FOLD's sign: valley positive; NaN without two faces), and how far
    that angle may be off: :data:`ANGLE_TOL_DEG` plus what rounding the corners by
    ``sqrt(3) q`` can turn the two faces' normals by."""
    ef = g.edge_faces[which]
    two = (ef >= 0).all(axis=1)
    if g._newell is None:
        g._newell = _face_newell(g)
    newell, perimeter = g._newell
    norm = np.linalg.norm(newell, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = newell / norm[:, None]
        fa, fb = np.where(ef >= 0, ef, 0).T
        na, nb = unit[fa], unit[fb]
        d = g.v3[g.edges[which, 1]] - g.v3[g.edges[which, 0]]
        folded = -dihedral_turns(na, nb, d)  # FOLD's sign: valley positive
        slack = math.sqrt(3.0) * g.q * (2 * perimeter / norm)  # P / A, A = |newell| / 2
        allowed = ANGLE_TOL_DEG + np.degrees(slack[fa] + slack[fb])
    allowed = np.where(np.isfinite(allowed), allowed, np.inf)
    folded = np.where(two & np.isfinite(folded), folded, np.nan)
    return two, folded, allowed


def _facet_folds(g: _Data, limit_deg: float) -> Check:
    """``facet folds``: no ``F`` edge folds beyond ``limit_deg``; every crease inside one
    cone is a ruling from its apex to a mesh edge left unrounded."""
    name = "facet folds"
    smooth = np.flatnonzero(g.assign == "F")
    two, folded, allowed = _folded(g, smooth)
    smooth, folded, allowed = smooth[two], folded[two], allowed[two]
    detail = f"largest |fold| (deg) of {len(smooth)} F edges between two faces"
    if not len(smooth):
        return Check(name, True, float("nan"), limit_deg, "no F edge between two faces")
    excess = np.abs(np.where(np.isnan(folded), 180.0, folded))
    k = _ratio_worst(np.maximum(excess - limit_deg, 0.0), allowed)
    if excess[k] <= limit_deg:
        k = int(np.argmax(excess))
    e = int(smooth[k])
    fa, fb = g.edge_faces[e]
    where = g.patch[fa] if g.patch[fa] == g.patch[fb] else f"{g.patch[fa]} | {g.patch[fb]}"
    n_bad = int(np.count_nonzero(excess > limit_deg + allowed))
    detail += f": pattern edge {e} ({where}, {excess[k]:.6g} deg)"
    if n_bad:
        over = np.flatnonzero(excess > limit_deg + allowed)
        over = over[np.argsort(-excess[over], kind="stable")][:FAILING_NAMED]
        named = ", ".join(f"{int(smooth[j])} ({excess[j]:.4g} deg)" for j in over)
        detail += f"; {n_bad} F edge(s) fold beyond the facet limit: pattern edges {named}"
    detail += (
        f"; limit: the arc step {limit_deg:g} deg" if limit_deg < 180 else "; no limit (arc step 0)"
    )
    ok = n_bad == 0
    worst = {"pattern_edge": e, "patch": where}
    # creases inside one cone: rulings from its apex to an unrounded mesh edge
    crease = np.flatnonzero(np.isin(g.assign, ("M", "V")))
    ef = g.edge_faces[crease]
    inner = (ef >= 0).all(axis=1)
    crease, ef = crease[inner], ef[inner]
    fa, fb = ef.T
    in_cone = (g.kind[fa] == _CONE) & (g.kind[fb] == _CONE) & (g.index[fa] == g.index[fb])
    crease, u = crease[in_cone], g.index[fa[in_cone]]
    if len(crease):
        bad = _not_sharp_rulings(g, crease, u)
        detail += f"; {len(crease)} crease(s) inside cones"
        if len(bad):
            e = int(crease[bad[0]])
            detail += (
                f", {len(bad)} not a ruling to an unrounded edge: first pattern edge {e} "
                f"(cone {int(u[bad[0]])})"
            )
            ok, worst = False, {"pattern_edge": e, "patch": str(Patch("cone", int(u[bad[0]])))}
    return Check(name, ok, float(excess[k]), limit_deg, detail, "<=", worst)


def _not_sharp_rulings(g: _Data, crease: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Positions in ``crease`` (k,) (pattern edges inside the cones of mesh vertices ``u``)
    of those that are not a ruling from the cone's apex to a point of an unrounded mesh edge
    at ``u`` (within ``GLUE_TOL`` of the design size)."""
    eps = GLUE_TOL * g.size + 4 * g.q
    a, b = g.v3[g.edges[crease, 0]], g.v3[g.edges[crease, 1]]
    apex = g.apex[u]
    at_a = np.linalg.norm(a - apex, axis=1) <= eps
    at_b = np.linalg.norm(b - apex, axis=1) <= eps
    far = np.where(at_a[:, None], b, a)  # the end away from the apex
    ok = np.zeros(len(crease), dtype=bool)
    ev = g.edge_vertices
    sharp = ~g.rounded
    for j in np.flatnonzero(at_a ^ at_b).tolist():
        mine = np.flatnonzero(sharp & ((ev[:, 0] == u[j]) | (ev[:, 1] == u[j])))
        if len(mine):
            dist = _distance_to_segments(
                np.repeat(far[j][None], len(mine), axis=0), g.mv[ev[mine, 0]], g.mv[ev[mine, 1]]
            )
            ok[j] = bool((dist <= eps).any())
    return np.flatnonzero(~ok)


def _edge_lengths(g: _Data, limit_deg: float) -> Check:
    """``edge lengths``: every pattern edge as long folded as flat, up to a chord's loss."""
    name = "edge lengths"
    if not len(g.edges):
        return Check(name, True, float("nan"), 0.0, "no pattern edge")
    bound = chord_mismatch_bound(EDGE_TURNS * limit_deg)
    short = g.l2 - g.l3
    allowed = bound * g.l2 + LENGTH_QUANTA * g.q
    k = _ratio_worst(np.abs(short), allowed)
    rel = float(abs(short[k]) / g.l2[k]) if g.l2[k] > 0 else float("inf")
    n_bad = int(np.count_nonzero(np.abs(short) > allowed))
    e = int(k)
    fa, fb = g.edge_faces[e]
    where = " | ".join(dict.fromkeys(g.patch[f] for f in (fa, fb) if f >= 0))
    detail = (
        f"|len2D - len3D| / len2D of {len(g.edges)} pattern edges: worst pattern edge {e} "
        f"({g.assign[e]}, {where}; 2D {g.l2[e]:.6g}, 3D {g.l3[e]:.6g})"
    )
    if n_bad:
        over = np.flatnonzero(np.abs(short) > allowed)
        ratio = np.abs(short[over]) / np.where(g.l2[over] > 0, g.l2[over], 1.0)
        order = np.argsort(-ratio, kind="stable")[:FAILING_NAMED]
        named = ", ".join(f"{int(over[j])} ({ratio[j]:.4g})" for j in order)
        detail += f"; {n_bad} edge(s) differ by more: pattern edges {named}"
    detail += _quantum_note(
        g.q, f"the chord of {EDGE_TURNS:g} x {limit_deg:g} deg: {bound:.3g}", g.q_source
    )
    limit = float(allowed[k] / g.l2[k]) if g.l2[k] > 0 else bound
    worst = {"pattern_edge": e, "patch": where}
    return Check(name, n_bad == 0, rel, limit, detail, "<=", worst)


def _fold_angles(g: _Data) -> list[Check]:
    """``M/V``, ``fold-angle match``, ``fold-angle range`` and ``smallest fold angle``."""
    crease = np.flatnonzero(np.isin(g.assign, ("M", "V")))
    names = ("M/V", "fold-angle match", "fold-angle range", "smallest fold angle")
    if not len(crease):
        why = "no M/V crease in the design"
        return [
            Check(names[0], True, 0.0, 0.0, why),
            Check(names[1], True, float("nan"), ANGLE_TOL_DEG, why),
            Check(names[2], True, float("nan"), MAX_FOLD_DEG, why),
            Check(names[3], True, float("nan"), MIN_FOLD_DEG, why, ">"),
        ]
    m = g.assign[crease] == "M"
    written = g.angle[crease]
    two, folded, allowed = _folded(g, crease)
    # M/V: the written angle has the assignment's sign, and so has the folded form's
    bad_written = np.where(m, written >= 0, written <= 0)
    with np.errstate(invalid="ignore"):
        bad_folded = np.where(m, folded > allowed, folded < -allowed)
    disagree = ~two | bad_written | bad_folded
    n_bad = int(np.count_nonzero(disagree))
    detail = f"{len(crease)} creases ({int(m.sum())} M, {int((~m).sum())} V)"
    worst = {}
    if n_bad:
        k = int(np.flatnonzero(disagree)[0])
        e = int(crease[k])
        worst = {"pattern_edge": e}
        if not two[k]:
            why = "has only one face"
        else:
            why = f"written {written[k]:.6g}, folded form {folded[k]:.6g} deg"
        detail += f"; {n_bad} disagree: first pattern edge {e} ({g.assign[e]}, {why})"
    mv = Check(names[0], n_bad == 0, float(n_bad), 0.0, detail, "<=", worst)
    # fold-angle match: the written angle is the folded form's
    diff = np.abs((written - folded + 180.0) % 360.0 - 180.0)
    diff = np.where(np.isnan(diff), np.inf, diff)
    k = _ratio_worst(diff, allowed)
    e = int(crease[k])
    detail = (
        f"|written - folded form| (deg) of {len(crease)} creases; worst pattern edge {e} "
        f"(written {written[k]:.6g})"
        + _quantum_note(g.q, f"{ANGLE_TOL_DEG:g} deg + sqrt(3) q (P_a/A_a + P_b/A_b)", g.q_source)
    )
    match = Check(
        names[1],
        bool((diff <= allowed).all()),
        float(diff[k]),
        float(allowed[k]),
        detail,
        "<=",
        {"pattern_edge": e},
    )
    # fold-angle range: no crease folds flat, nor beyond the limit unless the mesh does
    magnitude = np.abs(written)
    k = int(np.argmax(magnitude))
    e = int(crease[k])
    sharpest = float(np.degrees(2.0 * np.nanmax(g.half_angle, initial=0.0)))
    limit = max(MAX_FOLD_DEG, sharpest)
    detail = f"largest |fold angle| (deg): pattern edge {e} ({g.assign[e]}, {written[k]:.6g})"
    # a crease on an edge left sharp folds by the mesh's dihedral: to round-off (``allowed``)
    n_flat = int(np.count_nonzero((magnitude > limit + allowed) | (magnitude >= 180.0)))
    if n_flat:
        detail += f"; {n_flat} crease(s) fold beyond the limit"
    detail += f"; limit {MAX_FOLD_DEG:g}, or the mesh's sharpest dihedral ({sharpest:.6g})"
    span = Check(
        names[2],
        n_flat == 0,
        float(magnitude[k]),
        limit + float(allowed[k]),
        detail,
        "<=",
        {"pattern_edge": e},
    )
    # smallest fold angle: every crease folds
    k = int(np.argmin(magnitude))
    e = int(crease[k])
    n_none = int(np.count_nonzero(magnitude <= MIN_FOLD_DEG))
    detail = f"smallest |fold angle| (deg): pattern edge {e} ({g.assign[e]}, {written[k]:.6g})"
    if n_none:
        detail += f"; {n_none} M/V edge(s) that do not fold"
    small = Check(
        names[3], n_none == 0, float(magnitude[k]), MIN_FOLD_DEG, detail, ">", {"pattern_edge": e}
    )
    return [mv, match, span, small]


def _signed_area_2d(g: _Data) -> np.ndarray:
    """(n_faces,) signed area in 2D (shoelace about each face's first corner)."""
    p = g.v2[g.flat] - np.repeat(g.v2[g.flat[g.start[:-1]]], g.size_of, axis=0)
    pn = p[g.nxt]
    return 0.5 * np.add.reduceat(p[:, 0] * pn[:, 1] - pn[:, 0] * p[:, 1], g.start[:-1])


def _overlap(g: _Data) -> list[Check]:
    """``no overlap`` (faces' interiors disjoint in 2D, every face a simple polygon) and
    ``face orientation`` (every face counter-clockwise)."""
    area = _signed_area_2d(g)
    n_faces = len(area)
    # orientation
    scale = g.size**2
    k = int(np.argmin(area))
    n_cw = int(np.count_nonzero(area <= 0))
    detail = f"smallest signed area / size^2 of {n_faces} faces: {g.where_face(k)}"
    if n_cw:
        detail += f"; {n_cw} face(s) clockwise or flat"
    orient = Check(
        "face orientation", n_cw == 0, float(area[k] / scale), 0.0, detail, ">", {"pattern_face": k}
    )
    # overlap: the pairs of faces whose bounding boxes meet (closed; from a grid of the boxes,
    # a block of faces at a time, each block's pairs in order), told apart in numpy when both
    # are convex (:class:`_Separator`), their shared area measured by shapely otherwise; only
    # the faces measured, and those that are not convex (checked to be simple polygons), are
    # made shapely polygons (a shapely box per face would take some 400 bytes each)
    p = g.v2[g.flat]
    lo, hi = np.minimum.reduceat(p, g.start[:-1]), np.maximum.reduceat(p, g.start[:-1])
    grid = BoxGrid(lo, hi)
    convex = _convex_faces(g, area)
    separator = _Separator(g, convex)
    polys = np.full(n_faces, None, dtype=object)
    _make_polygons(g, polys, ~convex)
    valid = convex.copy()
    valid[~convex] = shapely.is_valid(polys[~convex])
    n_pairs = n_measured = n_over = 0
    value, value_limit, worst_pair = 0.0, OVERLAP_TOL, None
    perimeter = np.add.reduceat(np.linalg.norm(g.v2[g.flat[g.nxt]] - p, axis=1), g.start[:-1])
    for first in range(0, n_faces, QUERY_CHUNK):
        i, j = grid.query(lo[first : first + QUERY_CHUNK], hi[first : first + QUERY_CHUNK])
        i += first
        keep = i < j
        i, j = i[keep], j[keep]
        order = np.lexsort((j, i))
        i, j = i[order], j[order]
        n_pairs += len(i)
        both = convex[i] & convex[j]
        separated = np.zeros(len(i), dtype=bool)
        if both.any():
            separated[both] = separator.separated(i[both], j[both])
        near = np.flatnonzero(~separated)
        near = near[valid[i[near]] & valid[j[near]]]  # a face that is not simple: reported below
        if not len(near):
            continue
        i, j = i[near], j[near]
        needed = np.zeros(n_faces, dtype=bool)
        needed[i] = needed[j] = True
        _make_polygons(g, polys, needed)
        shared = _intersection_area(polys[i], polys[j])
        smaller = np.minimum(np.abs(area[i]), np.abs(area[j]))
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = np.where(smaller > 0, shared / smaller, np.where(shared > 0, np.inf, 0.0))
        ratio = np.where(np.isnan(ratio), np.inf, ratio)
        # moving every corner by up to sqrt(2) q moves each border by as much: the shared
        # area grows by at most that times the two perimeters
        with np.errstate(invalid="ignore", divide="ignore"):
            allowed = OVERLAP_TOL + np.where(
                smaller > 0, math.sqrt(2.0) * g.q * (perimeter[i] + perimeter[j]) / smaller, 0.0
            )
        n_measured += len(ratio)
        n_over += int(np.count_nonzero(ratio > allowed))
        k = int(np.argmax(ratio / allowed))
        if worst_pair is None or ratio[k] / allowed[k] > value / value_limit:
            value, value_limit = float(ratio[k]), float(allowed[k])
            worst_pair = (int(i[k]), int(j[k]))
    detail = f"{n_pairs} touching or close face pairs, {n_measured} measured"
    worst = {}
    if worst_pair is not None:
        a, b = worst_pair
        worst = {"pattern_faces": [a, b]}
        detail += f"; worst {g.where_face(a)} and {g.where_face(b)}"
    if n_over:
        detail += f"; {n_over} pair(s) overlap"
    invalid = np.flatnonzero(~valid)
    if len(invalid):
        value = max(value, 1.0)  # a face that is not a simple polygon overlaps itself
        detail += f"; {len(invalid)} face(s) not simple polygons (first {g.where_face(invalid[0])})"
        worst = worst or {"pattern_faces": [int(invalid[0])]}
    no_overlap = Check(
        "no overlap",
        bool(not n_over and not len(invalid)),
        value,
        value_limit,
        detail
        + f"; shared area / smaller face {OVERLAP_TOL:g}"
        + _quantum_note(g.q, f"{OVERLAP_TOL:g} + sqrt(2) q (P_a + P_b) / A", g.q_source),
        "<=",
        worst,
    )
    return [no_overlap, orient]


def _convex_faces(g: _Data, area: np.ndarray) -> np.ndarray:
    """(n_faces,) bool: counter-clockwise convex faces of at most :data:`SAT_CORNERS` corners
    (every turn to the left up to rounding, one turn in all)."""
    p = g.v2[g.flat]
    d = p[g.nxt] - p
    dn = d[g.nxt]
    cross = d[:, 0] * dn[:, 1] - d[:, 1] * dn[:, 0]
    length = np.hypot(d[:, 0], d[:, 1])
    left = cross >= -tol.roundoff * length * length[g.nxt]
    turn = np.arctan2(cross, np.einsum("ij,ij->i", d, dn))
    one_turn = np.add.reduceat(turn, g.start[:-1]) < 3 * np.pi
    return (
        np.logical_and.reduceat(left, g.start[:-1])
        & one_turn
        & (area > 0)
        & (g.size_of <= SAT_CORNERS)
    )


def _make_polygons(g: _Data, polys: np.ndarray, which: np.ndarray) -> None:
    """Set ``polys[f]`` (n_faces,) to the shapely polygon of face ``f`` where ``which`` (bool)
    says so and it is not made yet."""
    which = which & shapely.is_missing(polys)
    if not which.any():
        return
    corner = which[g.face_of]
    number = np.cumsum(which) - 1
    rings = shapely.linearrings(g.v2[g.flat[corner]], indices=number[g.face_of[corner]])
    polys[which] = shapely.polygons(rings)


class _Separator:
    """Separating-axis proofs for pairs of convex faces: every face's corners and outward unit
    edge normals as (n_faces, K) arrays (``K``: the most corners of a convex face; shorter faces
    repeat their last corner)."""

    def __init__(self, g: _Data, convex: np.ndarray):
        size = g.size_of
        self.size = size
        self.k = int(size[convex].max(initial=3))
        ks = np.arange(self.k)
        first = g.start[:-1, None]
        # (n_faces, K) arrays, made in place where they can be: a scan's 2 million faces
        # take some 80 MB per array
        corner = g.flat[first + np.minimum(ks, size[:, None] - 1)]
        x, y = g.v2[corner, 0], g.v2[corner, 1]
        del corner
        nxt = g.flat[first + np.where(ks + 1 < size[:, None], ks + 1, 0)]
        dx, dy = g.v2[nxt, 0] - x, g.v2[nxt, 1] - y
        del nxt
        length = np.hypot(dx, dy)
        live = (ks < size[:, None]) & (length > 0)
        with np.errstate(invalid="ignore", divide="ignore"):
            nx = np.divide(dy, length, out=dy)
            ny = np.divide(np.negative(dx, out=dx), length, out=dx)
        del length
        nx[~live] = 0.0
        ny[~live] = 0.0
        eps = 64 * np.finfo(float).eps * max(float(np.abs(g.v2).max()), g.size)
        self.x, self.y, self.nx, self.ny = x, y, nx, ny
        # an edge separates when the other face's nearest corner is at least this far along
        # its normal (the edge's own offset, less the rounding of the products)
        reach = nx * x
        reach += ny * y
        reach -= eps
        reach[~live] = np.inf
        self.reach = reach

    def separated(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """(k,) bool: whether the convex faces ``i`` and ``j`` (k,) are proved to have
        disjoint interiors: an edge of one has the other wholly on its outer side, up to
        rounding (two convex polygons with disjoint interiors always have such an edge).

        Pairs are taken by their numbers of corners, the other face's corners one at a time
        (every temporary is a (pairs, corners) array); the edges of ``j`` are tried only on
        the pairs the edges of ``i`` did not separate.
        """
        size, stride = self.size, self.k + 1
        x, y, nx, ny, reach = self.x, self.y, self.nx, self.ny, self.reach
        out = np.zeros(len(i), dtype=bool)
        for u_all, w_all in ((i, j), (j, i)):
            todo = np.flatnonzero(~out)
            combo = size[u_all[todo]] * stride + size[w_all[todo]]
            for key in np.unique(combo).tolist():
                ku, kw = divmod(key, stride)
                group = todo[combo == key]
                for lo in range(0, len(group), PAIR_CHUNK):
                    sel = group[lo : lo + PAIR_CHUNK]
                    u, w = u_all[sel], w_all[sel]
                    nu, mu = nx[u, :ku], ny[u, :ku]
                    xw, yw = x[w, :kw], y[w, :kw]
                    near = nu * xw[:, :1] + mu * yw[:, :1]  # (c, ku): nearest corner so far
                    for k in range(1, kw):
                        np.minimum(near, nu * xw[:, k : k + 1] + mu * yw[:, k : k + 1], out=near)
                    out[sel] = (near >= reach[u, :ku]).any(axis=1)
        return out


def _intersection_area(pa: np.ndarray, pb: np.ndarray) -> np.ndarray:
    """(k,) area shared by valid polygons ``pa`` and ``pb`` (k,) (infinity for a pair GEOS
    cannot intersect)."""
    try:
        return shapely.area(shapely.intersection(pa, pb))
    except shapely.errors.GEOSException:
        out = np.empty(len(pa))
        for k, (a, b) in enumerate(zip(pa, pb, strict=True)):  # only after GEOS failed
            try:
                out[k] = shapely.area(shapely.intersection(a, b))
            except shapely.errors.GEOSException:
                out[k] = np.inf
        return out


def _smallest_edge(g: _Data) -> Check:
    name = "smallest edge"
    if not len(g.edges):
        return Check(name, True, float("nan"), MIN_EDGE, "no pattern edge", ">=")
    length = np.minimum(g.l2, g.l3) / g.size
    k = int(np.argmin(length))
    detail = f"shortest of {len(g.edges)} pattern edges / size: pattern edge {k} ({g.assign[k]})"
    n_short = int(np.count_nonzero(length < MIN_EDGE))
    if n_short:
        detail += f"; {n_short} shorter than the limit"
    ok = n_short == 0
    return Check(name, ok, float(length[k]), MIN_EDGE, detail, ">=", {"pattern_edge": k})


def _smallest_face_angle(g: _Data) -> Check:
    p = g.v2[g.flat]
    u, w = p[g.prv] - p, p[g.nxt] - p
    cross = w[:, 0] * u[:, 1] - w[:, 1] * u[:, 0]
    angle = np.degrees(np.arctan2(cross, np.einsum("ij,ij->i", w, u))) % 360.0
    k = int(np.argmin(angle))
    f = int(g.face_of[k])
    detail = f"degrees, in 2D: corner at pattern vertex {int(g.flat[k])} of {g.where_face(f)}"
    worst = {"pattern_face": f, "pattern_vertex": int(g.flat[k])}
    return Check("smallest face angle", True, float(angle[k]), None, detail, "", worst)


def certify_design(design) -> Certificate:
    """:func:`certify` of an in-memory design (its pattern, cleaned mesh, rounding and apices).

    Parameters
    ----------
    design : Design

    Returns
    -------
    Certificate
    """
    mesh = design.mesh
    return certify(
        design.pattern,
        mesh.vertices,
        mesh.faces,
        design_edges(design),
        design.vertices.apex,
        coord_quantum=memory_quantum(design.pattern),
        quantum_source=f"round-off: {ROUNDOFF_ULPS} ulp of the largest coordinate",
        arc_step=float(design.params.arc_step),
        bend_floor=design.params.bend_floor(),
        material=design.params.sheet_material(),
    )


def design_edges(design) -> dict:
    """The ``edges`` of :func:`certify` for an in-memory design: its mesh's edges and their
    faces, and its rounding's radius, half angle and mountain/valley sign."""
    rd = design.rounding
    return {
        "vertices": design.mesh.edges,
        "faces": design.mesh.edge_faces,
        "radius": rd.radius,
        "half_angle": rd.half_angle,
        "kappa": rd.kappa,
    }


def memory_quantum(pattern: CreasePattern) -> float:
    """How far a coordinate computed in floating point may be from its exact value:
    :data:`ROUNDOFF_ULPS` units in the last place of the largest ``|coordinate|`` in 2D or 3D
    (the pieces' points come out of chained rigid maps and a layout translation)."""
    return ROUNDOFF_ULPS * np.finfo(float).eps * _largest_coordinate(pattern)


def _largest_coordinate(pattern: CreasePattern) -> float:
    return max(
        float(np.abs(pattern.vertices_2d).max(initial=0.0)),
        float(np.abs(pattern.vertices_3d).max(initial=0.0)),
    )


def file_quantum(pattern: CreasePattern) -> float:
    """How far a coordinate of a pattern read from a FOLD file may be from the one computed:
    :data:`FILE_ROUNDING` (5e-12) times the largest ``|coordinate|`` in 2D or 3D."""
    return FILE_ROUNDING * _largest_coordinate(pattern)


def check_folder(path) -> Certificate:
    """:func:`certify` the design in a folder written by ``filletfold round``.

    Reads ``design.fold`` (the pattern) and ``report.json`` (the mesh, its edges' radii, half
    angles and assignments, the vertices' apices); the tolerances allow for the FOLD file's
    rounding (:func:`file_quantum`).

    Parameters
    ----------
    path : str or os.PathLike
        The folder.

    Returns
    -------
    Certificate

    Raises
    ------
    MeshReadError
        When the folder or one of the two files is missing or unreadable, or the two do not
        belong together; the message is one line naming the file.
    """
    folder = Path(os.fspath(path))
    if not folder.is_dir():
        what = "not a folder" if folder.exists() else "no such folder"
        raise MeshReadError(f"{folder}: {what} (write a design with 'filletfold round')")
    fold, report = folder / "design.fold", folder / "report.json"
    for f in (fold, report):
        if not f.is_file():
            raise MeshReadError(f"{f}: no such file (write the design with 'filletfold round')")
    pattern, doc = read_fold_document(fold)
    mesh_vertices, mesh_faces, edges, apex, arc_step, sheet = _read_report(report, doc, fold)
    try:
        return certify(
            pattern,
            mesh_vertices,
            mesh_faces,
            edges,
            apex,
            coord_quantum=file_quantum(pattern),
            arc_step=arc_step,
            bend_floor=sheet[0],
            material=sheet[1],
        )
    except ParameterError as exc:
        raise MeshReadError(f"{fold} does not match {report.name}: {exc}") from None


#: The prefix of the mesh's keys in ``design.fold`` (see ``mesh_fold_keys`` in
#: :mod:`filletfold.export.outputs`).
MESH_KEY = "filletfold:mesh_"


def _read_report(path: Path, fold_doc: dict | None = None, fold_path: Path | None = None):
    """(mesh vertices, mesh faces, edges dict, vertex apices, arc step, (bend floor,
    material)) of a
    design: the mesh
    and its edges and apices from the ``filletfold:mesh_*`` keys of its FOLD document when it
    has them, else from the tables of its ``report.json`` (written with ``--report-tables``,
    or by filletfold before 0.2); the arc step the report's parameters name, else the
    default."""
    doc = load_json(path, "a report")  # a named error for any file that is not JSON
    if not isinstance(doc, dict) or "parameters" not in doc:
        raise MeshReadError(f"{path}: not a filletfold report (no key 'parameters')")
    in_fold = fold_doc is not None and MESH_KEY + "vertices_coords" in fold_doc
    where = fold_path or "design.fold"
    if not in_fold and "edges" not in doc:
        raise MeshReadError(
            f"{where} has no mesh data and {path.name} no tables "
            "(write the design again with 'filletfold round')"
        )
    source, what = (where, "filletfold's mesh data") if in_fold else (path, "a filletfold report")
    try:
        columns = _fold_columns(fold_doc) if in_fold else _report_columns(doc)
        vertices, faces, ev, ef, radius, gamma, kappa, apex = _mesh_arrays(*columns)
    except KeyError as exc:
        raise MeshReadError(f"{source}: not {what} (no key {exc})") from None
    except (TypeError, ValueError, AttributeError) as exc:
        raise MeshReadError(f"{source}: not {what} (malformed: {exc})") from None
    if in_fold:
        counts = doc.get("mesh_counts")
        mine = {"vertices": len(vertices), "edges": len(ev), "faces": len(faces)}
        if isinstance(counts, dict) and {k: counts.get(k) for k in mine} != mine:
            raise MeshReadError(
                f"{where} does not match {path.name}: its mesh has {mine['vertices']} vertices, "
                f"{mine['edges']} edges and {mine['faces']} faces, the report's "
                f"{counts.get('vertices')}, {counts.get('edges')} and {counts.get('faces')}"
            )
    try:
        arc_step = float((doc.get("parameters") or {}).get("arc_step", DEFAULT_ARC_STEP))
    except (TypeError, ValueError, AttributeError) as exc:
        raise MeshReadError(f"{path}: not a filletfold report (malformed: {exc})") from None
    if len(apex) != len(vertices):
        raise MeshReadError(
            f"{source}: {len(apex)} vertex apices for a mesh of {len(vertices)} vertices"
        )
    kappa = np.where((radius > 0) & (ef >= 0).all(axis=1), kappa, 0.0)  # flat edges: no cylinder
    edges = {"vertices": ev, "faces": ef, "radius": radius, "half_angle": gamma, "kappa": kappa}
    if not (math.isfinite(arc_step) and 0 <= arc_step <= 180):
        raise MeshReadError(f"{path}: arc_step {arc_step} is not in [0, 180] degrees")
    return vertices, faces, edges, apex, arc_step, _report_sheet(doc, path)


def _report_sheet(doc: dict, path: Path) -> tuple:
    """``(bend floor, material)`` of the parameters a design's report names: the floor in
    mesh units (:meth:`~filletfold.parameters.Parameters.bend_floor`; 0 without a material)
    and the :class:`~filletfold.materials.Material` (None)."""
    from .parameters import Parameters

    try:
        params = Parameters.from_dict(doc.get("parameters"), where=f"{path}: parameters")
        return params.bend_floor(), params.sheet_material()
    except ParameterError as exc:
        raise MeshReadError(f"{path}: {exc}") from None


def _fold_columns(doc: dict) -> tuple:
    """The mesh's columns (see :func:`_mesh_arrays`) from the ``filletfold:mesh_*`` keys."""

    def key(name):
        return doc[MESH_KEY + name]

    return (
        key("vertices_coords"),
        key("faces_vertices"),
        key("edges_vertices"),
        key("edges_faces"),
        key("edges_radius"),
        key("edges_halfAngle"),
        key("edges_assignment"),
        key("vertices_apex"),
    )


def _report_columns(doc: dict) -> tuple:
    """The mesh's columns (see :func:`_mesh_arrays`) from a report's tables."""
    records = doc["edges"]
    return (
        doc["mesh"]["vertices"],
        doc["mesh"]["faces"],
        [r["vertices"] for r in records],
        [[-1, -1] if r["faces"] is None else r["faces"] for r in records],
        [r["radius"] for r in records],
        [r["half_angle"] for r in records],
        [r["assignment"] for r in records],
        [v["apex"] for v in doc["vertices"]],
    )


def _mesh_arrays(vertices, faces, ev, ef, radius, half, assignment, apex) -> tuple:
    """(vertices, faces, edge vertices, edge faces, radius, half angle, kappa, apex) as
    arrays, from the columns a FOLD or a report holds: ``null`` radii and half angles NaN,
    kappa +1 / -1 for ``M`` / ``V`` (0 otherwise), a ``null`` apex a row of NaN."""
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    faces = [np.asarray(f, dtype=np.int64).reshape(-1) for f in faces]
    ev = np.asarray(ev, dtype=np.int64).reshape(-1, 2)
    ef = np.asarray(ef, dtype=np.int64).reshape(-1, 2)
    radius = np.array([_number(r) for r in radius], dtype=np.float64)
    gamma = np.array([_number(g) for g in half], dtype=np.float64)
    sign = {"M": 1.0, "V": -1.0}
    kappa = np.array([sign.get(a, 0.0) for a in assignment], dtype=np.float64)
    apex = np.array([[np.nan] * 3 if a is None else a for a in apex], dtype=np.float64).reshape(
        -1, 3
    )
    if not (len(ev) == len(ef) == len(radius) == len(gamma) == len(kappa)):
        raise ValueError("its edge columns differ in length")
    return vertices, faces, ev, ef, radius, gamma, kappa, apex


def _number(x) -> float:
    return float("nan") if x is None else float(x)
