"""Stacking scenes: a tower of boxes, a pyramid of boxes, and a pile of spheres in a walled box."""
import numpy as np

from ..shapes.primitives import Box, Plane, Sphere
from ..world import World


def box_tower(world=None, *, height=20, size=1.0, friction=0.6):
    """A column of ``height`` cubes of edge ``size`` (m) on the ground plane y = 0.

    Returns ``(world, boxes)`` with the boxes from the bottom up.
    """
    w = World() if world is None else world
    w.add_static(Plane(), friction=friction)
    h = size / 2.0
    boxes = [w.add_body(Box((h, h, h)), position=(0.0, h + i * size, 0.0), friction=friction)
             for i in range(height)]
    return w, boxes


def box_pyramid(world=None, *, base=20, size=1.0, friction=0.6):
    """A 2D pyramid of cubes in the x-y plane: ``base`` cubes in the bottom row, one fewer in each row above.

    Returns ``(world, boxes)`` row by row from the bottom; the last box is the top one.
    """
    w = World() if world is None else world
    w.add_static(Plane(), friction=friction)
    h = size / 2.0
    boxes = []
    for row in range(base):
        n = base - row
        for i in range(n):
            x = (i - (n - 1) / 2.0) * size
            boxes.append(w.add_body(Box((h, h, h)), position=(x, h + row * size, 0.0), friction=friction))
    return w, boxes


def sphere_pile(world=None, *, count=1000, radius=0.5, seed=0, rolling_friction=0.0, torsional_friction=0.0):
    """``count`` spheres of ``radius`` (m) dropped into a walled box whose floor is about
    ``sqrt(count) * radius`` wide.

    The spheres start on a loose lattice above the floor, jittered by a seeded random generator.  Every body
    (spheres, floor and walls) gets friction 0.5 and the lever arms ``rolling_friction`` and
    ``torsional_friction`` (m; 0, the defaults: spheres roll and spin without resistance, so a pile never
    comes quite to rest).  Returns ``(world, spheres)``.
    """
    w = World() if world is None else world
    material = dict(friction=0.5, rolling_friction=rolling_friction, torsional_friction=torsional_friction)
    side = max(4.0, 1.1 * np.sqrt(count) * radius * 2.0 / 3.0) * 2.0
    w.add_static(Plane(), **material)
    wall = 0.5
    height = 4.0 * radius + count / (side / (2.2 * radius)) ** 2 * 2.2 * radius + 2.0
    reach = side / 2 + wall
    for sx, sz, px, pz in ((wall, reach, -reach, 0.0), (wall, reach, reach, 0.0),
                           (reach, wall, 0.0, -reach), (reach, wall, 0.0, reach)):
        w.add_static(Box((sx, height / 2, sz)), position=(px, height / 2, pz), **material)
    rng = np.random.default_rng(seed)
    pitch = 2.2 * radius
    per_row = max(1, int((side - pitch) / pitch))
    spheres = []
    for k in range(count):
        layer, rest = divmod(k, per_row * per_row)
        ix, iz = divmod(rest, per_row)
        pos = np.array([-side / 2 + pitch * (ix + 1), radius * 2 + layer * pitch, -side / 2 + pitch * (iz + 1)])
        pos[[0, 2]] += rng.uniform(-0.05, 0.05, 2) * radius
        spheres.append(w.add_body(Sphere(radius), position=pos, **material))
    return w, spheres
