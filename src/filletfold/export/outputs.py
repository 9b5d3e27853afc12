"""What a design reports: ``report.json``, the terminal summary, and the output folder."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from .. import __version__
from ..arrays import run_next, run_starts
from ..errors import named_stages
from ..layout.making import score_layers
from ..layout.tabs import assembly_text
from ..memory import release_memory
from ..rounding.edges import loss_from_radius
from ..surface.bend import cone_tip_zones
from ..surface.pattern import LabelRows, face_arrays
from ..surface.validate import face_signed_area_2d
from ..tolerances import tol
from ..units import MIN_LABEL_MM, MIN_PIECE_MM
from . import report_json
from .assembly import assembly_pdf
from .cutfiles import DEFAULT_FORMATS, cut_files, output_names, parse_formats
from .folder import write_design_folder
from .png import parse_view
from .presets import get_preset, score_preset
from .report import Records

#: The files :func:`export_design` writes by default (and ``assembly.txt`` with glue tabs).
OUTPUT_FILES = (*output_names(DEFAULT_FORMATS), "timings.json")


def _num(x):
    """A float for JSON, or None for NaN."""
    x = float(x)
    return None if not np.isfinite(x) else x


def design_report(design) -> dict:
    """The content of ``report.json`` (see the README for every key).

    Parameters
    ----------
    design : Design

    Returns
    -------
    dict
        Numbers and lists only: ``edges`` and ``vertices`` hold one dict per edge and vertex.
    """
    report = report_records(design)
    return {k: _listed(v) if k in ("mesh", "edges", "vertices") else v for k, v in report.items()}


def _listed(value):
    """A value of :func:`report_records` as :func:`design_report` has it: records as dicts,
    arrays as lists."""
    if isinstance(value, Records):
        return value.dicts()
    if isinstance(value, dict):
        return {k: _listed(v) for k, v in value.items()}
    if isinstance(value, list):
        return list(map(_listed, value))
    return value.tolist() if isinstance(value, np.ndarray) else value


def report_records(design) -> dict:
    """:func:`design_report` with its mesh as arrays and its ``edges`` and ``vertices`` as
    :class:`~filletfold.export.report.Records` of arrays: the same ``report.json`` from
    :func:`~filletfold.export.report.report_json`, without a dict or list per edge and vertex.

    Parameters
    ----------
    design : Design

    Returns
    -------
    dict
    """
    mesh = design.mesh
    rd = design.rounding
    pat = design.pattern
    mismatch, relative = _mismatches(pat)
    counts = {k: int(np.sum(pat.edge_assignment == k)) for k in ("M", "V", "B", "F")}
    return {
        "filletfold": __version__,
        "source": design.source,
        "parameters": design.params.as_dict(),
        "mean_edge_length": float(mesh.mean_edge_length),
        "uniform_radius_limit": _num(rd.uniform_limit),
        "status_counts": design.status_counts(),
        "treatment_counts": _treatment_counts(design.vertices.treatment),
        "mesh_counts": {
            "vertices": int(mesh.n_vertices),
            "edges": int(mesh.n_edges),
            "faces": int(mesh.n_faces),
        },
        "mesh": {"vertices": mesh.vertices, "faces": list(mesh.faces)},
        "edges": _edge_records(
            mesh, rd, design.fitting.get("radius_requested"), design.vertices.treatment
        ),
        "vertices": _vertex_records(design.vertices),
        "pattern": {
            "pieces": int(pat.n_pieces),
            "cut_edges": int(pat.cut_mask().sum()),
            "vertices": len(pat.vertices_2d),
            "faces": len(pat.faces),
            "edges": counts,
            "max_edge_mismatch": float(mismatch.max(initial=0.0)),
            "max_relative_edge_mismatch": float(relative.max(initial=0.0)),
        },
        "repairs": [r.as_dict() for r in design.repairs],
        "coarsening": design.coarsening.as_dict() if design.coarsening is not None else None,
        "certificate": design.certificate.as_dict() if design.certificate is not None else None,
        "fitting": _fitting_report(design),
        "layout": {"kind": design.layout, "note": design.layout_note or None},
        "up": {"axis": design.up, "why": design.up_why},
        "fabrication": _fabrication_report(design),
        "material_loss": _loss_report(design.material_loss),
        "material": material_report(design),
    }


def material_report(design) -> dict | None:
    """The sheet material and what it did (None without one): its figures
    (:meth:`~filletfold.materials.Material.as_dict`), the size (mm) and the fillets against
    its bend floor: how many, the least radius (mm), how many below the floor (0 in a valid
    design); the tapering fillets, which narrow to their sharp corner and are not held to
    it; and the cones' tip zones (:func:`~filletfold.surface.bend.cone_tip_zones`: within
    what distance of its apex a cone bends tighter than the floor; median, largest and
    where), in mm."""
    p = design.params
    material = p.sheet_material()
    if material is None:
        return None
    r = np.asarray(design.rounding.radius, dtype=float)
    mm = p.mm_per_unit if p.scale is not None else None
    rounded = r[r > 0]
    patches = {str(x) for x in design.pattern.face_patch}
    floor = material.bend_floor_mm()
    least = float(rounded.min()) * mm if (mm is not None and len(rounded)) else None
    tips = None
    if mm is not None and floor > 0:
        zone = cone_tip_zones(design.pattern, design.vertices.apex, p.bend_floor()) * mm
        held = np.flatnonzero(np.isfinite(zone))
        if len(held):
            worst = int(held[np.argmax(zone[held])])
            tips = {
                "cones": len(held),
                "median_mm": float(np.median(zone[held])),
                "max_mm": float(zone[worst]),
                "max_at_vertex": worst,
            }
    return {
        **material.as_dict(),
        "size": p.size,
        "fillets": len(rounded),
        "least_fillet_radius_mm": least,
        "fillets_below_floor": (
            int((rounded * mm < floor * (1 - 1e-9)).sum()) if mm is not None else None
        ),
        "tapering_fillets": sum(x.startswith("fillet ") for x in patches),
        "cones": sum(x.startswith("cone ") for x in patches),
        "cone_tip_zones": tips,
        "not_held": (
            "a cone bends tighter than the floor near its tip (cone_tip_zones: within that "
            "distance of its apex) and a tapering fillet near its sharp corner: relieve or "
            "crease the sheet there"
        ),
        "making": _making_report(design, material),
    }


#: Per way of making (:attr:`~filletfold.materials.Material.making`), what the cut files do.
_MAKING_WHY = {
    "score": (
        "creases scored: mountains on the front (layer SCORE_FRONT), valleys on the back "
        "(SCORE_BACK, the sheet turned over); the sheet bends its fillets and cones freely "
        "and creases itself at a cone's tip"
    ),
    "relief": (
        "bends rolled or braked; where a cone near its tip or a tapering fillet near its "
        "sharp corner would bend tighter than the floor, the sheet is cut away (layer RELIEF)"
    ),
    "kerf": (
        "every cylinder and cone grooved along its rulings on its inner side (layers "
        "KERF_FRONT, KERF_BACK), the grooves' turns adding up to its bend; the cones' tips, "
        "the cones too tight to groove and the tapering fillets' corners relieved (RELIEF)"
    ),
}


def _making_report(design, material) -> dict:
    """How the material's bends are made (:mod:`~filletfold.layout.making`): the way, why,
    and the counts of the paths drawn for it."""
    making = design.pattern.annotations.making
    reliefs = [m for m in making if m.kind == "relief"]
    grooves = [m for m in making if m.kind != "relief"]
    out = {
        "method": material.making,
        "why": _MAKING_WHY.get(material.making, ""),
        "score_layers": score_layers(material.making),
        "reliefs": len(reliefs),
        "relieved_cones": len({m.patch for m in reliefs if m.patch.startswith("cone ")}),
        "relieved_fillets": len({m.patch for m in reliefs if m.patch.startswith("fillet ")}),
        "grooves_front": sum(m.kind == "kerf-front" for m in grooves),
        "grooves_back": sum(m.kind == "kerf-back" for m in grooves),
        "grooved_cylinders": len({m.patch for m in grooves if m.patch.startswith("cylinder ")}),
        "grooved_cones": len({m.patch for m in grooves if m.patch.startswith("cone ")}),
        "creased_fillets": len((design.fitting or {}).get("creased", ())),
    }
    if material.kerf is not None:
        out["kerf"] = material.kerf.as_dict()
    return out


#: The per-element tables of :func:`report_records`, in ``report.json`` only on request
#: (``export_design(tables=True)``, ``filletfold round --report-tables``): the file is a
#: summary, and what ``filletfold check`` needs per element is in ``design.fold``
#: (:func:`mesh_fold_keys`).
REPORT_TABLES = ("mesh", "edges", "vertices")
#: The per-element lists of the report's ``fitting``, with the tables only: the summary keeps
#: their counts (``radii_reduced``, ``edges_sharp``, ``vertices_rescued``,
#: ``vertices_sharpened``). On a 100k-face scan ``sharp`` alone was 458 KB of a 1.0 MB file.
FITTING_TABLES = ("reduced", "sharp", "creased", "rescued", "sharpened")


def _treatment_counts(treatment) -> dict:
    """Vertices per treatment: ``cone``, ``sharp``, ``hole`` (every key, zeros included)."""
    out = dict.fromkeys(("cone", "sharp", "hole"), 0)
    for t in treatment:
        out[t] = out.get(t, 0) + 1
    return out


def summary_records(design, tables: bool = False) -> dict:
    """:func:`report_records` as ``report.json`` has it: without :data:`REPORT_TABLES` and the
    ``fitting`` lists :data:`FITTING_TABLES` (their counts stay) unless ``tables``."""
    report = report_records(design)
    if tables:
        return report
    out = {k: v for k, v in report.items() if k not in REPORT_TABLES}
    if out.get("fitting"):
        out["fitting"] = {k: v for k, v in out["fitting"].items() if k not in FITTING_TABLES}
    return out


def mesh_fold_keys(design) -> dict:
    """What ``filletfold check`` needs per element of the (cleaned) mesh, as namespaced keys
    of ``design.fold``: the certificate can be measured again from the file alone.

    Keys (``E`` mesh edges, ``V`` mesh vertices): ``filletfold:mesh_vertices_coords``
    (V, 3); ``filletfold:mesh_faces_vertices`` (the polygons, counter-clockwise seen from
    outside); ``filletfold:mesh_edges_vertices`` (E, 2) and ``filletfold:mesh_edges_faces``
    (E, 2, ``-1`` where an edge has one face); ``filletfold:mesh_edges_radius`` (E,),
    ``filletfold:mesh_edges_halfAngle`` (E, radians: half the turn between the two faces'
    normals) and ``filletfold:mesh_edges_assignment`` (E, ``M``/``V``/``B``) of the rounding;
    ``filletfold:mesh_vertices_apex`` (V, the cone's apex, ``null`` at a vertex without one).

    Parameters
    ----------
    design : Design

    Returns
    -------
    dict
    """
    mesh, rd = design.mesh, design.rounding
    apex = np.asarray(design.vertices.apex, dtype=float).reshape(-1, 3)
    has = np.isfinite(apex).all(axis=1)
    apex_rows = [row if ok else None for row, ok in zip(apex.tolist(), has.tolist(), strict=True)]
    return {
        "filletfold:mesh_vertices_coords": np.asarray(mesh.vertices, dtype=float),
        "filletfold:mesh_faces_vertices": [list(map(int, f)) for f in mesh.faces],
        "filletfold:mesh_edges_vertices": np.asarray(mesh.edges, dtype=np.int64),
        "filletfold:mesh_edges_faces": np.asarray(mesh.edge_faces, dtype=np.int64),
        "filletfold:mesh_edges_radius": np.asarray(rd.radius, dtype=float),
        "filletfold:mesh_edges_halfAngle": np.asarray(rd.half_angle, dtype=float),
        "filletfold:mesh_edges_assignment": _edge_assignment(mesh, rd),
        "filletfold:mesh_vertices_apex": apex_rows,
    }


def _edge_assignment(mesh, rd) -> list:
    """Per mesh edge: ``B`` at the boundary, else ``M`` or ``V`` by the rounding's sign."""
    boundary = (mesh.edge_faces < 0).any(axis=1)
    return np.where(boundary, "B", np.where(rd.kappa > 0, "M", "V")).tolist()


def timings_json(design) -> str:
    """The content of ``timings.json``: seconds per stage of ``design``, as JSON text.

    Kept out of ``report.json`` so that the report, like every other output file, has the
    same bytes for the same input and parameters.

    Parameters
    ----------
    design : Design

    Returns
    -------
    str
        ``{"read": s, "rounding": s, ..., "total": s, "export": s}`` (the stages that ran, in
        order), indented by 2, ending with a newline.
    """
    return report_json({k: float(v) for k, v in design.timings.items()})


def _fitting_report(design) -> dict:
    """``fitting`` of the report: radii reduced to fit, edges left sharp, vertices rescued."""
    fit = design.fitting
    if not fit:
        return {}
    asked, fitted = fit["radius_requested"], fit["fitted_radius"]
    reduced = fit["reduced"]
    factor = fitted[reduced] / asked[reduced]
    sharpened = [int(u) for u in fit.get("sharpened", [])]
    return {
        "radii_reduced": len(reduced),
        "smallest_factor": float(factor.min()) if len(reduced) else None,
        "edges_sharp": len(fit["sharp"]),
        "edges_creased": len(fit.get("creased", ())),
        "bend_floor": float(fit.get("bend_floor", 0.0)),
        "vertices_sharpened": len(sharpened),
        "reduced": [
            {"edge": int(e), "requested": float(asked[e]), "radius": float(fitted[e])}
            for e in reduced.tolist()
        ],
        "sharp": fit["sharp"].tolist(),
        "creased": np.asarray(fit.get("creased", []), dtype=np.int64).tolist(),
        "vertices_rescued": len(fit["rescued"]),
        "rescue_applied": bool(fit["rescue_applied"]),
        "rescued": [{"vertex": int(u), "factor": float(f)} for u, f in fit["rescued"].items()],
        "sharpened": sharpened,
        "cones_by_lp": int(fit.get("cones_by_lp", 0)),
        "cones_by_fallback": {k: int(v) for k, v in fit.get("cones_by_fallback", {}).items()},
        "apex_work": {k: int(v) for k, v in fit.get("apex_work", {}).items()},
    }


def _not_finite(x: np.ndarray) -> np.ndarray:
    """(n,) bool: the values (n,), or rows (n, k), of ``x`` with a NaN or infinity."""
    bad = ~np.isfinite(x)
    return bad.any(axis=1) if bad.ndim == 2 else bad


def _edge_records(mesh, rd, design_requested=None, treatment=None) -> Records:
    """The ``edges`` of the report: one record per mesh edge (``treatment`` from the
    vertices' treatments, :func:`~filletfold.vertex.sharpen.edge_treatments`)."""
    from ..vertex.sharpen import edge_treatments

    if treatment is None:
        treatment = [""] * mesh.n_vertices
    boundary = (mesh.edge_faces < 0).any(axis=1)
    bent = rd.half_angle > 0
    loss_limit = np.full(mesh.n_edges, np.nan)  # None where not bent
    loss_limit[bent] = loss_from_radius(rd.limit[bent], rd.half_angle[bent])
    limit = np.asarray(rd.limit, dtype=float)
    return Records(
        {
            "vertices": mesh.edges,
            "faces": mesh.edge_faces,
            "length": np.asarray(mesh.edge_length, dtype=float),
            "radius": np.asarray(rd.radius, dtype=float),
            "radius_requested": np.asarray(
                design_requested if design_requested is not None else rd.radius, dtype=float
            ),
            "sharp": (
                np.zeros(mesh.n_edges, dtype=bool) if rd.sharp is None else rd.sharp
            ).tolist(),
            "half_angle": np.asarray(rd.half_angle, dtype=float),
            "assignment": _edge_assignment(mesh, rd),
            "treatment": edge_treatments(mesh, rd, treatment),
            "arc_length": np.asarray(rd.arc_length, dtype=float),
            "strip_width": np.asarray(rd.strip_width, dtype=float),
            "material_loss": np.asarray(rd.loss, dtype=float),
            "radius_limit": limit,
            "material_loss_limit": loss_limit,
        },
        nulls={
            "faces": boundary,
            "radius_limit": _not_finite(limit),
            "material_loss_limit": _not_finite(loss_limit),
        },
    )


def _vertex_records(res) -> Records:
    """The ``vertices`` of the report: one record per mesh vertex (``reason`` unless ok);
    None for a number, or vector, that is not finite, and for a zero ``sigma``."""

    def floats(x) -> np.ndarray:
        return np.asarray(x, dtype=float)

    sigma = np.asarray(res.sigma).astype(np.int64)
    columns = {
        "kind": list(res.kind),
        "status": list(res.status),
        "treatment": list(res.treatment),
        "reason": list(res.reason),
        "angle_sum": floats(res.angle_sum),
        "angle_defect": floats(res.defect),
        "solid_angle": floats(res.solid_angle),
        "sigma": sigma,
        "normal": floats(res.normal),
        "normal_bound": floats(res.normal_bound),
        "apex": floats(res.apex),
        "apex_developed": floats(res.apex_developed),
        "apex_2d": floats(res.apex_2d),
        "depth_requested": floats(res.depth_requested),
        "depth": floats(res.depth),
        "margin": floats(res.margin),
    }
    nulls = {k: _not_finite(v) for k, v in columns.items() if isinstance(v, np.ndarray)}
    nulls["sigma"] = sigma == 0
    return Records(columns, present={"reason": [s != "ok" for s in res.status]}, nulls=nulls)


def _fabrication_report(design) -> dict:
    """Pieces, glue tabs, (with sheets) pieces per sheet and material use, and (with drawing
    units) the smallest piece's span and the pieces under the minimum
    (:func:`piece_sizes_mm`). The seams (one record per cut border) are not repeated here:
    ``assembly.txt`` lists them."""
    out = {"pieces": int(design.pattern.n_pieces)}
    for k, v in design.fabrication.items():
        if k != "seams":
            out[k] = v if isinstance(v, list | dict) else int(v)
    out.update(cut_and_fold(design.pattern))
    out.update(piece_sizes_mm(design) or {})
    return out


def cut_and_fold(pattern) -> dict:
    """What a cutter and a folder do, in pattern units: ``cut_length`` (the pieces' borders,
    less the tabs' hinges, plus the tabs' outlines less their hinges), ``fold_length`` (the
    mountain and valley creases, the tabs' hinges not counted), ``piece_area`` (the pieces'
    area in 2D: the folded form's, as the pattern is its development, up to what the chords
    across bent facets lose: 8e-5 on the cube) and, with sheets, ``sheet_area`` (the
    material the sheets take)."""
    from .paths import point_rows

    e = pattern.edges
    length = np.linalg.norm(pattern.vertices_2d[e[:, 0]] - pattern.vertices_2d[e[:, 1]], axis=1)
    cut = float(length[pattern.edge_assignment == "B"].sum())
    fold = float(length[np.isin(pattern.edge_assignment, ["M", "V"])].sum())
    ann = pattern.annotations
    if len(ann.tabs):
        pts, sizes = point_rows(ann.tabs)
        nxt = run_next(run_starts(sizes))  # each outline closed
        cut += float(np.linalg.norm(pts[nxt] - pts, axis=1).sum())
        hinge_pts, _ = point_rows(ann.tab_hinges)
        hinge = hinge_pts.reshape(-1, 2, 2)
        cut -= 2.0 * float(np.linalg.norm(hinge[:, 1] - hinge[:, 0], axis=1).sum())
    out = {
        "cut_length": cut,
        "fold_length": fold,
        "piece_area": float(face_signed_area_2d(pattern.vertices_2d, pattern.faces).sum()),
    }
    sheets = np.asarray(ann.sheets, dtype=float).reshape(-1, 4)
    if len(sheets):
        w, h = sheets[:, 2] - sheets[:, 0], sheets[:, 3] - sheets[:, 1]
        out["sheet_area"] = float((w * h).sum())
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


def _edge_lengths(pattern) -> tuple[np.ndarray, np.ndarray]:
    """(n_edges,) 2D and 3D length of every pattern edge."""
    e = pattern.edges
    l2 = np.linalg.norm(pattern.vertices_2d[e[:, 0]] - pattern.vertices_2d[e[:, 1]], axis=1)
    l3 = np.linalg.norm(pattern.vertices_3d[e[:, 0]] - pattern.vertices_3d[e[:, 1]], axis=1)
    return l2, l3


def _mismatches(pattern) -> tuple[np.ndarray, np.ndarray]:
    """:func:`edge_mismatch` and :func:`relative_mismatch`, the lengths measured once."""
    l2, l3 = _edge_lengths(pattern)
    return l2 - l3, (l2 - l3) / np.where(l2 > 0, l2, 1.0)


def edge_mismatch(pattern) -> np.ndarray:
    """(n_edges,) 2D length minus 3D length of every pattern edge (>= 0 up to round-off)."""
    l2, l3 = _edge_lengths(pattern)
    return l2 - l3


def relative_mismatch(pattern) -> np.ndarray:
    """(n_edges,) edge mismatch divided by the 2D edge length (converges with order 2)."""
    return _mismatches(pattern)[1]


#: A mesh thinner than this share of its length is nearly flat: the summary warns that its
#: modules could be far fewer pieces.
FLAT_RATIO = 0.02
#: A design of more pieces gets a line in the summary suggesting ``--faces``.
MANY_PIECES = 1000
#: A design on more sheets gets a warning in the summary.
MANY_SHEETS = 30
#: The triangle count that line suggests.
COARSE_FACES = 2000


def piece_spans(pattern) -> np.ndarray:
    """(n_pieces,) the longer side of each piece's bounding box in the pattern (pattern
    units; NaN for a piece without faces)."""
    flat, start = face_arrays(pattern.faces)
    piece = np.repeat(np.asarray(pattern.face_piece, dtype=np.int64), np.diff(start))
    xy = pattern.vertices_2d[flat]
    n = int(pattern.n_pieces)
    lo, hi = np.full((n, 2), np.inf), np.full((n, 2), -np.inf)
    np.minimum.at(lo, piece, xy)
    np.maximum.at(hi, piece, xy)
    span = (hi - lo).max(axis=1)
    return np.where(np.isfinite(span), span, np.nan)


def piece_sizes_mm(design) -> dict | None:
    """With drawing ``units`` (given, or from ``size``): the smallest piece's span and the
    pieces that span less than :data:`MIN_PIECE_MM`, and the lowest label, in millimetres on
    the sheet (the report's ``fabrication.smallest_piece_mm``, ``pieces_under_min``,
    ``smallest_label_mm``); None without units."""
    p = design.params
    if not p.units:
        return None
    mm_per = p.mm_per_unit
    mm = piece_spans(design.pattern) * mm_per
    mm = mm[np.isfinite(mm)]
    labels = design.pattern.annotations.labels
    heights = np.abs(np.asarray(LabelRows.of(labels).height if len(labels) else [], dtype=float))
    heights = heights[np.isfinite(heights) & (heights > 0)] * mm_per
    return {
        "smallest_piece_mm": float(mm.min(initial=np.inf)) if len(mm) else None,
        "pieces_under_min": int(np.count_nonzero(mm < MIN_PIECE_MM)),
        "min_piece_mm": MIN_PIECE_MM,
        "smallest_label_mm": float(heights.min()) if len(heights) else None,
    }


#: What set the default size (:func:`~filletfold.layout.arrange.default_size`), for the summary.
_DEFAULT_SIZE_WHY = {
    "least": "a model held in the hand",
    "labels": f"the least with labels {MIN_LABEL_MM:g} mm high",
    "pieces": f"the least with every piece {MIN_PIECE_MM:g} mm across",
    "material": (
        "the least at which the fillets are as wide as the material bends, but for the "
        "tightest tenth of their length (creases)"
    ),
}


def _material_lines(design) -> list[str]:
    """The summary's line for the sheet material (none without one)."""
    m = material_report(design)
    if m is None:
        return []
    line = (
        f"material: {m['name']}, {m['thickness_mm']:g} mm thick, fillets no tighter than "
        f"{m['bend_floor_mm']:g} mm (least inner radius {m['min_bend_radius_mm']:g} mm + half "
        f"the thickness)"
    )
    if m["least_fillet_radius_mm"] is not None:
        line += f": {m['fillets']} fillets, the least {m['least_fillet_radius_mm']:.4g} mm"
    lines = [line]
    tips = m["cone_tip_zones"]
    mk = m["making"]
    if mk["method"] == "score":
        lines.append("  made by: " + mk["why"])
    else:
        lines.append(
            f"  made by: {mk['reliefs']} reliefs ({mk['relieved_cones']} cone tips, "
            f"{mk['relieved_fillets']} tapering fillets)"
            + (
                f", {mk['grooves_front'] + mk['grooves_back']} kerf grooves on "
                f"{mk['grooved_cylinders']} cylinders and {mk['grooved_cones']} cones "
                f"({mk['grooves_front']} front, {mk['grooves_back']} back)"
                if mk["method"] == "kerf"
                else ""
            )
            + " in the cut files"
        )
    if mk["method"] == "score":
        if tips is not None and tips["max_mm"] > 0:
            lines.append(
                f"  note: the cones bend tighter than that within {tips['median_mm']:.3g} mm "
                f"of their tips (median of {tips['cones']}; {tips['max_mm']:.3g} mm at vertex "
                f"{tips['max_at_vertex']}): the sheet creases there"
            )
        if m["tapering_fillets"]:
            lines.append(
                f"  note: {m['tapering_fillets']} tapering fillets narrow to their sharp "
                "corner: the sheet creases there"
            )
    return lines


def _size_lines(design) -> list[str]:
    """The summary's lines for the physical size: with ``size``, the scale it gave and the
    smallest piece at it; with any units, a warning for pieces under :data:`MIN_PIECE_MM`."""
    p, sizes = design.params, piece_sizes_mm(design)
    if sizes is None:
        return []
    lines = []
    smallest = sizes["smallest_piece_mm"]
    mm = p.mm_per_unit
    work = cut_and_fold(design.pattern)
    line = (
        f"to make: {work['cut_length'] * mm / 1000:.4g} m of cuts, "
        f"{work['fold_length'] * mm / 1000:.4g} m of folds, "
        f"{work['piece_area'] * mm * mm / 1e6:.4g} m² of pieces"
    )
    if "sheet_area" in work:
        line += f" on {work['sheet_area'] * mm * mm / 1e6:.4g} m² of sheets"
    lines.append(line)
    if p.size is not None:
        default = design.fabrication.get("default_size")
        why = (
            ""
            if default is None
            else f", the default: {_DEFAULT_SIZE_WHY[default['binding']]}; --size to choose"
        )
        lines.append(
            f"size: {p.size} (the mesh's largest side{why}): 1 unit = {float(p.scale):.4g} "
            f"{p.units}; the smallest piece spans {smallest:.3g} mm"
        )
    label = sizes["smallest_label_mm"]
    if label is not None and label < MIN_LABEL_MM:
        lines.append(
            f"  warning: labels {label:.3g} mm high, under {MIN_LABEL_MM:g} mm: hard to read "
            "(a larger --size)"
        )
    if sizes["pieces_under_min"]:
        lines.append(
            f"  warning: {sizes['pieces_under_min']} of {design.pattern.n_pieces} pieces span "
            f"less than {MIN_PIECE_MM:g} mm (the smallest {smallest:.3g} mm), too small to cut "
            "and fold: a larger --size, or fewer faces (--faces N)"
        )
    return lines


def thickness_ratio(points: np.ndarray) -> float:
    """The extent of ``points`` (k, 3) along their least principal axis over the extent along
    the largest (0: flat, 1: as thick as long)."""
    p = np.asarray(points, dtype=np.float64)
    p = p - p.mean(axis=0)
    _, _, axes = np.linalg.svd(p, full_matrices=False)
    extent = np.ptp(p @ axes.T, axis=0)
    return float(extent[-1] / extent[0]) if len(extent) == 3 and extent[0] > 0 else 0.0


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
    lines[1:1] = _repair_lines(design, max_listed)
    if design.coarsening is not None:
        lines.insert(1, design.coarsening.summary())
    lines[-1:-1] = _fitting_lines(design)
    if design.material_loss is not None:
        ml = design.material_loss
        w = ml.edge_loss[ml.edge_loss > 0]
        lines.append(
            f"material loss: b = {ml.bound:.4g}, loss {w.min():.4g}-{w.max():.4g} per edge, "
            f"{len(ml.tight)} tight constraint group(s)"
        )
    if len(depth):
        lines.append(f"apex depth used: {depth.min():.4g}-{depth.max():.4g}")
    mismatch, relative = _mismatches(pat)
    lines.append(
        f"pattern: {pat.n_pieces} piece{'s' if pat.n_pieces != 1 else ''} ({design.layout}), "
        f"{len(pat.faces)} faces, "
        f"{int(np.sum(pat.edge_assignment == 'M'))} mountain / "
        f"{int(np.sum(pat.edge_assignment == 'V'))} valley crease segments, "
        f"max edge mismatch {mismatch.max(initial=0.0):.2e} "
        f"(relative {relative.max(initial=0.0):.2e})"
    )
    lines += _size_lines(design)
    lines += _material_lines(design)
    if design.up_why != "given":
        lines.append(f"up: +{design.up} ({design.up_why}; in the pictures; --up to choose)")
    thin = thickness_ratio(mesh.vertices)
    if thin < FLAT_RATIO and pat.n_pieces > 1 and design.layout == "modules":
        lines.append(
            f"  warning: the mesh is nearly flat (its thickness is {100 * thin:.2g} % of its "
            f"length): its {pat.n_pieces} pieces could be far fewer (--layout net joins them)"
        )
    if design.coarsening is None and pat.n_pieces > MANY_PIECES:
        lines.append(
            f"  {pat.n_pieces} pieces are more than a person cuts: --faces N coarsens the mesh "
            f"first (quadric decimation; --faces {COARSE_FACES} gives some "
            f"{COARSE_FACES // 2} vertices)"
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
        nesting = fab.get("nesting", {})
        placed = (
            f" ({nesting['nester']}, material use {nesting['material_use']:.0%})" if nesting else ""
        )
        lines.append(f"sheets: {len(pat.annotations.sheets)}{placed}")
        if len(pat.annotations.sheets) > MANY_SHEETS:
            lines.append(
                f"  warning: {len(pat.annotations.sheets)} sheets are more than a person prints "
                f"and cuts (over {MANY_SHEETS}): a smaller --size, fewer faces (--faces N), or "
                "--nest sparrow (the 'nest' extra) to place the pieces closer"
            )
    flagged = [u for u, st in enumerate(design.vertices.status) if st not in ("ok", "boundary")]
    for u in flagged[:max_listed]:
        reason = design.vertices.reason[u]
        if len(reason) > 160:
            reason = reason[:157] + "..."
        lines.append(f"  vertex {u}: {design.vertices.status[u]} - {reason}")
    if len(flagged) > max_listed:
        lines.append(f"  ... and {len(flagged) - max_listed} more (see report.json)")
    cert = design.certificate
    if cert is not None:
        if cert.ok:
            lines.append(
                f"certificate: valid ({sum(c.limit is not None for c in cert.checks)} checks)"
            )
        else:
            lines.append(
                "certificate: NOT VALID: "
                + "; ".join(
                    f"{c.name} {_figure(c.value)} (limit {_figure(c.limit)})" for c in cert.failed
                )
            )
    lines.append(f"time: {design.timings.get('total', 0.0):.2f} s")
    return "\n".join(lines)


def _figure(x) -> str:
    """A certificate figure for the summary (a number with 5 digits, or as it is)."""
    return f"{x:.5g}" if isinstance(x, float | int) and not isinstance(x, bool) else str(x)


def _repair_lines(design, max_listed: int) -> list[str]:
    """Summary lines of the mesh repairs: the count per kind, the first few of them."""
    repairs = design.repairs
    if not repairs:
        return []
    kinds: dict = {}
    for r in repairs:
        kinds[r.what] = kinds.get(r.what, 0) + 1
    out = [
        f"repairs: {len(repairs)} ("
        + ", ".join(f"{n} {k}" for k, n in kinds.items())
        + "; see report.json)"
    ]
    for r in repairs[:max_listed]:
        text = str(r)
        out.append("  " + (text if len(text) <= 160 else text[:157] + "..."))
    if len(repairs) > max_listed:
        out.append(f"  ... and {len(repairs) - max_listed} more")
    return out


def _fitting_lines(design) -> list[str]:
    """Summary lines of the radius fitting, the sharp edges and the rescued vertices."""
    fit = design.fitting
    if not fit:
        return []
    out = []
    reduced = fit["reduced"]
    if len(reduced):
        f = fit["fitted_radius"][reduced] / fit["radius_requested"][reduced]
        out.append(
            f"radii fitted: {len(reduced)} edges reduced to fit their limits (smallest factor "
            f"{f.min():.3g})"
        )
    if len(fit["sharp"]):
        out.append(
            f"sharp edges: {len(fit['sharp'])} left sharp (a fillet narrower than "
            f"{tol.fillet_floor:g} of the edge would be a sliver)"
        )
    creased = fit.get("creased", ())
    if len(creased):
        p = design.params
        material = p.sheet_material()
        length = design.mesh.edge_length
        rounded = fit["fitted_radius"] > 0
        share = length[creased].sum() / max(length[rounded].sum() + length[creased].sum(), 1e-300)
        name = material.name if material is not None else "the sheet"
        out.append(
            f"creased for the material: {len(creased)} fillets ({100 * share:.1f} % of the "
            f"fillets' length) are tighter than {name} bends at {p.size} and too narrow to "
            "widen: straight creases (a larger --size keeps more of them round)"
        )
    rescued = fit["rescued"]
    if rescued:
        f = np.array(list(rescued.values()))
        verb = "rescued" if fit["rescue_applied"] else "would be feasible"
        out.append(
            f"vertices {verb}: {len(rescued)} with the radii of their edges scaled by "
            f"{f.min():g} to {f.max():g}"
            + ("" if fit["rescue_applied"] else " (--fit-vertices does so)")
        )
    if fit.get("sharpened"):
        out.append(
            f"vertices left sharp: {len(fit['sharpened'])} (no radius on their edges made their "
            "cone feasible: their edges are sharp, their faces meet at the vertex)"
        )
    return out


def _input_files(design) -> tuple:
    """The file the design was read from, when it was read from one."""
    source = getattr(design, "source", None)
    return (source,) if isinstance(source, str) and Path(source).is_file() else ()


@named_stages("export")
def export_design(
    design,
    folder,
    *,
    title: str | None = None,
    formats=DEFAULT_FORMATS,
    units: str | None = None,
    scale: float | None = None,
    page: str | None = None,
    preset=None,
    view=None,
    tables: bool = False,
    force: bool = False,
) -> list[Path]:
    """Write the design's files as the contents of the design folder ``folder``: the old
    design or the new one, never a mix (:func:`~filletfold.export.folder.write_design_folder`).

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
        ``preview.png``. With glue tabs, ``assembly.txt`` (the assembly sheet) is written too;
        with ``json``, ``timings.json`` (:func:`timings_json`), the one file that differs
        between two runs on the same input.
    units, scale, page
        Real size of the cut files and PDF page (see
        :func:`~filletfold.export.cutfiles.cut_files`); by default the design's
        (``design.params``: its units and scale, with the default size those it settled;
        its sheet, or A4). Units given without a scale: scale 1.
    preset : str or Preset, optional
        Cutter preset of ``pattern.svg`` and ``pattern.dxf``
        (:data:`~filletfold.export.presets.PRESETS`; default ``print``); with a scored sheet
        material (``design.params.material``) its mountain and valley lines are on the layers
        ``SCORE_FRONT`` and ``SCORE_BACK`` (:func:`~filletfold.export.presets.score_preset`).
    view : str or (2,) float, optional
        The direction ``preview.png`` is seen from (see
        :func:`~filletfold.export.cutfiles.cut_files`), up the design's ``up`` unless it
        names its own.
    force : bool
        Write into a folder that holds files this tool did not write (they are kept); by
        default such a folder is refused. A folder holding the input mesh under a name of the
        design's files is always refused.
    tables : bool
        Whether ``report.json`` holds the per-element tables ``mesh``, ``edges`` and
        ``vertices`` (:data:`REPORT_TABLES`); by default it is a summary, and ``design.fold``
        holds what ``filletfold check`` needs per element (:func:`mesh_fold_keys`).

    Returns
    -------
    list of Path
        The files written.
    """
    t = time.perf_counter()
    release_memory()  # what the design's stages freed, before the files are built
    if units is None:
        units, scale = design.params.units, design.params.scale if scale is None else scale
    page = page or design.params.sheet or "A4"
    view = parse_view("front" if view is None else view, design.up)  # up: the design's
    formats = parse_formats(formats)
    title = title or f"filletfold design of {design.source}"
    pattern_formats = [f for f in formats if f != "json"]
    files = {}
    material = design.params.sheet_material()
    if material is not None:  # a scored material's fold lines on its score layers
        preset = score_preset(get_preset(preset), score_layers(material.making))
    if pattern_formats:
        files = cut_files(
            design.pattern,
            pattern_formats,
            units=units,
            scale=scale,
            page=page,
            view=view,
            title=title,
            description="Curved-crease rounded design: vertex modules",
            lazy=True,  # built one at a time as they are written
            preset=preset,
            fold_extra=mesh_fold_keys(design),
        )
    if "json" in formats:

        def timings() -> str:
            design.timings["export"] = time.perf_counter() - t  # the files built before it
            return timings_json(design)

        files["report.json"] = lambda: report_json(summary_records(design, tables))
        files["timings.json"] = timings
    names = list(output_names(formats))
    seams = design.fabrication.get("seams")
    if seams:
        files["assembly.txt"] = assembly_text(seams)
        names.append("assembly.txt")
        if "pdf" in formats:  # the guide, with pictures
            files["assembly.pdf"] = lambda: assembly_pdf(
                design.pattern, seams, up=design.up, page=page
            )
            names.append("assembly.pdf")
    if "json" in formats:
        names.append("timings.json")  # last: its export time covers the other files
    written = write_design_folder(
        folder, {k: files[k] for k in names}, force=force, inputs=_input_files(design)
    )
    design.timings["export"] = time.perf_counter() - t
    return written
