"""The ``filletfold`` command line: a thin front end over the library.

Commands
--------
``filletfold examples``
    List the built-in meshes.
``filletfold round MESH [-o OUT] [--radius R] [--depth D] [--samples N] [--coplanar-tol DEG]``
    Round a mesh (file or built-in name) and write ``design.fold``, ``report.json``,
    ``folded.obj`` and ``pattern.svg`` into ``OUT``.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from . import __version__
from .design import DEFAULT_DEPTH, DEFAULT_RADIUS, DEFAULT_SAMPLES, round_mesh
from .errors import FilletfoldError
from .tolerances import tol

app = typer.Typer(
    name="filletfold",
    help="Turn a polyhedral mesh into a curved-crease folded design (rounded edges, conical "
    "vertices) and the flat pieces to cut and fold.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
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
    from .mesh import EXAMPLES, example_mesh

    table = Table("name", "vertices", "faces", "kind", "description")
    for name, ex in EXAMPLES.items():
        v, f = example_mesh(name)
        table.add_row(name, str(len(v)), str(len(f)), ", ".join(ex.kinds), ex.description)
    console.print(table)


def _default_out(mesh: str) -> Path:
    return Path("out") / Path(mesh).stem


@app.command("round")
def round_cmd(
    mesh: Annotated[
        str,
        typer.Argument(
            help="Mesh file (OBJ, OFF, PLY, STL, glTF/GLB) or the "
            "name of a built-in example (see 'examples')."
        ),
    ],
    out: Annotated[
        Path | None, typer.Option("-o", "--out", help="Output folder [default: out/<mesh name>].")
    ] = None,
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
        int, typer.Option("--samples", "-n", min=3, help="Points per cylinder arc.")
    ] = DEFAULT_SAMPLES,
    clamp: Annotated[
        bool,
        typer.Option(
            "--clamp",
            help="Reduce each radius over its edge's "
            "limit to 90% of the limit instead of stopping.",
        ),
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
            help="'modules' (one piece per vertex), 'sheet' (all glued into one sheet; fails "
            "if they do not fit) or 'auto' (the sheet when possible).",
        ),
    ] = "auto",
    coplanar_tol: Annotated[
        float,
        typer.Option(
            "--coplanar-tol", help="Merge neighbouring faces within this angle (degrees)."
        ),
    ] = tol.coplanar_deg,
    dry_run: Annotated[
        bool, typer.Option("--dry-run", help="Solve and print the summary, write nothing.")
    ] = False,
    quiet: Annotated[
        bool, typer.Option("--quiet", "-q", help="Print only errors and the output folder.")
    ] = False,
):
    """Round every edge and vertex of MESH; write the design into the output folder.

    Writes design.fold (crease pattern + folded form), report.json, folded.obj and pattern.svg,
    all or nothing.
    """
    target = out if out is not None else _default_out(mesh)
    try:
        with Progress(
            TextColumn("{task.description}"),
            BarColumn(),
            TimeElapsedColumn(),
            console=err_console,
            transient=True,
            disable=quiet,
        ) as bar:
            tasks = {}

            def progress(stage, done, total):
                if stage not in tasks:
                    tasks[stage] = bar.add_task(stage, total=total)
                bar.update(tasks[stage], completed=done)

            design = round_mesh(
                mesh,
                radius=radius,
                depth=depth,
                samples=samples,
                clamp=clamp,
                material_loss=material_loss,
                max_loss=max_loss,
                layout=layout,
                coplanar_deg=coplanar_tol,
                progress=progress,
            )
        if not quiet:
            console.print(design.summary(), highlight=False)
        if dry_run:
            return
        written = design.export(target)
    except FilletfoldError as exc:
        err_console.print(f"[bold red]error:[/] {exc}", highlight=False)
        raise typer.Exit(2) from None
    console.print(f"wrote {len(written)} files to {target}/", highlight=False)


def main(argv: list[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); return the exit code."""
    try:
        app(args=argv, prog_name="filletfold", standalone_mode=True)
    except SystemExit as exc:
        return int(exc.code or 0) if not isinstance(exc.code, str) else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
