"""Time of impact: shapes posed along their bodies' motion, the time a gap can close at the earliest,
closed forms for the pairs whose gap is an exact function of time (``closed_forms``), and conservative
advancement of a shape pair to its first contact (``conservative_advancement``)."""
