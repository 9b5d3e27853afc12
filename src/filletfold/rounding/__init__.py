"""Stage 2, the rounding: a cylinder on every edge, its radius requested, fitted to the edge's
limit (:mod:`.edges`) or chosen by the consistent-material-loss LP of sec. 4 (stage 6,
:mod:`.material_loss`, and the face offsets of conical meshes, sec. 4.4, stage 7:
:mod:`.conical`); the conical fillets that taper into a sharp vertex (:mod:`.tapered`); a
sheet material's bend floor on the fillets (:mod:`.bend`)."""
