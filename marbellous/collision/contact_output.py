"""Appending one contact to a narrow-phase contact buffer (see docs/architecture.md).

A row of ``out_f`` is ``[px, py, pz, nx, ny, nz, depth]``; ``out_i`` holds the feature id.  The
point is the midpoint between the surfaces: ``point = p_on_a - normal * depth / 2`` where ``p_on_a``
is shape a's deepest point towards b (so ``p_on_b = p_on_a - normal * depth``).
"""
from .._jit import njit


@njit
def add_contact(out_f, out_i, n, p_on_a, normal, depth, feature):
    """Write the contact into row ``n`` if the buffer has room; return ``n + 1`` either way.

    ``p_on_a`` (m) and ``normal`` (unit, from a to b) are 3-tuples, ``depth`` (m) > 0 for overlap,
    ``feature`` an int64 id that stays the same for the same touching features.
    """
    if n < out_f.shape[0]:
        h = 0.5 * depth
        out_f[n, 0] = p_on_a[0] - normal[0] * h
        out_f[n, 1] = p_on_a[1] - normal[1] * h
        out_f[n, 2] = p_on_a[2] - normal[2] * h
        out_f[n, 3] = normal[0]
        out_f[n, 4] = normal[1]
        out_f[n, 5] = normal[2]
        out_f[n, 6] = depth
        out_i[n] = feature
    return n + 1
