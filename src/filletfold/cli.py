"""The ``filletfold`` command line: a thin front end over the library.

Commands
--------
``filletfold examples``
    List the built-in meshes.
``filletfold round MESH [-o OUT] [--from REPORT] [--radius R] [--depth D] [--samples N]``
``[--arc-step DEG]``
``[--chord-tol TOL] [--coplanar-tol DEG] [--faces N | --edge-length L]``
``[--format LIST] [--units U] [--scale S] [--sheet PAGE] [--preset NAME] [--nest NESTER]``
``[--view V]``
    Round a mesh (file or built-in name) and write ``design.fold``, ``report.json``,
    ``folded.obj`` and ``pattern.svg`` into ``OUT`` (``--format all`` adds the cut files and
    pictures). ``--from REPORT`` makes a design again from its ``report.json`` (its mesh and
    parameters, the options given replacing theirs).
``filletfold app [MESH] [--port N] [--host ADDR]``
    Start the browser app (viser) on MESH and print its address.
``filletfold hops [--port N] [--host ADDR]``
    Serve the Grasshopper Hops components Round and Pattern on this machine.
``filletfold export DIR [--format dxf,pdf,svg,png] [--units U] [--scale S] [--sheet PAGE]``
``[--preset NAME] [--view V]``
    Read ``DIR/design.fold`` and write cut files (``pattern.dxf``, ``pattern.pdf``,
    ``pattern.svg``) and pictures (``pattern.png``, ``preview.png``) into ``DIR``.
``filletfold check DIR [--json]``
    Measure the design's invariants from ``DIR/design.fold`` and ``DIR/report.json`` and print
    them, one line each; exit 0 when all hold, 1 when one fails, 2 when the files cannot be read.
"""

from __future__ import annotations

import logging
import sys
import time
import traceback
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.markup import escape

from . import __version__
from .defaults import (
    DEFAULT_ARC_STEP,
    DEFAULT_CHORD_TOL,
    DEFAULT_DEPTH,
    DEFAULT_MAX_CORNERS,
    DEFAULT_MAX_POINTS,
    DEFAULT_RADIUS,
    DEFAULT_SAMPLES,
    DEFAULT_SHARP,
)
from .errors import FilletfoldError, InternalError, ParameterError, one_line, watching_stages
from .memory import limit_arenas
from .tolerances import tol

app = typer.Typer(
    name="filletfold",
    help="Turn a polyhedral mesh into a curved-crease folded design (rounded edges, conical "
    "vertices) and the flat pieces to cut and fold.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # help texts are plain: "filletfold[app]", "[default: ...]" kept
)
console = Console()
err_console = Console(stderr=True)


def _version(value: bool):
    if value:
        console.print(f"filletfold {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_version, is_eager=True, help="Print the version and exit."
        ),
    ] = False,
):
    """filletfold: curved-crease edge rounding of polyhedral meshes."""


@app.command()
def examples():
    """List the built-in example meshes (use a name wherever a mesh file is expected)."""
    from rich.table import Table

    from .mesh import EXAMPLES, example_mesh

    table = Table("name", "vertices", "faces", "kind", "description")
    for name, ex in EXAMPLES.items():
        v, f = example_mesh(name)
        table.add_row(name, str(len(v)), str(len(f)), ", ".join(ex.kinds), ex.description)
    console.print(table)


@app.command()
def materials():
    """List the sheet materials of --material: thickness t, least inner bend radius min r, the
    bend floor of the fillets (min r + t/2), k-factor, how creases are made (docs/materials.md
    gives where each figure comes from)."""
    from rich.table import Table

    from .materials import material_table

    table = Table("name", "t mm", "min r mm", "floor mm", "k", "made by", "description")
    for m in material_table():
        table.add_row(
            m["name"], f"{m['thickness_mm']:g}", f"{m['min_bend_radius_mm']:g}",
            f"{m['bend_floor_mm']:g}", f"{m['k_factor']:.2f}", m["making"], m["description"],
        )  # fmt: skip
    console.print(table)


#: Formats ``filletfold export`` can write from a ``design.fold``.
EXPORT_FORMATS = ("simulator", "obj", "svg", "dxf", "pdf", "png", "3dm", "glb", "ply", "stl")

FormatOption = Annotated[
    str | None,
    typer.Option(
        "--format",
        "-f",
        help="Comma-separated output formats: fold, simulator (simulator.fold and "
        "simulator.svg, for Origami Simulator), json, obj, svg, dxf, pdf, png (pattern.png "
        "and preview.png), 3dm (pattern.3dm and folded.3dm, needs rhino3dm), glb (or gltf), "
        "ply, stl, or all.",
    ),
]
UnitsOption = Annotated[
    str,
    typer.Option(
        "--units",
        help="Drawing unit of the cut files: mm, cm, m or in (default: unitless; the PDF then "
        "fits the drawing on one page).",
    ),
]
ScaleOption = Annotated[
    float | None,
    typer.Option(
        "--scale",
        help="Drawing units per mesh length unit in the DXF, SVG, PDF, 3DM, GLB, PLY and STL "
        "(default 1).",
    ),
]
PresetOption = Annotated[
    str | None,
    typer.Option(
        "--preset",
        help="Cutter preset of pattern.svg and pattern.dxf: print (to print and cut: cut black, "
        "mountain red, valley blue, joined paths, no facet lines; DXF layers "
        "CUT/MOUNTAIN/VALLEY/TAB/LABEL), origami-simulator (Origami Simulator's import: facet "
        "lines, fold-angle opacities), "
        "laser (hairlines, cut red, scores blue/green), plotter (dashed score lines) or card "
        "(perforated fold lines) [default: print].",
    ),
]
ViewOption = Annotated[
    str | None,
    typer.Option(
        "--view",
        help="Direction preview.png is seen from: front, back, top, side or AZIMUTH,ELEVATION "
        "in degrees, optionally followed by ,x ,y or ,z: the axis up (else --up's) "
        "[default: front, i.e. -60,25].",
    ),
]
UpOption = Annotated[
    str | None,
    typer.Option(
        "--up",
        help="The axis up in preview.png (and the app's view): x, y, z or auto, the one the "
        "mesh stands on (else its format's convention: y for OBJ, PLY and glTF) "
        "[default: auto; export: the design's].",
        show_default=False,
    ),
]
SheetOption = Annotated[
    str | None,
    typer.Option(
        "--sheet",
        help="Sheet size: A4, A3, A2, A1, Letter, Legal or WxH in millimetres (e.g. 600x400). "
        "The PDF is tiled on it [default: A4]; with 'round' the pieces are also split to fit "
        "and placed on sheets of this size.",
    ),
]


def _error(message: str) -> typer.Exit:
    """Print ``message`` as an error on one line (never wrapped); return the exit (code 2)."""
    err_console.print(f"[bold red]error:[/] {escape(message)}", highlight=False, soft_wrap=True)
    return typer.Exit(2)


def _failure(exc: BaseException, debug: bool) -> typer.Exit:
    """The one-line error of a failure; with ``debug`` the traceback of its cause first."""
    if debug:
        cause = exc.__cause__ if isinstance(exc, InternalError) and exc.__cause__ else exc
        traceback.print_exception(cause, file=sys.stderr)
    if isinstance(exc, FilletfoldError):
        return _error(str(exc))
    return _error(f"internal error: {one_line(exc)} (run with --debug for the traceback)")


def _default_out(mesh: str) -> Path:
    return Path("out") / Path(mesh).stem


def _out_folder(out: str | None, mesh: str, force: bool) -> Path:
    """The output folder of ``round``: ``-o`` (an empty path is refused: it would be the
    working folder) or ``out/<mesh name>``, checked for what writing would refuse."""
    from .export.folder import check_design_folder

    if out is not None and not out.strip():
        raise ParameterError("the output folder (-o) is an empty path; name a folder", name="out")
    target = Path(out) if out is not None else _default_out(mesh)
    check_design_folder(target, force=force, inputs=(mesh,))
    return target


#: The options of ``filletfold round`` that are design parameters: option -> field of
#: :class:`~filletfold.parameters.Parameters` (``--no-tabs`` is ``tabs`` negated).
ROUND_PARAMETERS = {
    "radius": "radius",
    "depth": "depth",
    "samples": "samples",
    "arc_step": "arc_step",
    "chord_tol": "chord_tol",
    "clamp": "clamp",
    "material_loss": "material_loss",
    "max_loss": "max_loss",
    "layout": "layout",
    "coplanar_tol": "coplanar_deg",
    "fit_vertices": "fit_vertices",
    "strict": "strict",
    "sharp": "sharp",
    "sheet": "sheet",
    "units": "units",
    "scale": "scale",
    "no_tabs": "tabs",
    "nest": "nest",
    "faces": "faces",
    "edge_length": "edge_length",
    "size": "size",
    "up": "up",
    "max_corners": "max_corners",
    "max_points": "max_points",
    "material": "material",
    "thickness": "thickness",
    "min_bend_radius": "min_bend_radius",
    "k_factor": "k_factor",
}


def _round_parameters(ctx: typer.Context, from_report: Path | None):
    """The :class:`~filletfold.parameters.Parameters` of ``filletfold round`` and the mesh
    its report names (None without ``--from``): the report's parameters (or the defaults),
    with the options given on the command line replacing theirs."""
    from .parameters import Parameters, report_parameters

    base, source = Parameters(), None
    if from_report is not None:
        base, source = report_parameters(from_report)
    given = {}
    for option, name in ROUND_PARAMETERS.items():
        source_of = ctx.get_parameter_source(option)  # click's (or typer's own) enum
        if source_of is not None and source_of.name == "COMMANDLINE":
            value = ctx.params[option]
            given[name] = not value if option == "no_tabs" else value
    if isinstance(given.get("up"), str):
        given["up"] = given["up"].strip().lower()
    if "scale" in given and "size" in given:
        raise ParameterError("give --size or --scale, not both", name="size")
    if "scale" in given:  # a scale given now replaces a size the report had
        given["size"] = None
    if str(given.get("size", "")).strip().lower() == "none":
        given["size"] = None  # a unitless drawing
    return base.replace(**given), source


@app.command("round")
def round_cmd(
    ctx: typer.Context,
    mesh: Annotated[
        str | None,
        typer.Argument(
            help="Mesh file (OBJ, OFF, PLY, STL, glTF/GLB) or the "
            "name of a built-in example (see 'examples'). With --from: the report's mesh "
            "by default.",
            show_default=False,
        ),
    ] = None,
    from_report: Annotated[
        Path | None,
        typer.Option(
            "--from",
            help="Make a design again from its report.json: its mesh and parameters, the "
            "options given here replacing theirs (the same input and options give the same "
            "files).",
        ),
    ] = None,
    out: Annotated[
        str | None,
        typer.Option(
            "-o",
            "--out",
            metavar="<path>",
            help="Output folder [default: out/<mesh name>]. It must be new, empty or hold a "
            "design only (see --force); it is replaced whole.",
        ),
    ] = None,
    force: Annotated[
        bool,
        typer.Option(
            "--force",
            help="Write into an output folder that holds files filletfold did not write "
            "(they are kept, the old design's files replaced).",
        ),
    ] = False,
    radius: Annotated[
        str,
        typer.Option(
            "--radius",
            "-r",
            help="Rounding radius: a length, or a percentage of the mean edge length ('10%').",
        ),
    ] = DEFAULT_RADIUS,
    depth: Annotated[
        str,
        typer.Option(
            "--depth",
            "-d",
            help="Apex depth along the vertex "
            "normal: a length or a percentage of the mean edge "
            "length.",
        ),
    ] = DEFAULT_DEPTH,
    samples: Annotated[
        int,
        typer.Option(
            "--samples",
            "-n",
            min=3,
            help="Most points per arc, both ends included (with --chord-tol 0 and "
            "--arc-step 0: every arc gets this many).",
        ),
    ] = DEFAULT_SAMPLES,
    arc_step: Annotated[
        float,
        typer.Option(
            "--arc-step",
            help="Largest turn between two samples of an arc (degrees): every arc gets at "
            "least one point per step (at most --samples). 0: no limit.",
        ),
    ] = DEFAULT_ARC_STEP,
    chord_tol: Annotated[
        str,
        typer.Option(
            "--chord-tol",
            help="Largest distance between an arc and its chords: a length, or a percentage "
            "of the mean edge length. An arc of radius r turning by t gets "
            "ceil(t / (2 acos(1 - tol / r))) + 1 points (at least 2, at most --samples). "
            "0: no limit.",
        ),
    ] = DEFAULT_CHORD_TOL,
    clamp: Annotated[
        bool | None,
        typer.Option(
            "--clamp/--strict-radius",
            help="Reduce each radius over its edge's limit to 90% of the limit (the default), "
            "or refuse such a radius naming the edge. Fillets narrower than 0.1% of their edge "
            "are left sharp.",
            show_default=False,
        ),
    ] = None,
    fit_vertices: Annotated[
        bool | None,
        typer.Option(
            "--fit-vertices/--no-fit-vertices",
            help="Halve the radii of an infeasible vertex's edges (up to 4 times) where that "
            "makes its cone feasible (the default); off, its reason only says what works.",
            show_default=False,
        ),
    ] = None,
    sharp: Annotated[
        str,
        typer.Option(
            "--sharp",
            help="Which vertices without a cone keep their corner instead of a hole: none, "
            "all, or a comma-separated list of saddle, infeasible, boundary. Their edges to "
            "cones taper into them (conical fillets). Default: all, less boundary with "
            "--material-loss (so the sheet stays one piece).",
            show_default=False,
        ),
    ] = DEFAULT_SHARP,
    strict: Annotated[
        bool,
        typer.Option(
            "--strict",
            help="Refuse instead of repairing or fitting: a defect of the mesh, or a radius "
            "over its edge's limit, stops with the error naming it.",
        ),
    ] = False,
    debug: Annotated[
        bool, typer.Option("--debug", help="On an unforeseen failure, print its traceback.")
    ] = False,
    material_loss: Annotated[
        bool,
        typer.Option(
            "--material-loss",
            help="Choose every radius from the consistent-material-loss linear programme "
            "(paper sec. 4): a developable input then folds from one uncut sheet. --radius is "
            "ignored.",
        ),
    ] = False,
    max_loss: Annotated[
        str | None,
        typer.Option(
            "--max-loss",
            help="With --material-loss: cap on each edge's material loss (a length or a "
            "percentage of the mean edge length).",
        ),
    ] = None,
    layout: Annotated[
        str,
        typer.Option(
            "--layout",
            help="'modules' (one piece per vertex), 'net' (modules joined into few pieces), "
            "'sheet' (all glued into one uncut sheet; fails if they do not fit) or 'auto' (the "
            "sheet with --material-loss when possible, else nets).",
        ),
    ] = "auto",
    coplanar_tol: Annotated[
        float,
        typer.Option(
            "--coplanar-tol", help="Merge neighbouring faces within this angle (degrees)."
        ),
    ] = tol.coplanar_deg,
    max_corners: Annotated[
        int,
        typer.Option(
            "--max-corners",
            metavar="<int>",
            help="The most corners a face may have; a larger face is refused before anything "
            "is solved (time grows about with the square of a face's corners).",
        ),
    ] = DEFAULT_MAX_CORNERS,
    max_points: Annotated[
        int,
        typer.Option(
            "--max-points",
            metavar="<int>",
            help="The most crease-pattern points the design may be estimated at (64 + 4 per "
            "sample, per edge); more is refused before anything is solved.",
        ),
    ] = DEFAULT_MAX_POINTS,
    faces: Annotated[
        int | None,
        typer.Option(
            "--faces",
            min=4,
            help="Coarsen the mesh to about this many triangles before rounding (quadric "
            "decimation; the summary and report.json give how far the surface moved). A scan "
            "of 100,000 triangles otherwise gives tens of thousands of pieces.",
            show_default=False,
        ),
    ] = None,
    edge_length: Annotated[
        str | None,
        typer.Option(
            "--edge-length",
            help="Coarsen instead to triangles of about this side: a length, or N% of the "
            "mean edge length (300% for edges three times as long); not with --faces.",
            show_default=False,
        ),
    ] = None,
    dry_run: Annotated[
        bool, typer.Option("--dry-run", help="Solve and print the summary, write nothing.")
    ] = False,
    quiet: Annotated[
        bool, typer.Option("--quiet", "-q", help="Print only errors and the output folder.")
    ] = False,
    formats: FormatOption = None,
    units: UnitsOption = "",
    scale: ScaleOption = None,
    size: Annotated[
        str | None,
        typer.Option(
            "--size",
            help="The object's size: its mesh's largest side becomes this long (300mm, 30cm, "
            "12in; a bare number is mm). Sets --units (the size's unit unless given) and "
            "--scale for the cut files and sheets; not with --scale. Default (auto): the "
            "least size at which every label is 2 mm high and every piece spans 3 mm (at "
            "least 100 mm), printed in the summary; with --units or --scale, none (the mesh "
            "is in those units); 'none': a unitless drawing.",
            show_default=False,
        ),
    ] = None,
    material: Annotated[
        str | None,
        typer.Option(
            "--material",
            help="The sheet material ('filletfold materials' lists them: card-300gsm, "
            "aluminium-1mm, plywood-3mm...): no fillet is made tighter than it bends (its "
            "least inner bend radius plus half its thickness) at the design's size; with "
            "--size, tighter fillets are widened or the least size is named; by default the "
            "size grows until they hold.",
            show_default=False,
        ),
    ] = None,
    thickness: Annotated[
        float | None,
        typer.Option(
            "--thickness",
            help="The sheet's thickness in mm (overrides the material's).",
            show_default=False,
        ),
    ] = None,
    min_bend_radius: Annotated[
        float | None,
        typer.Option(
            "--min-bend-radius",
            help="The least inner bend radius in mm (overrides the material's).",
            show_default=False,
        ),
    ] = None,
    k_factor: Annotated[
        float | None,
        typer.Option(
            "--k-factor",
            help="The neutral axis's distance from the inner surface over the thickness, 0-1 "
            "(overrides the material's).",
            show_default=False,
        ),
    ] = None,
    sheet: SheetOption = None,
    preset: PresetOption = None,
    view: ViewOption = None,
    up: UpOption = None,
    no_tabs: Annotated[
        bool, typer.Option("--no-tabs", help="No glue tabs, seam labels or part numbers.")
    ] = False,
    nest: Annotated[
        str,
        typer.Option(
            "--nest",
            help="How pieces are placed on --sheet sheets: 'shelf' (rows of bounding "
            "rectangles), 'sparrow' (the irregular nester, needs the 'nest' extra; "
            "'sparrow:S' searches S seconds per packing run, which is not byte-reproducible) "
            "or 'auto' (sparrow when installed, else shelf).",
        ),
    ] = "shelf",
    report_tables: Annotated[
        bool,
        typer.Option(
            "--report-tables",
            help="Write the per-element tables (mesh, edges, vertices) into report.json too; "
            "without it the report is a summary.",
        ),
    ] = False,
):
    """Round every edge and vertex of MESH; write the design into the output folder.

    Writes design.fold (crease pattern + folded form + the mesh's data), report.json (a
    summary, with timings.json beside it), folded.obj and pattern.svg, all or nothing;
    --format all adds every other format
    (simulator.fold and simulator.svg for Origami Simulator, pattern.dxf, pattern.pdf,
    pattern.png and preview.png, the 3dm, glb, ply and stl files). Every file but
    timings.json has the same bytes for the same input and options.
    """
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from .design import round_mesh
    from .export.cutfiles import DEFAULT_FORMATS, parse_formats
    from .export.outputs import export_design

    try:
        params, source = _round_parameters(ctx, from_report)
        if mesh is None:
            if source is None:
                raise _error("give MESH (a mesh file or a built-in example) or --from REPORT")
            mesh = source
        chosen = parse_formats(formats if formats is not None else DEFAULT_FORMATS)
        # check units, scale, page, preset and view before the (slow) design
        _check_export_options(params.units, params.scale, params.sheet, preset, view)
    except FilletfoldError as exc:
        raise _error(str(exc)) from None
    try:  # the output folder is checked before the (slow) design
        target = _out_folder(out, mesh, force)
    except FilletfoldError as exc:
        raise _error(str(exc)) from None
    try:
        log = StageLog(err_console) if not quiet and not err_console.is_terminal else None
        with (
            Progress(
                TextColumn("{task.description}"),
                BarColumn(),
                TimeElapsedColumn(),
                console=err_console,
                transient=True,
                disable=quiet or log is not None,
            ) as bar,
            watching_stages(log.stage if log is not None else None),
        ):
            tasks = {}

            def progress(stage, done, total):
                if log is not None:
                    log.progress(stage, done, total)
                    return
                if stage not in tasks:
                    tasks[stage] = bar.add_task(stage, total=total)
                bar.update(tasks[stage], completed=done)

            design = round_mesh(
                mesh,
                params,
                progress=progress,
                keep_stages=False,  # nothing is reused: let frames and modules go early
            )
            if log is not None:
                log.close()
        if not quiet:
            console.print(design.summary(), highlight=False, soft_wrap=True)
        if dry_run:
            if log is not None:
                log.finish()
            return
        if log is not None:
            log.stage("writing the files")
        written = export_design(
            design,
            target,
            formats=chosen,  # at the design's units and scale (with a size, those it gave)
            preset=preset,
            view=view,
            tables=report_tables,
            force=force,
        )
        if log is not None:
            log.finish()
    except typer.Exit:
        raise
    except Exception as exc:  # every failure is one line; --debug adds the traceback
        raise _failure(exc, debug) from None
    console.print(f"wrote {len(written)} files to {target}/", highlight=False)
    if design.certificate is not None and not design.certificate.ok:
        names = ", ".join(c.name for c in design.certificate.failed)
        raise _error(f"the design fails its certificate ({names}): see report.json")


class StageLog:
    """Progress as lines, for a log (stderr not a terminal: CI, a pipe, the app's server):
    one line per stage of the pipeline when it ends, with its seconds and the last count it
    reported (``filletfold: apices 1598/1598 in 6.1 s``).

    Lines are held for the first :attr:`DELAY` seconds of the run: a run that fails at once
    (a bad option, an unreadable mesh) prints its one-line error and nothing else; a run that
    succeeds prints them all at the end (:meth:`finish`)."""

    DELAY = 2.0

    def __init__(self, out: Console):
        self.out = out
        self.name: str | None = None
        self.start = 0.0
        self.counts: dict = {}
        self.born = time.perf_counter()
        self.held: list[str] | None = []

    def stage(self, name) -> None:
        """A stage begins (:func:`filletfold.errors.stage`): the last one ends."""
        self.close()
        self.name, self.start, self.counts = name, time.perf_counter(), {}

    def progress(self, what: str, done: int, total: int) -> None:
        """A count within the stage (the pipeline's ``progress`` callback)."""
        if self.name is None:
            self.stage(what)
        self.counts[what] = (done, total)

    def close(self) -> None:
        """End the running stage with its line."""
        if self.name is None:
            return
        seconds = time.perf_counter() - self.start
        counts = "".join(f", {w} {d}/{n}" for w, (d, n) in self.counts.items() if w != self.name)
        own = self.counts.get(self.name)
        head = self.name + (f" {own[0]}/{own[1]}" if own else "")
        self.name = None
        self._say(f"filletfold: {head}{counts} in {seconds:.1f} s")

    def finish(self) -> None:
        """The run succeeded: end the running stage and print every line held."""
        self.close()
        self.born = -float("inf")
        self._say(None)

    def _say(self, line: str | None) -> None:
        if self.held is not None:
            if line is not None:
                self.held.append(line)
            if time.perf_counter() - self.born < self.DELAY:
                return
            lines, self.held = self.held, None
        else:
            lines = [] if line is None else [line]
        for text in lines:
            self.out.print(text, highlight=False, markup=False, soft_wrap=True)


def _check_export_options(
    units: str, scale, sheet: str | None, preset=None, view: str | None = None
) -> None:
    """Raise the ParameterError that writing would raise for ``units``, ``scale``, ``sheet``,
    ``preset`` or ``view``."""
    from .export.dxf import check_scale
    from .export.png import parse_view
    from .export.presets import get_preset
    from .units import check_units, sheet_size_mm

    if view is not None:
        parse_view(view)
    check_units(units, unitless=True)
    if scale is not None:
        check_scale(scale)
    if sheet is not None:
        sheet_size_mm(sheet)
    get_preset(preset)


@app.command("export")
def export_cmd(
    folder: Annotated[
        Path, typer.Argument(help="A design folder written by 'filletfold round' (design.fold).")
    ],
    formats: FormatOption = "dxf,pdf,svg,png",
    units: UnitsOption = "",
    scale: ScaleOption = None,
    sheet: SheetOption = None,
    preset: PresetOption = None,
    view: ViewOption = None,
    up: UpOption = None,
):
    """Write cut files and pictures of the design in FOLDER (read from FOLDER/design.fold).

    Formats: dxf (pattern.dxf), pdf (pattern.pdf, tiled at true scale, and assembly.pdf, the
    assembly guide, for a design with glue tabs), svg (pattern.svg), png
    (pattern.png and preview.png), simulator (simulator.fold and simulator.svg, for Origami
    Simulator), obj (folded.obj), 3dm (pattern.3dm, folded.3dm), glb, ply, stl (folded.glb,
    .ply, .stl); all of them with --format all. The files are written into
    FOLDER, all or nothing. Without --units and --scale, at the design's size, and without
    --up, with the design's up (both from FOLDER/report.json, when it has them).
    """
    from .export import write_outputs
    from .export.cutfiles import cut_files, parse_formats
    from .export.fold_read import read_fold
    from .export.png import parse_view

    try:
        spec = formats if formats is not None else "dxf,pdf,svg,png"
        every = parse_formats("all") if spec.strip().lower() == "all" else None
        chosen = (
            parse_formats(spec) if every is None else tuple(f for f in every if f in EXPORT_FORMATS)
        )
        bad = [f for f in chosen if f not in EXPORT_FORMATS]
        if bad:
            raise _error(
                f"format {bad[0]} cannot be written from design.fold (export writes "
                f"{', '.join(EXPORT_FORMATS)}; use 'filletfold round' for fold and json)"
            )
        _check_export_options(units, scale, sheet, preset, view)
        if not folder.is_dir():
            raise _error(f"{folder}: no such folder (write a design with 'filletfold round')")
        source = folder / "design.fold"
        if not source.is_file():
            raise _error(f"{source}: no design.fold in {folder} (write it with 'filletfold round')")
        pattern = read_fold(source)
        made = _made_with(folder / "report.json")
        if not units and scale is None:  # at the design's size
            units, scale = made.get("units", ""), made.get("scale")
        up = (up or made.get("up") or "z").strip().lower()
        if up not in ("x", "y", "z"):
            raise ParameterError(f"up must be 'x', 'y' or 'z', got {up!r}", name="up")
        files = cut_files(
            pattern,
            chosen,
            units=units,
            scale=scale,
            page=sheet or "A4",
            preset=preset,
            view=parse_view("front" if view is None else view, up),
        )
        seams = pattern.annotations.seams  # from annotations.json: the assembly guide too
        if "pdf" in chosen and seams is not None and len(seams):
            from .export.assembly import assembly_pdf

            files["assembly.pdf"] = assembly_pdf(pattern, seams, up=up, page=sheet or "A4")
        written = write_outputs(folder, files)
    except FilletfoldError as exc:
        raise _error(str(exc)) from None
    console.print(
        f"wrote {len(written)} files to {folder}/: {', '.join(p.name for p in written)}",
        highlight=False,
    )


def _made_with(path: Path) -> dict:
    """The drawing ``units`` and ``scale`` and the ``up`` axis a design's ``report.json``
    gives (those it has, of the right types; none when it cannot be read)."""
    from .export.fold_read import load_json

    try:
        doc = load_json(path, "a filletfold report")
    except FilletfoldError:
        return {}
    out = {}
    params = doc.get("parameters") if isinstance(doc, dict) else None
    if isinstance(params, dict):
        if isinstance(params.get("units"), str):
            out["units"] = params["units"]
        scale = params.get("scale")
        if isinstance(scale, int | float) and not isinstance(scale, bool):
            out["scale"] = float(scale)
    up = doc.get("up") if isinstance(doc, dict) else None
    if isinstance(up, dict) and isinstance(up.get("axis"), str):
        out["up"] = up["axis"]
    return out


@app.command("check")
def check_cmd(
    folder: Annotated[
        Path,
        typer.Argument(
            help="A design folder written by 'filletfold round' (design.fold and report.json)."
        ),
    ],
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the certificate as JSON instead of lines.")
    ] = False,
):
    """Check that the design in FOLDER is valid: measure its invariants again from its files.

    One line per invariant (name, measured figure, limit, ok/FAIL, what was measured): ruling
    isometry, contraction, points on their planes and cylinders, M/V signs and fold angles, no
    overlap, face orientation, smallest edge (and the smallest face angle, for information).
    Exit code 0 when every invariant holds, 1 when one fails, 2 when the files cannot be read.
    """
    import json

    from .check import check_folder

    try:
        certificate = check_folder(folder)
    except FilletfoldError as exc:
        typer.echo(f"error: {exc}", err=True)  # one line, never wrapped
        raise typer.Exit(2) from None
    if as_json:
        typer.echo(json.dumps(certificate.as_dict(), indent=2))
    else:
        typer.echo("\n".join(certificate.summary()))
    raise typer.Exit(0 if certificate.ok else 1)


@app.command("app")
def app_cmd(
    mesh: Annotated[
        str, typer.Argument(help="Mesh file or built-in example name to open first.")
    ] = "icosahedron",
    port: Annotated[int, typer.Option("--port", help="Port to serve on (0: a free one).")] = 0,
    host: Annotated[
        str, typer.Option("--host", help="Address to bind (default: this machine only).")
    ] = "127.0.0.1",
    open_browser: Annotated[
        bool, typer.Option("--open", help="Open the page in the default browser.")
    ] = False,
    allow_remote: Annotated[
        bool,
        typer.Option(
            "--allow-remote",
            help="Let --host be an address other machines reach (whoever reaches the app can "
            "drive it and upload files to it); without it such an address is refused.",
        ),
    ] = False,
):
    """Start the browser app (needs the 'app' extra: pip install 'filletfold[app]').

    Prints the page's address and runs until Ctrl-C.
    """
    from .app.server import run_app

    try:  # the port, as the host, checked by run_app (app/bind.py)
        server = run_app(
            mesh, host=host, port=port, open_browser=open_browser, allow_remote=allow_remote
        )
    except FilletfoldError as exc:
        raise _error(str(exc)) from None
    console.print(f"filletfold app at {server.url}  (Ctrl-C to stop)", highlight=False)
    if allow_remote and server.remote:
        err_console.print(
            f"warning: the app at {server.url} is open to other machines: whoever reaches "
            "this address can drive it and upload files to it",
            highlight=False,
        )
    server.wait()


@app.command("hops")
def hops_cmd(
    port: Annotated[
        int, typer.Option("--port", help="Port to serve on (0: a free one; Hops' own is 5000).")
    ] = 5000,
    host: Annotated[
        str,
        typer.Option(
            "--host",
            help="Address to bind: this machine only (127.0.0.1, ::1 or localhost); another "
            "is refused.",
        ),
    ] = "127.0.0.1",
):
    """Serve the Grasshopper Hops components Round and Pattern (needs the 'hops' extra: pip
    install 'filletfold[hops]').

    In Grasshopper, give a Hops component the printed address followed by round or pattern
    (http://127.0.0.1:5000/round). Prints a line per request and runs until Ctrl-C.
    """
    from .hops.server import run_hops

    def say(line: str) -> None:
        err_console.print(line, highlight=False, soft_wrap=True, markup=False)

    try:
        server = run_hops(host=host, port=port, say=say)
    except FilletfoldError as exc:
        raise _error(str(exc)) from None
    console.print(
        f"filletfold hops at {server.url}  (components: {server.url}round, {server.url}pattern;"
        " Ctrl-C to stop)",
        highlight=False,
        soft_wrap=True,
    )
    server.wait()


def main(argv: list[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); return the exit code.

    Python warnings (a numerical library's RuntimeWarning) go to the ``py.warnings`` logger,
    shown only with ``--debug``: what a user reads is the summary and one-line errors.
    """
    limit_arenas(2)  # threads share the allocator's arenas: a lower peak (filletfold.memory)
    logging.captureWarnings(True)
    if "--debug" in (sys.argv[1:] if argv is None else argv):
        logging.basicConfig(level=logging.WARNING, format="%(name)s: %(message)s")
    else:  # a handler that drops them (else logging's last resort prints them)
        logging.getLogger("py.warnings").addHandler(logging.NullHandler())
    try:
        app(args=argv, prog_name="filletfold", standalone_mode=True)
    except SystemExit as exc:
        return int(exc.code or 0) if not isinstance(exc.code, str) else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
