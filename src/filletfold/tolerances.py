"""The one tolerance object of filletfold.

All comparisons against zero in the library go through ``tol``; lengths are relative to the
mesh's mean edge length unless the name says otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Tolerances:
    """Numerical tolerances.

    Attributes
    ----------
    merge : float
        Vertices closer than ``merge * bbox_diagonal`` are the same point (merged on input).
    weld : float
        Vertices closer than ``weld * bbox_diagonal`` are welded on input (a reported repair).
    degenerate : float
        A face whose height over its longest edge is below ``degenerate`` times that edge has
        (almost) zero area (a corner under 1e-6 rad, or within it of straight): it is removed
        on input, its middle vertex put into the face across that edge.
    collinear : float
        A polygon corner within this angle (radians) of straight is straight on input: the
        coordinates' own noise (float32 in an STL is 6e-8 of the size) bends a straight
        line by about this much.
    straight : float
        A polygon corner within this angle (radians) of straight is split on input (no
        tangent-line crossing could be placed there), unless straight within ``collinear`` and
        removable.
    planar : float
        A polygon face is planar when every vertex is within ``planar * face_size`` of its plane.
    flat : float
        A polygon is planar to round-off once its corners are within ``flat`` of its diameter
        from its plane after its vertices were moved onto the planes (a polygon that stays
        further out is triangulated): planes off by more part a development's 2D and 3D
        lengths by as much (9e-13 on a float32 quad torus).
    area : float
        A face with area below ``area * mean_edge_length**2`` is degenerate.
    coplanar_deg : float
        Default angle (degrees) under which two neighbouring faces are merged as coplanar.
    angle : float
        Absolute angle tolerance (radians) for "equal angles" such as angle sum == 2*pi.
    developable : float
        A vertex is developable when ``|2*pi - angle_sum| < developable`` (radians).
    normal_bound : float
        The max-min vertex-normal bound ``b`` must exceed this for a cone to exist.
    margin : float
        Safety margin of the sampled apex constraints, as a share of the shortest incident edge
        or of four times the shortest rounded arc when that is shorter (nearly flat vertices).
    closure : float
        A developable vertex's rounded development closes when the gap of ``rho`` is below
        ``closure * mean incident edge length``.
    validate : float
        Slack allowed when the solved apex is validated densely, relative to the local edge length.
    fillet_floor : float
        An edge whose fillet would be narrower than this share of the edge's length is left
        sharp (not rounded): a narrower strip only makes slivers.
    min_fillet : float
        Nor may a fillet be narrower than this share of the mesh's size (its bounding-box
        diagonal): a short edge's fillet in a large design would give pattern edges below the
        certificate's smallest edge (1e-7 of the design); arcs are also sampled no finer than
        ``2 * ruling`` of the size.
    fold : float
        Smallest angle (radians; 1.03 degrees) between a straight crease's cone triangle and
        its face: the apex stays above each face's plane by at least ``sin(fold)`` times its
        distance from the crease on that face, so that no straight crease folds by more than
        180 degrees less this angle (an apex in a face's plane folds the cone flat onto it).
    ruling : float
        Shortest crease ruling aimed at, as a share of the mesh's size (its bounding-box
        diagonal): the apex keeps every crease at least this far above its base curve (capped
        at a quarter of the vertex's shortest ``l_max``), so that no ruling of a cylinder is a
        sliver edge of the pattern (the certificate's shortest edge is 1e-7 of the design).
    fixed_point : float
        The development's map ``rho`` of a vertex has a fixed point (the developed apex) when
        ``|det(I - Q)| = 4 sin^2(theta / 2)`` is at least this (a turn ``theta`` above about
        1e-7 radians); below, it is a translation.
    parallel : float
        Two lines (or a segment and a triangle's plane) are parallel when the determinant of
        their crossing, for unit directions ``sin^2`` of their angle (``1e-12``: 1e-6 rad), is
        below this: the one singular-2x2 test of line crossings and segment hits.
    coincide : float
        Two points of a vertex module are one point (merged) when they are this close in 2D
        and in 3D, relative to the larger of the module's shortest edge and the size of its
        coordinates: only round-off apart (about 45 units in the last place), so that a merge
        moves no point by more than the rounding of its coordinates (a looser merge breaks the
        ruling isometry and the contraction by as much, e.g. across the cut of a development
        that closes to 1e-11).
    roundoff : float
        Relative slack for round-off in a test that is exact in exact arithmetic: a turn's sign
        against the product of its two lengths, a fitted radius against the asked one, an area
        against the polygon's, a solver's constraint value against its length scale.
    relative : float
        Two quantities that agree to this share of their size are equal where nothing finer is
        at stake: a piece fits its sheet, a turn is an exact multiple of the arc step, a page
        count, a point on a triangle's edge, a vertex is conical, layout's merge distance.
    """

    merge: float = 1e-9
    weld: float = 1e-6
    degenerate: float = 1e-6
    collinear: float = 1e-6
    straight: float = 0.0175  # 1 degree
    planar: float = 1e-6
    flat: float = 1e-14
    area: float = 1e-12
    coplanar_deg: float = 1e-3
    angle: float = 1e-9
    developable: float = 1e-7
    normal_bound: float = 1e-9
    margin: float = 5e-3
    closure: float = 1e-9
    validate: float = 1e-9
    fillet_floor: float = 1e-3
    min_fillet: float = 1e-6
    fold: float = 0.018
    ruling: float = 2e-7
    parallel: float = 1e-12
    coincide: float = 1e-14
    fixed_point: float = 1e-14
    roundoff: float = 1e-12
    relative: float = 1e-9


tol = Tolerances()
