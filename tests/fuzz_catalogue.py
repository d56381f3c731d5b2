"""The catalogue of the public entry points and of bad input, shared by ``tests/test_fuzz.py`` (random
bad values drawn by hypothesis) and ``tools/fuzz_census.py`` (every listed bad value once, counted by
outcome, run against any checkout).

An *argument* is an entry point and the argument it takes, with the *kind* of value it expects
(``KINDS``); each kind lists bad values by *input class* (nan, inf, huge, tiny, negative, zero, str,
bool, complex, none, nested, shape, object, ...).  Calling the entry point with a bad value must raise
``ValueError`` or ``TypeError`` and, when a world is involved, leave its ``state_hash`` unchanged.

Only the public API is used, so the census runs unchanged against older checkouts.
"""
import math
from types import SimpleNamespace

import numpy as np

import marbellous as mb

NAN, INF = math.nan, math.inf
BIG_INT = 10 ** 400                     # does not fit a float
SUB = 5e-324                            # the smallest subnormal float


class Lazy:
    """A bad value made only inside the call (a shape whose construction may itself refuse)."""

    def __init__(self, make, text):
        self.make, self.text = make, text

    def __call__(self):
        return self.make()

    def __repr__(self):
        return self.text


# --- bad values by kind ----------------------------------------------------------------------------------
def _scalar_types(none_ok=False):
    """Values of the wrong type for a number."""
    vals = [("str", "1"), ("str", b"1"), ("bool", True), ("bool", np.bool_(False)), ("complex", 1 + 0j),
            ("complex", 2j), ("complex", np.complex128(1)), ("nested", [1.0]), ("nested", (1.0, 2.0)),
            ("nested", np.array([1.0])), ("object", object()), ("object", {}), ("object", {1.0})]
    if not none_ok:
        vals.append(("none", None))
    return vals


def _vector_types(n, none_ok=False):
    """Values of the wrong type or shape for a vector of ``n`` numbers."""
    ok = [0.5] * n
    vals = [("str", "abc"), ("str", ["1"] * n), ("str", "1" * n), ("bool", [True] * n), ("bool", np.ones(n, bool)),
            ("complex", [1j] + ok[1:]), ("complex", np.ones(n, complex)), ("nested", [ok]),
            ("nested", [[v] for v in ok]), ("nested", np.ones((n, 1))), ("shape", ok[:-1]), ("shape", ok + [0.5]),
            ("shape", []), ("number", 3.0), ("object", object()), ("object", set(ok)), ("object", [None] + ok[1:]),
            ("str", np.array(["a"] * n)), ("object", {i: v for i, v in enumerate(ok)})]
    if not none_ok:
        vals.append(("none", None))
    return vals


def _vector_values(n, bound):
    """Finite or infinite values out of range for a vector with components bounded by ``bound``."""
    ok = [0.5] * n
    return [("nan", [NAN] + ok[1:]), ("inf", ok[:-1] + [INF]), ("inf", [-INF] + ok[1:]),
            ("huge", [1e300] + ok[1:]), ("huge", [BIG_INT] + ok[1:]), ("huge", ok[:-1] + [bound * 10])]


def scalar_kind(*, lo=None, hi=None, positive=False, nonneg=False, none_ok=False, int_only=False):
    """Bad values of a scalar with the given bounds (without ``hi``, any finite value up is fine)."""
    vals = _scalar_types(none_ok) + [("nan", NAN), ("inf", INF), ("inf", -INF), ("huge", BIG_INT)]
    if hi is not None:
        vals.append(("huge", 1e300))
    if lo is not None or positive or nonneg:
        vals.append(("huge", -1e300))
    if int_only:
        vals += [("float", 2.5), ("float", 3.0)]
    elif positive:
        vals += [("tiny", SUB), ("tiny", -SUB), ("tiny", 1e-310)]
    elif nonneg or (lo is not None and lo >= 0):
        vals += [("negative", -SUB)]
    if hi is not None:
        vals.append(("huge", hi * 10 if hi > 0 else hi + 10))
    if positive:
        vals += [("zero", 0.0), ("negative", -1.0), ("zero", 0)]
    if nonneg:
        vals += [("negative", -1.0), ("negative", -1e-3)]
    if lo is not None and lo > 0:
        vals.append(("tiny", lo / 10))
    if lo is not None and lo <= 0:
        vals.append(("negative", lo - 1 if lo > -1e300 else -1e308 * 10))
    return vals


KINDS = {
    "size": scalar_kind(lo=1e-6, hi=1e6, positive=True) + [("tiny", 1e-300), ("huge", 1e7)],
    "coord": scalar_kind(lo=-1e12, hi=1e12),
    "length": scalar_kind(positive=True, hi=2e12),
    "length0": scalar_kind(nonneg=True, hi=2e12),
    "rest_length": scalar_kind(nonneg=True, hi=1e6, none_ok=True),
    "rod_length": scalar_kind(positive=True, hi=2e12, none_ok=True),
    "mass": scalar_kind(lo=1e-30, hi=1e30, positive=True, none_ok=True) + [("tiny", 1e-300)],
    "density": scalar_kind(lo=1e-6, hi=1e6, positive=True, none_ok=True),
    "friction": scalar_kind(nonneg=True, hi=1e3),
    "static_friction": scalar_kind(nonneg=True, hi=1e3, none_ok=True),
    "rolling": scalar_kind(nonneg=True, hi=1e6),
    "damping": scalar_kind(nonneg=True, hi=1e6),
    "restitution": scalar_kind(lo=0.0, hi=1.0) + [("huge", 1.5), ("negative", -0.1)],
    "stiffness": scalar_kind(nonneg=True, hi=1e15),
    "breaking": scalar_kind(positive=True, none_ok=True),
    "dt": scalar_kind(lo=1e-6, hi=1.0, positive=True) + [("tiny", 1e-300), ("huge", 10.0)],
    "frame_time": scalar_kind(nonneg=True),
    "max_distance": [v for v in scalar_kind(nonneg=True) if v[0] not in ("inf",)] + [("inf", -INF)],
    "hertz": scalar_kind(lo=1e-3, hi=1e6, positive=True),
    "nonneg": scalar_kind(nonneg=True, hi=1e9),
    "positive": scalar_kind(positive=True, hi=1e9),
    "ratio": scalar_kind(nonneg=True, hi=1e6),
    "iterations": scalar_kind(lo=1, hi=10000, int_only=True, none_ok=True) + [("zero", 0), ("negative", -1)],
    "substeps": scalar_kind(lo=1, hi=1000, int_only=True, none_ok=True) + [("zero", 0), ("negative", -1)],
    "grid_count": scalar_kind(lo=2, hi=4096, int_only=True) + [("zero", 0), ("negative", -1), ("tiny", 1)],
    "threads": scalar_kind(lo=1, hi=64, int_only=True) + [("zero", 0)],
    "max_steps": scalar_kind(lo=1, hi=1_000_000, int_only=True, none_ok=True) + [("zero", 0), ("negative", -5)],
    "max_halvings": scalar_kind(lo=0, hi=30, int_only=True) + [("negative", -1), ("huge", 31)],
    "passes": scalar_kind(lo=0, hi=100, int_only=True) + [("negative", -1), ("huge", 101)],
    "bits": _scalar_types() + [("float", 2.5), ("float", 3.0), ("nan", NAN), ("huge", 2 ** 63),
             ("huge", -(2 ** 63) - 1), ("huge", BIG_INT)],
    "flag": [("number", 1), ("number", 0), ("number", 1.0), ("str", "yes"), ("none", None), ("nested", [True])],
    "flag_or_none": [("number", 1), ("number", 0), ("number", 1.0), ("str", "yes"), ("nested", [True])],
    "choice": [("str", "magic"), ("str", ""), ("number", 3), ("none", None), ("str", b"grid"),
               ("nested", ["grid"]), ("bool", True)],
    "vec3": _vector_types(3) + _vector_values(3, 1e12),
    "offset3": _vector_types(3) + _vector_values(3, 1e6),
    "speed3": _vector_types(3) + _vector_values(3, 1e9),
    "accel3": _vector_types(3) + _vector_values(3, 1e6),
    "force3": _vector_types(3) + _vector_values(3, 1e20),
    "point3": _vector_types(3, none_ok=True) + _vector_values(3, 1e12),
    "direction": _vector_types(3) + [v for v in _vector_values(3, 1e12) if v[1][0] != 1e300 and v[1][-1] != 1e13]
    + [("zero", [0.0, 0.0, 0.0]), ("zero", np.zeros(3))],
    "quat": _vector_types(4) + [v for v in _vector_values(4, 1e12) if v[1][0] != 1e300 and v[1][-1] != 1e13]
    + [("zero", [0.0, 0.0, 0.0, 0.0])],
    "half_extents": _vector_types(3) + _vector_values(3, 1e6) + [("zero", [1.0, 0.0, 1.0]),
                                                                  ("negative", [1.0, -1.0, 1.0]),
                                                                  ("tiny", [1.0, 1e-300, 1.0]),
                                                                  ("tiny", [SUB, 1.0, 1.0])],
    "shape": [("str", "sphere"), ("none", None), ("nested", []), ("nested", [None]), ("number", 3),
              ("nested", [(mb.Sphere(1.0), "here")]), ("nested", [(mb.Sphere(1.0), (0, 0, 0), (0, 0, 0, 0))]),
              ("nested", [(mb.Sphere(1.0), (1e7, 0, 0))]), ("object", object()), ("shape", mb.Shape()),
              ("tiny", Lazy(lambda: mb.Sphere(1e-300), "Sphere(1e-300)")),
              ("tiny", Lazy(lambda: mb.Box((1.0, 1e-300, 1.0)), "Box((1, 1e-300, 1))")),
              ("tiny", Lazy(lambda: mb.Capsule(5e-324, 1.0), "Capsule(5e-324, 1)")),
              ("huge", Lazy(lambda: mb.Sphere(1e300), "Sphere(1e300)")),
              ("huge", Lazy(lambda: mb.Box((1e200, 1e200, 1e200)), "Box((1e200, 1e200, 1e200))")),
              ("tiny", Lazy(lambda: mb.ConvexHull(np.vstack([np.zeros(3), np.eye(3) * 1e-300])),
                            "ConvexHull(1e-300 tetrahedron)"))],
    "dynamic_shape": [("static_only", mb.Plane())],
    "body": [("str", "x"), ("number", 3), ("object", object())],
    "angle_limits": _vector_types(2, none_ok=True) + _vector_values(2, 4.0) + [("reversed", (0.5, -0.5)),
                                                                                ("huge", (-4.0, 0.0))],
    "position_limits": _vector_types(2, none_ok=True) + _vector_values(2, 2e12) + [("reversed", (1.0, 0.0))],
    "motor_speed": scalar_kind(lo=-1e9, hi=1e9, none_ok=True) + [("huge", -1e300)],
    "motor_max": scalar_kind(nonneg=True, hi=1e20),
    "spacing": [("str", "11"), ("number", 1.0), ("none", None), ("shape", (1.0,)), ("shape", (1.0, 1.0, 1.0)),
                ("zero", (0.0, 1.0)), ("negative", (1.0, -1.0)), ("nan", (NAN, 1.0)), ("inf", (1.0, INF)),
                ("tiny", (1e-300, 1.0)), ("tiny", (SUB, 1.0)), ("huge", (1e300, 1.0)), ("huge", (BIG_INT, 1.0)),
                ("bool", (True, True)), ("complex", (1j, 1.0)), ("nested", ((1.0,), 1.0))],
    "heights": [("str", "abc"), ("none", None), ("number", 3.0), ("shape", [1.0, 2.0]), ("shape", [[1.0, 2.0]]),
                ("shape", np.zeros((2, 2, 2))), ("nan", [[0.0, NAN], [0.0, 0.0]]), ("inf", [[0.0, INF], [0.0, 0.0]]),
                ("huge", [[0.0, 1e300], [0.0, 0.0]]), ("huge", [[0.0, BIG_INT], [0.0, 0.0]]),
                ("str", [["a", "b"], ["c", "d"]]), ("bool", np.ones((2, 2), bool)),
                ("bool", [[True, False], [1.0, 2.0]]),
                ("complex", np.ones((2, 2), complex)), ("complex", [[1j, 0.0], [0.0, 0.0]]),
                ("nested", [[0.0, 1.0], [0.0]]), ("object", [[object(), 0.0], [0.0, 0.0]])],
    "vertices": [("str", "abc"), ("none", None), ("shape", [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
                 ("shape", [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), ("nan", [[0, 0, 0], [1, NAN, 0], [0, 0, 1]]),
                 ("inf", [[0, 0, 0], [1, INF, 0], [0, 0, 1]]), ("huge", [[0, 0, 0], [1e300, 0, 0], [0, 0, 1]]),
                 ("huge", [[0, 0, 0], [BIG_INT, 0, 0], [0, 0, 1]]), ("bool", np.ones((3, 3), bool)),
                 ("complex", np.ones((3, 3), complex)), ("str", [["a"] * 3] * 3), ("nested", [[0, 0, 0], [1, 0]]),
                 ("zero", np.zeros((3, 3))), ("bool", [[True, False, True], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])],
    "points": [("str", "abc"), ("none", None), ("shape", [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]),
               ("shape", [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
               ("nan", [[0, 0, 0], [1, NAN, 0], [0, 1, 0], [0, 0, 1]]),
               ("inf", [[0, 0, 0], [1, INF, 0], [0, 1, 0], [0, 0, 1]]),
               ("huge", [[0, 0, 0], [1e300, 0, 0], [0, 1, 0], [0, 0, 1]]),
               ("huge", [[0, 0, 0], [BIG_INT, 0, 0], [0, 1, 0], [0, 0, 1]]), ("bool", np.ones((4, 3), bool)),
               ("complex", np.ones((4, 3), complex)), ("str", [["a"] * 3] * 4), ("nested", [[0, 0, 0], [1, 0]]),
               ("zero", np.zeros((4, 3))), ("flat", [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]),
               ("tiny", [[0, 0, 0], [1e-9, 0, 0], [0, 1e-9, 0], [0, 0, 1e-9]]),
               ("huge", [[0, 0, 0], [1e7, 0, 0], [0, 1e7, 0], [0, 0, 1e7]]), ("object", object())],
    "triangles": [("str", "abc"), ("none", None), ("shape", [[0, 1]]), ("shape", [[0, 1, 2, 3]]), ("shape", [0, 1, 2]),
                  ("negative", [[0, -1, 2]]), ("huge", [[0, 1, 4]]), ("huge", [[0, 1, 2 ** 62]]),
                  ("float", [[0, 1, 2.5]]), ("nan", [[0, 1, NAN]]), ("bool", [[True, False, True]]),
                  ("complex", [[0, 1, 2j]]), ("nested", [[0, 1, 2], [0, 1]]), ("zero", np.zeros((0, 3), int)),
                  ("degenerate", [[0, 1, 1]]), ("degenerate", [[0, 0, 0], [1, 1, 2]]), ("huge", [[0, 1, BIG_INT]])],
    "accel": [("str", "octree"), ("none", None), ("number", 1), ("bool", True)],
    "positions": [("str", "abc"), ("none", None), ("shape", [0.0, 0.0, 0.0, 0.0]), ("shape", [[0.0, 0.0]]),
                  ("shape", np.zeros((2, 3, 1))), ("zero", np.zeros((0, 3))), ("nan", [[0.0, NAN, 0.0]]),
                  ("inf", [[0.0, 0.0, INF]]), ("huge", [[1e300, 0.0, 0.0]]), ("huge", [[BIG_INT, 0.0, 0.0]]),
                  ("bool", np.ones((2, 3), bool)), ("complex", np.ones((2, 3), complex)),
                  ("str", [["a"] * 3]), ("nested", [[0, 0, 0], [1, 0]]), ("object", object())],
    "particle_rows": [("shape", np.zeros((2, 3))), ("shape", np.zeros((5, 3))), ("nan", np.full((3, 3), NAN)),
                      ("inf", np.full((3, 3), INF)), ("huge", np.full((3, 3), 1e300)), ("str", "abc"),
                      ("none", None), ("bool", np.ones((3, 3), bool)), ("object", object())],
    "edges": [("str", "abc"), ("none", None), ("shape", [0, 1]), ("shape", [[0, 1, 2]]),
              ("zero", np.zeros((0, 2), int)), ("negative", [[0, -1]]), ("huge", [[0, 3]]),
              ("huge", [[0, 2 ** 62]]), ("float", [[0.0, 1.0]]),
              ("nan", [[0, NAN]]), ("bool", [[True, False]]), ("complex", [[0, 1j]]), ("degenerate", [[1, 1]]),
              ("nested", [[0, 1], [2]]), ("object", object())],
    "indices": [("str", "abc"), ("float", [0.5]), ("huge", [3]), ("negative", [-4]), ("bool", [True]),
                ("complex", [1j]), ("object", object()), ("huge", [2 ** 62])],
    "cell_size": [v for v in scalar_kind(positive=True, none_ok=True)],
    "weld": [v for v in scalar_kind(positive=True, none_ok=True)] + [("huge", 1e9)],
    "action": _vector_types(2) + _vector_values(2, 1e300)[:3],
    "modulus": scalar_kind(positive=True, hi=1e15),
    "poisson": scalar_kind(lo=-0.99, hi=0.49) + [("huge", 0.5), ("negative", -1.0)],
    "radius_or_none": scalar_kind(lo=1e-6, hi=1e6, positive=True, none_ok=True),
    "tetrahedra": [("str", "abc"), ("none", None), ("shape", [[0, 1, 2]]), ("shape", [0, 1, 2, 3]),
                   ("negative", [[0, 1, 2, -1]]), ("huge", [[0, 1, 2, 8]]), ("huge", [[0, 1, 2, 2 ** 62]]),
                   ("float", [[0, 1, 2, 3.5]]), ("nan", [[0, 1, 2, NAN]]), ("bool", [[True, False, True, False]]),
                   ("complex", [[0, 1, 2, 3j]]), ("nested", [[0, 1, 2, 3], [0, 1]]), ("zero", np.zeros((0, 4), int)),
                   ("degenerate", [[0, 1, 1, 2]]), ("flat", [[0, 1, 2, 3], [0, 1, 2, 3]]),
                   ("object", object())],
    "resolution": [("str", "3"), ("none", None), ("zero", 0), ("negative", -2), ("float", 2.5), ("huge", 10 ** 6),
                   ("shape", (2, 2)), ("zero", (2, 0, 2)), ("nan", (2, NAN, 2)), ("bool", True),
                   ("object", object())],
    "max_volume": scalar_kind(positive=True, hi=1e12, none_ok=True),
    "soft_indices": [("str", "abc"), ("float", [0.5]), ("huge", [8]), ("negative", [-9]), ("bool", [True]),
                     ("complex", [1j]), ("object", object()), ("huge", [2 ** 62])],
    "soft_rows": [("shape", np.zeros((7, 3))), ("shape", np.zeros((9, 3))), ("nan", np.full((8, 3), NAN)),
                  ("inf", np.full((8, 3), INF)), ("huge", np.full((8, 3), 1e300)), ("str", "abc"),
                  ("none", None), ("bool", np.ones((8, 3), bool)), ("object", object())],
    "fluid_resolution": [("str", "44"), ("none", None), ("zero", 0), ("number", 4), ("shape", (4,)),
                         ("shape", (4, 4, 4, 4)), ("zero", (4, 0, 4)), ("negative", (4, -1)), ("float", (4, 2.5)),
                         ("huge", (4, 10 ** 6)), ("huge", (4096, 4096, 4096)), ("nan", (4, NAN)),
                         ("bool", (True, 4)), ("object", object())],
    "fluid_cell": scalar_kind(lo=1e-6, hi=1e3, positive=True),
    "fluid_density": scalar_kind(lo=1e-3, hi=1e5, positive=True),
    "fluid_viscosity": scalar_kind(nonneg=True, hi=1e3),
    "fluid_tolerance": scalar_kind(lo=1e-14, hi=0.1, positive=True),
    "surface": scalar_kind(lo=-1e12, hi=1e12, none_ok=True),
    "boundary": [("str", "open"), ("str", ""), ("none", None), ("number", 3), ("shape", ("wall",)),
                 ("shape", ("wall", "wall", "wall", "wall")), ("str", ("wall", "open", "wall")),
                 ("object", object())],
    "fluid_accel3": _vector_types(3) + _vector_values(3, 1e4),
    "wall_velocity": _vector_types(3) + _vector_values(3, 1e4) + [("normal", [0.0, 1.0, 0.0])],
    "side": [("str", "w+"), ("str", ""), ("str", "X+"), ("none", None), ("number", 1), ("object", object())],
    "fluid_velocity": [("shape", np.zeros((4, 4, 4, 2))), ("shape", np.zeros((4, 4, 3, 3))),
                       ("nan", np.full((4, 4, 4, 3), NAN)), ("inf", np.full((4, 4, 4, 3), INF)),
                       ("huge", np.full((4, 4, 4, 3), 1e300)), ("str", "abc"), ("none", None),
                       ("bool", np.ones((4, 4, 4, 3), bool)), ("object", object())],
    "fluid_dye": [("shape", np.zeros((4, 4))), ("nan", np.full((4, 4, 4), NAN)), ("inf", np.full((4, 4, 4), INF)),
                  ("huge", np.full((4, 4, 4), 1e300)), ("str", "abc"), ("none", None),
                  ("bool", np.ones((4, 4, 4), bool)), ("object", object())],
    "fluid_points": [("shape", np.zeros((2, 2))), ("shape", np.zeros((2, 3, 1))), ("nan", [[NAN, 0.0, 0.0]]),
                     ("inf", [[0.0, INF, 0.0]]), ("huge", [[1e13, 0.0, 0.0]]), ("str", "abc"), ("none", None),
                     ("bool", [[True, False, True]]), ("object", object())],
    "fluid": [("str", "water"), ("none", None), ("number", 3), ("object", object()),
              ("2d", Lazy(lambda: mb.Fluid((4, 4), 0.1), "Fluid((4, 4), 0.1)"))],
}
# (a tetrahedron 1e7 m across is a valid soft body, unlike a convex hull of that size)
KINDS["tet_points"] = [v for v in KINDS["points"] if not (v[0] == "huge" and np.shape(v[1]) == (4, 3)
                                                            and np.max(np.abs(v[1])) == 1e7)]


# --- the world fixture --------------------------------------------------------------------------------
def make_world():
    """A small world after one step: a plane, a ball, a box, a static box, a spring between the ball and
    the box, an arm on a hinge and a cart on a slider (``ns.w``, ``ns.ball``, ``ns.box``, ``ns.ground``,
    ``ns.post``, ``ns.spring``, ``ns.hinge``, ``ns.slider``, ``ns.platform``, a kinematic box), three beads on
    a spring network (``ns.beads``, ``ns.network``), a cloth of one triangle (``ns.sheet``), a soft cube of
    six tetrahedra (``ns.jelly``) and a pool of fluid, 4^3 cells (``ns.pool``)."""
    w = mb.World()
    ground = w.add_static(mb.Plane())
    post = w.add_static(mb.Box((0.5, 0.5, 0.5)), position=(4, 0.5, 0))
    ball = w.add_body(mb.Sphere(0.3), position=(0, 1, 0), velocity=(0.5, 0, 0))
    box = w.add_body(mb.Box((0.2, 0.3, 0.4)), position=(1.5, 1, 0))
    spring = w.add_spring(ball, box, rest_length=1.0, stiffness=10.0)
    arm = w.add_body(mb.Box((0.3, 0.05, 0.05)), position=(-2, 1, 0))
    hinge = w.add_hinge(arm, None, anchor=(-2.3, 1, 0), axis=(0, 0, 1), limits=(-1.0, 1.0))
    cart = w.add_body(mb.Box((0.1, 0.1, 0.1)), position=(-4, 1, 0))
    slider = w.add_slider(cart, None, anchor=(-4, 1, 0), axis=(1, 0, 0), limits=(-1.0, 1.0))
    platform = w.add_kinematic(mb.Box((0.5, 0.1, 0.5)), position=(0, 2, 3), velocity=(0.1, 0, 0))
    beads = w.add_particles([(2, 1, 2), (2.2, 1, 2), (2.4, 1, 2)], radius=0.05, collide_particles=True)
    network = w.add_network(beads, [(0, 1), (1, 2)], kind="spring", stiffness=100.0)
    sheet = w.add_cloth([(3, 1, 3), (3.3, 1, 3), (3, 1, 3.3)], [(0, 1, 2)], mass=0.01)
    jelly = w.add_soft_body(*mb.tet_box((0.1, 0.1, 0.1), 1), position=(-3, 0.5, 3))
    pool = w.add_fluid(mb.Fluid((4, 4, 4), 0.5, origin=(-1, 0, -1), surface=1.0))
    w.step(1 / 60)
    return SimpleNamespace(w=w, ground=ground, post=post, ball=ball, box=box, spring=spring, hinge=hinge,
                           slider=slider, platform=platform, beads=beads, network=network, sheet=sheet, jelly=jelly,
                           pool=pool)


def _setter(obj_name, attr):
    def call(ns, v):
        setattr(getattr(ns, obj_name), attr, v)
    return call


def _kw(method, fixed=None, **defaults):
    """A call of ``ns.w.<method>`` (or a dotted path like ``ball.apply_force``) with one argument replaced."""
    def make(arg):
        def call(ns, v):
            obj = ns
            for part in method.split("."):
                obj = getattr(obj, part)
            kw = dict(defaults)
            kw[arg] = v
            pos = [kw.pop(k) for k in (fixed or [])]
            return obj(*pos, **kw)
        return call
    return make


_SPHERE = mb.Sphere(0.5)

# (entry point, argument, kind, call(ns, value), needs a world)
WORLD_ARGS = []


def _add(entry, arg, kind, call, world=True):
    def made(ns, v, _call=call):
        return _call(ns, v() if isinstance(v, Lazy) else v)
    WORLD_ARGS.append((entry, arg, kind, made, world))


for _arg, _kind in (("gravity", "accel3"), ("solver", "choice"), ("integrator", "choice"), ("broadphase", "choice"),
                    ("iterations", "iterations"), ("substeps", "substeps"), ("threads", "threads"),
                    ("ccd", "flag"), ("sleeping", "flag"), ("time_stepping", "choice")):
    _add("World()", _arg, _kind, (lambda a: lambda ns, v: mb.World(**{a: v}))(_arg), world=False)
    _add("World setter", _arg, _kind, _setter("w", _arg))
_add("World setter", "profiling", "flag", _setter("w", "profiling"))
_add("World setter", "adaptive_iterations", "flag", _setter("w", "adaptive_iterations"))
_add("World setter", "pair_cache", "flag", _setter("w", "pair_cache"))
_add("World setter", "solve_order", "choice", _setter("w", "solve_order"))
_add("World setter", "max_halvings", "max_halvings", _setter("w", "max_halvings"))
for _arg, _kind in (("speculative_distance", "nonneg"), ("contact_hertz", "hertz"), ("contact_damping_ratio", "ratio"),
                    ("joint_hertz", "hertz"), ("joint_damping_ratio", "ratio"), ("max_push_speed", "positive"),
                    ("slide_speed", "nonneg"), ("velocity_tolerance", "nonneg"), ("sleep_linear_speed", "nonneg"),
                    ("sleep_angular_speed", "nonneg"), ("time_to_sleep", "positive"), ("penalty_hertz", "hertz"),
                    ("lcp_relaxation", "positive"), ("max_penetration", "positive")):
    _add("World tunable", _arg, _kind, _setter("w", _arg))

_body = _kw("w.add_body", fixed=["shape"], shape=_SPHERE, position=(3, 2, 0))
for _arg, _kind in (("shape", "shape"), ("shape", "dynamic_shape"), ("position", "vec3"), ("orientation", "quat"),
                    ("velocity", "speed3"), ("angular_velocity", "speed3"), ("mass", "mass"), ("density", "density"),
                    ("friction", "friction"), ("static_friction", "static_friction"), ("restitution", "restitution"),
                    ("rolling_friction", "rolling"), ("torsional_friction", "rolling"), ("linear_damping", "damping"),
                    ("angular_damping", "damping"), ("sensor", "flag"), ("group", "bits"), ("mask", "bits"),
                    ("ccd", "flag_or_none")):
    _add("World.add_body", _arg, _kind, _body(_arg))
_static = _kw("w.add_static", fixed=["shape"], shape=mb.Box((1, 1, 1)), position=(-3, 0, 0))
for _arg, _kind in (("shape", "shape"), ("position", "vec3"), ("orientation", "quat"), ("friction", "friction"),
                    ("restitution", "restitution"), ("torsional_friction", "rolling"), ("sensor", "flag"),
                    ("group", "bits"), ("mask", "bits")):
    _add("World.add_static", _arg, _kind, _static(_arg))

def _between(method, defaults, arg):
    """A call of ``ns.w.<method>(ball, box, **defaults)`` (a constraint between two bodies) with ``arg``
    (one of its keywords, or ``a`` / ``b``) replaced."""
    def call(ns, v):
        kw = dict(defaults)
        kw.update(a=ns.ball, b=ns.box)
        kw[arg] = v
        a, b = kw.pop("a"), kw.pop("b")
        return getattr(ns.w, method)(a, b, **kw)
    return call


for _method, _args in (
        ("add_spring", (("rest_length", "length0"), ("stiffness", "stiffness"), ("damping", "stiffness"),
                        ("anchor_a", "vec3"), ("anchor_b", "vec3"), ("breaking_force", "breaking"), ("a", "body"),
                        ("b", "body"))),
        ("add_rod", (("length", "length"), ("anchor_a", "vec3"), ("anchor_b", "vec3"), ("a", "body"), ("b", "body"))),
        ("add_cable", (("max_length", "length"), ("anchor_a", "vec3"), ("anchor_b", "vec3"), ("a", "body")))):
    _defaults = {"add_spring": dict(rest_length=1.0, stiffness=5.0), "add_rod": dict(length=1.0),
                 "add_cable": dict(max_length=2.0)}[_method]
    for _arg, _kind in _args:
        _add(f"World.{_method}", _arg, "rod_length" if _method == "add_rod" and _arg == "length" else _kind,
             _between(_method, _defaults, _arg))

_JOINTS = {"add_ball_joint": (dict(anchor=(0.7, 1.0, 0.0)), (("anchor", "vec3"), ("breaking_force", "breaking"))),
           "add_hinge": (dict(anchor=(0.7, 1.0, 0.0), axis=(0.0, 0.0, 1.0)),
                         (("anchor", "vec3"), ("axis", "direction"), ("limits", "angle_limits"),
                          ("motor_speed", "motor_speed"), ("max_motor_torque", "motor_max"),
                          ("breaking_force", "breaking"))),
           "add_slider": (dict(anchor=(0.7, 1.0, 0.0), axis=(1.0, 0.0, 0.0)),
                          (("anchor", "vec3"), ("axis", "direction"), ("limits", "position_limits"),
                           ("motor_speed", "motor_speed"), ("max_motor_force", "motor_max"),
                           ("breaking_force", "breaking"))),
           "add_fixed_joint": ({}, (("breaking_force", "breaking"),))}
for _method, (_defaults, _args) in _JOINTS.items():
    for _arg, _kind in _args + (("a", "body"), ("b", "body")):
        _add(f"World.{_method}", _arg, _kind, _between(_method, _defaults, _arg))
_add("Hinge setter", "motor_speed", "motor_speed", _setter("hinge", "motor_speed"))
_add("Hinge setter", "limits", "angle_limits", _setter("hinge", "limits"))
_add("Hinge setter", "max_motor_torque", "motor_max", _setter("hinge", "max_motor_torque"))
_add("Slider setter", "limits", "position_limits", _setter("slider", "limits"))
_add("Slider setter", "max_motor_force", "motor_max", _setter("slider", "max_motor_force"))

_add("World.step", "dt", "dt", lambda ns, v: ns.w.step(v))
_add("World.advance", "frame_time", "frame_time", lambda ns, v: ns.w.advance(v))
_add("World.advance", "dt", "dt", lambda ns, v: ns.w.advance(0.02, dt=v))
_add("World.advance", "max_steps", "max_steps", lambda ns, v: ns.w.advance(0.02, max_steps=v))
_kinematic = _kw("w.add_kinematic", fixed=["shape"], shape=mb.Box((0.5, 0.1, 0.5)), position=(0, 3, 3))
for _arg, _kind in (("shape", "shape"), ("shape", "dynamic_shape"), ("position", "vec3"), ("orientation", "quat"),
                    ("velocity", "speed3"), ("angular_velocity", "speed3"), ("friction", "friction"),
                    ("restitution", "restitution"), ("torsional_friction", "rolling"), ("sensor", "flag"),
                    ("group", "bits"), ("mask", "bits")):
    _add("World.add_kinematic", _arg, _kind, _kinematic(_arg))
_add("Body.move_to", "position", "vec3", lambda ns, v: ns.platform.move_to(v, (1, 0, 0, 0), 1 / 60))
_add("Body.move_to", "orientation", "quat", lambda ns, v: ns.platform.move_to((0, 2, 3), v, 1 / 60))
_add("Body.move_to", "dt", "dt", lambda ns, v: ns.platform.move_to((0, 2, 3), (1, 0, 0, 0), v))
_add("World.raycast", "origin", "vec3", lambda ns, v: ns.w.raycast(v, (0, -1, 0)))
_add("World.raycast", "direction", "direction", lambda ns, v: ns.w.raycast((0, 5, 0), v))
_add("World.raycast", "max_distance", "max_distance", lambda ns, v: ns.w.raycast((0, 5, 0), (0, -1, 0), v))
_add("World.raycast", "mask", "bits", lambda ns, v: ns.w.raycast((0, 5, 0), (0, -1, 0), mask=v))
_add("World.query_box", "lower", "vec3", lambda ns, v: ns.w.query_box(v, (1e12, 1e12, 1e12)))
_add("World.query_box", "upper", "vec3", lambda ns, v: ns.w.query_box((-1e12, -1e12, -1e12), v))
for _kind in ("shape", "dynamic_shape"):
    _add("World.shape_cast", "shape", _kind, lambda ns, v: ns.w.shape_cast(v, (0, 5, 0), (0, -5, 0)))
_add("World.shape_cast", "start", "vec3", lambda ns, v: ns.w.shape_cast(_SPHERE, v, (0, -5, 0)))
_add("World.shape_cast", "end", "vec3", lambda ns, v: ns.w.shape_cast(_SPHERE, (0, 5, 0), v))
_add("World.shape_cast", "orientation", "quat", lambda ns, v: ns.w.shape_cast(mb.Box((1, 1, 1)), (0, 5, 0),
                                                                              (0, -5, 0), orientation=v))
_add("World.shape_cast", "mask", "bits", lambda ns, v: ns.w.shape_cast(_SPHERE, (0, 5, 0), (0, -5, 0), mask=v))
_add("World.remove", "body_or_constraint", "body", lambda ns, v: ns.w.remove(v))

for _arg, _kind in (("position", "vec3"), ("orientation", "quat"), ("velocity", "speed3"),
                    ("angular_velocity", "speed3"), ("group", "bits"), ("mask", "bits"), ("friction", "friction"),
                    ("static_friction", "friction"), ("restitution", "restitution"), ("rolling_friction", "rolling"),
                    ("torsional_friction", "rolling"), ("linear_damping", "damping"), ("angular_damping", "damping")):
    _add("Body setter", _arg, _kind, _setter("ball", _arg))
for _arg, _kind in (("friction", "friction"), ("restitution", "restitution"), ("torsional_friction", "rolling")):
    _add("Body setter (static)", _arg, _kind, _setter("ground", _arg))
_add("Body.apply_force", "force", "force3", lambda ns, v: ns.ball.apply_force(v))
_add("Body.apply_force", "point", "point3", lambda ns, v: ns.ball.apply_force((1, 0, 0), point=v))
_add("Body.apply_torque", "torque", "force3", lambda ns, v: ns.ball.apply_torque(v))
_add("Body.apply_impulse", "impulse", "force3", lambda ns, v: ns.ball.apply_impulse(v))
_add("Body.apply_impulse", "point", "point3", lambda ns, v: ns.ball.apply_impulse((1, 0, 0), point=v))

# (four particles: a list of one to three masses or radii, a wrong-type value of the fuzz, is never one each)
_particles = _kw("w.add_particles", fixed=["positions"], positions=[(0, 3, 0), (0.1, 3, 0), (0.2, 3, 0), (0.3, 3, 0)])
for _arg, _kind in (("positions", "positions"), ("mass", "mass"), ("mass", "particle_rows"), ("radius", "size"),
                    ("velocity", "speed3"), ("friction", "friction"), ("static_friction", "static_friction"),
                    ("restitution", "restitution"), ("damping", "damping"), ("collide_particles", "flag")):
    _add("World.add_particles", _arg, _kind, _particles(_arg))


def _network(arg):
    """A call of ``ns.w.add_network(ns.beads, ...)`` with ``arg`` replaced."""
    def call(ns, v):
        # (four edges: a list of one to three rest lengths, a wrong-type value of the fuzz, is never one each)
        kw = dict(edges=[(0, 2), (0, 1), (1, 2), (0, 2)], kind="spring", stiffness=10.0)
        kw[arg] = v
        return ns.w.add_network(ns.beads, kw.pop("edges"), **kw)
    return call


for _arg, _kind in (("edges", "edges"), ("kind", "choice"), ("stiffness", "stiffness"), ("damping", "damping"),
                    ("rest_length", "rest_length"), ("breaking_force", "breaking")):
    _add("World.add_network", _arg, _kind, _network(_arg))
_add("World.add_network", "particles", "body", lambda ns, v: ns.w.add_network(v, [(0, 1)], kind="rod"))
_add("World setter", "particle_substeps", "substeps", _setter("w", "particle_substeps"))
_add("World setter", "cloth_stretch_passes", "passes", _setter("w", "cloth_stretch_passes"))
_add("Particles setter", "positions", "particle_rows", _setter("beads", "positions"))
_add("Particles setter", "velocities", "particle_rows", _setter("beads", "velocities"))
_add("Particles.pin", "indices", "indices", lambda ns, v: ns.beads.pin(v))
_add("Particles.pin", "body", "body", lambda ns, v: ns.beads.pin([0], body=v))
_add("Particles.unpin", "indices", "indices", lambda ns, v: ns.beads.unpin(v))
_add("Particles.apply_force", "force", "force3", lambda ns, v: ns.beads.apply_force(v))
_add("Particles.apply_force", "indices", "indices", lambda ns, v: ns.beads.apply_force((1, 0, 0), v))



def _cloth(arg):
    """A call of ``ns.w.add_cloth`` (a square of two triangles; one triangle when ``arg`` is the vertices)
    with ``arg`` replaced."""
    def call(ns, v):
        kw = dict(vertices=[(0, 3, 0), (1, 3, 0), (0, 3, 1), (1, 3, 1)], triangles=[(0, 1, 2), (1, 3, 2)], mass=0.1)
        if arg == "vertices":
            kw["triangles"] = [(0, 1, 2)]
        kw[arg] = v
        return ns.w.add_cloth(kw.pop("vertices"), kw.pop("triangles"), **kw)
    return call


for _arg, _kind in (("vertices", "vertices"), ("triangles", "triangles"), ("mass", "mass"),
                    ("stretch_stiffness", "stiffness"), ("bend_stiffness", "stiffness"), ("damping", "damping"),
                    ("thickness", "size"), ("friction", "friction"), ("self_collision", "flag"),
                    ("tear_strain", "breaking"), ("position", "vec3"), ("orientation", "quat")):
    _add("World.add_cloth", _arg, _kind, _cloth(_arg))
_add("Cloth setter", "positions", "particle_rows", _setter("sheet", "positions"))
_add("Cloth setter", "velocities", "particle_rows", _setter("sheet", "velocities"))
_add("Cloth.pin", "indices", "indices", lambda ns, v: ns.sheet.pin(v))
_add("Cloth.pin", "body", "body", lambda ns, v: ns.sheet.pin([0], body=v))
_add("Cloth.unpin", "indices", "indices", lambda ns, v: ns.sheet.unpin(v))
_add("Cloth.apply_force", "force", "force3", lambda ns, v: ns.sheet.apply_force(v))
_add("Cloth.apply_force", "indices", "indices", lambda ns, v: ns.sheet.apply_force((1, 0, 0), v))
_add("cloth_grid()", "width", "size", lambda ns, v: mb.cloth_grid(v, 1.0, 3, 3), world=False)
_add("cloth_grid()", "depth", "size", lambda ns, v: mb.cloth_grid(1.0, v, 3, 3), world=False)
_add("cloth_grid()", "nx", "grid_count", lambda ns, v: mb.cloth_grid(1.0, 1.0, v, 3), world=False)
_add("cloth_grid()", "nz", "grid_count", lambda ns, v: mb.cloth_grid(1.0, 1.0, 3, v), world=False)


def _soft(arg):
    """A call of ``ns.w.add_soft_body`` (a cube of six tetrahedra) with ``arg`` replaced."""
    def call(ns, v):
        vertices, tetrahedra = mb.tet_box((0.2, 0.2, 0.2), 1)
        kw = dict(vertices=vertices, tetrahedra=tetrahedra, position=(0, 5, 0))
        if arg == "vertices":
            kw["tetrahedra"] = [(0, 1, 2, 3)]
        kw[arg] = v
        return ns.w.add_soft_body(kw.pop("vertices"), kw.pop("tetrahedra"), **kw)
    return call


for _arg, _kind in (("vertices", "tet_points"), ("tetrahedra", "tetrahedra"), ("density", "density"),
                    ("young_modulus", "modulus"), ("poisson_ratio", "poisson"), ("damping", "damping"),
                    ("friction", "friction"), ("position", "vec3"), ("orientation", "quat"),
                    ("radius", "radius_or_none")):
    _add("World.add_soft_body", _arg, _kind, _soft(_arg))
_add("SoftBody setter", "positions", "soft_rows", _setter("jelly", "positions"))
_add("SoftBody setter", "velocities", "soft_rows", _setter("jelly", "velocities"))
_add("SoftBody.pin", "indices", "soft_indices", lambda ns, v: ns.jelly.pin(v))
_add("SoftBody.pin", "body", "body", lambda ns, v: ns.jelly.pin([0], body=v))
_add("SoftBody.unpin", "indices", "soft_indices", lambda ns, v: ns.jelly.unpin(v))
_add("SoftBody.apply_force", "force", "force3", lambda ns, v: ns.jelly.apply_force(v))
_add("SoftBody.apply_force", "indices", "soft_indices", lambda ns, v: ns.jelly.apply_force((1, 0, 0), v))
_add("tet_box()", "half_extents", "half_extents", lambda ns, v: mb.tet_box(v, 2), world=False)
_add("tet_box()", "resolution", "resolution", lambda ns, v: mb.tet_box((1, 1, 1), v), world=False)
_add("tetrahedralize()", "surface_vertices", "tet_points",
     lambda ns, v: mb.tetrahedralize(v, [(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)]), world=False)
_add("tetrahedralize()", "surface_triangles", "triangles",
     lambda ns, v: mb.tetrahedralize(np.vstack([np.zeros(3), np.eye(3)]), v), world=False)
_add("tetrahedralize()", "max_volume", "max_volume",
     lambda ns, v: mb.tetrahedralize(np.vstack([np.zeros(3), np.eye(3)]), [(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)],
                                     max_volume=v), world=False)

# fluids
def _fluid(arg):
    """A call of ``mb.Fluid`` (3D, 4^3 cells) with ``arg`` replaced."""
    def call(ns, v):
        kw = dict(resolution=(4, 4, 4), cell_size=0.5)
        kw[arg] = v
        return mb.Fluid(**kw)
    return call


for _arg, _kind in (("resolution", "fluid_resolution"), ("cell_size", "fluid_cell"), ("origin", "vec3"),
                    ("density", "fluid_density"), ("viscosity", "fluid_viscosity"), ("boundary", "boundary"),
                    ("surface", "surface"), ("tolerance", "fluid_tolerance")):
    _add("Fluid()", _arg, _kind, _fluid(_arg), world=False)
_add("Fluid setter", "velocity", "fluid_velocity", _setter("pool", "velocity"))
_add("Fluid setter", "dye", "fluid_dye", _setter("pool", "dye"))
_add("Fluid setter", "body_force", "fluid_accel3", _setter("pool", "body_force"))
_add("Fluid setter", "viscosity", "fluid_viscosity", _setter("pool", "viscosity"))
_add("Fluid setter", "surface", "surface", _setter("pool", "surface"))
_add("Fluid.set_wall_velocity", "side", "side", lambda ns, v: ns.pool.set_wall_velocity(v, (0.0, 0.0, 0.0)))
_add("Fluid.set_wall_velocity", "velocity", "wall_velocity", lambda ns, v: ns.pool.set_wall_velocity("y+", v))
_add("Fluid.velocity_at", "points", "fluid_points", lambda ns, v: ns.pool.velocity_at(v))
_add("Fluid.dye_at", "points", "fluid_points", lambda ns, v: ns.pool.dye_at(v))
_add("Fluid.step", "dt", "dt", lambda ns, v: mb.Fluid((4, 4), 0.5).step(v), world=False)
_add("World.add_fluid", "fluid", "fluid", lambda ns, v: ns.w.add_fluid(v))

# many worlds
KINDS["world"] = [("number", 3), ("none", None), ("str", "w"), ("object", object()), ("nested", [[]])]
_add("step_worlds", "dt", "dt", lambda ns, v: mb.step_worlds([ns.w], v))
_add("step_worlds", "threads", "threads", lambda ns, v: mb.step_worlds([ns.w], 1 / 60, threads=v))
_add("step_worlds", "worlds", "world", lambda ns, v: mb.step_worlds([ns.w, v], 1 / 60))
_add("step_worlds", "worlds", "world", lambda ns, v: mb.step_worlds(v, 1 / 60))

# sweeps and the autopilot trial they run (no world)
KINDS["runs"] = [("number", 3), ("none", None), ("str", "x=1"), ("object", object()), ("nested", [[1]]),
                 ("nested", [{1: 2}]), ("dict", {"x": 1})]
KINDS["workers"] = scalar_kind(lo=1, hi=4096, int_only=True, none_ok=True) + [("zero", 0), ("negative", -2)]
KINDS["axis"] = [("number", 3), ("none", None), ("str", "abc"), ("dict", {"k": 1}), ("object", object()),
                 ("empty", [])]
KINDS["level_name"] = [("number", 3.5), ("none", None), ("str", "nosuch-level"), ("object", object()),
                       ("nested", ["course"])]
_add("sweep()", "runs", "runs", lambda ns, v: mb.sweep(_sweep_run, v), world=False)
_add("sweep()", "backend", "choice", lambda ns, v: mb.sweep(_sweep_run, [{"x": 1}], backend=v), world=False)
_add("sweep()", "workers", "workers",
     lambda ns, v: mb.sweep(_sweep_run, [{"x": 1}], backend="processes", workers=v), world=False)
_add("grid()", "a", "axis", lambda ns, v: mb.grid(a=v), world=False)


def _sweep_run(x):
    return {"y": x}


def _trial(arg, **fixed):
    def call(ns, v):
        from marbellous.game.trial import autopilot_trial

        return autopilot_trial(**{"seconds": 0.1, **fixed, arg: v})
    return call


def _trial_numbers(arg):
    def call(ns, v):
        from marbellous.game.trial import trial_numbers

        return trial_numbers(**{arg: v})
    return call


for _arg, _kind in (("level", "level_name"), ("friction", "friction"), ("push", "nonneg"),
                    ("start_offset", "coord"), ("seconds", "nonneg"), ("flag", "flag")):
    _add("autopilot_trial()", _arg, _kind, _trial(_arg), world=False)
    if _arg != "level":              # (the level file is read by the trial, not by its check of the numbers)
        _add("trial_numbers()", _arg, _kind, _trial_numbers(_arg), world=False)

# shapes (no world)
_add("Sphere()", "radius", "size", lambda ns, v: mb.Sphere(v), world=False)
_add("Box()", "half_extents", "half_extents", lambda ns, v: mb.Box(v), world=False)
_add("Capsule()", "radius", "size", lambda ns, v: mb.Capsule(v, 0.5), world=False)
_add("Capsule()", "half_height", "size", lambda ns, v: mb.Capsule(0.5, v), world=False)
_add("Plane()", "normal", "direction", lambda ns, v: mb.Plane(normal=v), world=False)
_add("Plane()", "offset", "coord", lambda ns, v: mb.Plane(offset=v), world=False)
_add("HeightField()", "heights", "heights", lambda ns, v: mb.HeightField(v), world=False)
_add("HeightField()", "spacing", "spacing", lambda ns, v: mb.HeightField(np.zeros((3, 3)), spacing=v), world=False)
_add("HeightField()", "origin", "vec3", lambda ns, v: mb.HeightField(np.zeros((3, 3)), origin=v), world=False)
_FIELD = mb.HeightField(np.zeros((4, 4)))
_add("HeightField.height_at", "x", "coord", lambda ns, v: _FIELD.height_at(v, 1.0), world=False)
_add("HeightField.raycast", "direction", "direction", lambda ns, v: _FIELD.raycast((1, 5, 1), v), world=False)
_QUAD = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 1], [1, 0, 1]], float)
_add("TriangleMesh()", "vertices", "vertices", lambda ns, v: mb.TriangleMesh(v, [[0, 2, 1]]), world=False)
_add("TriangleMesh()", "triangles", "triangles", lambda ns, v: mb.TriangleMesh(_QUAD, v), world=False)
_add("TriangleMesh()", "accel", "accel", lambda ns, v: mb.TriangleMesh(_QUAD, [[0, 2, 1]], accel=v), world=False)
_add("TriangleMesh()", "cell_size", "cell_size",
     lambda ns, v: mb.TriangleMesh(_QUAD, [[0, 2, 1]], cell_size=v), world=False)
_add("TriangleMesh()", "weld_tolerance", "weld",
     lambda ns, v: mb.TriangleMesh(_QUAD, [[0, 2, 1]], weld_tolerance=v), world=False)
_add("ConvexHull()", "points", "points", lambda ns, v: mb.ConvexHull(v), world=False)
_add("collide()", "shape_a", "shape", lambda ns, v: mb.collide(v, _SPHERE), world=False)
_add("collide()", "position_a", "vec3", lambda ns, v: mb.collide(_SPHERE, _SPHERE, position_a=v), world=False)
_add("collide()", "orientation_b", "quat", lambda ns, v: mb.collide(_SPHERE, _SPHERE, orientation_b=v), world=False)


def world_cases():
    """Every (entry, argument, class, value, call, needs a world) of ``WORLD_ARGS`` x ``KINDS``."""
    out = []
    for entry, arg, kind, call, world in WORLD_ARGS:
        for klass, value in KINDS[kind]:
            out.append((entry, arg, klass, value, call, world))
    return out


# --- shapes after construction: every attribute assignment must raise AttributeError ----------------------
def immutable_cases():
    """(shape name, attribute, new value, shape factory): assigning must raise AttributeError; the census
    also steps a world holding the shape afterwards (a changed mesh used to crash the step)."""
    v = np.array([[0, 0, 0], [4, 0, 0], [0, 0, 4], [4, 0, 4]], float)
    return [
        ("Sphere", "radius", -1.0, lambda: mb.Sphere(0.5)),
        ("Box", "half_extents", (0.0, 0.0, 0.0), lambda: mb.Box((1, 1, 1))),
        ("Capsule", "half_height", 1e9, lambda: mb.Capsule(0.5, 0.5)),
        ("Plane", "normal", (0.0, 0.0, 0.0), lambda: mb.Plane()),
        ("Plane", "offset", math.nan, lambda: mb.Plane()),
        ("HeightField", "dx", 0.0, lambda: mb.HeightField(np.zeros((3, 3)))),
        ("HeightField", "heights", np.zeros((50, 50)), lambda: mb.HeightField(np.zeros((3, 3)))),
        ("TriangleMesh", "triangles", np.array([[0, 2, 1]] * 1000000 + [[3, 2, 1]]),
         lambda: mb.TriangleMesh(v, [[0, 2, 1], [1, 2, 3]], accel="brute")),
        ("TriangleMesh", "vertices", v[:3] * 1e6, lambda: mb.TriangleMesh(v, [[0, 2, 1], [1, 2, 3]])),
        ("TriangleMesh", "accel", "bvh", lambda: mb.TriangleMesh(v, [[0, 2, 1], [1, 2, 3]])),
        ("ConvexHull", "vertices", np.zeros((4, 3)), lambda: mb.ConvexHull(np.vstack([np.zeros(3), np.eye(3)]))),
    ]


def inplace_cases():
    """(name, shape factory, attribute): editing the returned array in place must raise or change a copy."""
    return [("Box.half_extents", lambda: mb.Box((1, 1, 1)), "half_extents"),
            ("Plane.normal", lambda: mb.Plane(), "normal"),
            ("HeightField.heights", lambda: mb.HeightField(np.zeros((3, 3))), "heights"),
            ("HeightField.origin", lambda: mb.HeightField(np.zeros((3, 3))), "origin"),
            ("TriangleMesh.vertices", lambda: mb.TriangleMesh(_QUAD, [[0, 2, 1]]), "vertices"),
            ("ConvexHull.vertices", lambda: mb.ConvexHull(np.vstack([np.zeros(3), np.eye(3)])), "vertices"),
            ("ConvexHull.centroid", lambda: mb.ConvexHull(np.vstack([np.zeros(3), np.eye(3)])), "centroid")]


# --- files -------------------------------------------------------------------------------------------------
GOOD_LEVEL = """name = "T"
[start]
position = [0.0, 1.0, 0.0]
[goal]
center = [5.0, 1.0, 0.0]
half_extents = [1.0, 1.0, 1.0]
[materials.m]
friction = 0.5
[[colliders]]
type = "box"
half_extents = [10.0, 0.5, 10.0]
position = [0.0, -0.5, 0.0]
material = "m"
"""
_BOX = 'type = "box"\nhalf_extents = [10.0, 0.5, 10.0]\nposition = [0.0, -0.5, 0.0]'


def _good_obj():
    return "v 0 0 0\nv 1 0 0\nv 0 0 1\nv 1 0 1\nf 1 3 2\nf 2 3 4\n"


def mesh_files():
    """(class, file name, bytes): bad mesh files; ``TriangleMesh.load`` must raise ValueError naming the file."""
    good = _good_obj()
    return [
        ("empty", "empty.obj", b""),
        ("garbage", "garbage.stl", bytes(range(256)) * 8),
        ("garbage", "garbage.glb", b"glTF\x02\x00\x00\x00\xff\xff\xff\x7f" + bytes(range(256)) * 4),
        ("truncated", "cut_face.obj", (good + "f 1 2").encode()),
        ("truncated", "cut_vertex.obj", (b"v 0 0 0\nv 1 0 0\nv 0 0\nf 1 2 3\n")),
        ("truncated", "cut_continuation.obj", (good + "f 1 2 \\").encode()),
        ("nan", "nan.obj", good.replace("v 1 0 0", "v 1 nan 0").encode()),
        ("inf", "inf.obj", good.replace("v 1 0 0", "v 1 1e999 0").encode()),
        ("huge", "huge.obj", good.replace("v 1 0 0", "v 1 1e300 0").encode()),
        ("index", "zero_index.obj", (good + "f 0 1 2\n").encode()),
        ("index", "big_index.obj", (good + "f 1 2 99\n").encode()),
        ("index", "huge_index.obj", (good + "f 1 2 99999999999999999999999\n").encode()),
        ("index", "word_index.obj", (good + "f 1 2 x\n").encode()),
        ("degenerate", "degenerate.obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n"),
        ("no_faces", "points.obj", b"v 0 0 0\nv 1 0 0\nv 0 0 1\n"),
        ("binary", "binary.obj", bytes(range(256)) * 4),
        ("hostile", "hostile.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 999999999999\n"
                                   b"property float x\nproperty float y\nproperty float z\nelement face 999999999\n"
                                   b"property list uchar int vertex_indices\nend_header\n\x00\x00\x00\x00"),
        ("extension", "mesh.txt", good.encode()),
    ]


def good_mesh_files():
    """(name, bytes) of mesh files that must load: UTF-8 and Latin-1 names and comments, polygons."""
    good = _good_obj()
    return [("latin1.obj", ("# caf\u00e9 \u00e0 la cr\u00e8me\no d\u00e9cor\n" + good).encode("latin-1")),
            ("utf8.obj", ("# caf\u00e9 \u2014 \u65e5\u672c\no d\u00e9cor\n" + good).encode("utf-8")),
            ("quad.obj", b"v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1/1/1 4/2/2 3//3 2\n"),
            ("negative.obj", b"v 0 0 0\nv 1 0 0\nv 0 0 1\nf -3 -1 -2\n"),
            ("utf16.obj", ("# caf\u00e9\n" + good).encode("utf-16"))]


def level_texts():
    """(class, text or bytes, extra files {name: bytes}) of malformed levels: ``load_level`` must raise
    ``LevelError`` (a ValueError) whose message names the file."""
    g = GOOD_LEVEL
    big_png = _png(2000, 2000)
    hf = '[[colliders]]\ntype = "heightfield"\nimage = "big.png"\nspacing = [1.0, 1.0]\nheight_scale = 1.0\n' \
         'material = "m"\n'
    cases = [
        ("nested", "a = " + "[" * 20000 + "]" * 20000 + "\n" + g, {}),
        ("nested", "a = " + "[" * 500 + "]" * 500 + "\n" + g, {}),
        ("huge", g.replace("half_extents = [1.0, 1.0, 1.0]", "half_extents = [1e308, 1.0, 1.0]"), {}),
        ("huge", g.replace("center = [5.0, 1.0, 0.0]", "center = [1e300, 1.0, 0.0]"), {}),
        ("huge", g.replace("position = [0.0, 1.0, 0.0]", "position = [0.0, 9223372036854775807, 0.0]"), {}),
        ("nan", g.replace("friction = 0.5", "friction = nan"), {}),
        ("inf", g.replace("center = [5.0, 1.0, 0.0]", "center = [inf, 1.0, 0.0]"), {}),
        ("tiny", g.replace("half_extents = [10.0, 0.5, 10.0]", "half_extents = [10.0, 5e-324, 10.0]"), {}),
        ("tiny", g.replace(_BOX, 'type = "sphere"\nradius = 1e-300'), {}),
        ("zero", g.replace(_BOX, 'type = "capsule"\nradius = 0.5\nhalf_height = 0.0'), {}),
        ("zero", g.replace(_BOX, 'type = "plane"\nnormal = [0.0, 0.0, 0.0]'), {}),
        ("huge", g.replace(_BOX, 'type = "plane"\nnormal = [1e300, 1e300, 0.0]\noffset = 1e300'), {}),
        ("huge", g.replace(_BOX, _BOX + "\norientation = [1e300, 1e300, 0.0, 0.0]"), {}),
        ("type", g.replace("friction = 0.5", "friction = true"), {}),
        ("type", g.replace("friction = 0.5", 'friction = "0.5"'), {}),
        ("type", g.replace('name = "T"', "name = 3"), {}),
        ("type", g.replace("[goal]", "goal = 3\n[other]"), {}),
        ("type", g.replace("[materials.m]\nfriction = 0.5", "materials = 3"), {}),
        ("type", g.replace("[[colliders]]", "[colliders]"), {}),
        ("type", g + "[course]\npath = 3\n", {}),
        ("type", g + "[course]\npath = [[0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]\nspeeds = [1.0, true]\n", {}),
        ("type", g + "[course]\npath = [[0.0, 1.0, 0.0], [1.0, 1.0]]\n", {}),
        ("type", g + "[course]\npath = [[0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]\nspeeds = 3\n", {}),
        ("huge", g + "[course]\npath = [[0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]\nspeeds = [1.0, 1e300]\n", {}),
        ("type", g.replace(_BOX, 'type = 3'), {}),
        ("type", g.replace(_BOX, _BOX + '\naxis = [0.0, 1.0, 0.0]'), {}),
        ("type", g.replace(_BOX, _BOX + '\nangle = 1.0'), {}),
        ("type", g.replace(_BOX, _BOX + '\norientation = [1.0, 0.0, 0.0, 0.0]\nangle = 1.0'), {}),
        ("type", g.replace('[materials.m]\nfriction = 0.5', '[materials.m]\nfriction = 0.5\ncolor = [1.0, 2.0]'), {}),
        ("type", g.replace('[materials.m]\nfriction = 0.5', '[materials]\nm = 3'), {}),
        ("text", g.replace('name = "T"', 'name = "' + "x" * 100000 + '"'), {}),
        ("file", g.replace(_BOX, 'type = "mesh"\nfile = "missing.obj"'), {}),
        ("file", g.replace(_BOX, 'type = "mesh"\nfile = 3'), {}),
        ("file", g.replace(_BOX, 'type = "mesh"\nfile = "."'), {}),
        ("file", g.replace(_BOX, 'type = "mesh"\nfile = "bad\\u0000name.obj"'), {}),
        ("file", g.replace(_BOX, 'type = "mesh"\nfile = "cut.obj"'), {"cut.obj": (_good_obj() + "f 1 2").encode()}),
        ("file", g.replace(_BOX, 'type = "mesh"\nfile = "flat.obj"'),
         {"flat.obj": b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"}),
        ("file", g.replace(_BOX, 'type = "mesh"\nfile = "idx.obj"'), {"idx.obj": (_good_obj() + "f 1 2 9\n").encode()}),
        ("file", g.replace(_BOX, 'type = "mesh"\nfile = "bad.glb"'), {"bad.glb": b"glTF" + bytes(100)}),
        ("file", g.replace(_BOX, 'type = "heightfield"\nimage = "bad.png"\nspacing = [1.0, 1.0]\n'
                                 'height_scale = 2.0'), {"bad.png": b"not an image"}),
        ("file", g.replace(_BOX, 'type = "heightfield"\nimage = "cut.png"\nspacing = [1.0, 1.0]\n'
                                 'height_scale = 2.0'), {"cut.png": _png(64, 64)[:300]}),
        ("file", g.replace(_BOX, 'type = "heightfield"\nimage = "one.png"\nspacing = [1.0, 1.0]\n'
                                 'height_scale = 2.0'), {"one.png": _png(1, 5)}),
        ("huge", g.replace(_BOX, 'type = "heightfield"\nimage = "ok.png"\nspacing = [1e300, 1.0]\n'
                                 'height_scale = 2.0'), {"ok.png": _png(4, 4)}),
        ("budget", g + hf * 400, {"big.png": big_png}),
        ("encoding", g.replace('name = "T"', 'name = "caf\u00e9"').encode("latin-1"), {}),
    ]
    return cases


def _png(w, h):
    import io

    from PIL import Image

    buf = io.BytesIO()
    noise = np.random.default_rng(w * 7919 + h).integers(0, 256, (h, w), dtype=np.uint8)   # (incompressible)
    Image.fromarray(noise).save(buf, format="PNG")
    return buf.getvalue()


ENV_OPTIONS = [
    ("frame_skip", [("huge", 1e300), ("str", "3"), ("negative", -1), ("zero", 0), ("nan", NAN), ("bool", True),
                    ("float", 2.5), ("huge", 10 ** 9), ("none", None)]),
    ("start_jitter", [("negative", -1), ("nan", NAN), ("inf", INF), ("str", "0.3"), ("huge", 1e300),
                      ("complex", 1j), ("none", None)]),
    ("goal_reward", [("nan", NAN), ("inf", INF), ("str", "10"), ("huge", 1e300), ("complex", 1 + 1j),
                     ("none", None)]),
    ("fall_penalty", [("nan", NAN), ("inf", -INF), ("str", "5"), ("bool", False)]),
    ("max_episode_steps", [("zero", 0), ("float", 1.5), ("str", "10"), ("nan", NAN), ("huge", 1e300),
                           ("negative", -3)]),
    ("render_mode", [("str", "human"), ("number", 3), ("nested", ["rgb_array"])]),
    ("flag", [("number", 1), ("number", 0.0), ("str", "yes"), ("nested", [True])]),
    ("size", [("shape", (1, 1)), ("str", "320x180"), ("shape", (320,)), ("huge", (10 ** 9, 180)),
              ("float", (320.5, 180)), ("none", None), ("nan", (NAN, 180))]),
    ("level", [("number", 3.5), ("str", "nosuch-level"), ("object", object())]),
]
#: the native vector environment's own options (it takes the single environment's too)
VECTOR_ENV_OPTIONS = [
    ("num_envs", [("zero", 0), ("negative", -1), ("float", 2.5), ("str", "2"), ("huge", 10 ** 9), ("none", None),
                  ("nan", NAN), ("bool", True)]),
    ("threads", [("zero", 0), ("float", 1.5), ("str", "2"), ("huge", 10 ** 6), ("none", None)]),
    ("autoreset_mode", [("str", "Later"), ("str", "Disabled"), ("number", 3), ("none", None),
                        ("nested", ["NextStep"])]),
]
ENV_RESET = [("options", [("object", "x"), ("unknown", {"foo": 1}), ("nested", [1])]),
             ("seed", [("negative", -1), ("str", "1"), ("float", 1.5), ("nan", NAN)])]
