"""A body's material: the coefficients its contacts combine, and the damping its integration applies.

Contacts combine the two bodies' values when they are made (each step): friction coefficients by geometric
mean, ``mu = sqrt(mu_a mu_b)``; restitution, rolling and torsional friction by maximum.  Damping acts on the
body alone: over a sub-step ``h`` the velocities decay as ``dv/dt = -c v`` does, ``v := v exp(-c h)``.
"""
from ._validate import MAX_DAMPING, MAX_FRICTION, MAX_SIZE, as_float
from .state import layout as L


def _coefficient(name, value):
    return as_float(name, value, nonnegative=True, hi=MAX_FRICTION)


def _restitution(name, value):
    return as_float(name, value, lo=0.0, hi=1.0)


def _lever_arm(name, value):
    return as_float(name, value, nonnegative=True, hi=MAX_SIZE, unit="m")


def _rate(name, value):
    return as_float(name, value, nonnegative=True, hi=MAX_DAMPING, unit="1/s")


#: Each material property: its body column and its validator, in the order of ``layout.MATERIAL``.
FIELDS = {
    "friction": (L.FRICTION, _coefficient),
    "static_friction": (L.STATIC_FRICTION, _coefficient),
    "restitution": (L.RESTITUTION, _restitution),
    "rolling_friction": (L.ROLLING, _lever_arm),
    "torsional_friction": (L.TORSION, _lever_arm),
    "linear_damping": (L.LINEAR_DAMPING, _rate),
    "angular_damping": (L.ANGULAR_DAMPING, _rate),
}


def validated(name, value):
    """``value`` checked as the material property ``name`` (a key of :data:`FIELDS`); raises naming it."""
    return FIELDS[name][1](name, value)


def material_values(friction, static_friction, restitution, rolling_friction, torsional_friction=0.0,
                    linear_damping=0.0, angular_damping=0.0):
    """The validated values of the columns ``layout.MATERIAL``; ``static_friction`` None: ``friction``."""
    given = dict(friction=friction, static_friction=friction if static_friction is None else static_friction,
                 restitution=restitution, rolling_friction=rolling_friction, torsional_friction=torsional_friction,
                 linear_damping=linear_damping, angular_damping=angular_damping)
    return tuple(validated(name, given[name]) for name in FIELDS)
