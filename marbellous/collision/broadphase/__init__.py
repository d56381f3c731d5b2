"""Broad phases: find the pairs of bodies whose bounding boxes overlap, before the exact tests.

Seven interchangeable methods (``METHODS``) that report exactly the same pairs in one canonical order:
brute force, sweep and prune, uniform grid, dynamic AABB tree, loose octree, KD-tree and BSP tree.
The kernels in ``dispatch`` serve the step; ``BroadPhase`` is a validated Python handle.
"""
from marbellous.collision.broadphase._common import ALIVE, STATIC
from marbellous.collision.broadphase.broad_phase import BroadPhase
from marbellous.collision.broadphase.dispatch import (BRUTE, BSP, BVH, GRID, KDTREE, METHODS, OCTREE, SAP, find_pairs,
                                                      make_state, query_aabb, query_ray, state_sizes, update)

__all__ = ["ALIVE", "STATIC", "BRUTE", "SAP", "GRID", "BVH", "OCTREE", "KDTREE", "BSP", "METHODS",
           "BroadPhase", "find_pairs", "make_state", "query_aabb", "query_ray", "state_sizes",
           "update"]
