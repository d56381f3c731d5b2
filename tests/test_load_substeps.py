"""The particles' automatic sub-steps (deformables/load_substeps.py): a heavy body resting on light cloth gets
the sub-steps its mass ratio needs, against a slow reference of the rule and on a corner-held sheet."""
import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import marbellous as mb
from marbellous.cloth import cloth_grid
from marbellous.deformables import particle_layout as P
from marbellous.deformables.load_substeps import LOAD_SAG, MOST_LOAD_SUBSTEPS, load_substeps
from marbellous.state import layout as L

DT = 1.0 / 60.0
G = 9.81


def reference_substeps(masses, sets, flags, cloth, inv_mass, body_flags, shape_body, shape_pairs, whole, least):
    """The rule of the module docstring, written plainly: each dynamic body's lightest set among the particles
    under it (not soft bodies' nodes, nor, with ``whole``, cloth vertices), none for a body with a held particle
    under it."""
    set_mass = {s: sum(m for m, t in zip(masses, sets) if t == s) for s in set(sets)}
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
        lightest = min(set_mass[sets[p]] for p in ps)
        n = max(n, min(math.ceil(DT * math.sqrt(G / (inv_mass[b] * lightest * LOAD_SAG))), MOST_LOAD_SUBSTEPS))
    return n


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_the_sub_steps_follow_the_rule(data):
    n = data.draw(st.integers(3, 12))
    nb = data.draw(st.integers(1, 4))
    shapes = data.draw(st.integers(nb, nb + 3))
    masses = data.draw(st.lists(st.floats(1e-4, 0.1), min_size=n, max_size=n))
    sets = data.draw(st.lists(st.integers(0, 2), min_size=n, max_size=n))
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
    least = data.draw(st.integers(1, 20))
    pf, pi = np.zeros((n + 2, P.PF_COLS)), np.zeros((n + 2, P.PI_COLS), dtype=np.int64)
    pf[:n, P.P_MASS], pi[:n, P.P_SET], pi[:n, P.P_FLAGS], pi[:n, P.P_CLOTH] = masses, sets, flags, cloth
    bf, bi = np.zeros((nb, L.BF_COLS)), np.zeros((nb, L.BI_COLS), dtype=np.int64)
    bf[:, L.INV_MASS], bi[:, L.FLAGS] = inv_mass, body_flags
    si = np.zeros((shapes, L.SI_COLS), dtype=np.int64)
    si[:, L.S_BODY] = shape_body
    got = load_substeps(pf, pi, n, bf, bi, si, shape_pairs, len(shape_pairs), nb, DT, G, whole, least)
    assert got == reference_substeps(masses, sets, flags, cloth, inv_mass, body_flags, shape_body, shape_pairs, whole,
                                     least)


def _trampoline(box_mass, substeps=None):
    """The 21 x 21 sheet of 0.2 kg held at its corners 1 m up, and a 0.3 x 0.1 x 0.3 m box of ``box_mass`` kg
    dropped on it from 0.5 m above; returns ``(world, cloth, box)``."""
    n = 21
    v, t = cloth_grid(1.0, 1.0, n, n)
    w = mb.World()
    w.particle_substeps = substeps
    w.add_static(mb.Plane((0.0, 1.0, 0.0), 0.0))
    c = w.add_cloth(v, t, mass=0.2, position=(0.0, 1.0, 0.0), damping=1.0)
    c.pin([0, n - 1, n * (n - 1), n * n - 1])
    box = w.add_body(mb.Box((0.15, 0.05, 0.15)), position=(0.0, 1.5, 0.0), mass=box_mass)
    return w, c, box


def test_a_ten_kilogram_box_rests_on_a_sheet_of_two_hundred_grams():
    # 16 sub-steps carry about 15 times the sheet's mass (3 kg; 5 kg and this box went through); the 10 kg box
    # asks for dt sqrt(g 50 / LOAD_SAG) = 42, bounces and settles (its bounce in each second: 0.75 m, 0.31 m, ...,
    # 1.2 mm in the tenth, 0.6 mm in the twelfth), and then lies on the sheet
    w, c, box = _trampoline(10.0)
    y, taken = [], set()
    for _ in range(720):
        w.step(DT)
        y.append(box.position[1])
        taken.add(w.particle_substeps_taken)
    assert taken == {16, math.ceil(DT * math.sqrt(G * 50.0 / LOAD_SAG))}
    assert np.ptp(y[-60:]) < 1e-3 and np.all(np.isfinite(c.positions))
    # its underside over the sheet's vertex nearest under its centre (it may creep across the sagging sheet: 1 cm/s
    # after 12 s), within the thickness
    x = c.positions
    near = np.argmin(np.linalg.norm(x[:, [0, 2]] - box.position[[0, 2]], axis=1))
    assert np.all(np.abs(box.position[[0, 2]]) < 0.5)
    assert 0.0 <= y[-1] - 0.05 - x[near, 1] <= c.thickness


def test_a_light_box_and_a_given_count_keep_their_sub_steps():
    # the 1 kg box (5 times the sheet) needs no more than the default 16; a number set is taken as it is
    w, _, _ = _trampoline(1.0)
    for _ in range(90):
        w.step(DT)
        assert w.particle_substeps_taken == 16
    w, _, _ = _trampoline(10.0, substeps=20)
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
