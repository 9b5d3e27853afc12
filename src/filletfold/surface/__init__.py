"""Stages 4 and 5, the surface: each vertex's module (cone, half-cylinders, face shares; the
curved creases of eq. (1) and the straight creases on the faces) as flat pieces with their
folded positions, built for all vertices at once (:mod:`.module`; the fans of sharp vertices
:mod:`.sharp`; :mod:`.piece`, :mod:`.faces`, :mod:`.overlap`, :mod:`.centres`), sampled so
that no cone's facets fold by more than the arc step (:mod:`.sampling`), the crease
pattern they assemble into (:mod:`.assemble`, :mod:`.pattern`; each face on a patch of
:mod:`.patch`), its validation
(:mod:`.validate`), the triangles of its faces (:mod:`.triangulate`), its coarse copy for
Origami Simulator (:mod:`.coarse`), and how tightly its cones bend (:mod:`.bend`)."""
