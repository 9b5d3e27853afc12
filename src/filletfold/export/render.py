"""A small software renderer: triangles and lines with hidden surfaces and hidden lines removed.

No display, no OpenGL, only numpy: triangles are scan-converted into a z-buffer all at once
(every triangle's bounding box of pixels is tested against its barycentric coordinates in one
array operation, a chunk of triangles at a time), flat-shaded colours are looked up from the
nearest triangle at each pixel, and lines are drawn over them where their depth is not behind
the z-buffer. The image is drawn at ``supersample`` times the size and averaged down, which
smooths the edges of triangles and lines.

Camera: orthographic, looking at the centre of the drawn points from the direction given by an
azimuth and an elevation in degrees, as in matplotlib's 3D axes (:func:`view_frame`): azimuth 0
looks from +x, 90 from +y; elevation 90 looks down from +z. A model whose up is +y (as most
scans are) or +x is seen the same way with ``up="y"`` (``"x"``): the axes are renamed cyclically
so that the up axis plays the part of z (for y up, azimuth 0 looks from +z and 90 from +x).
The picture is fitted to the
projected points with a margin of :data:`MARGIN` of the image on every side.
"""

from __future__ import annotations

import io
import math

import numpy as np

from ..arrays import run_owners, run_starts

__all__ = ["MARGIN", "UP_AXES", "face_image", "png_bytes", "project", "render", "view_frame"]

#: Share of the image left blank on each side of the fitted picture.
MARGIN = 0.04
#: Candidate pixels (triangle bounding boxes) tested at once: bounds the temporaries' memory.
_CHUNK = 1 << 22
#: Step between the samples of a line, in (supersampled) pixels; a line wider than 1.33 pixels
#: is sampled every 3/4 of its half width instead.
_LINE_STEP = 0.5


#: World coordinates of the (x, y, z) of the z-up view frame, for each up axis: a cyclic
#: renaming of the axes (a rotation, never a mirror image).
UP_AXES = {"z": [0, 1, 2], "y": [1, 2, 0], "x": [2, 0, 1]}


def view_frame(azim: float, elev: float, up: str = "z") -> np.ndarray:
    """The camera's axes for a view direction.

    Parameters
    ----------
    azim, elev : float
        Azimuth and elevation of the eye in degrees (matplotlib's convention).
    up : {"z", "y", "x"}
        The axis that points up in the picture (the others renamed cyclically: for ``"y"``,
        z plays the part of x and x that of y).

    Returns
    -------
    (3, 3) float
        Rows ``right``, ``up`` and ``towards the eye``, orthonormal and right-handed; ``up``
        has a non-negative component along the up axis, and ``right`` is perpendicular to it
        (at elevation ±90 it is the azimuth's ``(-sin a, cos a, 0)``).
    """
    e, a = math.radians(elev), math.radians(azim)
    eye = np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])
    right = np.array([-math.sin(a), math.cos(a), 0.0])
    frame = np.vstack([right, np.cross(eye, right), eye])
    return frame[:, UP_AXES[up]]


def _fit(xy: np.ndarray, width: int, height: int) -> tuple[np.ndarray, float]:
    """Centre and scale (pixels per unit) that fit the finite points ``xy`` into the image."""
    ok = np.isfinite(xy).all(axis=1)
    if not ok.any():
        return np.zeros(2), 1.0
    lo, hi = xy[ok].min(axis=0), xy[ok].max(axis=0)
    span = hi - lo
    usable = np.array([width, height], dtype=np.float64) * (1.0 - 2.0 * MARGIN)
    big = float(span.max())
    if big <= 0.0:
        return 0.5 * (lo + hi), 1.0
    span = np.maximum(span, 1e-12 * big)
    return 0.5 * (lo + hi), float((usable / span).min())


def _pixels(cam: np.ndarray, centre: np.ndarray, scale: float, width: int, height: int):
    """Camera coordinates (n, 3: right, up, towards the eye) to pixel x (right), y (down) and
    depth (larger nearer, in pixel units) of a picture framed by :func:`_fit`."""
    return (
        (cam[:, 0] - centre[0]) * scale + 0.5 * width,
        0.5 * height - (cam[:, 1] - centre[1]) * scale,
        cam[:, 2] * scale,
    )


def project(points, fit, width: int, height: int, azim: float, elev: float, up: str = "z"):
    """Pixel positions (x right, y down) of ``points`` (n, 3) in a picture of
    :func:`render` framed on the points ``fit`` (its ``points``, with no lines).

    Returns
    -------
    (n, 2) float
    """
    frame = view_frame(azim, elev, up)
    cam = np.asarray(points, dtype=np.float64).reshape(-1, 3) @ frame.T
    centre, scale = _fit(
        (np.asarray(fit, dtype=np.float64).reshape(-1, 3) @ frame.T)[:, :2], width, height
    )
    return np.column_stack(_pixels(cam, centre, scale, width, height)[:2])


def face_image(
    points, triangles, triangle_face, width: int, height: int, azim: float, elev: float, up="z"
) -> np.ndarray:
    """(height, width) int: the face seen at each pixel (-1: none) of a picture of
    :func:`render` (hidden surfaces removed, no lines, framed on ``points``), drawn once and
    coloured by the caller as often as it likes.
    """
    frame = view_frame(azim, elev, up)
    cam = np.asarray(points, dtype=np.float64).reshape(-1, 3) @ frame.T
    centre, scale = _fit(cam[:, :2], width, height)
    px, py, depth = _pixels(cam, centre, scale, width, height)
    _, ident = _zbuffer(px, py, depth, np.asarray(triangles, np.int64), width, height)
    face = np.where(ident >= 0, np.asarray(triangle_face, dtype=np.int64)[ident], -1)
    return face.reshape(height, width)


def _zbuffer(px, py, depth, triangles, width, height):
    """Scan-convert triangles (vertex pixel coordinates ``px``, ``py``, ``depth``: larger is
    nearer) into a depth buffer and the index of the nearest triangle at each pixel (-1: none).

    A pixel is covered when its centre is inside the triangle or on its boundary. Triangles
    with a non-finite or zero-area projection are skipped.
    """
    n_pix = width * height
    zbuf = np.full(n_pix, -np.inf)
    ident = np.full(n_pix, -1, dtype=np.int64)
    if len(triangles) == 0:
        return zbuf, ident
    x, y, z = px[triangles], py[triangles], depth[triangles]  # (t, 3)
    ax, ay, az = x[:, 0], y[:, 0], z[:, 0]
    ux, uy, uz = x[:, 1] - ax, y[:, 1] - ay, z[:, 1] - az
    vx, vy, vz = x[:, 2] - ax, y[:, 2] - ay, z[:, 2] - az
    with np.errstate(invalid="ignore", over="ignore"):
        area = ux * vy - uy * vx
        good = np.isfinite(area) & np.isfinite(z).all(axis=1) & (np.abs(area) > 1e-9)
        lo_x = np.ceil(x.min(axis=1) - 0.5)
        hi_x = np.floor(x.max(axis=1) - 0.5)
        lo_y = np.ceil(y.min(axis=1) - 0.5)
        hi_y = np.floor(y.max(axis=1) - 0.5)
    good &= (hi_x >= 0) & (lo_x <= width - 1) & (hi_y >= 0) & (lo_y <= height - 1)
    tri = np.flatnonzero(good)
    if len(tri) == 0:
        return zbuf, ident
    x0 = np.clip(lo_x[tri], 0, width - 1).astype(np.int64)
    x1 = np.clip(hi_x[tri], 0, width - 1).astype(np.int64)
    y0 = np.clip(lo_y[tri], 0, height - 1).astype(np.int64)
    y1 = np.clip(hi_y[tri], 0, height - 1).astype(np.int64)
    # s, t (barycentric coordinates of corners 1 and 2) and the depth as planes over the pixel
    inv = 1.0 / area[tri]
    s_x, s_y = vy[tri] * inv, -vx[tri] * inv
    t_x, t_y = -uy[tri] * inv, ux[tri] * inv
    s_c = -(s_x * ax[tri] + s_y * ay[tri])
    t_c = -(t_x * ax[tri] + t_y * ay[tri])
    d_x = s_x * uz[tri] + t_x * vz[tri]
    d_y = s_y * uz[tri] + t_y * vz[tri]
    d_c = az[tri] + s_c * uz[tri] + t_c * vz[tri]
    # one span of pixels per triangle and row: where the row's centre line is inside all
    # three edges (s >= 0, t >= 0, 1 - s - t >= 0, each a * x + b >= 0 along the row)
    ny = y1 - y0 + 1
    k = run_owners(ny)
    cy = y0[k] + np.arange(len(k)) - np.repeat(run_starts(ny)[:-1], ny)
    fy = cy + 0.5
    lo_f = np.full(len(k), -np.inf)
    hi_f = np.full(len(k), np.inf)
    eps = 1e-9
    for slope, offset in (
        (s_x[k], s_y[k] * fy + s_c[k]),
        (t_x[k], t_y[k] * fy + t_c[k]),
        (-(s_x[k] + t_x[k]), 1.0 - (s_y[k] + t_y[k]) * fy - s_c[k] - t_c[k]),
    ):
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = (-eps - offset) / slope
        lo_f = np.where(slope > 0, np.maximum(lo_f, bound), lo_f)
        hi_f = np.where(slope < 0, np.minimum(hi_f, bound), hi_f)
        hi_f = np.where((slope == 0) & (offset < -eps), -np.inf, hi_f)
    with np.errstate(invalid="ignore"):
        sx0 = np.maximum(np.ceil(lo_f - 0.5), x0[k])
        sx1 = np.minimum(np.floor(hi_f - 0.5), x1[k])
    span = np.where(sx1 >= sx0, sx1 - sx0 + 1, 0).astype(np.int64)
    row = np.flatnonzero(span)
    k, cy, sx0, span = k[row], cy[row], sx0[row].astype(np.int64), span[row]
    ends = np.cumsum(span)
    lo = 0
    while lo < len(k):
        # a chunk of spans of at most _CHUNK pixels (at least one span)
        base = ends[lo - 1] if lo else 0
        hi = max(int(np.searchsorted(ends, base + _CHUNK, side="right")), lo + 1)
        n = span[lo:hi]
        kk = np.repeat(k[lo:hi], n)
        px_y = np.repeat(cy[lo:hi], n)
        px_x = np.repeat(sx0[lo:hi], n) + (
            np.arange(base, base + len(kk), dtype=np.int64) - np.repeat(ends[lo:hi] - n, n)
        )
        d = d_x[kk] * (px_x + 0.5) + d_y[kk] * (px_y + 0.5) + d_c[kk]
        pix = px_y * width + px_x
        np.maximum.at(zbuf, pix, d)
        win = d >= zbuf[pix]
        ident[pix[win]] = tri[kk[win]]  # equal depths: the last triangle in order
        lo = hi
    return zbuf, ident


def _disc(radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Pixel offsets within ``radius`` of a pixel (at least the pixel itself)."""
    r = max(math.ceil(radius), 0)
    dx, dy = np.meshgrid(np.arange(-r, r + 1), np.arange(-r, r + 1), indexing="ij")
    keep = dx**2 + dy**2 <= max(radius, 0.0) ** 2 + 1e-9
    return dx[keep], dy[keep]


def render(
    points: np.ndarray,
    triangles: np.ndarray,
    colors: np.ndarray,
    *,
    triangle_face: np.ndarray | None = None,
    lines=(),
    width: int = 800,
    height: int = 600,
    azim: float = -60.0,
    elev: float = 25.0,
    up: str = "z",
    supersample: int = 2,
    background=(1.0, 1.0, 1.0),
    depth_bias: float = 1.5,
) -> np.ndarray:
    """Draw triangles and lines with hidden surfaces and hidden lines removed.

    Parameters
    ----------
    points : (n, 3) float
        Vertex positions.
    triangles : (t, 3) int
        Indices into ``points``. Degenerate (zero-area on screen) or non-finite triangles are
        not drawn.
    colors : (t, 3) float
        RGB in 0..1 of each triangle (shading already applied).
    triangle_face : (t,) int, optional
        The face each triangle belongs to (default: each its own). A line point is never hidden
        by a face it borders.
    lines : sequence of (segments, faces, rgb, width_px)
        Drawn in order over the triangles, later over earlier: ``segments`` (s, 2, 3) float,
        ``faces`` (s, 2) int or None (the faces each segment borders, -1 for none), ``rgb`` a
        colour in 0..1 and ``width_px`` the line width in output pixels.
    width, height : int
        Image size in pixels.
    azim, elev : float
        View direction in degrees (:func:`view_frame`).
    up : {"z", "y", "x"}
        The axis up in the picture (:func:`view_frame`).
    supersample : int
        Drawn at this many times the size, then averaged down.
    background : sequence of 3 float
        RGB in 0..1.
    depth_bias : float
        A line point is hidden when a surface at its pixel is more than this many
        (supersampled) pixel sizes nearer to the eye.

    Returns
    -------
    (height, width, 3) uint8
    """
    ss = int(supersample)
    w_ss, h_ss = width * ss, height * ss
    frame = view_frame(azim, elev, up)
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    with np.errstate(invalid="ignore", over="ignore"):
        cam = pts @ frame.T  # (n, 3): right, up, towards the eye
    segs_all = [np.asarray(s, dtype=np.float64).reshape(-1, 2, 3) for s, *_ in lines]
    fit_pts = np.vstack([cam[:, :2]] + [(s.reshape(-1, 3) @ frame.T)[:, :2] for s in segs_all])
    centre, scale = _fit(fit_pts, w_ss, h_ss)

    def to_pixels(c):
        return _pixels(c, centre, scale, w_ss, h_ss)

    tris = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    px, py, pd = to_pixels(cam)
    zbuf, ident = _zbuffer(px, py, pd, tris, w_ss, h_ss)
    bg = np.asarray(background, dtype=np.float32).reshape(3)
    img = np.broadcast_to(bg, (w_ss * h_ss, 3)).copy()
    hit = ident >= 0
    col = np.clip(np.nan_to_num(np.asarray(colors, dtype=np.float32).reshape(-1, 3), nan=0.5), 0, 1)
    img[hit] = col[ident[hit]]
    face_of = np.arange(len(tris)) if triangle_face is None else np.asarray(triangle_face, np.int64)
    face_at = np.full(len(ident), -1, dtype=np.int64)
    face_at[hit] = face_of[ident[hit]]

    for segs, (_, faces, rgb, lw) in zip(segs_all, lines, strict=True):
        if len(segs) == 0:
            continue
        fc = (
            np.full((len(segs), 2), -1, dtype=np.int64)
            if faces is None
            else np.asarray(faces, dtype=np.int64).reshape(-1, 2)
        )
        with np.errstate(invalid="ignore", over="ignore"):
            a = np.column_stack(to_pixels(segs[:, 0] @ frame.T))
            b = np.column_stack(to_pixels(segs[:, 1] @ frame.T))
            ok = np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1)
            a, b, fc = a[ok], b[ok], fc[ok]
            length = np.hypot(*(b - a)[:, :2].T)
            step = max(_LINE_STEP, 0.75 * 0.5 * lw * ss)  # a disc's radius: no gaps
            n = np.minimum(np.ceil(length / step).astype(np.int64), 4 * (w_ss + h_ss)) + 1
        seg = run_owners(n)
        first = run_starts(n)[:-1]
        u = (np.arange(len(seg)) - np.repeat(first, n)) / np.maximum(n[seg] - 1, 1)
        p = a[seg] + (b[seg] - a[seg]) * u[:, None]
        cx, cy = np.floor(p[:, 0]).astype(np.int64), np.floor(p[:, 1]).astype(np.int64)
        inside = (cx >= 0) & (cx < w_ss) & (cy >= 0) & (cy < h_ss)
        seg, p, cx, cy = seg[inside], p[inside], cx[inside], cy[inside]
        pix = cy * w_ss + cx
        f = face_at[pix]
        visible = (
            (p[:, 2] + depth_bias >= zbuf[pix]) | (f == fc[seg, 0]) | (f == fc[seg, 1]) | (f < 0)
        )
        cx, cy = cx[visible], cy[visible]
        dx, dy = _disc(0.5 * lw * ss)
        qx = (cx[:, None] + dx[None, :]).ravel()
        qy = (cy[:, None] + dy[None, :]).ravel()
        keep = (qx >= 0) & (qx < w_ss) & (qy >= 0) & (qy < h_ss)
        img[qy[keep] * w_ss + qx[keep]] = np.asarray(rgb, dtype=np.float32).reshape(3)

    img = img.reshape(height, ss, width, ss, 3)
    out = np.zeros((height, width, 3), dtype=np.float32)
    for i in range(ss):  # the ss x ss samples of each pixel, added one sample at a time
        for j in range(ss):
            out += img[:, i, :, j]
    return np.round(np.clip(out * (255.0 / ss**2), 0.0, 255.0)).astype(np.uint8)


def png_bytes(image: np.ndarray) -> bytes:
    """An RGB image (h, w, 3) uint8 as PNG bytes, with no metadata (the same image gives the same
    bytes)."""
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image, dtype=np.uint8)).save(
        buf, format="PNG", compress_level=6
    )
    return buf.getvalue()
