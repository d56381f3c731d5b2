"""The one read of a World's internals by the renderer: the broad phase's boxes.

The World has no public view of its broad phase, so :func:`broadphase_boxes` reads the box table
directly (``World._state.aabbs``, one row ``(lo x, y, z, hi x, y, z)`` per body row ``Body._index``).  When the
World's tables change shape, this is the only function to adapt.
"""
import numpy as np


def broadphase_boxes(world, bodies):
    """``(lo, hi)``: the broad-phase box corners (len(bodies), 3) (m) of ``bodies`` of ``world``, as the
    last step computed them (swept over the step's motion and grown by the speculative distance).

    A static body's box is set when it is added (infinite for a plane); a dynamic body has no box
    before its first step (both corners zero).
    """
    rows = np.array([b._index for b in bodies], np.int64)
    boxes = world._state.aabbs[rows] if len(rows) else np.zeros((0, 6))
    return boxes[:, :3].copy(), boxes[:, 3:].copy()
