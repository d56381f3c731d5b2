"""Jointed scenes: a ragdoll, a flight of stairs, a bridge of hinged planks, and a hanging chain."""
import math

import numpy as np

from ..shapes.primitives import Box, Capsule, Plane, Sphere
from ..world import World

#: a ragdoll's parts standing at the origin, facing +z: name -> (shape, centre (m), mass (kg))
RAGDOLL_PARTS = {
    "torso": (Capsule(0.15, 0.25), (0.0, 1.15, 0.0), 30.0),
    "head": (Sphere(0.12), (0.0, 1.75, 0.0), 5.0),
    "upper_arm_left": (Capsule(0.05, 0.12), (0.27, 1.30, 0.0), 2.5),
    "lower_arm_left": (Capsule(0.045, 0.12), (0.27, 0.96, 0.0), 1.5),
    "upper_arm_right": (Capsule(0.05, 0.12), (-0.27, 1.30, 0.0), 2.5),
    "lower_arm_right": (Capsule(0.045, 0.12), (-0.27, 0.96, 0.0), 1.5),
    "thigh_left": (Capsule(0.07, 0.15), (0.1, 0.6, 0.0), 8.0),
    "shin_left": (Capsule(0.06, 0.13), (0.1, 0.2, 0.0), 4.0),
    "thigh_right": (Capsule(0.07, 0.15), (-0.1, 0.6, 0.0), 8.0),
    "shin_right": (Capsule(0.06, 0.13), (-0.1, 0.2, 0.0), 4.0),
}
#: its joints: (kind, part a, part b, anchor (m), axis, limits (rad)); a knee bends its shin back (positive
#: about +x), an elbow its forearm forward (negative about +x)
RAGDOLL_JOINTS = (
    ("ball", "head", "torso", (0.0, 1.6, 0.0), None, None),
    ("ball", "upper_arm_left", "torso", (0.24, 1.47, 0.0), None, None),
    ("hinge", "lower_arm_left", "upper_arm_left", (0.27, 1.13, 0.0), (1.0, 0.0, 0.0), (-2.5, 0.0)),
    ("ball", "upper_arm_right", "torso", (-0.24, 1.47, 0.0), None, None),
    ("hinge", "lower_arm_right", "upper_arm_right", (-0.27, 1.13, 0.0), (1.0, 0.0, 0.0), (-2.5, 0.0)),
    ("ball", "thigh_left", "torso", (0.1, 0.8, 0.0), None, None),
    ("hinge", "shin_left", "thigh_left", (0.1, 0.4, 0.0), (1.0, 0.0, 0.0), (0.0, 2.5)),
    ("ball", "thigh_right", "torso", (-0.1, 0.8, 0.0), None, None),
    ("hinge", "shin_right", "thigh_right", (-0.1, 0.4, 0.0), (1.0, 0.0, 0.0), (0.0, 2.5)),
)


def ragdoll(world, *, position=(0.0, 0.0, 0.0), velocity=(0.0, 0.0, 0.0)):
    """A 1.9 m, 67 kg ragdoll of capsules and a sphere, standing with its feet at ``position`` (m), facing +z:
    ball joints at the neck, shoulders and hips, hinges with limits at the elbows and knees.

    Returns ``(bodies, joints)``: a dict of the parts by name (``RAGDOLL_PARTS``) and the list of joints.
    """
    offset = np.asarray(position, dtype=float)
    bodies = {name: world.add_body(shape, position=offset + centre, mass=mass, velocity=velocity, friction=0.6)
              for name, (shape, centre, mass) in RAGDOLL_PARTS.items()}
    joints = []
    for kind, a, b, anchor, axis, limits in RAGDOLL_JOINTS:
        if kind == "ball":
            joints.append(world.add_ball_joint(bodies[a], bodies[b], anchor=offset + anchor))
        else:
            joints.append(world.add_hinge(bodies[a], bodies[b], anchor=offset + anchor, axis=axis, limits=limits))
    return bodies, joints


def stairs(world=None, *, steps=10, rise=0.2, depth=0.35, width=3.0):
    """A flight of ``steps`` static steps going down along +z from a landing at the height ``steps * rise``
    (m) above the ground plane y = 0, the landing's front edge at z = 0.  Returns ``(world, top)``: the world
    and the landing's top height (m)."""
    w = World() if world is None else world
    w.add_static(Plane(), friction=0.6)
    top = steps * rise
    w.add_static(Box((width / 2, top / 2, 1.0)), position=(0.0, top / 2, -1.0), friction=0.6)
    for k in range(1, steps):
        h = top - k * rise
        w.add_static(Box((width / 2, h / 2, depth / 2)), position=(0.0, h / 2, (k - 0.5) * depth), friction=0.6)
    return w, top


def plank_bridge(world=None, *, planks=30, plank_depth=0.2, gap=0.01, width=1.2, mass=1.0, sag=0.25,
                 origin=(0.0, 0.0, 0.0)):
    """A rope bridge of ``planks`` planks along +z, hinged to each other at their shared edges about x and the
    end planks to the world, hung from two points 3 m above the ground plane.  It is built already sagging:
    plank ``k`` is tilted down by ``sag (1 - 2 k / (planks - 1))`` rad, so the middle hangs lowest.

    Returns ``(world, planks, hinges)``; the bridge starts at ``origin`` + (0, 3, 0) (m).
    """
    w = World() if world is None else world
    w.add_static(Plane(), friction=0.6)
    pitch = plank_depth + gap
    edge = np.asarray(origin, dtype=float) + (0.0, 3.0, 0.0)
    edges = [edge]
    for k in range(planks):
        tilt = sag * (1.0 - 2.0 * k / (planks - 1))
        edge = edge + pitch * np.array([0.0, -math.sin(tilt), math.cos(tilt)])
        edges.append(edge)
    bodies = []
    for k in range(planks):
        tilt = sag * (1.0 - 2.0 * k / (planks - 1))
        bodies.append(w.add_body(Box((width / 2, 0.03, plank_depth / 2)), mass=mass, friction=0.8,
                                 position=0.5 * (edges[k] + edges[k + 1]),
                                 orientation=(math.cos(tilt / 2), math.sin(tilt / 2), 0.0, 0.0)))
    hinges = [w.add_hinge(bodies[0], None, anchor=edges[0], axis=(1.0, 0.0, 0.0))]
    for k in range(1, planks):
        hinges.append(w.add_hinge(bodies[k], bodies[k - 1], anchor=edges[k], axis=(1.0, 0.0, 0.0)))
    hinges.append(w.add_hinge(bodies[-1], None, anchor=edges[-1], axis=(1.0, 0.0, 0.0)))
    return w, bodies, hinges


def hinged_chain(world=None, *, links=20, length=0.1, mass=0.2, tilt=0.5):
    """A chain of ``links`` capsules of ``length`` (m) hanging from the world at the origin by hinges about z
    (a chain that swings in the x-y plane), let go at ``tilt`` (rad) from the vertical.

    Returns ``(world, links, hinges)``."""
    w = World() if world is None else world
    s, c = math.sin(tilt), math.cos(tilt)
    q = (math.cos(tilt / 2), 0.0, 0.0, math.sin(tilt / 2))
    bodies, hinges, previous = [], [], None
    for k in range(links):
        link = w.add_body(Capsule(length * 0.2, length * 0.3), mass=mass, orientation=q,
                          position=(s * length * (k + 0.5), -c * length * (k + 0.5), 0.0))
        hinges.append(w.add_hinge(link, previous, anchor=(s * length * k, -c * length * k, 0.0), axis=(0, 0, 1)))
        bodies.append(link)
        previous = link
    return w, bodies, hinges
