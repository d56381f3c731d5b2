"""Debug overlays of a world, drawn over the scene: contact points and normals, contact events, broad-phase
boxes,
springs, rods and cables as lines between their world anchors, and joints as arms from each body's centre
to the joint (with the hinge's or slider's axis).

Sizes that are lengths in the world (a contact normal's length) scale with the camera's distance, so
they read the same at any zoom; dots and line widths are in pixels.
"""
import numpy as np

from ..constraints import Cable, Constraint, Joint, Rod, Spring
from . import palette
from .draw_lists import Lines, Points
from .transforms import quat_to_matrix
from .world_internals import broadphase_boxes

#: Length of a drawn contact normal, in camera distances.
NORMAL_LENGTH = 0.06
#: Length of a drawn joint axis, in camera distances.
AXIS_LENGTH = 0.05
#: The twelve edges of a box as pairs of corner numbers (bit 0: x, bit 1: y, bit 2: z at the high side).
BOX_EDGES = np.array([(a, a | bit) for bit in (1, 2, 4) for a in range(8) if not a & bit])

_CONSTRAINT_COLORS = {Spring: palette.SPRING, Rod: palette.ROD, Cable: palette.CABLE}


def contact_marks(frame):
    """A dot at every contact point of the last step and a line along its normal (from body_a to body_b)."""
    contacts = frame.contacts
    if not contacts:
        return []
    points = np.array([c.point for c in contacts])
    normals = np.array([c.normal for c in contacts])
    color = np.tile(palette.CONTACT, (len(contacts), 1))
    tips = points + NORMAL_LENGTH * frame.distance * normals
    return [Lines(np.stack([points, tips], axis=1), color, 2.0), Points(points, color, 7.0)]


#: Size (pixels) of a contact event's dot: the base, the growth per m/s of approach speed, and the largest.
EVENT_DOT = (8.0, 4.0, 28.0)


def event_marks(frame):
    """A dot where each pair of bodies began touching in the last step (red, larger the faster they met:
    ``8 + 4 v`` pixels for an approach speed ``v`` m/s, at most 28) and where each stopped (pale blue)."""
    out = []
    for e in frame.world.contact_events():
        begin = e.kind == "begin"
        base, per_speed, most = EVENT_DOT
        size = min(base + per_speed * e.approach_speed, most) if begin else base
        out.append(Points(e.point[None, :], np.array([palette.EVENT_BEGIN if begin else palette.EVENT_END]),
                          size))
    return out


def box_outlines(frame):
    """The twelve edges of every body's broad-phase box (infinite boxes and bodies never stepped left out)."""
    lo, hi = broadphase_boxes(frame.world, frame.bodies)
    keep = np.all(np.isfinite(lo) & np.isfinite(hi), axis=1) & np.any(hi != lo, axis=1)
    lo, hi = lo[keep], hi[keep]
    if not len(lo):
        return []
    bits = (np.arange(8)[:, None] >> np.arange(3)) & 1                   # (8 corners, 3 axes)
    corners = np.where(bits[None], hi[:, None, :], lo[:, None, :])      # (boxes, 8, 3)
    segments = corners[:, BOX_EDGES].reshape(-1, 2, 3)
    return [Lines(segments, np.tile(palette.BOX, (len(segments), 1)), 1.5)]


def constraint_lines(frame):
    """A line between the world anchors of every spring, rod and cable that is not broken, and a dot at
    each anchor; colours by kind (:mod:`palette`; another kind is drawn like a rod).  A joint that is not
    broken: a line from each body's centre to the joint, a dot there, and the axis of a hinge or slider.
    (Particle networks, listed in ``world.constraints`` too, are drawn by ``particle_drawing.network_lines``.)"""
    ends, colors = [], []
    for c in frame.world.constraints:
        if not isinstance(c, Constraint) or c.broken:
            continue
        if isinstance(c, Joint):
            joint = c.anchor
            for body in (c.body_a, c.body_b):
                if body is not None:
                    ends.append((body.position, joint))
                    colors.append(palette.JOINT)
            if hasattr(c, "axis"):
                half = 0.5 * AXIS_LENGTH * frame.distance * c.axis
                ends.append((joint - half, joint + half))
                colors.append(palette.JOINT_AXIS)
            continue
        a = _world_point(c.body_a, c.anchor_a)
        b = c.anchor_b if c.body_b is None else _world_point(c.body_b, c.anchor_b)
        ends.append((a, b))
        colors.append(_CONSTRAINT_COLORS.get(type(c), palette.ROD))
    if not ends:
        return []
    segments = np.array(ends)
    colors = np.array(colors, np.float64)
    return [Lines(segments, colors, 3.0), Points(segments.reshape(-1, 3), np.repeat(colors, 2, axis=0), 8.0)]


def _world_point(body, local):
    """A point (m) given in ``body``'s frame, in the world frame."""
    return body.position + quat_to_matrix(body.orientation) @ local
