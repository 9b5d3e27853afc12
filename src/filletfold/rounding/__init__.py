"""Step 1, the rounding: a cylinder on every edge, its radius requested, fitted to the edge's
limit (:mod:`.edges`) or chosen by the consistent-material-loss LP of sec. 4
(:mod:`.material_loss`, and the face offsets of conical meshes, sec. 4.4: :mod:`.conical`)."""
