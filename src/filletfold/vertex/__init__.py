"""Stage 3, the vertices: each one classified, its vertex normal (sec. 3.1, :mod:`.normal`),
its frames and development with the developed apex (sec. 2.4, :mod:`.frame`), the crease of
eq. (1) (:mod:`.crease`), the sec. 3.2 constraints (:mod:`.apex`) and the spatial apex solved
for all vertices at once (:mod:`.batch`, :mod:`.batch_kernel`, on the constraint rows of
:mod:`.rows`, :mod:`.settings`, with the
reductions over each vertex's sides of :mod:`.runs`;
:mod:`.reference` the per-vertex SLSQP solver of the hard cases); :mod:`.solve` runs them,
:mod:`.rescue` tries smaller radii on infeasible vertices and :mod:`.sharpen` keeps the corner
of the vertices without a cone (sharp vertices), both on the state the apex stage shares with
them (:mod:`.state`); the stage's result is a :mod:`.solution`."""
