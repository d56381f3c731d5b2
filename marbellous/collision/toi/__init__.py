"""Time of impact: shapes posed along their bodies' motion, the time a gap can close at the earliest, and
conservative advancement of a shape pair to its first contact (``conservative_advancement``)."""
