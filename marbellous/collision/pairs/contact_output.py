"""Appending one contact to a narrow-phase contact buffer (see docs/architecture.md).

A row of ``out_f`` is ``[px, py, pz, nx, ny, nz, depth]``; ``out_i`` holds the feature id.  The
point is the midpoint between the surfaces: ``point = p_on_a - normal * depth / 2`` where ``p_on_a``
is shape a's deepest point towards b (so ``p_on_b = p_on_a - normal * depth``).
"""
from ..._numba.jit import njit


@njit
def contact_point(p_on_a, normal, depth):
    """The contact point (3-tuple, m) midway between the surfaces: ``p_on_a - normal * depth / 2``."""
    h = 0.5 * depth
    return (p_on_a[0] - normal[0] * h, p_on_a[1] - normal[1] * h, p_on_a[2] - normal[2] * h)


@njit
def add_contact(out_f, out_i, n, p_on_a, normal, depth, feature):
    """Write the contact into row ``n`` if the buffer has room; return ``n + 1`` either way.

    ``p_on_a`` (m) and ``normal`` (unit, from a to b) are 3-tuples, ``depth`` (m) > 0 for overlap,
    ``feature`` an int64 id that stays the same for the same touching features.

    Written without a branch around the stores (a full buffer rewrites its last row unchanged):
    Numba then drops the reference counting of the two arrays, which costs ~20 ns a call otherwise.
    """
    cap = out_f.shape[0]
    if cap == 0:
        return n + 1
    room = n < cap
    row = min(n, cap - 1)
    point = contact_point(p_on_a, normal, depth)
    out_f[row, 0] = point[0] if room else out_f[row, 0]
    out_f[row, 1] = point[1] if room else out_f[row, 1]
    out_f[row, 2] = point[2] if room else out_f[row, 2]
    out_f[row, 3] = normal[0] if room else out_f[row, 3]
    out_f[row, 4] = normal[1] if room else out_f[row, 4]
    out_f[row, 5] = normal[2] if room else out_f[row, 5]
    out_f[row, 6] = depth if room else out_f[row, 6]
    out_i[row] = feature if room else out_i[row]
    return n + 1
