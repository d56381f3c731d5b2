"""Force accumulation (D'Alembert's principle): sum every force on a body and its torque.

    F_i = F_user,i + m_i g + sum of force generators (springs)
    T_i = T_user,i + sum (p - x_i) x f

The integrators call this at each of their stages with the state of that stage, so a fourth-order
method really sees the springs at its intermediate states.
"""
import math

from .._numba.jit import njit, njit_inline
from ..math3d import row4, tensor_vec
from ..state.layout import (F_ALIVE, F_KINEMATIC, F_SLEEPING, F_STATIC, FLAGS, FORCE, INV_MASS, MASS, OMEGA, QUAT,
                            TORQUE, VEL)
from .rigid import inverse_inertia_world
from .springs import add_spring_forces


@njit
def is_moving(bi, i):
    """True if body row ``i`` is alive, dynamic and awake (it is integrated this step)."""
    f = bi[i, FLAGS]
    return (f & F_ALIVE) != 0 and (f & (F_STATIC | F_KINEMATIC | F_SLEEPING)) == 0


@njit_inline
def free_acceleration(bf, i, gravity):
    """``a = g + F_user / m`` (m/s^2, a tuple): body row ``i``'s acceleration before contacts, joints and
    springs."""
    inv_m = bf[i, INV_MASS]
    return (gravity[0] + bf[i, FORCE] * inv_m, gravity[1] + bf[i, FORCE + 1] * inv_m,
            gravity[2] + bf[i, FORCE + 2] * inv_m)


@njit_inline
def user_acceleration(bf, i):
    """``|F_user| / m`` (m/s^2): the acceleration body row ``i``'s user force gives it (0 for a static body).  The
    step's reach of a body counts it with gravity's: a small ball pressed at 100 g from rest 5 cm above a mesh,
    reached by its velocity and gravity alone, went through the mesh in its first step."""
    f2 = bf[i, FORCE] ** 2 + bf[i, FORCE + 1] ** 2 + bf[i, FORCE + 2] ** 2
    return math.sqrt(f2) * bf[i, INV_MASS] if f2 > 0.0 else 0.0


@njit_inline
def user_angular_acceleration(bf, i):
    """``|I^-1 T|`` (rad/s^2): the angular acceleration body row ``i``'s user torque ``T`` gives it at its
    orientation now (``I^-1`` its world inverse inertia; 0 for a static body).  A plank spun by a torque from rest
    over a mesh, reached by its velocity alone, turned 21 cm of its end through the mesh in its first step and
    was flung off at 15 m/s."""
    t = (bf[i, TORQUE], bf[i, TORQUE + 1], bf[i, TORQUE + 2])
    if t[0] == 0.0 and t[1] == 0.0 and t[2] == 0.0:
        return 0.0
    a = tensor_vec(inverse_inertia_world(bf, i, row4(bf, i, QUAT)), t)
    return math.sqrt(a[0] ** 2 + a[1] ** 2 + a[2] ** 2)


@njit
def is_dynamic(bi, i):
    """True if body row ``i`` is alive and dynamic, awake or asleep (neither static nor kinematic)."""
    f = bi[i, FLAGS]
    return (f & F_ALIVE) != 0 and (f & (F_STATIC | F_KINEMATIC)) == 0


@njit
def is_driven(bf, bi, i):
    """True if body row ``i`` is a kinematic body in motion (a nonzero velocity or angular velocity)."""
    if (bi[i, FLAGS] & (F_ALIVE | F_KINEMATIC)) != (F_ALIVE | F_KINEMATIC):
        return False
    for k in range(3):
        if bf[i, VEL + k] != 0.0 or bf[i, OMEGA + k] != 0.0:
            return True
    return False


@njit_inline
def add_applied_forces(bf, bi, nb, gravity, F, T):
    """Fill ``F`` (N) and ``T`` (N m) with gravity and the user's accumulators; rows of resting bodies are zero."""
    for i in range(nb):
        if is_moving(bi, i):
            m = bf[i, MASS]
            for k in range(3):
                F[i, k] = bf[i, FORCE + k] + m * gravity[k]
                T[i, k] = bf[i, TORQUE + k]
        else:
            for k in range(3):
                F[i, k] = 0.0
                T[i, k] = 0.0


@njit_inline
def accumulate_forces(bf, bi, kf, ki, nb, nk, gravity, X, Q, V, W, F, T, record, implicit, vecs):
    """Fill ``F`` (N) and ``T`` (N m) for the state ``(X, Q, V, W)``: applied forces and springs.

    ``record``: weight with which each spring's force is added to its recorded mean (0: none);
    ``implicit``: the springs the constraint solver takes instead; ``vecs``: scratch (see ``add_spring_forces``).
    """
    add_applied_forces(bf, bi, nb, gravity, F, T)
    if nk > 0:
        add_spring_forces(kf, ki, nk, X, Q, V, W, F, T, record, implicit, vecs)
