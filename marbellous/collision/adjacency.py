"""Which items are joined to which, as a compressed adjacency list: the items joined to item ``i`` are
``adjacent[start[i]:start[i + 1]]``, two entries per link.  The pair searches look links up here to skip the
pairs that must not collide (particles joined by an edge, bodies joined by a joint).

A list is built in place in four moves, with no scratch beyond ``start`` (n + 1 ints) and ``adjacent`` (two per
link): :func:`clear_counts`, :func:`count_link` for every link, :func:`begin_fill` (the counts become each item's
first slot), :func:`fill_link` for every link in the same order (each item's slot advances to its end),
:func:`end_fill` (the ends shifted back one item are the starts again).  A list of other entries per item (the
joint trees list each body's joints, ``dynamics/joint_tree.py``) counts and fills them one end at a time
(:func:`count_end`, :func:`fill_end`).
"""
from .._numba.jit import njit


@njit
def clear_counts(start, n):
    """Zero the counts of ``n`` items (``start[0:n + 1]``)."""
    for i in range(n + 1):
        start[i] = 0


@njit
def count_end(start, a):
    """Count one entry in item ``a``'s row."""
    start[a + 1] += 1


@njit
def count_link(start, a, b):
    """Count the link between items ``a`` and ``b`` in both items' rows."""
    count_end(start, a)
    count_end(start, b)


@njit
def begin_fill(start, n):
    """The counts of ``n`` items summed up: ``start[i]`` is where item ``i``'s list begins."""
    for i in range(n):
        start[i + 1] += start[i]


@njit
def fill_end(start, adjacent, a, value):
    """Write ``value`` into item ``a``'s list, advancing its slot (counted by :func:`count_end`)."""
    adjacent[start[a]] = value
    start[a] += 1


@njit
def fill_link(start, adjacent, a, b):
    """Write the link between ``a`` and ``b`` into both items' lists, advancing each item's slot."""
    fill_end(start, adjacent, a, b)
    fill_end(start, adjacent, b, a)


@njit
def end_fill(start, n):
    """After every link is filled ``start[i]`` stands at item ``i``'s end, the next item's start: shift them back."""
    for i in range(n, 0, -1):
        start[i] = start[i - 1]
    start[0] = 0


@njit
def joined(start, adjacent, a, b):
    """Whether a link joins items ``a`` and ``b``."""
    for k in range(start[a], start[a + 1]):
        if adjacent[k] == b:
            return True
    return False
