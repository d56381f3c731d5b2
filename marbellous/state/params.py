"""The world's tunables and how they reach the step: validated floats on the World, written into the
parameter slots ``params_f``/``params_i`` (``state/layout.py``) whenever the step length or a setting
changes.  Kernels never read tunables from globals (Numba's cache would freeze them).

docs/architecture.md explains each tunable in physical terms.
"""
import math

import numpy as np

from .._validate import as_float
from ..collision.broadphase import METHODS as BROADPHASE_CODES
from ..dynamics.integrators import INTEGRATORS
from ..dynamics.penalty import STABLE_FRACTION
from . import layout as L

#: the collision-handling schemes, in the order of their codes (layout.SEQUENTIAL_IMPULSE, PENALTY, LCP)
SOLVERS = ("sequential_impulse", "penalty", "lcp")
#: the orders of the sequential-impulse passes over the contacts, in the order of their codes
#: (``layout.PI_SOLVE_ORDER``): coloured bundles, or one by one from the ground up (dynamics/support_depth.py)
SOLVE_ORDERS = ("coloured", "bottom_up")


#: the longest sub-step (s) of the automatic sub-steps (``World.substeps = None``, the default): a step of
#: ``dt`` takes at least ``ceil(dt / MAX_SUBSTEP)`` of them (a number the user sets is taken exactly).
#: A sub-step's velocity passes stop only what they converge on in ``iterations``
#: passes, and gravity adds ``g h`` per sub-step: at ``h = 0.25 s`` (dt = 1 s, 4 sub-steps) a three-cube stack
#: sank 20 cm per step and toppled, and the penalty springs, capped at ``0.4 / h`` rad/s, let it sink 1.5 m.
#: At 1/120 s a stack sinks by at most 0.3 mm with sequential impulses (LCP 1 um), and the penalty springs'
#: rate is 48 rad/s (a 3-cube stack rests 4 cm low).  Real-time steps (dt <= 1/30 s with the default 4
#: sub-steps) never reach it; a step of 1 s takes 120 sub-steps, as much work per simulated second as 1/30 s.
MAX_SUBSTEP = 1.0 / 120.0


#: the most sub-steps a step takes, with automatic sub-steps, so that no awake body turns by more than
#: ``pipeline.step.MAX_TURN`` (0.25 rad) in one: a box spinning at 400 rad/s after hitting a wall at 69 m/s
#: turned 1.7 rad per sub-step of 1/240 s, its contacts' velocities, linear in the sub-step, said its corners
#: were leaving the wall, and it went through (1 shot in 30,000).  At 16 or more sub-steps it bounced back.
MAX_TURN_SUBSTEPS = 64


def substeps_for(world, dt):
    """Sub-steps of a step of ``dt`` s: ``world.substeps``, or with automatic sub-steps more, so that none is
    longer than ``MAX_SUBSTEP``."""
    if not world._substeps_auto:
        return world.substeps
    return max(world.substeps, math.ceil(dt / MAX_SUBSTEP - 1e-9))


class Tunable:
    """A physical tunable of the world (a float): validated on assignment; the next step rewrites the
    parameters."""

    def __init__(self, default, doc, **rule):
        self.default = default
        self.rule = rule
        self.__doc__ = doc

    def __set_name__(self, owner, name):
        self.name = name

    def __get__(self, obj, owner=None):
        if obj is None:
            return self
        return obj._tunables.get(self.name, self.default)

    def __set__(self, obj, value):
        obj._tunables[self.name] = as_float(self.name, value, **self.rule)
        obj._parameters_changed()


#: the time-stepping modes, in the order World takes them
TIME_STEPPING = ("fixed", "retroactive", "conservative")


def toi_mode(time_stepping, ccd):
    """The step's time-of-impact mode (layout TOI_*) for a world's ``time_stepping`` and ``ccd``."""
    if time_stepping == "conservative":
        return L.TOI_ALL
    return L.TOI_FAST if ccd else L.TOI_NONE


def write_params(world, dt, params_f, params_i, step_dt=None):
    """Fill ``params_f``/``params_i`` from ``world``'s settings for steps (or an interval) of ``dt`` seconds;
    ``step_dt`` (s, default ``dt``): the whole step's length, whose ``2**-max_halvings`` is the shortest
    interval."""
    pf, pi = params_f, params_i
    pf[L.PF_DT] = dt
    pf[L.PF_GRAVITY:L.PF_GRAVITY + 3] = world.gravity
    substeps = substeps_for(world, dt)
    h = dt / substeps
    pf[L.PF_SPECULATIVE] = world.speculative_distance
    # Contacts no stiffer than a quarter of the sub-step rate, joints half (stable for any dt).
    pf[L.PF_CONTACT_HERTZ] = min(world.contact_hertz, 0.25 / h)
    pf[L.PF_CONTACT_ZETA] = world.contact_damping_ratio
    pf[L.PF_JOINT_HERTZ] = min(world.joint_hertz, 0.5 / h)
    pf[L.PF_JOINT_ZETA] = world.joint_damping_ratio
    pf[L.PF_MAX_PUSH] = world.max_push_speed
    pf[L.PF_SLIDE_SPEED] = world.slide_speed
    pf[L.PF_TOLERANCE] = world.velocity_tolerance
    pf[L.PF_SLEEP_LINEAR] = world.sleep_linear_speed
    pf[L.PF_SLEEP_ANGULAR] = world.sleep_angular_speed
    pf[L.PF_TIME_TO_SLEEP] = world.time_to_sleep if world.sleeping else 0.0
    # A contact closing no faster than gravity makes in one sub-step is resting, not bouncing.
    pf[L.PF_RESTITUTION_SPEED] = float(np.linalg.norm(world.gravity)) * h
    pf[L.PF_SWEEP] = 1.0 if world.ccd else 0.0
    pi[L.PI_INTEGRATOR] = INTEGRATORS.index(world.integrator)
    pi[L.PI_SUBSTEPS] = substeps
    pi[L.PI_TURN_SUBSTEPS] = MAX_TURN_SUBSTEPS if world._substeps_auto else 0
    pi[L.PI_ITERATIONS] = world.iterations
    pi[L.PI_ADAPTIVE] = int(world.adaptive_iterations)
    pi[L.PI_PAIR_CACHE] = int(world.pair_cache)
    pi[L.PI_SOLVE_ORDER] = SOLVE_ORDERS.index(world.solve_order)
    pi[L.PI_BROADPHASE] = BROADPHASE_CODES[world.broadphase]
    pi[L.PI_SOLVER] = SOLVERS.index(world.solver)
    pi[L.PI_THREADS] = world.threads
    # The penalty springs are as stiff as the whole step's sub-steps allow, also in a shorter interval of it
    # (time_stepping, ccd): a spring that stiffened there would push a body resting at the long sub-steps'
    # depth out with the energy of the stiffer spring, 1/2 k d^2 for a larger k.
    whole = dt if step_dt is None else step_dt
    pf[L.PF_PENALTY_HERTZ] = min(world.penalty_hertz, STABLE_FRACTION * substeps_for(world, whole) / whole)
    pi[L.PI_LCP_SWEEPS] = int(world.lcp_sweeps)
    pf[L.PF_LCP_SOR] = world.lcp_relaxation
    mode = toi_mode(world.time_stepping, world.ccd and world.solver != "penalty")
    pi[L.PI_TOI_MODE] = mode
    pi[L.PI_TOI_SPLIT] = int(mode != L.TOI_NONE)
    pi[L.PI_DETECT] = 0
    pf[L.PF_STEP_DT] = dt if step_dt is None else step_dt
    pf[L.PF_MIN_INTERVAL] = pf[L.PF_STEP_DT] / 2.0 ** world.max_halvings
