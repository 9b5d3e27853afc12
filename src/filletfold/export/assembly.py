"""The assembly guide, ``assembly.pdf``: how the pieces go together, with pictures.

Page 1 is an overview: the folded object from the front and from the back, each piece drawn
in a colour of its own and named (``P1``, ``P2``, ...) where it faces the viewer. Then the
steps, :data:`STEPS_PER_PAGE` to a page: the largest piece first, then at each step the
largest piece that shares a numbered border with the part assembled so far
(:func:`assembly_steps`), drawn in orange on the assembled part in grey, with the borders to
glue (the numbers printed on the pieces' tabs and beside their borders). A piece with borders
of its own (two of its edges glued to each other) closes them when it is placed. Pieces that
share no border with the rest (a mesh of several parts) start a part of their own.

Pictures are drawn by :func:`~filletfold.export.render.render` (hidden surfaces removed), as
``preview.png``, from the same view (``up`` the design's). The output is deterministic.
"""

from __future__ import annotations

import heapq
import io
import textwrap
from dataclasses import dataclass

import numpy as np

from ..surface.pattern import CreasePattern, face_arrays
from ..surface.triangulate import triangulate_faces
from ..surface.validate import face_signed_area_2d
from ..units import sheet_size_mm
from .palette import LABEL_COLOR
from .png import DEFAULT_VIEW, face_shades
from .render import face_image, project, view_frame

__all__ = [
    "CAPTION_BORDERS",
    "STEPS_PER_PAGE",
    "Step",
    "assembly_pages",
    "assembly_pdf",
    "assembly_steps",
]

#: Steps drawn on one page (3 rows of 2).
STEPS_PER_PAGE = 6
#: Borders named in a step's caption before "...".
CAPTION_BORDERS = 10
#: Characters per line of a step's caption (two pictures side by side).
CAPTION_WIDTH = 60
#: Each picture is drawn at this many times its size, then averaged down.
SUPERSAMPLE = 2
_NEW = np.array([0.96, 0.55, 0.2])  # the piece placed at a step
_DONE = np.array([0.75, 0.75, 0.75])  # the part assembled so far
_LATER = np.array([0.97, 0.97, 0.97])  # the pieces still to come, as a pale ghost
_MM_PER_IN = 25.4
_LABEL = {
    "color": LABEL_COLOR,
    "bbox": {"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none"},
}
_FONT_PT = 8.0


@dataclass(frozen=True)
class Step:
    """One step of the assembly: glue ``piece`` onto the pieces ``onto`` along the borders
    ``borders`` (their labels), closing its own borders ``own`` first; ``onto`` empty for
    the first piece of a part."""

    piece: int
    onto: tuple
    borders: tuple
    own: tuple


def assembly_steps(seams: np.ndarray, area: np.ndarray) -> list[Step]:
    """The order in which the pieces are glued together.

    Parameters
    ----------
    seams : (k, 2) int
        The two pieces of each numbered border (border ``j`` is labelled ``j + 1``; both the
        same piece for a border the piece glues to itself).
    area : (n,) float
        Each piece's area: the largest piece starts, and at each step the largest piece
        sharing a border with the assembled part is glued next (the lower number on a tie).

    Returns
    -------
    list of Step
        One per piece.
    """
    seams = np.asarray(seams, dtype=np.int64).reshape(-1, 2)
    n = len(area)
    touching = [[] for _ in range(n)]  # (other piece, label) per piece
    own = [[] for _ in range(n)]
    for j, (a, b) in enumerate(seams.tolist()):
        if a == b:
            own[a].append(j + 1)
        else:
            touching[a].append((b, j + 1))
            touching[b].append((a, j + 1))
    order = sorted(range(n), key=lambda p: (-float(area[p]), p))  # the starts of the parts
    placed = np.zeros(n, dtype=bool)
    steps: list[Step] = []
    heap: list = []
    for start in order:
        if placed[start]:
            continue
        heapq.heappush(heap, (-float(area[start]), start))
        while heap:
            _, piece = heapq.heappop(heap)
            if placed[piece]:
                continue
            placed[piece] = True
            glued = sorted((label, other) for other, label in touching[piece] if placed[other])
            onto = tuple(sorted({other for _, other in glued}))
            steps.append(Step(piece, onto, tuple(label for label, _ in glued), tuple(own[piece])))
            for other, _ in touching[piece]:
                if not placed[other]:
                    heapq.heappush(heap, (-float(area[other]), other))
    return steps


def _piece_colors(n: int) -> np.ndarray:
    """(n, 3) distinct light colours, one per piece (hues by the golden angle)."""
    import colorsys

    return np.array(
        [colorsys.hsv_to_rgb((0.618034 * k) % 1.0, 0.45, 0.95) for k in range(n)], dtype=float
    ).reshape(-1, 3)


def _caption(step: Step, names: list) -> str:
    """``"P12 onto P1, P5: 3 borders (14, 15, 22)"`` (at most :data:`CAPTION_BORDERS`
    named)."""

    def listed(labels) -> str:
        shown = ", ".join(map(str, labels[:CAPTION_BORDERS]))
        more = ", ..." if len(labels) > CAPTION_BORDERS else ""
        return f"{len(labels)} border{'s' if len(labels) != 1 else ''} ({shown}{more})"

    name = names[step.piece]
    onto = ", ".join(names[p] for p in step.onto[:CAPTION_BORDERS])
    onto += ", ..." if len(step.onto) > CAPTION_BORDERS else ""
    text = f"{name} onto {onto}: {listed(step.borders)}" if step.onto else f"{name} first"
    if step.own:
        text += f"; first close its own {listed(step.own)}"
    return text


class _View:
    """The folded form seen from one direction, drawn once (the face at each pixel, at
    :data:`SUPERSAMPLE` times the size) and coloured per picture: all at once
    (:meth:`paint`), or again only where given pieces show (:meth:`repaint`)."""

    def __init__(self, pattern: CreasePattern, triangles, view: tuple, px: int):
        azim, elev, up = view
        tri, tri_face = triangles  # the pattern's faces' (triangulate_faces)
        ss = SUPERSAMPLE
        self.p, self.azim, self.elev, self.up = pattern, azim, elev, up
        self.w, self.h = px, round(0.75 * px)
        self.eye = view_frame(azim, elev, up)[2]
        self.shade = face_shades(pattern, azim, elev, up).astype(np.float32)
        face = face_image(
            pattern.vertices_3d, tri, tri_face, ss * self.w, ss * self.h, azim, elev, up
        )
        n_faces = len(pattern.faces)
        # the ss x ss samples of each pixel, -1 (none) as the white row n_faces
        self.samples = (
            np.where(face >= 0, face, n_faces)
            .reshape(self.h, ss, self.w, ss)
            .transpose(0, 2, 1, 3)
            .reshape(self.h * self.w, ss * ss)
        )
        self.piece = np.asarray(pattern.face_piece, dtype=np.int64)
        n = int(pattern.n_pieces)
        self.owner = np.append(np.where(self.piece < n, self.piece, -1), -1)[self.samples]
        seen = self.owner[self.owner >= 0]
        self.pixels = np.bincount(seen, minlength=n)  # samples seen per piece
        self.by_piece = None  # the pixels of each piece, made on the first repaint
        self.faces_of = None  # the faces of each piece, likewise
        self.rgb = np.ones((n_faces + 1, 3), dtype=np.float32)
        self.img = np.ones((self.h * self.w, 3), dtype=np.float32)

    def _lit(self, face_rgb: np.ndarray, faint: np.ndarray, faces) -> np.ndarray:
        """The colours of ``faces`` shaded; those ``faint`` barely (a ghost)."""
        shade = self.shade[faces]
        shade = np.where(faint[faces], 0.9 + 0.1 * shade, shade)
        return np.clip(face_rgb[faces] * shade[:, None], 0.0, 1.0)

    def paint(self, face_rgb: np.ndarray, faint: np.ndarray) -> np.ndarray:
        """(h, w, 3) uint8: the picture with each face in its colour ``face_rgb`` (n_faces, 3),
        shaded (the faces ``faint`` barely), on white."""
        self.rgb[:-1] = self._lit(face_rgb, faint, slice(None))
        self.img = self.rgb[self.samples].mean(axis=1)
        return self.picture()

    def _pixels_by_piece(self) -> list:
        """The pixels each piece shows in, ascending (a pixel whose samples show two pieces
        is each's)."""
        n = len(self.pixels)
        own = self.owner
        first = np.ones(own.shape, dtype=bool)  # a piece's first sample in its pixel
        for j in range(1, own.shape[1]):
            first[:, j] = (own[:, :j] != own[:, j : j + 1]).all(axis=1)
        pixel = np.broadcast_to(np.arange(len(own))[:, None], own.shape)
        keep = first & (own >= 0)
        piece, pixel = own[keep], pixel[keep]
        order = np.argsort(piece, kind="stable")  # pixels ascending within each piece
        return np.split(pixel[order], np.searchsorted(piece[order], np.arange(1, n)))

    def repaint(self, pieces, face_rgb: np.ndarray, faint: np.ndarray) -> np.ndarray:
        """:meth:`paint` after only the faces of ``pieces`` changed."""
        if self.by_piece is None:
            self.by_piece = self._pixels_by_piece()
            self.faces_of = _faces_by_piece(self.piece, len(self.pixels))
        for k in pieces:
            faces = self.faces_of[k]
            self.rgb[faces] = self._lit(face_rgb, faint, faces)
            at = self.by_piece[k]
            self.img[at] = self.rgb[self.samples[at]].mean(axis=1)
        return self.picture()

    def picture(self) -> np.ndarray:
        """The current picture, (h, w, 3) uint8."""
        return np.round(self.img * 255.0).astype(np.uint8).reshape(self.h, self.w, 3)

    def label_points(self, area_3d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pixel positions of each piece's centre and whether the piece faces the eye."""
        p = self.p
        flat, start = face_arrays(p.faces)
        size = np.diff(start)
        centre = np.add.reduceat(p.vertices_3d[flat], start[:-1], axis=0) / size[:, None]
        n = int(p.n_pieces)
        owner = np.clip(self.piece, 0, None)
        weight = np.where(self.piece >= 0, area_3d, 0.0)
        sums = np.zeros((n, 3))
        np.add.at(sums, owner, centre * weight[:, None])
        facing = np.zeros((n, 3))
        np.add.at(facing, owner, np.nan_to_num(p.face_normal_3d()) * weight[:, None])
        total = np.bincount(owner, weights=weight, minlength=n)
        at = sums / np.where(total > 0, total, 1.0)[:, None]
        xy = project(at, p.vertices_3d, self.w, self.h, self.azim, self.elev, self.up)
        return xy, (facing @ self.eye > 0) & (total > 0) & (self.pixels > 0)


def _faces_by_piece(face_piece: np.ndarray, n: int) -> list[np.ndarray]:
    """The faces of each of the ``n`` pieces, ascending: ``face_piece`` (n_faces,) int the
    piece of each face (one outside ``0 .. n - 1`` is in none)."""
    order = np.argsort(face_piece, kind="stable")
    bounds = np.searchsorted(face_piece[order], np.arange(n + 1))
    return [order[a:b] for a, b in zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True)]


def _place(fig, image: np.ndarray, x: float, y: float):
    """Put ``image`` on ``fig`` unscaled (one pixel a figure pixel) with its lower left corner
    at ``(x, y)`` (figure fractions); returns the map from the image's pixel positions
    (x right, y down) to figure fractions."""
    width, height = fig.bbox.width, fig.bbox.height
    xo, yo = round(x * width), round(y * height)
    fig.figimage(image, xo=xo, yo=yo, origin="upper")
    h = image.shape[0]
    return lambda p: ((xo + p[0]) / width, (yo + h - p[1]) / height)


def assembly_pages(
    pattern: CreasePattern,
    seams,
    *,
    up: str = "z",
    page: str = "A4",
    width_px: int = 400,
):
    """The pages of the assembly guide, one matplotlib Figure at a time (see
    :func:`assembly_pdf`, which writes them; a picture of a page: ``fig.savefig(...)``)."""
    from matplotlib.figure import Figure

    width_mm, height_mm = sheet_size_mm(page, name="page")
    size_in = (width_mm / _MM_PER_IN, height_mm / _MM_PER_IN)
    n = int(pattern.n_pieces)
    piece = np.asarray(pattern.face_piece, dtype=np.int64)
    inside = (piece >= 0) & (piece < n)
    area2 = np.abs(face_signed_area_2d(pattern.vertices_2d, pattern.faces))
    area = np.bincount(piece[inside], weights=area2[inside], minlength=n)
    steps = assembly_steps(seams.pieces, area)
    names = list(seams.names) if len(seams.names) == n else [f"P{k + 1}" for k in range(n)]
    azim, elev = DEFAULT_VIEW
    colors = _piece_colors(n)
    face_rgb = np.where(inside[:, None], colors[np.clip(piece, 0, None)], _DONE)
    tri = triangulate_faces(pattern.vertices_2d, pattern.faces)  # once for the four views
    sides = [(azim + turn, elev, up) for turn in (0.0, 180.0)]
    big = [_View(pattern, tri, side, 2 * width_px) for side in sides]
    dpi = 2 * width_px / (0.8 * size_in[0])  # the overview's pictures 0.8 of the width
    fig = Figure(figsize=size_in, dpi=dpi)
    fig.text(0.06, 0.965, f"Assembly: {n} pieces, {len(seams)} numbered borders", size=12)
    fig.text(
        0.06,
        0.945,
        "Glue each numbered border to the border with the same number, in the order of "
        "the steps (largest piece first).",
        size=_FONT_PT,
    )
    for row, view in enumerate(big):
        at = _place(fig, view.paint(face_rgb, ~inside), 0.1, 0.47 - 0.455 * row)
        xy, seen = view.label_points(area2)
        for k in np.flatnonzero(seen).tolist():
            fig.text(*at(xy[k]), names[k], size=7, ha="center", va="center", **_LABEL)
        caption = ("from the front", "from the back")[row]
        fig.text(0.5, 0.915 - 0.455 * row, caption, ha="center", size=_FONT_PT)
    yield fig
    del big
    views = [_View(pattern, tri, side, width_px) for side in sides]
    state = np.zeros(n, dtype=np.int64)  # 0 to come, 1 placed, 2 placed at this step
    palette = np.array([_LATER, _DONE, _NEW])
    rgb = np.where(inside[:, None], palette[state[np.clip(piece, 0, None)]], _DONE)
    for view in views:
        view.paint(rgb, inside)
    face_state = np.where(inside, state[np.clip(piece, 0, None)], 1)
    rgb, faint = palette[face_state], face_state == 0
    faces_of = _faces_by_piece(piece, n)
    for first in range(0, len(steps), STEPS_PER_PAGE):
        fig = Figure(figsize=size_in, dpi=dpi)
        for slot, step in enumerate(steps[first : first + STEPS_PER_PAGE]):
            changed = [*np.flatnonzero(state == 2).tolist(), step.piece]
            state[state == 2] = 1
            state[step.piece] = 2
            for k in changed:  # the faces of the pieces whose state changed
                rgb[faces_of[k]] = palette[state[k]]
                faint[faces_of[k]] = state[k] == 0
            images = [view.repaint(changed, rgb, faint) for view in views]
            best = max(range(len(views)), key=lambda v: views[v].pixels[step.piece])
            row, col = divmod(slot, 2)
            x, y = 0.07 + 0.47 * col, 0.68 - 0.31 * row
            _place(fig, images[best], x, y)  # from where it shows most
            caption = textwrap.fill(f"{first + slot + 1}. {_caption(step, names)}", CAPTION_WIDTH)
            fig.text(x, y + 0.215, caption, size=_FONT_PT - 1, va="bottom")
        last = min(first + STEPS_PER_PAGE, len(steps))
        fig.text(0.5, 0.02, f"steps {first + 1}-{last} of {len(steps)}", ha="center", size=_FONT_PT)
        yield fig


def assembly_pdf(
    pattern: CreasePattern,
    seams,
    *,
    up: str = "z",
    page: str = "A4",
    width_px: int = 400,
) -> bytes:
    """The assembly guide of a laid-out design with glue tabs.

    Parameters
    ----------
    pattern : CreasePattern
        With its pieces (``face_piece``).
    seams : Seams
        The numbered borders (``design.fabrication["seams"]``).
    up : {"z", "y", "x"}
        The axis up in the pictures (``design.up``).
    page : str
        Page size (:func:`~filletfold.units.sheet_size_mm`); portrait.
    width_px : int
        Width of a step's picture in pixels (the overview's twice).

    Returns
    -------
    bytes
        The PDF (:func:`assembly_pages`): the overview, then :data:`STEPS_PER_PAGE` steps per
        page.
    """
    import matplotlib
    from matplotlib.backends.backend_pdf import PdfPages

    buf = io.BytesIO()
    with (
        matplotlib.rc_context({"image.composite_image": False}),  # each picture on its own
        PdfPages(buf, metadata={"CreationDate": None, "Creator": "filletfold"}) as pdf,
    ):
        for fig in assembly_pages(pattern, seams, up=up, page=page, width_px=width_px):
            pdf.savefig(fig)
    return buf.getvalue()
