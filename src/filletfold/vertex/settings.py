"""Settings of the batched apex solver (:mod:`.batch`, :mod:`.batch_kernel`): when a problem is
done, how hard each phase works, how much is solved at once. Geometric tolerances are in
:mod:`filletfold.tolerances`."""

#: :func:`~filletfold.vertex.batch.kkt_point`: rows within this share of the scale are active,
#: and the gradient must be matched to this share of its size. (Rows up to 1e-5 of the scale:
#: an interior-point result
#: that stops short of its stationarity test sits that close to rows it has not quite reached;
#: on blob, SLSQP then improved such points by 3e-8 relative at most, mostly not at all.)
KKT_ACTIVE = 1e-5
KKT_TOL = 1e-6

#: Most vertices per chunk, and most padded rows per chunk (keeps the arrays in cache).
CHUNK = 2048
ROW_BUDGET = 150_000
#: Phase 1 stops once the smallest slack exceeds half of this (in units of the scale).
T_CAP = 1e-3
#: Stationarity (gradient of the Lagrangian over the size of its terms) at which a problem
#: is done.
STAT_TOL = 1e-8
#: Mean complementarity at which phase 2 (the projection of ``P``) is done, relative to the
#: squared length scale: its duality gap bounds the objective's error, so a target a hair
#: from the feasible set (objective ~1e-7) still gets its optimum to ~1e-7 relative.
PROJECTION_TOL = 1e-13
#: Proximal weight of phase 1 (maximise t - PROX / 2 |y - y0|^2): keeps the search near its
#: start, where the developed apex of a closed development would otherwise drift away.
PROX = 1e-2
#: The linearised feasibility phase (:func:`~filletfold.vertex.batch.phase1_lp`): its first
#: trust region (box half-width, in units of the scale), the most linear programmes per problem,
#: and the predicted gain of the smallest slack (over the scale) below which it stops.
LP_RADIUS = 0.05
LP_ROUNDS = 12
LP_STALL = 1e-10
#: Starts tried at once in phase 1 before the remaining ones.
PARALLEL_STARTS = 1
#: The fallbacks of a problem whose phase 1 from its best start ends short of feasibility
#: (:func:`~filletfold.vertex.batch.solve_apex_batch`), in the order they are tried:
#: ``"starts"`` phase 1 from each other start (thorough), ``"again"`` once more from the best
#: point with fresh multipliers (quick), ``"lp"`` sequential linear programmes (thorough, with
#: ``lp``), ``"long"`` phase 1 three times as long without the give-up rule (thorough). Each
#: cone's ``solver`` names the one that found its feasible point, and the report counts them
#: (``fitting.cones_by_fallback``).
KNOWN_FALLBACKS = ("starts", "again", "lp", "long")
#: The fallbacks tried (``starts`` and ``lp`` only in a solve with ``lp``: not where a rescue
#: follows, which tries the vertex again with smaller radii). ``benchmarks/fallbacks.py`` on
#: the 54 designs of the corpus's meshes of up to 6,000 faces (2026-12-07), each fallback
#: turned off alone, ``starts`` then in every thorough solve: without ``lp`` 118 cones fewer,
#: without ``again`` 7, without ``long`` 5 (and 9 vertices more with halved radii); without
#: ``starts`` one cone more and 4 vertices more with halved radii, for 21,232 of the 58,434
#: phase-1 problems (36 %), so it no longer runs where a rescue follows (cow: phase-1
#: problems 17,468 -> 13,278, the same cones and rescued vertices). It stays where no rescue
#: follows: there it solves single problems that the reference SLSQP solver solves and the
#: others do not (``tests/vertex/test_batch.py``).
FALLBACKS = KNOWN_FALLBACKS
#: The start of a closed development's developed apex is where two consecutive central rulings
#: cross (sec. 3.2), taken from the first pair whose directions are further than this from
#: parallel (``|det|``, unit directions): nearer pairs cross too far away to start from.
START_PARALLEL = 1e-6

# ---- the interior-point method (both versions, numpy and numba, read these)
#: Mean complementarity at which a problem is done, relative to the squared length scale.
IPM_TOL = 1e-12
#: Smallest scale of the starting multipliers (of the objective's gradient).
MULTIPLIER_START_FLOOR = 1e-2
#: With ``give_up``, phase 1 stops once the smallest slack plus the complementarity is below
#: minus this: the problem is infeasible.
GIVE_UP_SLACK = 1e-9
#: Above this barrier parameter the curvature weights use ``max(lambda, mu / g)`` (rows that just
#: became nearly active); below it the exact ``lambda`` (fast local convergence).
PRIMAL_WEIGHT_MU = 1e-8
#: The Newton matrix is shifted to at least this times its largest diagonal entry (or 1).
HESSIAN_FLOOR = 1e-8
#: Sufficient decrease of the merit function along a step (Armijo).
ARMIJO = 1e-4
#: Round-off allowed in that test, relative to the merit (or 1).
MERIT_ROUNDOFF = 1e-13
#: Multipliers stay above this share of their row's mask (never exactly 0).
MULTIPLIER_FLOOR = 1e-30
