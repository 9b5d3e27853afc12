"""Built-in example meshes, generated in code.

Every example has edges of length about 1 (the Platonic solids exactly 1, centred at the
origin) and faces counter-clockwise seen from outside. ``EXAMPLES`` maps each name to an
:class:`Example`; :func:`example_mesh` builds one.

Some examples take parameters, written after a colon: ``"miura:4x3,angle=65,fold=0.6"``. A bare
first token ``AxB`` is the ``cells`` parameter; the others are ``name=value``. The folded
tessellations (:mod:`filletfold.mesh.tessellations`) are parametrised this way.
"""

from __future__ import annotations

import difflib
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull

from ..errors import MeshReadError, ParameterError
from ..tolerances import tol
from . import tessellations

_PHI = (1.0 + np.sqrt(5.0)) / 2.0


@dataclass(frozen=True)
class Example:
    """One built-in example mesh.

    Attributes
    ----------
    name : str
    description : str
    kinds : tuple of str
        Tags among ``"platonic"``, ``"convex"``, ``"non-convex"``, ``"saddle"``, ``"closed"``,
        ``"open"``, ``"triangles"``, ``"quads"``, ``"polygons"``, ``"genus-1"``,
        ``"developable"``, ``"tessellation"``, ``"conical"``.
    builder : callable
        ``builder(**params) -> (vertices (n, 3) float, faces list of (k,) int)``.
    params : tuple of str
        Names of the keyword parameters ``builder`` accepts (empty: none). ``"cells"`` takes a
        pair of ints written ``AxB``; every other parameter a float.
    """

    name: str
    description: str
    kinds: tuple[str, ...]
    builder: Callable[..., tuple[np.ndarray, list[np.ndarray]]]
    params: tuple[str, ...] = ()

    @property
    def closed(self) -> bool:
        return "open" not in self.kinds


# ------------------------------------------------------------------------------- helpers
def _convex_polyhedron(points) -> tuple[np.ndarray, list[np.ndarray]]:
    """Faces of the convex hull of ``points`` (n, 3), coplanar hull triangles merged.

    Every point must be a hull vertex. Faces are counter-clockwise seen from outside, start at
    their smallest vertex index and are sorted, so the output does not depend on Qhull's order.
    """
    p = np.asarray(points, dtype=np.float64)
    hull = ConvexHull(p)
    if len(hull.vertices) != len(p):
        raise ValueError("every point must be a vertex of the convex hull")
    scale = float(np.abs(p).max())
    eq = hull.equations
    group = -np.ones(len(eq), dtype=np.int64)
    n_groups = 0
    for i in range(len(eq)):
        if group[i] >= 0:
            continue
        same = (np.abs(eq - eq[i]) <= tol.relative * max(scale, 1.0)).all(axis=1) & (group < 0)
        group[same] = n_groups
        n_groups += 1
    faces = []
    for g in range(n_groups):
        idx = np.unique(hull.simplices[group == g])
        n = eq[group == g][0, :3]
        c = p[idx].mean(axis=0)
        u = p[idx[0]] - c
        u /= np.linalg.norm(u)
        w = np.cross(n, u)
        ang = np.arctan2((p[idx] - c) @ w, (p[idx] - c) @ u)
        f = idx[np.argsort(ang)]
        faces.append(np.roll(f, -int(np.argmin(f))))
    faces.sort(key=lambda f: tuple(f.tolist()))
    return p, faces


def _prism(polygon_xy, height: float) -> tuple[np.ndarray, list[np.ndarray]]:
    """A right prism over a simple CCW polygon (k, 2), bottom at z=-h/2, top at z=+h/2."""
    q = np.asarray(polygon_xy, dtype=np.float64)
    k = len(q)
    bottom = np.column_stack([q, np.full(k, -height / 2)])
    top = np.column_stack([q, np.full(k, height / 2)])
    vertices = np.vstack([bottom, top])
    faces = [np.arange(k)[::-1].copy(), np.arange(k, 2 * k)]
    for i in range(k):
        j = (i + 1) % k
        faces.append(np.array([i, j, k + j, k + i]))
    return vertices, faces


def _scale_mean_edge(vertices, faces, target: float = 1.0) -> np.ndarray:
    edges = {(min(a, b), max(a, b)) for f in faces for a, b in zip(f, np.roll(f, -1), strict=True)}
    e = np.array(sorted(edges))
    mean = np.linalg.norm(vertices[e[:, 1]] - vertices[e[:, 0]], axis=1).mean()
    return vertices * (target / mean)


# --------------------------------------------------------------------------- Platonic solids
def _tetrahedron():
    p = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=np.float64)
    return _convex_polyhedron(p / (2 * np.sqrt(2)))


def _cube():
    p = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
    return _convex_polyhedron(p)


def _octahedron():
    p = np.vstack([np.eye(3), -np.eye(3)]) / np.sqrt(2)
    return _convex_polyhedron(p)


def _dodecahedron():
    cube = [[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    rest = []
    for a in (-1 / _PHI, 1 / _PHI):
        for b in (-_PHI, _PHI):
            rest += [[0, a, b], [a, b, 0], [b, 0, a]]
    p = np.array(cube + rest, dtype=np.float64)
    return _convex_polyhedron(p * (_PHI / 2))  # edge 2/phi -> 1


def _icosahedron_points() -> np.ndarray:
    p = []
    for a in (-1, 1):
        for b in (-_PHI, _PHI):
            p += [[0, a, b], [a, b, 0], [b, 0, a]]
    return np.array(p, dtype=np.float64) / 2  # edge 2 -> 1


def _icosahedron():
    return _convex_polyhedron(_icosahedron_points())


# ----------------------------------------------------------------------- other convex solids
def _square_pyramid():
    h = 1 / np.sqrt(2)  # Johnson solid J1: all edges 1
    base = [[x, y, -h / 4] for x, y in ((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5))]
    return _convex_polyhedron(np.array([*base, [0, 0, 3 * h / 4]]))


def _triangular_prism():
    ang = np.radians([90, 210, 330])
    tri = np.column_stack([np.cos(ang), np.sin(ang)]) / np.sqrt(3)  # side 1
    v, _ = _prism(tri, 1.0)
    return _convex_polyhedron(v)


def _pentagonal_bipyramid():
    r = 1 / (2 * np.sin(np.pi / 5))  # pentagon side 1
    h = np.sqrt(1 - r**2)  # Johnson solid J13: all edges 1
    ang = 2 * np.pi * np.arange(5) / 5
    ring = np.column_stack([r * np.cos(ang), r * np.sin(ang), np.zeros(5)])
    return _convex_polyhedron(np.vstack([ring, [[0, 0, h], [0, 0, -h]]]))


def _house():
    box = [[x, y, z] for x in (-0.5, 0.5) for y in (-0.75, 0.75) for z in (-0.5, 0.5)]
    ridge = [[0, -0.75, 1.0], [0, 0.75, 1.0]]
    return _convex_polyhedron(np.array(box + ridge))


def _random_convex():
    rng = np.random.default_rng(700)  # a seed whose hull has no very short edge (min ~0.5)
    p = rng.normal(size=(14, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    p *= [1.0, 1.0, 0.75]
    v, f = _convex_polyhedron(p)
    return _scale_mean_edge(v, f), f


# ------------------------------------------------------------------------------ non-convex
def _dimpled_cube():
    v, f = _cube()
    top = next(fi for fi in f if np.allclose(v[fi, 2], 0.5))
    rest = [fi for fi in f if fi is not top]
    c = len(v)
    v = np.vstack([v, [0, 0, 0.5 - 0.2]])
    tris = [np.array([top[i], top[(i + 1) % 4], c]) for i in range(4)]
    return v, rest + tris


def _l_prism():
    outline = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    q = np.array(outline, dtype=np.float64) - [0.75, 0.75]
    return _prism(q, 1.0)


def _torus(n_major: int = 8, n_minor: int = 6, major: float = 1.6, minor: float = 0.6):
    t = 2 * np.pi * np.arange(n_major) / n_major
    s = 2 * np.pi * np.arange(n_minor) / n_minor
    tt, ss = np.meshgrid(t, s, indexing="ij")
    rho = major + minor * np.cos(ss)
    v = np.column_stack(
        [(rho * np.cos(tt)).ravel(), (rho * np.sin(tt)).ravel(), (minor * np.sin(ss)).ravel()]
    )
    faces = []
    for i in range(n_major):
        for j in range(n_minor):
            a = i * n_minor + j
            b = ((i + 1) % n_major) * n_minor + j
            c = ((i + 1) % n_major) * n_minor + (j + 1) % n_minor
            d = i * n_minor + (j + 1) % n_minor
            faces.append(np.array([a, b, c, d]))
    return _scale_mean_edge(v, faces), faces


def _icosphere(subdivisions: int) -> tuple[np.ndarray, list[np.ndarray]]:
    v, faces = _icosahedron()
    pts = list(v / np.linalg.norm(v, axis=1)[:, None])
    tris = [tuple(int(x) for x in f) for f in faces]
    for _ in range(subdivisions):
        mid: dict[tuple[int, int], int] = {}

        def midpoint(a: int, b: int, mid=mid) -> int:
            key = (min(a, b), max(a, b))
            if key not in mid:
                m = pts[a] + pts[b]
                pts.append(m / np.linalg.norm(m))
                mid[key] = len(pts) - 1
            return mid[key]

        new = []
        for a, b, c in tris:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        tris = new
    return np.array(pts), [np.array(t, dtype=np.int64) for t in tris]


def _geodesic_sphere(level: float = 1):
    """Icosahedron subdivided ``level`` times (4**level x 20 triangles) on the unit sphere."""
    lv = float(level)
    if lv != int(lv) or not 0 <= lv <= 6:
        raise ParameterError(f"level must be a whole number in 0..6, got {level!r}", name="level")
    v, f = _icosphere(int(lv))
    return _scale_mean_edge(v, f), f


def _blob():
    v, faces = _icosphere(2)
    bumps = [  # (direction, height, width): bumps out (>0) and dents in (<0)
        ((1.0, 0.2, 0.3), 0.35, 0.5),
        ((-0.6, 0.8, 0.1), 0.25, 0.45),
        ((0.1, -0.3, 1.0), -0.22, 0.5),
        ((-0.4, -0.9, -0.3), 0.3, 0.55),
        ((-0.2, 0.1, -1.0), -0.18, 0.6),
    ]
    r = np.ones(len(v))
    for d, height, width in bumps:
        d = np.asarray(d) / np.linalg.norm(d)
        ang = np.arccos(np.clip(v @ d, -1, 1))
        r += height * np.exp(-((ang / width) ** 2))
    r += 0.05 * np.sin(3 * v[:, 0]) * np.cos(2 * v[:, 1])
    return _scale_mean_edge(v * r[:, None], faces), faces


# ---------------------------------------------------------------------------------- open
def _open_box():
    v, f = _cube()
    return v, [fi for fi in f if not np.allclose(v[fi, 2], 0.5)]


def _tent():
    v = np.array(
        [
            [-0.5, -0.75, 0],
            [0.5, -0.75, 0],
            [0.5, 0.75, 0],
            [-0.5, 0.75, 0],
            [0, -0.75, 0.8],
            [0, 0.75, 0.8],
        ],
        dtype=np.float64,
    )
    faces = [[0, 1, 4], [2, 3, 5], [1, 2, 5, 4], [3, 0, 4, 5]]
    return v, [np.array(f) for f in faces]


def _saddle_patch():
    n = 5
    x = np.linspace(-1, 1, n)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    zz = 0.6 * xx * yy  # (x^2 - y^2 would make every grid square planar)
    v = np.column_stack([xx.ravel(), yy.ravel(), zz.ravel()])
    faces = []
    for i in range(n - 1):
        for j in range(n - 1):
            a, b, c, d = i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1, i * n + j + 1
            # one diagonal direction: alternating ones would make pairs of coplanar triangles
            faces += [np.array([a, b, c]), np.array([a, c, d])]
    return _scale_mean_edge(v, faces), faces


def _shell(cells=(6, 4), opening: float = 140.0, sag: float = 0.1):
    """An open vault shell (a shelter, as in the paper's fig. 20): a translational surface of
    planar quads, convex at every interior vertex.

    The arch across is an arc of the unit circle turning ``opening`` degrees, ``a`` quads of equal
    angle; along the vault, ``b`` rows of quads whose width equals the arch's step, on a
    parabola that lowers both ends by ``sag`` times the vault's length. A translational
    surface ``P(i, j) = (x_i, y_j, f_i + g_j)`` has parallelogram quads, so every quad is
    planar; with both curves concave each interior vertex has a positive angle defect. Scaled
    to a mean edge length of 1, its lowest point at z = 0.

    Parameters
    ----------
    cells : (2,) int
        ``(a, b)``: quads across the arch (2..24) and along the vault (1..24).
    opening : float
        Turn of the arch in degrees, in [30, 170].
    sag : float
        Drop of the two ends over the vault's length, in [0, 0.4] (0: a barrel vault, every
        interior vertex developable).

    Returns
    -------
    vertices : ((a + 1) * (b + 1), 3) float64
        Row ``j`` along the vault holds vertices ``j * (a + 1) .. j * (a + 1) + a``.
    faces : list of (4,) int64
        Counter-clockwise seen from above (outside).
    """
    a, b = tessellations._cells(cells, low=1, high=24)
    if a < 2:
        raise ParameterError(f"cells must have 2..24 quads across the arch, got {a}", name="cells")
    turn = np.radians(tessellations._in_range(opening, "opening", 30.0, 170.0))
    drop = tessellations._in_range(sag, "sag", 0.0, 0.4)
    theta = turn * (np.arange(a + 1) / a - 0.5)
    length = b * turn / a
    y = length * (np.arange(b + 1) / b - 0.5)
    g = -drop * length * (2.0 * y / length) ** 2
    jj, ii = np.meshgrid(np.arange(b + 1), np.arange(a + 1), indexing="ij")
    v = np.column_stack(
        [np.sin(theta)[ii.ravel()], y[jj.ravel()], (np.cos(theta)[ii] + g[jj]).ravel()]
    )
    v[:, 2] -= v[:, 2].min()
    faces = [
        np.array(
            [j * (a + 1) + i, j * (a + 1) + i + 1, (j + 1) * (a + 1) + i + 1, (j + 1) * (a + 1) + i]
        )
        for j in range(b)
        for i in range(a)
    ]
    return _scale_mean_edge(v, faces), faces


# -------------------------------------------------------------------------------- registry
EXAMPLES: dict[str, Example] = {
    e.name: e
    for e in [
        Example(
            "tetrahedron",
            "regular tetrahedron, edge 1",
            ("platonic", "convex", "closed", "triangles"),
            _tetrahedron,
        ),
        Example("cube", "cube, edge 1", ("platonic", "convex", "closed", "polygons"), _cube),
        Example(
            "octahedron",
            "regular octahedron, edge 1",
            ("platonic", "convex", "closed", "triangles"),
            _octahedron,
        ),
        Example(
            "dodecahedron",
            "regular dodecahedron, edge 1 (pentagon faces)",
            ("platonic", "convex", "closed", "polygons"),
            _dodecahedron,
        ),
        Example(
            "icosahedron",
            "regular icosahedron, edge 1",
            ("platonic", "convex", "closed", "triangles"),
            _icosahedron,
        ),
        Example(
            "square-pyramid",
            "square pyramid with all edges 1 (Johnson solid J1)",
            ("convex", "closed", "polygons"),
            _square_pyramid,
        ),
        Example(
            "triangular-prism",
            "right prism over an equilateral triangle, edges 1",
            ("convex", "closed", "polygons"),
            _triangular_prism,
        ),
        Example(
            "pentagonal-bipyramid",
            "pentagonal bipyramid with all edges 1 (J13)",
            ("convex", "closed", "triangles"),
            _pentagonal_bipyramid,
        ),
        Example(
            "house",
            "1 x 1.5 x 1 box with a gable roof (pentagon gable ends)",
            ("convex", "closed", "polygons"),
            _house,
        ),
        Example(
            "random-convex",
            "convex hull of 14 seeded points on a squashed sphere",
            ("convex", "closed", "triangles"),
            _random_convex,
        ),
        Example(
            "dimpled-cube",
            "cube whose top is a shallow inward pyramid (depth 0.2)",
            ("non-convex", "closed", "polygons"),
            _dimpled_cube,
        ),
        Example(
            "l-prism",
            "L-shaped prism; the ends of its reflex edge are saddles",
            ("non-convex", "saddle", "closed", "polygons"),
            _l_prism,
        ),
        Example(
            "torus",
            "coarse 8 x 6 quad torus; its inner vertices are saddles",
            ("non-convex", "saddle", "closed", "polygons", "genus-1"),
            _torus,
        ),
        Example(
            "blob",
            "bumpy icosphere (320 triangles): convex, concave and saddle vertices",
            ("non-convex", "saddle", "closed", "triangles"),
            _blob,
        ),
        Example(
            "geodesic-sphere",
            "icosahedron subdivided on a sphere: 20 x 4^level triangles, mean edge 1, convex "
            "(for scaling studies). Parameters: level (0..6, default 1)",
            ("convex", "closed", "triangles"),
            _geodesic_sphere,
            ("level",),
        ),
        Example("open-box", "cube without its top face", ("convex", "open", "polygons"), _open_box),
        Example(
            "tent",
            "gable roof with its two end triangles, no floor",
            ("convex", "open", "polygons"),
            _tent,
        ),
        Example(
            "saddle-patch",
            "5 x 5 grid on the saddle z = 0.6 x y, triangles",
            ("non-convex", "saddle", "open", "triangles"),
            _saddle_patch,
        ),
        Example(
            "shell",
            "open vault shell (a shelter, paper fig. 20): translational surface of planar "
            "quads, every interior vertex convex. Parameters: cells AxB (A quads across the "
            "arch x B along, default 6x4), opening = turn of the arch in degrees (30..170, "
            "default 140), sag = drop of the ends over the length (0..0.4, default 0.1)",
            ("convex", "open", "quads"),
            _shell,
            ("cells", "opening", "sag"),
        ),
        Example(
            "miura",
            "folded Miura-ori, unit-side parallelograms (closed form). Parameters: cells AxB "
            "(A along the straight creases x B along the zigzags, default 4x4), angle = sector "
            "angle in degrees (30..85, default 65), fold (0.05..0.95, default 0.5; 0 flat, "
            "1 folded flat)",
            ("developable", "tessellation", "open", "quads"),
            tessellations.miura,
            ("cells", "angle", "fold"),
        ),
        Example(
            "chicken-wire",
            "folded chicken-wire pattern: rows of isosceles trapezoids in anti-phase, curling "
            "into a corrugated vault (closed form). Parameters: cells AxB (A trapezoids per "
            "row x B rows, default 4x4), fold (0.05..0.95, default 0.5)",
            ("developable", "tessellation", "open", "quads"),
            tessellations.chicken_wire,
            ("cells", "fold"),
        ),
        Example(
            "yoshimura",
            "folded Yoshimura diamond pattern, an arch of antiprism bands (closed form). "
            "Parameters: cells AxB (A horizontal edges per row x B rows, default 5x4), fold "
            "(0.05..0.95, default 0.5)",
            ("developable", "tessellation", "open", "triangles"),
            tessellations.yoshimura,
            ("cells", "fold"),
        ),
        Example(
            "resch",
            "Ron Resch's triangle tessellation, partly folded: hexagonal star tucks sunk "
            "under twisted triangle tops (numerical solve of the edge lengths). Parameters: "
            "cells AxB (stars along the two lattice directions, 1..6, default 3x3), fold "
            "(0.4..0.8, default 0.5; star depth as a share of the fully tucked depth)",
            ("developable", "tessellation", "open", "triangles"),
            tessellations.resch,
            ("cells", "fold"),
        ),
        Example(
            "conical-dome",
            "conical mesh of a dome cap: planar quads on meridians and parallels, one cap "
            "polygon; not developable. Parameters: cells AxB (A around x B rings, default 8x4), "
            "opening = polar angle of the rim in degrees (10..150, default 60), height = "
            "vertical stretch (0.2..5, default 1)",
            ("convex", "conical", "open", "polygons"),
            tessellations.conical_dome,
            ("cells", "opening", "height"),
        ),
    ]
}


def example_names() -> list[str]:
    """Names of the built-in examples, in registry order."""
    return list(EXAMPLES)


def _split_spec(name: str) -> tuple[str, str]:
    """``"miura:4x3,fold=0.6"`` -> ``("miura", "4x3,fold=0.6")``."""
    base, _, params = str(name).partition(":")
    return base.strip().lower().replace("_", "-").replace(" ", "-"), params.strip()


def find_example(name: str) -> Example | None:
    """The example called ``name`` (case-insensitive, ``_`` or space for ``-``), or None.

    Parameters after a colon are ignored here (see :func:`example_mesh`).
    """
    return EXAMPLES.get(_split_spec(name)[0])


def unknown_example_message(name: str) -> str:
    """``"did you mean ..."`` plus the list of names, for error messages about ``name``."""
    hint = difflib.get_close_matches(_split_spec(name)[0], example_names(), n=1)
    did = f"did you mean '{hint[0]}'? " if hint else ""
    return f"{did}built-in examples: {', '.join(example_names())}"


def _accepted(example: Example) -> str:
    if not example.params:
        return f"'{example.name}' takes no parameters"
    return f"'{example.name}' accepts: {', '.join(example.params)} (cells as AxB, e.g. 4x3)"


def parse_example_params(example: Example, text: str) -> dict[str, object]:
    """Parse the parameter text of an example spec (the part after the colon).

    Parameters
    ----------
    example : Example
    text : str
        Comma-separated ``name=value`` items; a first item without ``=`` is ``cells``.
        ``cells`` is written ``AxB`` (two ints), other values are floats.

    Returns
    -------
    dict
        Keyword arguments for ``example.builder``.

    Raises
    ------
    MeshReadError
        An unknown or repeated parameter name, or a value that does not parse (the message
        lists the accepted parameters).
    """
    params: dict[str, object] = {}
    items = [t.strip() for t in text.split(",")] if text else []
    for k, item in enumerate(items):
        if "=" in item:
            key, _, value = item.partition("=")
            key, value = key.strip().lower(), value.strip()
        elif k == 0:
            key, value = "cells", item
        else:
            raise MeshReadError(
                f"example parameter {item!r} needs a name (name=value); {_accepted(example)}"
            )
        if key not in example.params:
            raise MeshReadError(f"unknown example parameter {key!r}; {_accepted(example)}")
        if key in params:
            raise MeshReadError(f"example parameter {key!r} given twice; {_accepted(example)}")
        try:
            if key == "cells":
                a, b = value.lower().split("x")
                params[key] = (int(a), int(b))
            else:
                params[key] = float(value)
        except ValueError:
            form = "AxB with integers A and B" if key == "cells" else "a number"
            raise MeshReadError(
                f"bad value {value!r} for example parameter {key!r}: expected {form}; "
                f"{_accepted(example)}"
            ) from None
    return params


def example_mesh(name: str) -> tuple[np.ndarray, list[np.ndarray]]:
    """Build a built-in example mesh.

    Parameters
    ----------
    name : str
        One of :func:`example_names`, optionally with parameters after a colon, e.g.
        ``"miura:4x3,angle=65,fold=0.6"`` (see :func:`parse_example_params`).

    Returns
    -------
    vertices : (n_vertices, 3) float64
    faces : list of (k,) int64
        Counter-clockwise seen from outside (from the front, for open sheets).

    Raises
    ------
    MeshReadError
        ``name`` is not a built-in example (the message lists them), or its parameters are
        unknown, malformed or out of range (the message lists the accepted ones).
    """
    example = find_example(name) if isinstance(name, str) else None
    if example is None:
        raise MeshReadError(f"no built-in example named {name!r}; {unknown_example_message(name)}")
    params = parse_example_params(example, _split_spec(name)[1])
    try:
        v, faces = example.builder(**params)
    except ParameterError as exc:
        raise MeshReadError(f"example {name!r}: {exc}; {_accepted(example)}") from exc
    return np.array(v, dtype=np.float64), [np.asarray(f, dtype=np.int64).copy() for f in faces]
