"""What a design reports: ``report.json``, the terminal summary, and the output folder."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from . import __version__
from .export import report_json, write_outputs
from .export.cutfiles import DEFAULT_FORMATS, cut_files, output_names, parse_formats
from .rounding import loss_from_radius
from .tabs import assembly_text

#: The files :func:`export_design` writes by default.
OUTPUT_FILES = output_names(DEFAULT_FORMATS)


def _num(x):
    """A float for JSON, or None for NaN."""
    x = float(x)
    return None if not np.isfinite(x) else x


def _vec(x):
    x = np.asarray(x, dtype=float)
    return None if not np.all(np.isfinite(x)) else x.tolist()


def design_report(design) -> dict:
    """The content of ``report.json`` (see the README for every key).

    Parameters
    ----------
    design : Design

    Returns
    -------
    dict
    """
    mesh = design.mesh
    rd = design.rounding
    res = design.vertices
    pat = design.pattern
    edges = []
    for e, (a, b) in enumerate(mesh.edges):
        f, g = mesh.edge_faces[e]
        boundary = f < 0 or g < 0
        edges.append(
            {
                "vertices": [int(a), int(b)],
                "faces": None if boundary else [int(f), int(g)],
                "length": float(mesh.edge_length[e]),
                "radius": float(rd.radius[e]),
                "half_angle": float(rd.half_angle[e]),
                "assignment": "B" if boundary else ("M" if rd.kappa[e] > 0 else "V"),
                "arc_length": float(rd.arc_length[e]),
                "strip_width": float(rd.strip_width[e]),
                "material_loss": float(rd.loss[e]),
                "radius_limit": _num(rd.limit[e]),
                "material_loss_limit": _num(loss_from_radius(rd.limit[e], rd.half_angle[e]))
                if rd.half_angle[e] > 0
                else None,
            }
        )
    vertices = []
    for u in range(mesh.n_vertices):
        item = {
            "kind": res.kind[u],
            "status": res.status[u],
        }
        if res.status[u] != "ok":
            item["reason"] = res.reason[u]
        item.update(
            {
                "angle_sum": _num(res.angle_sum[u]),
                "angle_defect": _num(res.defect[u]),
                "solid_angle": _num(res.solid_angle[u]),
                "sigma": int(res.sigma[u]) or None,
                "normal": _vec(res.normal[u]),
                "normal_bound": _num(res.normal_bound[u]),
                "apex": _vec(res.apex[u]),
                "apex_developed": _vec(res.apex_developed[u]),
                "apex_2d": _vec(res.apex_2d[u]),
                "depth_requested": _num(res.depth_requested[u]),
                "depth": _num(res.depth[u]),
                "margin": _num(res.margin[u]),
            }
        )
        vertices.append(item)
    counts = {k: int(np.sum(pat.edge_assignment == k)) for k in ("M", "V", "B", "F")}
    return {
        "filletfold": __version__,
        "source": design.source,
        "parameters": design.params.as_dict(),
        "mean_edge_length": float(mesh.mean_edge_length),
        "uniform_radius_limit": _num(rd.uniform_limit),
        "status_counts": design.status_counts(),
        "mesh": {
            "vertices": mesh.vertices.tolist(),
            "faces": [f.tolist() for f in mesh.faces],
        },
        "edges": edges,
        "vertices": vertices,
        "pattern": {
            "pieces": int(pat.n_pieces),
            "cut_edges": int(pat.cut_mask().sum()),
            "vertices": len(pat.vertices_2d),
            "faces": len(pat.faces),
            "edges": counts,
            "max_edge_mismatch": float(edge_mismatch(pat).max(initial=0.0)),
            "max_relative_edge_mismatch": float(relative_mismatch(pat).max(initial=0.0)),
        },
        "layout": {"kind": design.layout, "note": design.layout_note or None},
        "fabrication": _fabrication_report(design),
        "material_loss": _loss_report(design.material_loss),
        "timings": {k: float(v) for k, v in design.timings.items()},
    }


def _fabrication_report(design) -> dict:
    """Pieces, glue tabs, and (with sheets) pieces per sheet and material use."""
    out = {"pieces": int(design.pattern.n_pieces)}
    for k, v in design.fabrication.items():
        out[k] = v if isinstance(v, list) else int(v)
    return out


def _loss_report(loss) -> dict | None:
    if loss is None:
        return None
    return {
        "method": "conical face offset (sec. 4.4)"
        if loss.message.startswith("conical")
        else "linear programme (sec. 4.3)",
        "ok": bool(loss.ok),
        "bound": float(loss.bound),
        "max_closure_residual": float(loss.closure.max(initial=0.0)),
        "tight": list(loss.tight),
        "message": loss.message,
    }


def edge_mismatch(pattern) -> np.ndarray:
    """(n_edges,) 2D length minus 3D length of every pattern edge (>= 0 up to round-off)."""
    e = pattern.edges
    l2 = np.linalg.norm(pattern.vertices_2d[e[:, 0]] - pattern.vertices_2d[e[:, 1]], axis=1)
    l3 = np.linalg.norm(pattern.vertices_3d[e[:, 0]] - pattern.vertices_3d[e[:, 1]], axis=1)
    return l2 - l3


def relative_mismatch(pattern) -> np.ndarray:
    """(n_edges,) edge mismatch divided by the 2D edge length (converges with order 2)."""
    e = pattern.edges
    l2 = np.linalg.norm(pattern.vertices_2d[e[:, 0]] - pattern.vertices_2d[e[:, 1]], axis=1)
    return edge_mismatch(pattern) / np.where(l2 > 0, l2, 1.0)


def design_summary(design, max_listed: int = 8) -> str:
    """A few lines for the terminal (at most ``max_listed`` vertices that are not ok)."""
    mesh = design.mesh
    counts = design.status_counts()
    pat = design.pattern
    shown = ", ".join(f"{v} {k}" for k, v in counts.items() if v)
    r = design.rounding.radius[~mesh.is_boundary_edge]
    depth = design.vertices.depth[np.isfinite(design.vertices.depth)]
    lines = [
        f"mesh: {mesh.n_vertices} vertices, {mesh.n_edges} edges, {mesh.n_faces} faces "
        f"(mean edge {mesh.mean_edge_length:.4g})",
        f"radius: {r.min():.4g}"
        + (f"-{r.max():.4g}" if len(r) and r.max() > r.min() else "")
        + f" (largest uniform radius {design.rounding.uniform_limit:.4g})"
        if len(r)
        else "radius: no interior edge",
        f"vertices: {shown}",
    ]
    if design.material_loss is not None:
        ml = design.material_loss
        w = ml.edge_loss[ml.edge_loss > 0]
        lines.append(
            f"material loss: b = {ml.bound:.4g}, loss {w.min():.4g}-{w.max():.4g} per edge, "
            f"{len(ml.tight)} tight constraint group(s)"
        )
    if len(depth):
        lines.append(f"apex depth used: {depth.min():.4g}-{depth.max():.4g}")
    lines.append(
        f"pattern: {pat.n_pieces} piece{'s' if pat.n_pieces != 1 else ''} ({design.layout}), "
        f"{len(pat.faces)} faces, "
        f"{int(np.sum(pat.edge_assignment == 'M'))} mountain / "
        f"{int(np.sum(pat.edge_assignment == 'V'))} valley crease segments, "
        f"max edge mismatch {edge_mismatch(pat).max(initial=0.0):.2e} "
        f"(relative {relative_mismatch(pat).max(initial=0.0):.2e})"
    )
    if design.layout_note:
        lines.append(f"  no single sheet: {design.layout_note}")
    fab = design.fabrication
    if fab.get("cut_borders"):
        lines.append(
            f"glue tabs: {fab['tabs']} of {fab['cut_borders']} cut borders"
            + (f" ({fab['tabs_reduced']} at reduced height)" if fab["tabs_reduced"] else "")
            + (f", {fab['untabbed']} with labels only (no room)" if fab["untabbed"] else "")
        )
    if len(pat.annotations.sheets):
        lines.append(f"sheets: {len(pat.annotations.sheets)}")
    flagged = [u for u, st in enumerate(design.vertices.status) if st not in ("ok", "boundary")]
    for u in flagged[:max_listed]:
        reason = design.vertices.reason[u]
        if len(reason) > 160:
            reason = reason[:157] + "..."
        lines.append(f"  vertex {u}: {design.vertices.status[u]} - {reason}")
    if len(flagged) > max_listed:
        lines.append(f"  ... and {len(flagged) - max_listed} more (see report.json)")
    lines.append(f"time: {design.timings.get('total', 0.0):.2f} s")
    return "\n".join(lines)


def export_design(
    design,
    folder,
    *,
    title: str | None = None,
    formats=DEFAULT_FORMATS,
    units: str = "",
    scale: float | None = None,
    page: str = "A4",
) -> list[Path]:
    """Write the design's files into ``folder`` atomically (all of them or none).

    Parameters
    ----------
    design : Design
    folder : str or os.PathLike
    title : str, optional
        FOLD ``file_title`` (default ``"filletfold design of <source>"``).
    formats : str or iterable of str
        Output formats (see :mod:`filletfold.export.cutfiles`): by default ``fold``, ``json``,
        ``obj`` and ``svg``, i.e. ``design.fold``, ``report.json``, ``folded.obj`` and
        ``pattern.svg``; ``"all"`` adds ``pattern.dxf``, ``pattern.pdf``, ``pattern.png`` and
        ``preview.png``. With glue tabs, ``assembly.txt`` (the assembly sheet) is written too.
    units, scale, page
        Real size of the cut files and PDF page (see
        :func:`~filletfold.export.cutfiles.cut_files`).

    Returns
    -------
    list of Path
        The files written.
    """
    t = time.perf_counter()
    formats = parse_formats(formats)
    title = title or f"filletfold design of {design.source}"
    pattern_formats = [f for f in formats if f != "json"]
    files = {}
    if pattern_formats:
        files = cut_files(
            design.pattern,
            pattern_formats,
            units=units,
            scale=scale,
            page=page,
            title=title,
            description="Curved-crease rounded design: vertex modules",
        )
    design.timings["export"] = time.perf_counter() - t
    if "json" in formats:
        files["report.json"] = report_json(design_report(design))
    names = list(output_names(formats))
    seams = design.fabrication.get("seams")
    if seams:
        files["assembly.txt"] = assembly_text(seams)
        names.append("assembly.txt")
    return write_outputs(folder, {k: files[k] for k in names})
