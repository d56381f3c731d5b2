"""The benchmark's scenes: how each is built (from ``marbellous.scenes``), how long it runs, and the
sanity measure that shows speed was not bought with wrong physics.

Every scene steps at 60 Hz.  ``--quick`` sizes are for a fast check of the harness, not for numbers.
Sanity measures, per scene (from positions sampled during the run, in Marbellous axes):

- stacks (tower, pyramid): how far the top box moved (m), and the largest move of any box; standing
  means the top box moved less than 0.1 m (a tenth of a box); each once as the engines leave it (resting
  bodies fall asleep) and once ``_awake``, with sleeping off in every engine (the cost of a stack that is kept
  busy);
- sphere piles (rolling and torsional friction of 1 cm, ``PILE_ROLLING``): height of the pile's top and
  the mean centre height (m), fastest sphere at the end (m/s), spheres that left the walled box; settled and
  contained means none left and all slower than 0.5 m/s;
- marble on terrain: the marble's gap to the mesh surface under it (m, negative: sunk in), distance
  travelled; on the mesh means never sunk by more than half its radius and still over the terrain;
- free bodies and one body: largest distance (m) from the closed form  x0 + v0 t + g t^2 / 2; first-order
  integrators (PyBullet's and Marbellous' semi-implicit Euler) fall short by  g t h / 2  with step h, so
  correct means within  g t dt / 2  at the frame step dt (sub-stepping only shrinks the error);
- ball-jointed chains (``bench/chains.py``): the widest distance (m) between a joint's two anchors, each fixed
  in its body's frame (or the world) where the joint was made, over poses sampled at every step (a joint opens
  and closes again within a few steps); the joints hold when it stays below ``chains.MAX_GAP``, 2 cm, a
  quarter of a link;
- every scene: the deepest overlap (m) among contact points at the sampled steps.
"""
import functools
from dataclasses import dataclass

import numpy as np

import marbellous as mb
from marbellous.scenes import box_pyramid, box_tower, sphere_pile
from marbellous.scenes.free_bodies import free_bodies, free_bodies_start, free_fall_positions
from marbellous.scenes.terrain import marble_on_terrain, terrain_height, terrain_mesh

from .chains import MAX_GAP, JointGaps, chain_joints, chain_world

DT = 1.0 / 60.0
#: the piles' rolling and torsional friction (m, lever arms; 2 % of the spheres' radius, a rubber ball's
#: rolling resistance), set as a user would so that a pile comes to rest; every peer gets the same
PILE_ROLLING = PILE_TORSION = 0.01


@dataclass
class Scene:
    """One benchmark scene.  ``build(quick)`` returns ``(world, meta)``; ``sanity(trace, meta, pen)``
    returns a dict of measures with a boolean ``"ok"``; ``trace`` holds ``samples`` samples over the run
    (``bench.runs.timed_run``), each ``(step, positions)``, or with ``poses`` ``(step, positions,
    orientations)``."""
    label: str
    build: object
    steps: int
    quick_steps: int
    repeats: int
    sanity: object
    world: bool = True         # False: a query benchmark, not a stepped world
    judged_when_quick: bool = True   # False: the sanity verdict needs the full run (a pile must settle)
    samples: int = 10          # samples of the run for the sanity measure (the steps / samples apart)
    poses: bool = False        # True: the sanity measure needs the orientations too

    def n_steps(self, quick):
        return self.quick_steps if quick else self.steps

    def profile_steps(self, quick):
        return min(self.n_steps(quick), 60)

    def warmup_steps(self, quick):
        return self.n_steps(quick) // 3


# --- sanity measures ---------------------------------------------------------------------------------

def stack_sanity(trace, meta, pen):
    p0, p1 = trace[0][1], trace[-1][1]
    moved = np.linalg.norm(p1 - p0, axis=1)
    top = float(moved[-1])
    return {"top_displacement_m": top, "max_displacement_m": float(moved.max()), "max_penetration_m": pen,
            "ok": bool(top < 0.1)}


def pile_sanity(trace, meta, pen):
    p = trace[-1][1]
    speed = np.linalg.norm(trace[-1][1] - trace[-2][1], axis=1) / ((trace[-1][0] - trace[-2][0]) * DT)
    inner = meta["inner_half_width"]
    out = (np.abs(p[:, 0]) > inner + 0.01) | (np.abs(p[:, 2]) > inner + 0.01) | (p[:, 1] < -0.01)
    r = meta["radius"]
    return {"pile_top_m": float(p[:, 1].max() + r), "mean_centre_height_m": float(p[:, 1].mean()),
            "max_speed_end_m_s": float(speed.max()), "escaped": int(out.sum()), "max_penetration_m": pen,
            "ok": bool(out.sum() == 0 and speed.max() < 0.5)}


def marble_sanity(trace, meta, pen):
    r, cells, spacing = meta["radius"], meta["cells"], meta["spacing"]
    gaps = [float(p[0, 1] - terrain_height(p[0, 0], p[0, 2], cells, spacing) - r) for _, p in trace]
    start, end = trace[0][1][0], trace[-1][1][0]
    half = cells * spacing / 2.0
    inside = bool(abs(end[0]) < half and abs(end[2]) < half)
    return {"min_gap_m": min(gaps), "max_gap_m": max(gaps), "travelled_m": float(np.linalg.norm(end - start)),
            "max_penetration_m": pen, "ok": bool(min(gaps) > -0.5 * r and inside)}


def free_sanity(trace, meta, pen):
    step, p = trace[-1]
    t = step * DT
    expected = free_fall_positions(meta["positions"], meta["velocities"], meta["gravity"], t)
    err = float(np.linalg.norm(p - expected, axis=1).max())
    bound = float(np.linalg.norm(meta["gravity"])) * t * DT / 2.0
    return {"max_error_m": err, "euler_bound_m": bound, "max_penetration_m": pen,
            "ok": bool(err <= 1.01 * bound + 1e-9)}


def joint_sanity(trace, meta, pen):
    """The widest gap (m) between a joint's two anchors over the samples, the anchors fixed in the bodies' frames
    at the first sample's poses; non-finite poses count as an infinite gap."""
    gaps = JointGaps(meta["joints"], trace[0][1], trace[0][2])
    widest = max(float(np.nan_to_num(gaps(p, q), nan=np.inf).max()) for _, p, q in trace)
    return {"widest_gap_m": widest, "max_penetration_m": pen, "ok": bool(widest < MAX_GAP)}


def query_sanity(result, meta, pen):
    return result


# --- builders -------------------------------------------------------------------------------------------

def _pile(count, quick_count):
    def build(quick):
        n = quick_count if quick else count
        world, spheres = sphere_pile(count=n, rolling_friction=PILE_ROLLING, torsional_friction=PILE_TORSION)
        walls = [b for b in world.bodies if b.is_static and isinstance(b.shapes[0][0], mb.Box)]
        inner = min(max(abs(b.position[0]) - b.shapes[0][0].half_extents[0],
                        abs(b.position[2]) - b.shapes[0][0].half_extents[2]) for b in walls)
        return world, {"radius": spheres[0].shapes[0][0].radius, "inner_half_width": inner, "count": n}
    return build


def _stack(build, size, quick_size, sleeping):
    def stack(quick):
        world = build(size if not quick else quick_size)[0]
        world.sleeping = sleeping
        return world, {}
    return stack


@functools.lru_cache(maxsize=2)
def _terrain(cells):
    return terrain_mesh(cells)


def _marble(quick):
    cells = 64 if quick else 256
    world, (_, marble) = marble_on_terrain(cells=cells, mesh=_terrain(cells))
    return world, {"radius": marble.shapes[0][0].radius, "cells": cells, "spacing": 0.5,
                   "triangles": 2 * cells * cells}


def _free(count, quick_count):
    def build(quick):
        n = quick_count if quick else count
        world, _ = free_bodies(count=n)
        p, v = free_bodies_start(n)
        return world, {"positions": p, "velocities": v, "gravity": world.gravity, "count": n}
    return build


def _chains(quick):
    """The chains of ball-jointed boxes (10 of 20 links; quick: 2 of 10), and their joints as
    ``chains.chain_joints`` gives them (the bodies numbered as the world's, all dynamic; anchors in m)."""
    chains, links = (2, 10) if quick else (10, 20)
    world, _ = chain_world(chains, links)
    return world, {"joints": chain_joints(chains, links), "chains": chains, "links": links}


def _queries(quick):
    return None, {"cells": 64 if quick else 256, "queries": 500 if quick else 5000}


SCENES = {
    "pile_1k": Scene("sphere pile 1k", _pile(1000, 200), 600, 60, 1, pile_sanity, judged_when_quick=False),
    "pile_8k": Scene("sphere pile 8k", _pile(8000, 500), 600, 30, 1, pile_sanity, judged_when_quick=False),
    "pyramid_20": Scene("box pyramid base 20", _stack(lambda n: box_pyramid(base=n), 20, 10, True), 600, 60, 3,
                        stack_sanity),
    "pyramid_20_awake": Scene("box pyramid base 20, awake", _stack(lambda n: box_pyramid(base=n), 20, 10, False), 600,
                              60, 3, stack_sanity),
    "tower_20": Scene("box tower 20", _stack(lambda n: box_tower(height=n), 20, 10, True), 600, 60, 5, stack_sanity),
    "tower_20_awake": Scene("box tower 20, awake", _stack(lambda n: box_tower(height=n), 20, 10, False), 600, 60, 5,
                            stack_sanity),
    "marble_terrain": Scene("marble on 131k-tri mesh", _marble, 600, 60, 7, marble_sanity),
    "mesh_queries": Scene("sphere-mesh queries", _queries, 0, 0, 1, query_sanity, world=False),
    "free_10k": Scene("10k free bodies", _free(10000, 1000), 100, 20, 1, free_sanity),
    "one_body": Scene("one-body step", _free(1, 1), 20000, 2000, 5, free_sanity),
    "chains": Scene("ball-joint chains 10x20", _chains, 600, 60, 3, joint_sanity, samples=600, poses=True),
}


def build_scene(name, quick=False):
    """``(world, meta)`` of scene ``name``."""
    if name not in SCENES:
        raise ValueError(f"name must be one of {sorted(SCENES)}, got {name!r}")
    return SCENES[name].build(quick)
