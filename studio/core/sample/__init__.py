"""The bundled sample: the synthetic face made from formulas (`synthetic`, `mesh`, `maps`) and
the ICT head the studio opens on (`ict_head`)."""
