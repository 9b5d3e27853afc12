"""Stage 5, the layout: where the flat pieces go on the sheet — side by side on shelves
(:mod:`.shelf`), glued into one sheet where the input is developable (:mod:`.sheet`), into nets
packed on sheets of a size (:mod:`.net`, :mod:`.fabrication`; outlines nested by sparrow where
installed, :mod:`.nest`), with glue tabs and labels on the
cut borders (:mod:`.tabs`, tested against the faces with :mod:`.convex`), and a sheet
material's reliefs and kerf grooves (:mod:`.making`); :mod:`.arrange` runs them."""
