"""The particles' automatic sub-steps (deformables/load_substeps.py): a heavy body resting on light cloth gets
the sub-steps its mass ratio needs, against a slow reference of the rule and on a corner-held sheet."""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import marbellous as mb
from marbellous.cloth import cloth_grid
from marbellous.deformables import particle_layout as P
from marbellous.deformables.load_substeps import LOAD_SAG, MOST_LOAD_SUBSTEPS, load_substeps
from marbellous.state import layout as L

DT = 1.0 / 60.0
G = 9.81


def reference_substeps(masses, flags, cloth, inv_mass, body_flags, shape_body, shape_pairs, whole, least):
    """The rule of the module docstring, written plainly: each dynamic body's load on the mass of the particles
    under it (each counted once, not soft bodies' nodes, nor, with ``whole``, cloth vertices), none for a body with
    a held particle under it."""
    held = {p for p, f in enumerate(flags) if f & P.PP_PINNED}
    dynamic = [(f & L.F_ALIVE) and not (f & (L.F_STATIC | L.F_KINEMATIC)) for f in body_flags]
    held |= {int(p) for p, s, _ in shape_pairs if not dynamic[shape_body[s]]}
    under = {}
    for p, s, lies in shape_pairs:
        if lies:
            under.setdefault(shape_body[s], set()).add(int(p))
    n = least
    for b, ps in under.items():
        ps = {p for p in ps if not flags[p] & P.PP_SOFT and not (whole and cloth[p] >= 0)}
        if not ps or ps & held or not dynamic[b] or inv_mass[b] <= 0.0:
            continue
        m = sum(masses[p] for p in sorted(ps))      # (in the kernel's order: the rows run particle by particle)
        n = max(n, min(math.ceil(DT * math.sqrt(G / (inv_mass[b] * m * LOAD_SAG))), MOST_LOAD_SUBSTEPS))
    return n


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_the_sub_steps_follow_the_rule(data):
    n = data.draw(st.integers(3, 12))
    nb = data.draw(st.integers(1, 4))
    shapes = data.draw(st.integers(nb, nb + 3))
    masses = data.draw(st.lists(st.floats(1e-4, 0.1), min_size=n, max_size=n))
    flags = data.draw(st.lists(st.sampled_from([0, 0, 0, P.PP_PINNED, P.PP_SOFT]), min_size=n, max_size=n))
    cloth = data.draw(st.lists(st.sampled_from([-1, 0, 1]), min_size=n, max_size=n))
    whole = data.draw(st.booleans())
    inv_mass = data.draw(st.lists(st.floats(1e-3, 10.0), min_size=nb, max_size=nb))
    body_flags = data.draw(st.lists(st.sampled_from([L.F_ALIVE, L.F_ALIVE, L.F_ALIVE | L.F_SLEEPING,
                                                     L.F_ALIVE | L.F_STATIC, L.F_ALIVE | L.F_KINEMATIC]),
                                    min_size=nb, max_size=nb))
    shape_body = list(range(nb)) + data.draw(st.lists(st.integers(0, nb - 1), min_size=shapes - nb,
                                                      max_size=shapes - nb))
    shape_pairs = np.array(data.draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, shapes - 1),
                                                        st.integers(0, 1)), max_size=12)),
                           dtype=np.int64).reshape(-1, 3)
    shape_pairs = shape_pairs[np.argsort(shape_pairs[:, 0], kind="stable")]     # (the rows run particle by particle)
    least = data.draw(st.integers(1, 20))
    pf, pi = np.zeros((n + 2, P.PF_COLS)), np.zeros((n + 2, P.PI_COLS), dtype=np.int64)
    pf[:n, P.P_MASS], pi[:n, P.P_FLAGS], pi[:n, P.P_CLOTH] = masses, flags, cloth
    bf, bi = np.zeros((nb, L.BF_COLS)), np.zeros((nb, L.BI_COLS), dtype=np.int64)
    bf[:, L.INV_MASS], bi[:, L.FLAGS] = inv_mass, body_flags
    si = np.zeros((shapes, L.SI_COLS), dtype=np.int64)
    si[:, L.S_BODY] = shape_body
    got = load_substeps(pf, pi, n, bf, bi, si, shape_pairs, len(shape_pairs), nb, DT, G, whole, least)
    assert got == reference_substeps(masses, flags, cloth, inv_mass, body_flags, shape_body, shape_pairs, whole,
                                     least)


def _trampoline(shape, mass, substeps=None):
    """The 21 x 21 sheet of 0.2 kg held at its corners 1 m up, and a body of ``shape`` and ``mass`` kg dropped on it
    from 0.5 m above; returns ``(world, cloth, body)``."""
    n = 21
    v, t = cloth_grid(1.0, 1.0, n, n)
    w = mb.World()
    w.particle_substeps = substeps
    w.add_static(mb.Plane((0.0, 1.0, 0.0), 0.0))
    c = w.add_cloth(v, t, mass=0.2, position=(0.0, 1.0, 0.0), damping=1.0)
    c.pin([0, n - 1, n * (n - 1), n * n - 1])
    low = shape.radius if isinstance(shape, mb.Sphere) else shape.half_extents[1]
    body = w.add_body(shape, position=(0.0, 1.5 + low, 0.0), mass=mass)
    return w, c, body


def _lies_on_the_sheet(c, body, low):
    """Whether ``body`` (its lowest point ``low`` m under its centre) lies on the sheet: over it, its lowest point
    over the sheet's vertex nearest under its centre within the thickness."""
    x = c.positions
    near = np.argmin(np.linalg.norm(x[:, [0, 2]] - body.position[[0, 2]], axis=1))
    return bool(np.all(np.abs(body.position[[0, 2]]) < 0.5)
                and 0.0 <= body.position[1] - low - x[near, 1] <= c.thickness)


def test_a_ten_kilogram_box_rests_on_a_sheet_of_two_hundred_grams():
    # 16 sub-steps carry a 0.3 x 0.1 x 0.3 m box of about 15 times the sheet's mass (3 kg; 5 kg and this box went
    # through); the 10 kg box asks for more, bounces and settles, and then lies on the sheet (it may creep across
    # the sagging sheet: 1 cm/s after 12 s)
    w, c, box = _trampoline(mb.Box((0.15, 0.05, 0.15)), 10.0)
    y, taken = [], []
    for _ in range(720):
        w.step(DT)
        y.append(box.position[1])
        taken.append(w.particle_substeps_taken)
    assert min(taken[-60:]) > 16
    assert np.ptp(y[-60:]) < 1e-3 and np.all(np.isfinite(c.positions))
    assert _lies_on_the_sheet(c, box, 0.05)


@pytest.mark.parametrize("shape, mass", [(mb.Box((0.075, 0.075, 0.075)), 2.0), (mb.Sphere(0.05), 1.0)])
def test_a_small_heavy_body_stays_on_the_sheet(shape, mass):
    # the load of a small body lies on few vertices: a 15 cm cube of 2 kg (10 times the sheet) and a 10 cm ball of
    # 1 kg went through at 16 sub-steps, and the cube at 19 (the count a 2 kg load on the whole sheet's mass was
    # given); counted on the vertices under them, they stay on the sheet for 12 s (the cube settles slowly, its
    # bounce 17 cm in the fourth second, 2.5 cm in the twelfth; the ball rolls about in the sheet's dip)
    low = shape.radius if isinstance(shape, mb.Sphere) else shape.half_extents[1]
    w, c, body = _trampoline(shape, mass, 16)
    for _ in range(60):
        w.step(DT)
    assert body.position[1] < 0.5
    w, c, body = _trampoline(shape, mass)
    for i in range(720):
        w.step(DT)
        if i >= 120:
            # its lowest point never under the sheet's lowest vertex by more than the thickness
            assert body.position[1] - low >= c.positions[:, 1].min() - c.thickness, i
    assert np.all(np.isfinite(c.positions)) and _lies_on_the_sheet(c, body, low)


def test_a_light_box_and_a_given_count_keep_their_sub_steps():
    # the 0.5 kg box needs no more than the default 16; a number set is taken as it is
    w, _, _ = _trampoline(mb.Box((0.15, 0.05, 0.15)), 0.5)
    for _ in range(90):
        w.step(DT)
        assert w.particle_substeps_taken == 16
    w, _, _ = _trampoline(mb.Box((0.15, 0.05, 0.15)), 10.0, substeps=20)
    for _ in range(90):
        w.step(DT)
        assert w.particle_substeps_taken == 20
    assert w.particle_substeps == 20


def test_a_sheet_draped_over_a_heavy_box_keeps_the_default_count():
    # the 0.1 kg sheet falls onto a 64 kg box standing on the ground and hangs over its sides: the box lies on no
    # particle (the sheet lies on it), so the step keeps 16 sub-steps
    w = mb.World()
    w.add_static(mb.Plane())
    w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(0.0, 0.2, 0.0))
    v, t = cloth_grid(0.8, 0.8, 11, 11)
    c = w.add_cloth(v, t, mass=0.1, position=(0.0, 0.6, 0.0))
    for _ in range(90):
        w.step(DT)
        assert w.particle_substeps_taken == 16
    assert c.positions[:, 1].min() < 0.3       # its edges hang down the box's sides
