"""The parameters of a design: one frozen :class:`Parameters`, the single source.

The command line, the browser app and the Python API build a :class:`Parameters`;
:func:`~filletfold.design.round_mesh` takes one (or its fields as keywords); the design keeps it
resolved (:meth:`Parameters.resolved`) as ``design.params``; ``report.json`` writes it under
``parameters`` (:meth:`Parameters.as_dict`), and :meth:`Parameters.from_dict` reads it back, so
that a design can be made again from its report (``filletfold round --from report.json``).

A module of its own, light to import (numpy at most, the rooms only when checking), so that
the command line can build one before the pipeline is loaded.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, fields

from .defaults import (
    DEFAULT_ARC_STEP,
    DEFAULT_CHORD_TOL,
    DEFAULT_DEPTH,
    DEFAULT_MAX_CORNERS,
    DEFAULT_MAX_POINTS,
    DEFAULT_RADIUS,
    DEFAULT_SAMPLES,
    DEFAULT_SHARP,
    MAX_SAMPLES,
)
from .errors import ParameterError
from .tolerances import tol
from .units import AUTO_SIZE

__all__ = [
    "Parameters",
    "parse_length",
    "report_parameters",
    "resolve_chord_tol",
    "resolve_depth",
    "unsettled",
]

#: The JSON types each field of :class:`Parameters` may take in a report (``number`` is an int
#: or a float, never a bool).
_JSON_TYPES = {
    "radius": ("number", "string", "list"),
    "depth": ("number", "string", "list", "dict"),
    "samples": ("integer",),
    "arc_step": ("number",),
    "chord_tol": ("number", "string"),
    "clamp": ("bool", "null"),
    "material_loss": ("bool",),
    "max_loss": ("number", "string", "list", "null"),
    "layout": ("string",),
    "coplanar_deg": ("number",),
    "fit_vertices": ("bool", "null"),
    "strict": ("bool",),
    "sharp": ("string", "null"),
    "sheet": ("string", "null"),
    "units": ("string",),
    "scale": ("number", "null"),
    "tabs": ("bool",),
    "nest": ("string",),
    "faces": ("integer", "null"),
    "edge_length": ("number", "string", "null"),
    "size": ("number", "string", "null"),
    "up": ("string",),
    "max_corners": ("integer",),
    "max_points": ("integer",),
    "material": ("string", "null"),
    "thickness": ("number", "null"),
    "min_bend_radius": ("number", "null"),
    "k_factor": ("number", "null"),
}


@dataclass(frozen=True)
class Parameters:
    """The parameters of a design (as given; :meth:`resolved` fills in what ``strict`` and
    ``material_loss`` decide).

    Attributes
    ----------
    radius : float, str or (n_edges,) float
        Rounding radius: absolute, ``"10%"`` of the mean edge length, or per edge (in the
        order of the cleaned mesh's ``edges``). With ``material_loss``, the largest radius any
        edge may get.
    depth : float, str, (n_vertices,) float or dict
        Apex depth ``d`` along the vertex normal (``P = U + d D``): absolute, a percentage of
        the mean edge length, per vertex, or ``{"default": ..., vertex: value}``.
    samples : int
        Most points per arc, both ends included (>= 3). With ``chord_tol`` and ``arc_step``
        both 0, every arc gets this many.
    arc_step : float
        Largest turn between two samples of an arc, in degrees (0: no limit): an arc gets at
        least one point per ``arc_step`` it turns (and at least 2), at most ``samples``; the
        relative 2D - 3D mismatch of a chord grows with the square of its turn, which an
        absolute ``chord_tol`` alone leaves large on small fillets (a fillet of 10 % of the
        edge gets a point every 5.1 degrees from the default tolerance, one of 1 % every 16
        degrees: the step bounds it to 10). A finer step gives larger files at a smaller
        mismatch. It is also the design's facet limit: no two neighbouring triangles of a
        cone fold by more than it.
    chord_tol : float or str
        Largest distance between a chord of an arc and the arc: absolute, or a percentage of
        the mean edge length. An arc of radius ``r`` turning by ``2 gamma`` gets
        ``ceil(2 gamma / (2 acos(1 - chord_tol / r))) + 1`` points (at least 2, at most
        ``samples``; a conical fillet counts with twice its midpoint radius, the most it
        reaches on a module), so that the files grow with the curvature the geometry has, not
        with the number of edges. 0: no limit (see ``arc_step``).
    clamp : bool or None
        Reduce radii over their edge's limit to 90 % of it
        (:func:`~filletfold.rounding.edges.clamp_radii`) instead of refusing them. None: on,
        off with ``strict``.
    material_loss : bool
        Choose every edge's radius from the consistent-material-loss linear programme (sec.
        4, :func:`~filletfold.rounding.material_loss.solve_material_loss`). On a developable
        input the rounded development of every interior vertex closes, so the design folds
        from one uncut sheet.
    max_loss : float, str or None
        Upper bound on each edge's material loss (a length or a percentage of the mean edge
        length), with ``material_loss``.
    layout : {"auto", "modules", "net", "sheet"}
        ``"modules"``: one piece per vertex, side by side. ``"net"``: modules joined into as
        few non-overlapping pieces as found (each cone keeps its cut). ``"sheet"``: all
        modules glued into one uncut sheet (needs every vertex's development to close; raises
        otherwise). ``"auto"``: the sheet when it can be made (with ``material_loss``), else
        nets.
    coplanar_deg : float
        Merge neighbouring faces whose normals differ by less than this (degrees).
    fit_vertices : bool or None
        When a cone vertex is infeasible, halve the radii of its edges (up to four times) and
        keep them where that makes its cone feasible (:mod:`filletfold.vertex.rescue`); off,
        the radius that would work is only given in its reason. None: on, off with ``strict``.
    strict : bool
        Refuse instead of repairing: a defect of the mesh raises the error that names it
        (:func:`~filletfold.mesh.clean.clean_mesh`), and ``clamp`` and ``fit_vertices``
        default to off.
    sharp : str
        Which vertices without a cone keep their corner instead of a hole
        (:mod:`filletfold.vertex.sharpen`): ``"none"``, ``"all"`` or a comma-separated list of
        ``saddle``, ``infeasible`` (a developable vertex that does not close counts as
        infeasible) and ``boundary``. Their edges to vertices with a cone become conical
        fillets, those between two of them straight creases. ``"auto"``: all three, except
        ``boundary`` with ``material_loss`` (a conical fillet would open the neighbour's closed
        development, and the sheet would no longer be one piece).
    sheet : str or None
        Size of the material sheets (``"A4"``, ``"A3"``, ``"A2"``, ``"A1"``, ``"Letter"``,
        ``"Legal"`` or ``"WIDTHxHEIGHT"`` in mm): nets are split to fit and the pieces are
        placed on as few sheets as found.
    units : str
        One pattern unit is ``scale`` ``units`` on the sheet (``mm``, ``cm``, ``m``, ``in``);
        ``""``: unitless drawings (sheets are then read in mm).
    scale : float or None
        Drawing units per pattern unit (None: 1, and a PDF without ``units`` is fitted to its
        page).
    tabs : bool
        Add a glue tab and two matching labels to every cut border, and part numbers.
    nest : str
        How the pieces are placed on the sheets: ``"shelf"`` (rows of bounding rectangles),
        ``"sparrow"`` (the irregular nester of the ``nest`` extra, ``"sparrow:S"`` for S seconds
        per packing run; needs ``sheet``) or ``"auto"`` (sparrow when installed and ``sheet`` is
        given, else the shelves). See :mod:`filletfold.layout.nest`.
    faces : int or None
        Coarsen the mesh to about this many triangles before it is rounded (quadric
        decimation, :func:`~filletfold.mesh.coarsen.coarsen_mesh`): a scan of 100,000
        triangles otherwise gives tens of thousands of pieces. The design reports how far the
        surface moved (``coarsening``). None: the mesh as it is.
    edge_length : float, str or None
        Coarsen instead to the count of equilateral triangles of this side (a length, or
        ``"300%"`` of the mean edge length) that cover the mesh's area
        (:func:`~filletfold.mesh.coarsen.coarse_target`); not with ``faces``.
    size : str, float or None
        The physical size of the object: its mesh's largest bounding-box side becomes this
        length (``"300mm"``, ``"30cm"``, ``"12in"``; a bare number is mm,
        :func:`~filletfold.units.parse_size`). The design then has ``units`` (the size's unit
        unless given) and ``scale`` derived from it (:func:`sized`): the cut files and sheets
        are at that size. ``"auto"`` (the default): the least size, in millimetres, at which
        every label is 2 mm high and every piece spans 3 mm (at least 100 mm; on sheets,
        the labels' size: :func:`~filletfold.layout.arrange.default_size`); ``design.params``
        then holds the size chosen (``"620mm"``). Given ``units`` or ``scale``, ``"auto"``
        is no size: the mesh is in those units. None: no size, a unitless drawing unless
        ``units`` are given.
    up : str
        The axis up in the pictures and the app's view (``"x"``, ``"y"``, ``"z"``), or
        ``"auto"``: the one the mesh stands on (:func:`~filletfold.mesh.upright.up_axis`);
        ``design.up`` is the axis used.
    max_corners : int
        The most corners a face of the mesh (as cleaned and coarsened) may have; a larger
        face is refused with its index before anything is solved (a face's corners cost
        time about quadratic in their number: a prism of two 256-gons takes 7 s, one
        10,000-gon filled 24 GB). ``faces`` triangulates and coarsens a mesh instead.
    max_points : int
        The most crease-pattern points the design (of the mesh as cleaned and coarsened) may
        be estimated at before it is solved (``64 + 4 * samples`` per edge, an upper
        estimate); more is refused at once, naming ``--faces`` and ``--samples``.
    material : str or None
        The sheet material (:data:`~filletfold.materials.MATERIALS`: ``"card-300gsm"``,
        ``"aluminium-1mm"``...; None: paper of no thickness that bends to any radius). Every
        fillet is then at least the material's bend floor (its least inner bend radius plus
        half its thickness) at the design's size: with ``size`` given, fillets below it are
        raised (an edge whose limit is below it is refused, naming the least size that
        holds it); with the default size, the size grows until every fillet holds it.
    thickness, min_bend_radius, k_factor : float or None
        Overrides of the material's figures (millimetres; the k-factor is the neutral axis's
        distance from the inner surface over the thickness); without ``material`` they
        describe a sheet of their own.
    """

    radius: object = DEFAULT_RADIUS
    depth: object = DEFAULT_DEPTH
    samples: int = DEFAULT_SAMPLES
    arc_step: float = DEFAULT_ARC_STEP
    chord_tol: object = DEFAULT_CHORD_TOL
    clamp: bool | None = None
    material_loss: bool = False
    max_loss: object = None
    layout: str = "auto"
    coplanar_deg: float = tol.coplanar_deg
    fit_vertices: bool | None = None
    strict: bool = False
    sharp: str | None = DEFAULT_SHARP
    sheet: str | None = None
    units: str = ""
    scale: float | None = None
    tabs: bool = True
    nest: str = "shelf"
    faces: int | None = None
    edge_length: object = None
    size: object = "auto"
    up: str = "auto"
    max_corners: int = DEFAULT_MAX_CORNERS
    max_points: int = DEFAULT_MAX_POINTS
    material: str | None = None
    thickness: float | None = None
    min_bend_radius: float | None = None
    k_factor: float | None = None

    # -- building ---------------------------------------------------------------------------
    def replace(self, **changes) -> Parameters:
        """A copy with ``changes`` (field names as keywords).

        A value that followed ``strict`` (``clamp``, ``fit_vertices``) or ``material_loss``
        (``sharp``) in this one follows the new value, unless it is given too: a report's
        resolved parameters re-run with ``strict`` changed behave as a fresh run would.

        Raises
        ------
        ParameterError
            For a name that is not a parameter.
        """
        names = [f.name for f in fields(self)]
        for key in changes:
            if key not in names:
                raise ParameterError(
                    f"unknown parameter {key!r}: choose from {', '.join(names)}", name=key
                )
        if "strict" in changes and bool(changes["strict"]) != bool(self.strict):
            for key in ("clamp", "fit_vertices"):
                if key not in changes and getattr(self, key) is (not self.strict):
                    changes[key] = None
        if (
            "material_loss" in changes
            and bool(changes["material_loss"]) != bool(self.material_loss)
            and "sharp" not in changes
            and self.sharp == _sharp_text(_auto_kinds(self.material_loss))
        ):
            changes["sharp"] = DEFAULT_SHARP
        return dataclasses.replace(self, **changes)

    @classmethod
    def from_dict(cls, data, where: str = "parameters") -> Parameters:
        """The parameters a report wrote (:meth:`as_dict`): lists become arrays, keys missing
        (a report of an older version) keep their defaults.

        Raises
        ------
        ParameterError
            Naming ``where`` and the key, for a key that is not a parameter or a value of
            the wrong type.
        """
        import numpy as np

        if not isinstance(data, dict):
            raise ParameterError(f"{where} must be a JSON object, got {_json_type(data)}")
        values = {}
        for key, value in data.items():
            if key not in _JSON_TYPES:
                raise ParameterError(
                    f"{where}: unknown parameter {key!r}: choose from {', '.join(_JSON_TYPES)}",
                    name=str(key),
                )
            kind = _json_type(value)
            if kind not in _JSON_TYPES[key] and not (
                kind == "integer" and "number" in _JSON_TYPES[key]
            ):
                raise ParameterError(
                    f"{where}: {key} must be {' or '.join(_JSON_TYPES[key])}, got {kind}",
                    name=key,
                )
            if kind == "list":
                try:
                    value = np.asarray(value, dtype=float)
                except (TypeError, ValueError):
                    raise ParameterError(
                        f"{where}: {key} must be a list of numbers", name=key
                    ) from None
                if value.ndim != 1:
                    raise ParameterError(f"{where}: {key} must be a flat list of numbers", name=key)
            values[key] = value
        return cls(**values)

    # -- reading ----------------------------------------------------------------------------
    def check(self) -> None:
        """Refuse a bad parameter before any work, naming it (the radius and depth are
        checked against the mesh, whose mean edge length their percentages need).

        Raises
        ------
        ParameterError
        """
        import numpy as np

        from .layout.fabrication import sheet_in_pattern_units
        from .layout.nest import choose_nester
        from .vertex.sharpen import parse_sharp

        samples, arc_step = self.samples, self.arc_step
        if isinstance(samples, bool) or not isinstance(samples, int | np.integer) or samples < 3:
            raise ParameterError(
                f"samples must be an integer >= 3, got {samples!r}", name="samples"
            )
        if samples > MAX_SAMPLES:
            raise ParameterError(
                f"samples must be at most {MAX_SAMPLES} points per arc, got {samples} (the "
                "check's memory grows with their square: 1000 took 3.9 GB on a cube)",
                name="samples",
            )
        corners = self.max_corners
        if isinstance(corners, bool) or not isinstance(corners, int | np.integer) or corners < 3:
            raise ParameterError(
                f"max corners must be an integer >= 3, got {corners!r}", name="max_corners"
            )
        points = self.max_points
        if isinstance(points, bool) or not isinstance(points, int | np.integer) or points < 1:
            raise ParameterError(
                f"max points must be an integer >= 1, got {points!r}", name="max_points"
            )
        if isinstance(arc_step, bool) or not isinstance(arc_step, int | float | np.number):
            raise ParameterError(
                f"arc step must be a number of degrees, got {arc_step!r}", name="arc_step"
            )
        if not (np.isfinite(arc_step) and 0 <= arc_step <= 180):
            raise ParameterError(
                f"arc step must be in [0, 180] degrees (0: no limit), got {arc_step!r}",
                name="arc_step",
            )
        if self.layout not in ("auto", "modules", "net", "sheet"):
            raise ParameterError(
                f"layout must be 'auto', 'modules', 'net' or 'sheet', got {self.layout!r}",
                name="layout",
            )
        if not (np.isfinite(self.coplanar_deg) and 0 <= self.coplanar_deg < 90):
            raise ParameterError(
                f"coplanar tolerance must be in [0, 90) degrees, got {self.coplanar_deg!r}",
                name="coplanar_deg",
            )
        if self.up not in ("auto", "x", "y", "z"):
            raise ParameterError(f"up must be 'auto', 'x', 'y' or 'z', got {self.up!r}", name="up")
        if self.size is not None and self.size != AUTO_SIZE:
            from .units import parse_size

            parse_size(self.size)
        if self.sheet is not None:  # a bad sheet, before the solve
            sheet_in_pattern_units(self.sheet, self.sheet_units, self.sheet_scale)
        resolve_chord_tol(self.chord_tol, 1.0)
        self.sheet_material()  # an unknown material or a bad figure, before the solve
        choose_nester(self.nest, self.sheet)  # a bad nester, or a missing one
        if self.sharp != "auto":
            parse_sharp(self.sharp)

    @property
    def sheet_units(self) -> str:
        """The units sheets are read in: ``units``, or mm for unitless drawings."""
        return self.units or "mm"

    @property
    def sheet_scale(self) -> float:
        """Drawing units per pattern unit when fitting sheets (``scale``, or 1)."""
        return 1.0 if self.scale is None else float(self.scale)

    @property
    def mm_per_unit(self) -> float:
        """Millimetres on the sheet per pattern unit (``scale`` in ``units``; a unitless
        drawing is read in mm, as sheets are)."""
        from .units import MM_PER_UNIT

        return self.sheet_scale * MM_PER_UNIT[self.sheet_units]

    def sheet_material(self):
        """The :class:`~filletfold.materials.Material` of ``material`` and its overrides, or
        None (see :func:`~filletfold.materials.resolve_material`)."""
        from .materials import resolve_material

        return resolve_material(self.material, self.thickness, self.min_bend_radius, self.k_factor)

    def bend_floor(self) -> float:
        """The sheet material's bend floor
        (:meth:`~filletfold.materials.Material.bend_floor_mm`) in mesh units at the design's
        size (``mm_per_unit``: a unitless drawing is read in mm); 0 without a material, and
        while the size is the default still to settle (it grows to hold the floor instead:
        :func:`~filletfold.layout.arrange.default_size`)."""
        material = self.sheet_material()
        if material is None or self.size == AUTO_SIZE:
            return 0.0
        return material.bend_floor_mm() / self.mm_per_unit

    def sharp_kinds(self) -> frozenset:
        """The kinds of cone-less vertices kept sharp (``"auto"`` resolved)."""
        from .vertex.sharpen import parse_sharp

        if self.sharp == "auto":
            return _auto_kinds(self.material_loss)
        return parse_sharp(self.sharp)

    def resolved(self) -> Parameters:
        """These parameters with what ``strict`` and ``material_loss`` decide filled in: the
        parameters a design was made with (``design.params``), which give it again."""
        strict = bool(self.strict)
        return dataclasses.replace(
            self,
            samples=int(self.samples),
            arc_step=float(self.arc_step),
            clamp=(not strict) if self.clamp is None else bool(self.clamp),
            material_loss=bool(self.material_loss),
            fit_vertices=(not strict) if self.fit_vertices is None else bool(self.fit_vertices),
            strict=strict,
            sharp=_sharp_text(self.sharp_kinds()),
            tabs=bool(self.tabs),
        )

    def as_dict(self) -> dict:
        """The parameters as JSON values (arrays as lists), in field order: ``report.json``'s
        ``parameters``, which :meth:`from_dict` reads back."""
        return {f.name: _plain(getattr(self, f.name)) for f in fields(self)}


def report_parameters(path) -> tuple[Parameters, str]:
    """The parameters and the source (the mesh file or built-in name, as it was given) that a
    design's ``report.json`` names: what ``filletfold round --from`` makes again.

    Raises
    ------
    MeshReadError
        When ``path`` is missing, unreadable or not JSON.
    ParameterError
        When it is not a filletfold report, or a parameter is unknown or of the wrong type.
    """
    from pathlib import Path

    from .export.fold_read import load_json

    path = Path(path)
    doc = load_json(path, "a filletfold report")
    if not isinstance(doc, dict) or not isinstance(doc.get("parameters"), dict):
        raise ParameterError(f"{path}: not a filletfold report (no object 'parameters')")
    source = doc.get("source")
    if not isinstance(source, str):
        raise ParameterError(f"{path}: not a filletfold report (no string 'source')")
    params = Parameters.from_dict(doc["parameters"], where=f"{path}: parameters")
    fab = doc.get("fabrication")
    return unsettled(params, fab.get("default_size") if isinstance(fab, dict) else None), source


def unsettled(params: Parameters, default_size) -> Parameters:
    """``params`` of a design whose size was the default (``default_size``: its
    ``fabrication["default_size"]``, or None) with the default asked again (``"auto"``, no
    units or scale): it settles the same on the same mesh, anew on another layout or mesh."""
    if isinstance(default_size, dict) and params.size == default_size.get("size"):
        return params.replace(size=AUTO_SIZE, units="", scale=None)
    return params


def _plain(x):
    """``x`` as a JSON value: arrays and numpy numbers as lists and Python numbers, dict keys
    as strings."""
    import numpy as np

    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if x is None or isinstance(x, str | bool | int | float):
        return x
    return np.asarray(x).tolist()


def _json_type(value) -> str:
    """The JSON type of a parsed value: ``null``, ``bool``, ``integer``, ``number``,
    ``string``, ``list``, ``dict``."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, int):
        return "integer"
    if isinstance(value, float):
        return "number"
    if isinstance(value, str):
        return "string"
    if isinstance(value, list):
        return "list"
    if isinstance(value, dict):
        return "dict"
    return type(value).__name__


def _auto_kinds(material_loss: bool) -> frozenset:
    """The kinds of cone-less vertices ``sharp="auto"`` keeps sharp: all of them, but the
    boundary vertices with ``material_loss`` (one uncut sheet ends at its border)."""
    from .vertex.sharpen import SHARP_KINDS

    return frozenset(SHARP_KINDS) - ({"boundary"} if material_loss else set())


def _sharp_text(kinds) -> str:
    """``sharp`` as the resolved parameters write it: the kinds in :data:`SHARP_KINDS` order,
    or ``"none"``."""
    from .vertex.sharpen import SHARP_KINDS

    return ",".join(k for k in SHARP_KINDS if k in kinds) or "none"


def resolve_chord_tol(value, reference: float) -> float:
    """The chord tolerance of :class:`Parameters` as a length: a number, or a ``"N%"`` string
    of ``reference`` (the mean edge length); 0 (or ``"0"``, ``"0%"``) for none.

    Raises
    ------
    ParameterError
        When it is not a finite number >= 0 or such a percentage.
    """
    if isinstance(value, bool):
        raise ParameterError(
            f"chord tolerance must be a length or 'N%', got {value!r}", name="chord_tol"
        )
    text = value.strip() if isinstance(value, str) else None
    try:
        number = float(text.removesuffix("%")) if text is not None else float(value)
    except (TypeError, ValueError):
        raise ParameterError(
            f"chord tolerance must be a length or a percentage like '0.01%', got {value!r}",
            name="chord_tol",
        ) from None
    if not (math.isfinite(number) and number >= 0):
        raise ParameterError(
            f"chord tolerance must be finite and >= 0 (0: none), got {value!r}", name="chord_tol"
        )
    if text is not None and text.endswith("%"):
        return number / 100.0 * float(reference)
    return number


def parse_length(value, reference: float, name: str, *, count: int | None = None):
    """Absolute length(s) from a number, a ``"12%"`` string (of ``reference``) or an array.

    Parameters
    ----------
    value : float, str or array_like
    reference : float
        The length that 100% stands for (the mean edge length).
    name : str
        Parameter name, for error messages.
    count : int, optional
        Expected length of a per-element array.

    Returns
    -------
    float or (count,) float array

    Raises
    ------
    ParameterError
        Not a number, a percentage or an array of the right shape; not finite; not positive.
    """
    import numpy as np

    if isinstance(value, str):
        text = value.strip()
        try:
            if text.endswith("%"):
                out = float(text[:-1]) / 100.0 * reference
            else:
                out = float(text)
        except ValueError:
            raise ParameterError(
                f"{name} must be a number or a percentage like '10%', got {value!r}", name=name
            ) from None
    else:
        out = np.asarray(value, dtype=float)
        if out.ndim == 0:
            out = float(out)
        elif count is not None and out.shape != (count,):
            raise ParameterError(
                f"per-element {name} must have shape ({count},), got {out.shape}", name=name
            )
    arr = np.atleast_1d(out)
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"{name} must be finite, got {value!r}", name=name)
    if np.any(arr <= 0):
        raise ParameterError(f"{name} must be positive, got {value!r}", name=name)
    return out


def resolve_depth(depth, reference: float, n: int):
    """(n,) float: the cone depth at each of ``n`` vertices from :attr:`Parameters.depth` (a
    length, a percentage of ``reference``, an array, or a dict of vertex index -> length with
    an optional ``"default"``).

    Raises
    ------
    ParameterError
        A bad length, or a vertex index that does not exist.
    """
    import numpy as np

    if isinstance(depth, dict):
        base = parse_length(depth.get("default", DEFAULT_DEPTH), reference, "depth")
        out = np.full(n, float(base))
        for k, val in depth.items():
            if k == "default":
                continue
            if not (0 <= int(k) < n):
                raise ParameterError(
                    f"depth given for vertex {k}, which does not exist", name="depth"
                )
            out[int(k)] = float(parse_length(val, reference, "depth"))
        return _bounded_depth(out, reference)
    d = parse_length(depth, reference, "depth", count=n)
    return _bounded_depth(np.broadcast_to(np.asarray(d, dtype=float), (n,)).copy(), reference)


#: The deepest apex, in mean edge lengths: farther, a cone is a cylinder to round-off and its
#: solve overflows (a depth of 1e308 once raised ZeroDivisionError, then left every vertex
#: sharp).
MAX_DEPTH_EDGES = 1e4


def _bounded_depth(out, reference: float):
    """``out`` (the depths), or a :class:`ParameterError` naming the first deeper than
    :data:`MAX_DEPTH_EDGES` mean edge lengths ``reference``."""
    import numpy as np

    if reference > 0 and len(out):
        far = np.flatnonzero(np.abs(out) > MAX_DEPTH_EDGES * reference)
        if len(far):
            at = "" if np.all(out == out[0]) else f" at vertex {int(far[0])}"
            raise ParameterError(
                f"depth {out[far[0]]:.4g}{at} is more than {MAX_DEPTH_EDGES:g} times the mean "
                f"edge length ({reference:.4g}): an apex that far makes the cone a cylinder "
                "to round-off",
                name="depth",
            )
    return out


def sized(params: Parameters, extent: float, ref: float = 0.0) -> Parameters:
    """``params`` with ``units`` and ``scale`` derived from ``size`` for a mesh whose largest
    bounding-box side is ``extent`` and mean edge length ``ref`` (unchanged without
    ``size``): the units are ``units``, or the size's own unit; the scale makes ``extent``
    pattern units ``size`` long.

    ``size="auto"`` (the default) asks for the least size at which the object can be built
    (:func:`~filletfold.layout.arrange.default_size`): it is left ``"auto"`` here, for the
    layout to settle once the pieces are known
    (:func:`~filletfold.layout.arrange.settle_size`). Given ``units`` or ``scale``, or for a
    mesh of no extent, it is no size (``None``): the mesh is then in those units.

    Raises
    ------
    ParameterError
        For a bad size, or a mesh of no extent.
    """
    from .units import MM_PER_UNIT, parse_size

    if params.size is None:
        return params
    if params.size == AUTO_SIZE:
        given = params.units or params.scale is not None
        return params.replace(size=None) if given or not (extent > 0 and ref > 0) else params
    mm, unit = parse_size(params.size)
    if not extent > 0:
        raise ParameterError("size needs a mesh of some extent", name="size")
    units = params.units or unit
    return params.replace(units=units, scale=mm / MM_PER_UNIT[units] / extent)
