"""Grasshopper's Hops components (``filletfold hops``): *Round* and *Pattern* on an HTTP
server of this machine, for ``ghhops-server`` and ``rhino3dm`` (the ``hops`` extra:
``pip install 'filletfold[hops]'``).

:mod:`.server` serves the components (:func:`~filletfold.hops.server.run_hops`), parses their
inputs and keeps the designs for reuse; :mod:`.convert` turns a Rhino mesh into the library's
mesh and a design into Rhino geometry (the meshes and curves of the 3dm files). Geometry is the
library's: this package only parses, calls and converts, as the command line and the browser
app do. Nothing is imported here, so that ``filletfold --help`` stays light.
"""
