"""What the browser app draws, as plain arrays (no GUI): triangles, creases, markers.

Kept apart from :mod:`filletfold.app.server` so it can be tested without viser.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..design import Design
from ..export.render import UP_AXES
from ..surface.patch import patch_kind
from ..surface.triangulate import triangulate_faces

#: RGB (0..255) of each patch kind.
PATCH_RGB = {
    "cone": (245, 158, 64),
    "cylinder": (89, 153, 230),
    "fillet": (60, 200, 200),
    "face": (115, 199, 115),
}
#: RGB of each crease assignment drawn.
CREASE_RGB = {"M": (220, 40, 40), "V": (40, 80, 220), "B": (40, 40, 40)}
#: RGB of each vertex status.
STATUS_RGB = {
    "ok": (40, 170, 60),
    "saddle": (240, 140, 20),
    "infeasible": (220, 30, 30),
    "boundary": (150, 150, 150),
    "developable": (150, 70, 200),
}
#: RGB of a vertex kept sharp (its corner kept, whatever its status: ``--sharp``).
SHARP_RGB = (20, 20, 20)


def _hex(rgb) -> str:
    return "#{:02x}{:02x}{:02x}".format(*rgb)


def legend_markdown() -> str:
    """The legend shown in the GUI panel (Markdown with coloured squares)."""

    def row(rgb, text):
        return f'<span style="color:{_hex(rgb)}">&#9632;</span> {text}  '

    lines = ["**Patches**  "]
    lines += [row(PATCH_RGB[k], k) for k in ("cone", "cylinder", "fillet", "face")]
    lines += ["", "**Creases**  "]
    lines += [
        row(CREASE_RGB["M"], "mountain"),
        row(CREASE_RGB["V"], "valley"),
        row(CREASE_RGB["B"], "cut / border"),
    ]
    lines += ["", "**Vertices**  "]
    lines += [row(rgb, status) for status, rgb in STATUS_RGB.items()]
    lines += [row(SHARP_RGB, "kept sharp (its corner, no hole)")]
    return "\n".join(lines)


#: Width of the drawn scene (model, gap and pattern) in scene units: every design is scaled to
#: it and centred at the origin, so one fixed camera (:data:`CAMERA_POSITION`) frames them all.
SCENE_WIDTH = 4.0
#: Largest side of the drawn crease pattern, in multiples of the folded model's size (a
#: larger pattern, e.g. many modules side by side, is drawn smaller than true scale).
PATTERN_MAX_SIZE = 2.0
#: Gap between the model and the pattern, in multiples of the model's size.
PATTERN_GAP = 0.15
#: The initial camera (scene units, z up): in front of the scene (-y) and above it, looking
#: a little to the right of its centre so the scene clears the GUI panel on the right.
CAMERA_POSITION = (1.0, -2.9, 2.9)
#: Where the initial camera looks.
CAMERA_LOOK_AT = (1.0, 0.0, -0.4)


@dataclass
class SceneArrays:
    """Everything the 3D view shows of a design, in scene coordinates.

    Scene coordinates are the design's, scaled by ``scale`` about ``centre`` and moved to the
    origin (:data:`SCENE_WIDTH` wide); the crease pattern is also scaled by
    ``pattern_scale`` (1 = true size beside the model).

    Attributes
    ----------
    folded : dict of str to (vertices (n, 3), triangles (t, 3))
        The folded surface, one mesh per patch kind (``cone``, ``cylinder``, ``fillet``, ``face``).
    flat : dict of str to (vertices (n, 3), triangles (t, 3))
        The crease pattern laid flat beside the folded form (z constant).
    folded_creases, flat_creases : dict of str to (s, 2, 3) float
        Segments per assignment (``M``, ``V``; the flat view also ``B``).
    vertex_points : (n_vertices, 3) float
        Mesh vertices (status markers).
    vertex_colors : (n_vertices, 3) uint8
    point_size : float
        Marker size in scene units.
    scale : float
        Scene units per design unit.
    centre : (3,) float
        The design point drawn at the origin.
    pattern_scale : float
        Drawn size of the pattern relative to the model (at most 1).
    axes : (3,) int
        The design's axes that are the scene's x, y and z: the design's up axis
        (``design.up``) is the scene's z, the others turned cyclically as in the pictures
        (:data:`~filletfold.export.render.UP_AXES`).
    """

    folded: dict = field(default_factory=dict)
    flat: dict = field(default_factory=dict)
    folded_creases: dict = field(default_factory=dict)
    flat_creases: dict = field(default_factory=dict)
    vertex_points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    vertex_colors: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.uint8))
    point_size: float = 0.05
    scale: float = 1.0
    centre: np.ndarray = field(default_factory=lambda: np.zeros(3))
    pattern_scale: float = 1.0
    axes: tuple = (0, 1, 2)

    def to_scene(self, points) -> np.ndarray:
        """Design coordinates (..., 3) to scene coordinates (turned so that ``axes`` are
        the scene's x, y, z)."""
        return (np.asarray(points, dtype=float)[..., self.axes] - self.centre) * self.scale


def scene_arrays(design: Design) -> SceneArrays:
    """Triangles, crease segments and vertex markers of a design, in scene coordinates
    (turned so that the design's up axis is the scene's z).

    The crease pattern lies in the plane through the lowest folded point, to the right (+x)
    of the folded form with a gap of :data:`PATTERN_GAP` times the form's size, centred in y,
    drawn at most :data:`PATTERN_MAX_SIZE` times the form's size. Model and pattern together
    are scaled to :data:`SCENE_WIDTH` and centred at the origin.
    """
    pattern = design.pattern
    axes = tuple(np.argsort(UP_AXES[design.up]).tolist())  # the pictures' turn, undone
    v2, v3 = pattern.vertices_2d, pattern.vertices_3d[:, axes]  # turned: up is z
    lo, hi = v3.min(axis=0), v3.max(axis=0)
    size = float(np.max(hi - lo)) or 1.0
    p_lo, p_hi = v2.min(axis=0), v2.max(axis=0)
    p_size = float(np.max(p_hi - p_lo)) or 1.0
    shrink = min(1.0, PATTERN_MAX_SIZE * size / p_size)
    flat2 = (v2 - p_lo) * shrink  # from (0, 0)
    shift = np.array(
        [hi[0] + PATTERN_GAP * size, 0.5 * (lo[1] + hi[1]) - 0.5 * shrink * (p_hi[1] - p_lo[1])]
    )
    flat3 = np.column_stack([flat2 + shift, np.full(len(v2), lo[2])])
    all_lo = np.minimum(lo, flat3.min(axis=0))
    all_hi = np.maximum(hi, flat3.max(axis=0))
    out = SceneArrays(
        scale=SCENE_WIDTH / (float(np.max(all_hi - all_lo)) or 1.0),
        centre=0.5 * (all_lo + all_hi),
        pattern_scale=shrink,
        axes=axes,
    )
    v3 = out.to_scene(pattern.vertices_3d)
    flat3 = (flat3 - out.centre) * out.scale  # laid out in the turned frame already

    triangles, owner = triangulate_faces(v2, pattern.faces)
    kind_of = {patch: patch_kind(patch) for patch in set(pattern.face_patch)}
    kinds = [*PATCH_RGB, *sorted(set(kind_of.values()) - set(PATCH_RGB))]
    code = {patch: kinds.index(kind) for patch, kind in kind_of.items()}
    face_kind = np.fromiter(map(code.__getitem__, pattern.face_patch), dtype=np.int64)
    tri_kind = face_kind[owner]
    for c, kind in enumerate(kinds):
        t = triangles[tri_kind == c]
        if not len(t):
            continue
        used, local = _compact(t, len(v2))
        out.folded[kind] = (v3[used], local)
        out.flat[kind] = (flat3[used], local)
    assign = np.asarray(pattern.edge_assignment)
    for a in ("M", "V", "B"):
        e = pattern.edges[assign == a]
        if a != "B":
            out.folded_creases[a] = v3[e]
        out.flat_creases[a] = flat3[e]
    mesh = design.mesh
    out.vertex_points = out.to_scene(mesh.vertices)
    out.vertex_colors = np.array(
        [
            SHARP_RGB if t == "sharp" else STATUS_RGB.get(s, (0, 0, 0))
            for s, t in zip(design.vertices.status, design.vertices.treatment, strict=True)
        ],
        dtype=np.uint8,
    ).reshape(-1, 3)
    lengths = np.linalg.norm(
        mesh.vertices[mesh.edges[:, 1]] - mesh.vertices[mesh.edges[:, 0]], axis=1
    )
    marker = 0.08 * float(lengths.mean()) if len(lengths) else 0.05 * size
    out.point_size = marker * out.scale
    return out


def _compact(index: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``np.unique(index, return_inverse=True)`` of indices below ``n``, without sorting.

    Parameters
    ----------
    index : (t, 3) int
    n : int

    Returns
    -------
    used : (u,) int
        The indices that occur, increasing.
    local : (t, 3) int
        ``index`` renumbered into ``used``.
    """
    seen = np.zeros(n, dtype=bool)
    seen[index] = True
    return np.flatnonzero(seen), (np.cumsum(seen) - 1)[index]
