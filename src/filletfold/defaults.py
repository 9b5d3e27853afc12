"""Default parameters of a design, shared by :func:`~filletfold.round_mesh`, the command line
and the app (a module of its own, so that ``filletfold --help`` shows them without loading the
pipeline)."""

DEFAULT_RADIUS = "10%"
DEFAULT_DEPTH = "30%"
DEFAULT_SAMPLES = 24
DEFAULT_ARC_STEP = 1.5  # degrees (0: no limit): see round_mesh(arc_step=...)
#: Largest distance of an arc's chord from the arc: see round_mesh(chord_tol=...).
DEFAULT_CHORD_TOL = "0.01%"
#: Which cone-less vertices keep their corner (see round_mesh(sharp=...)): "auto" is every
#: kind (saddle, infeasible, boundary), less boundary with material loss.
DEFAULT_SHARP = "auto"
