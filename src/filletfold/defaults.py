"""Default parameters of a design, shared by :func:`~filletfold.round_mesh`, the command line
and the app (a module of its own, so that ``filletfold --help`` shows them without loading the
pipeline)."""

DEFAULT_RADIUS = "10%"
DEFAULT_DEPTH = "30%"
DEFAULT_SAMPLES = 24
#: The most points per arc a design may ask for: the certificate's memory grows with the square
#: of the points per arc (a cube with 256 on every arc: 12 s, 1.1 GB; 1000: 62 s, 3.9 GB).
MAX_SAMPLES = 256
#: The most corners a face may have (see round_mesh(max_corners=...)): a face's corners cost
#: time about quadratic in their number (a prism of two 256-gons: 7 s; of two 400-gons: 38 s;
#: one 10,000-gon filled 24 GB).
DEFAULT_MAX_CORNERS = 256
#: The most crease-pattern points a design may be estimated at before it is solved (see
#: round_mesh(max_points=...) and mesh.polymesh.estimate_pattern_points): about what a
#: 200,000-triangle mesh at the default samples is estimated at; such a run takes about half
#: an hour and 6 GB here (a 100,000-triangle scan: 640 s, 2.9 GB).
DEFAULT_MAX_POINTS = 50_000_000
#: Largest turn (degrees) between two samples of an arc (0: no limit): the chord tolerance
#: decides, this bounds the turn of a chord on a small fillet (see round_mesh(arc_step=...)).
DEFAULT_ARC_STEP = 10.0
#: Largest distance of an arc's chord from the arc: see round_mesh(chord_tol=...).
DEFAULT_CHORD_TOL = "0.01%"
#: Which cone-less vertices keep their corner (see round_mesh(sharp=...)): "auto" is every
#: kind (saddle, infeasible, boundary), less boundary with material loss.
DEFAULT_SHARP = "auto"
