"""Default parameters of a design, shared by :func:`~filletfold.round_mesh`, the command line
and the app (a module of its own, so that ``filletfold --help`` shows them without loading the
pipeline)."""

DEFAULT_RADIUS = "10%"
DEFAULT_DEPTH = "30%"
DEFAULT_SAMPLES = 24
#: Largest turn (degrees) between two samples of an arc (0: no limit): the chord tolerance
#: decides, this bounds the turn of a chord on a small fillet (see round_mesh(arc_step=...)).
DEFAULT_ARC_STEP = 10.0
#: Largest distance of an arc's chord from the arc: see round_mesh(chord_tol=...).
DEFAULT_CHORD_TOL = "0.01%"
#: Which cone-less vertices keep their corner (see round_mesh(sharp=...)): "auto" is every
#: kind (saddle, infeasible, boundary), less boundary with material loss.
DEFAULT_SHARP = "auto"
