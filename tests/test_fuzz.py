"""Fuzzing every public entry point with bad input (hypothesis), and accepted input with steps.

For each argument of ``fuzz_catalogue.WORLD_ARGS`` hypothesis draws bad values of its kind: the listed
ones (nan, inf, huge, tiny and subnormal, negative, zero, str, bool, complex, None, nested lists, wrong
shapes, other objects) and random ones around them.  Each must raise ValueError or TypeError and, when a
world is involved, leave its ``state_hash`` unchanged.  Shapes refuse assignment; mesh files, level
files and the gym environment refuse bad input with errors naming the file or option; and valid random
input never puts NaN into the state over a few steps.  ``max_examples`` is kept small per argument: the
suite covers ~150 arguments in a couple of minutes.
"""
import math
import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import fuzz_catalogue as fc
import marbellous as mb
from marbellous.game.level import LevelError, load_level

TINY = 2.2250738585072014e-308      # the smallest normal float
EXAMPLES = int(os.environ.get("MARBELLOUS_FUZZ_EXAMPLES", "12"))


# --- random bad values by kind --------------------------------------------------------------------------
def _wrong_scalar_types():
    return st.one_of(st.text(max_size=5), st.booleans(), st.complex_numbers(allow_nan=False, max_magnitude=10),
                     st.lists(st.floats(0.1, 1.0), min_size=1, max_size=3), st.binary(max_size=3),
                     st.just(object()), st.dictionaries(st.text(max_size=2), st.integers(), max_size=2))


def _nonfinite():
    return st.sampled_from([math.nan, math.inf, -math.inf, float("-nan")])


def _subnormal():
    return st.floats(min_value=5e-324, max_value=2.2e-308, allow_subnormal=True).flatmap(
        lambda x: st.sampled_from([x, -x]))


#: kinds for which +inf is a valid value (an unbounded ray)
INF_OK = {"max_distance"}
SCALAR_RULES = {   # kind: (lo, hi) of the valid range (None: unbounded; lo > 0 means positive)
    "size": (1e-6, 1e6), "coord": (-1e12, 1e12), "length": (TINY, 2e12), "length0": (0.0, 2e12),
    "rod_length": (TINY, 2e12), "mass": (1e-30, 1e30), "density": (1e-6, 1e6), "friction": (0.0, 1e3),
    "static_friction": (0.0, 1e3), "rolling": (0.0, 1e6), "restitution": (0.0, 1.0), "stiffness": (0.0, 1e15),
    "breaking": (TINY, None), "dt": (1e-6, 1.0), "frame_time": (0.0, None), "max_distance": (0.0, None),
    "hertz": (1e-3, 1e6), "nonneg": (0.0, 1e9), "positive": (TINY, 1e9), "ratio": (0.0, 1e6),
    "cell_size": (TINY, 1e12), "rest_length": (0.0, 1e6), "modulus": (TINY, 1e15), "poisson": (-0.99, 0.49),
    "radius_or_none": (1e-6, 1e6), "max_volume": (TINY, 1e12), "fluid_cell": (1e-6, 1e3),
    "fluid_density": (1e-3, 1e5), "fluid_viscosity": (0.0, 1e3), "fluid_tolerance": (1e-14, 0.1),
    "surface": (-1e12, 1e12),
}


def _out_of_range(lo, hi):
    """Finite floats outside [lo, hi]."""
    parts = []
    if lo is not None:
        if lo > 0:
            parts.append(st.floats(min_value=-1e308, max_value=lo, exclude_max=True))
        else:
            parts.append(st.floats(min_value=-1e308, max_value=lo, exclude_max=True).filter(lambda x: x < lo))
    if hi is not None:
        parts.append(st.floats(min_value=hi, max_value=1e308, exclude_min=True))
    return st.one_of(*parts) if parts else st.nothing()


def bad_values(kind):
    """A strategy of bad values for an argument of ``kind``: the catalogue's list, plus random ones."""
    listed = st.sampled_from([v for _, v in fc.KINDS[kind]])
    if kind in SCALAR_RULES:
        lo, hi = SCALAR_RULES[kind]
        extra = [_subnormal()] if lo is not None and lo > 0 else []     # (subnormal is fine where 0 is)
        nonfinite = _nonfinite().filter(lambda x: x != math.inf) if kind in INF_OK else _nonfinite()
        return st.one_of(listed, _wrong_scalar_types(), nonfinite, _out_of_range(lo, hi), *extra)
    if kind in ("vec3", "speed3", "accel3", "force3", "point3", "offset3", "direction", "quat", "half_extents",
                "action", "fluid_accel3", "wall_velocity"):
        n = {"quat": 4, "action": 2}.get(kind, 3)
        bound = {"vec3": 1e12, "speed3": 1e9, "accel3": 1e6, "force3": 1e20, "point3": 1e12, "offset3": 1e6,
                 "half_extents": 1e6, "fluid_accel3": 1e4, "wall_velocity": 1e4}.get(kind)
        ok = st.floats(-1.0, 1.0)
        bad_item = st.one_of(_nonfinite(), st.text(max_size=3), st.booleans(), st.none(),
                             st.complex_numbers(allow_nan=False, max_magnitude=10).filter(lambda z: z.imag != 0))
        if bound is not None:
            bad_item = st.one_of(bad_item, st.floats(min_value=bound, max_value=1e308, exclude_min=True))
        one_bad = st.tuples(st.lists(ok, min_size=n - 1, max_size=n - 1), bad_item,
                            st.integers(0, n - 1)).map(lambda t: t[0][:t[2]] + [t[1]] + t[0][t[2]:])
        wrong_len = st.lists(ok, max_size=6).filter(lambda v: len(v) != n)
        return st.one_of(listed, one_bad, wrong_len, _wrong_scalar_types().filter(lambda v: not isinstance(v, list)))
    return listed


# --- bad input to world entry points and shapes -----------------------------------------------------------
ARG_IDS = [f"{entry}-{arg}-{kind}" for entry, arg, kind, _, _ in fc.WORLD_ARGS]


@pytest.mark.parametrize("entry,arg,kind,call,world", fc.WORLD_ARGS, ids=ARG_IDS)
def test_bad_values_are_refused_and_change_nothing(entry, arg, kind, call, world):
    ns = fc.make_world() if world else None
    before = ns.w.state_hash() if world else None

    @settings(max_examples=EXAMPLES, database=None)
    @given(value=bad_values(kind))
    def check(value):
        with pytest.raises((ValueError, TypeError)) as err:
            call(ns, value)
        if world:
            assert ns.w.state_hash() == before, f"{entry}({arg}={value!r}) changed the world"
        msg = str(err.value)
        assert msg, "the error has no message"

    check()


@pytest.mark.parametrize("entry,arg,klass,value,call,world", fc.world_cases(),
                         ids=[f"{c[0]}-{c[1]}-{c[2]}-{i}" for i, c in enumerate(fc.world_cases())])
def test_every_listed_bad_value_names_its_argument(entry, arg, klass, value, call, world):
    ns = fc.make_world() if world else None
    before = ns.w.state_hash() if world else None
    with pytest.raises((ValueError, TypeError)) as err:
        call(ns, value)
    msg = str(err.value)
    names = {arg}
    if "shape" in arg:          # a shape refused by its own constructor names that constructor's argument
        names |= {"shape", "static only", "radius", "half_extents", "half_height", "points"}
    if arg in ("a", "b"):
        names |= {"constraint", "a and b"}
    assert any(n in msg for n in names), f"{entry}({arg}) error does not name the argument: {msg!r}"
    if world:
        assert ns.w.state_hash() == before


# --- immutability -----------------------------------------------------------------------------------------
@pytest.mark.parametrize("name,attr,value,factory", fc.immutable_cases(),
                         ids=[f"{c[0]}.{c[1]}" for c in fc.immutable_cases()])
def test_shape_attributes_cannot_be_assigned(name, attr, value, factory):
    shape = factory()
    before = shape._params().copy()
    with pytest.raises(AttributeError):
        setattr(shape, attr, value)
    with pytest.raises(AttributeError):
        shape.some_new_attribute = 1
    assert np.array_equal(shape._params(), before)


@pytest.mark.parametrize("name,factory,attr", fc.inplace_cases(), ids=[c[0] for c in fc.inplace_cases()])
def test_returned_arrays_cannot_change_the_shape(name, factory, attr):
    shape = factory()
    before = np.array(getattr(shape, attr))
    arr = getattr(shape, attr)
    if arr.flags.writeable:          # a copy: editing it leaves the shape alone
        arr[...] = 0.0
    else:                            # a read-only view that cannot be made writeable
        with pytest.raises(ValueError):
            arr[...] = 0.0
        with pytest.raises(ValueError):
            arr.flags.writeable = True
    assert np.array_equal(getattr(shape, attr), before)


def test_a_mesh_whose_attributes_were_assigned_still_steps():
    # Assigning TriangleMesh.triangles used to be accepted, and the next step read out of bounds (exit 139).
    v = np.array([[0, 0, 0], [4, 0, 0], [0, 0, 4], [4, 0, 4]], float)
    m = mb.TriangleMesh(v, [[0, 2, 1], [1, 2, 3]])
    for attr, value in (("triangles", np.array([[0, 2, 1]] * 1000)), ("accel", "bvh"), ("vertices", v * 2)):
        with pytest.raises(AttributeError):
            setattr(m, attr, value)
    w = mb.World()
    w.add_static(m)
    ball = w.add_body(mb.Sphere(0.3), position=(1.0, 0.5, 1.0))
    for _ in range(60):
        w.step(1 / 60)
    assert ball.position[1] == pytest.approx(0.3, abs=0.02)


def test_handles_refuse_unknown_attributes():
    ns = fc.make_world()
    before = ns.w.state_hash()
    for obj, attr in ((ns.w, "contact_hz"), (ns.ball, "mass"), (ns.ball, "foo"), (ns.ball, "shapes"),
                      (ns.spring, "body_a"), (ns.spring, "stiffness"), (ns.ball, "is_static")):
        with pytest.raises(AttributeError):
            setattr(obj, attr, 1)
    shapes = ns.ball.shapes
    shapes[0][1][:] = 99.0
    assert np.array_equal(ns.ball.shapes[0][1], np.zeros(3))
    assert ns.w.state_hash() == before


def test_box_with_three_arguments_explains_itself():
    with pytest.raises(TypeError, match=r"Box takes half_extents as one \(hx, hy, hz\) sequence"):
        mb.Box(1, 1, 1)


# --- directions: normalised safely ------------------------------------------------------------------------
@settings(max_examples=40, database=None)
@given(scale=st.floats(min_value=5e-324, max_value=1e308), axis=st.integers(0, 2))
def test_any_finite_nonzero_direction_is_normalised(scale, axis):
    d = [0.0, 0.0, 0.0]
    d[axis] = scale
    n = mb.Plane(normal=d).normal
    assert np.array_equal(n, np.eye(3)[axis])
    q = [0.0, 0.0, 0.0, 0.0]
    q[axis] = -scale
    w = mb.World()
    b = w.add_body(mb.Sphere(0.5))
    b.orientation = q
    assert np.array_equal(b.orientation, -np.eye(4)[axis])


def test_a_huge_ray_direction_still_hits():
    w = mb.World()
    w.add_static(mb.Plane())
    hit = w.raycast((0, 5, 0), (0, -1e300, 0))
    assert hit is not None and hit.distance == pytest.approx(5.0)
    hit = w.raycast((0, 5, 0), (0, -5e-324, 0))
    assert hit is not None and hit.distance == pytest.approx(5.0)


# --- bounded work -----------------------------------------------------------------------------------------
def test_advance_takes_at_most_a_quarter_second_of_steps():
    w = mb.World()
    w.add_body(mb.Sphere(0.5))
    alpha = w.advance(1e300)
    assert w.time == pytest.approx(30 / 120)          # ceil(0.25 * 120) steps, the rest dropped
    assert alpha == 0.0
    w.advance(1.0, dt=1 / 60)
    assert w.time == pytest.approx(30 / 120 + 15 / 60)
    with pytest.raises(ValueError, match="dt"):
        w.advance(0.05, dt=1e-300)
    w.advance(5.0, dt=1e-3, max_steps=3)
    assert w.time == pytest.approx(30 / 120 + 15 / 60 + 3e-3)


def test_duplicate_triangles_build_in_linear_time():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 1], [1, 0, 1]], float)
    with pytest.warns(UserWarning, match="duplicate"):
        m = mb.TriangleMesh(v, [[0, 2, 1]] * 100000)
    x0, z0, cell, nx, nz = m._grid
    assert nx * nz <= 64            # the grid grew its cells instead of filling 400,000 cells
    w = mb.World()
    w.add_static(m)
    ball = w.add_body(mb.Sphere(0.1), position=(0.3, 0.3, 0.3))
    for _ in range(30):
        w.step(1 / 60)
    assert ball.position[1] == pytest.approx(0.1, abs=0.02)


def test_all_degenerate_mesh_is_refused():
    v = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 0, 1]], float)
    for accel in ("grid2d", "bvh", "brute"):
        with pytest.raises(ValueError, match="degenerate"):
            mb.TriangleMesh(v, [[0, 1, 2], [0, 0, 3]], accel=accel)


# --- files ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("klass,name,data", fc.mesh_files(), ids=[c[1] for c in fc.mesh_files()])
def test_bad_mesh_files_are_refused_naming_the_file(tmp_path, klass, name, data):
    p = tmp_path / name
    p.write_bytes(data)
    with pytest.raises(ValueError, match=name.replace(".", r"\.")):
        mb.TriangleMesh.load(p)


@pytest.mark.parametrize("name,data", fc.good_mesh_files(), ids=[c[0] for c in fc.good_mesh_files()])
def test_obj_files_in_any_text_encoding_load(tmp_path, name, data):
    p = tmp_path / name
    p.write_bytes(data)
    m = mb.TriangleMesh.load(p)
    assert m.triangles.shape[0] in (1, 2)
    assert not m.check().has_problems


def test_mesh_path_must_be_a_path():
    for bad in (None, 3, ["a.obj"]):
        with pytest.raises(TypeError, match="path"):
            mb.TriangleMesh.load(bad)


@pytest.mark.parametrize("klass,text,files", fc.level_texts(), ids=[f"{c[0]}-{i}" for i, c in
                                                                      enumerate(fc.level_texts())])
def test_bad_levels_are_refused_naming_the_file(tmp_path, klass, text, files):
    for name, data in files.items():
        (tmp_path / name).write_bytes(data)
    p = tmp_path / "lvl.toml"
    p.write_bytes(text if isinstance(text, bytes) else text.encode())
    with pytest.raises(LevelError) as err:
        load_level(p)
    msg = str(err.value)
    assert "lvl.toml" in msg and len(msg) < 600


def test_the_level_fuzz_base_loads(tmp_path):
    p = tmp_path / "lvl.toml"
    p.write_text(fc.GOOD_LEVEL)
    assert load_level(p).goal_half_extents.tolist() == [1.0, 1.0, 1.0]


# --- the gym environment ----------------------------------------------------------------------------------
@pytest.mark.parametrize("option,klass,value", [(o, c, v) for o, vs in fc.ENV_OPTIONS for c, v in vs],
                         ids=[f"{o}-{c}-{i}" for o, vs in fc.ENV_OPTIONS for i, (c, v) in enumerate(vs)])
def test_bad_env_options_are_refused(option, klass, value):
    from marbellous.app.envs.marble_env import MarbellousEnv

    kw = {"level": "blocks", option: value}
    with pytest.raises((ValueError, TypeError)) as err:
        MarbellousEnv(**kw)
    assert option in str(err.value) or (option == "level" and "level" in str(err.value))


def test_bad_env_calls_are_refused():
    from marbellous.app.envs.marble_env import MarbellousEnv

    env = MarbellousEnv(level="blocks")
    for opt, values in fc.ENV_RESET:
        for _, value in values:
            with pytest.raises((ValueError, TypeError), match=opt):
                env.reset(**{opt: value})
    env.reset(seed=0)
    for _, value in fc.KINDS["action"]:
        with pytest.raises((ValueError, TypeError), match="action"):
            env.step(value)


@pytest.mark.parametrize("option,klass,value",
                         [(o, c, v) for o, vs in fc.VECTOR_ENV_OPTIONS + fc.ENV_OPTIONS for c, v in vs],
                         ids=[f"{o}-{c}-{i}" for o, vs in fc.VECTOR_ENV_OPTIONS + fc.ENV_OPTIONS
                              for i, (c, v) in enumerate(vs)])
def test_bad_vector_env_options_are_refused(option, klass, value):
    import gymnasium as gym

    kw = {"num_envs": 2, "level": "blocks", option: value}
    with pytest.raises((ValueError, TypeError)) as err:
        gym.make_vec("Marbellous-v0", vectorization_mode="vector_entry_point", **kw)
    assert option in str(err.value) or (option == "level" and "level" in str(err.value))


@pytest.mark.parametrize("num_envs", [1, 3])       # (from 3 envs the marbles are pushed and stepped together)
def test_bad_vector_env_calls_are_refused_and_change_nothing(num_envs):
    from marbellous.app.envs.marble_vector_env import MarbellousVectorEnv

    env = MarbellousVectorEnv(num_envs, level="blocks")
    for opt, values in fc.ENV_RESET:
        for _, value in values:
            with pytest.raises((ValueError, TypeError), match=opt):
                env.reset(**{opt: value})
    first = env.reset(seed=0)[0]
    for _, value in fc.KINDS["action"]:
        with pytest.raises((ValueError, TypeError), match="action"):
            env.step([(0.5, -0.5)] * (num_envs - 1) + [value])     # the last env's action bad
    np.testing.assert_array_equal(np.stack([e._obs() for e in env.envs]), first)


def test_gym_make_refuses_bad_options():
    import gymnasium as gym

    for kw in ({"frame_skip": 1e300}, {"start_jitter": -1}, {"goal_reward": math.nan}, {"frame_skip": "3"}):
        with pytest.raises((ValueError, TypeError), match=next(iter(kw))):
            gym.make("Marbellous-v0", level="blocks", **kw)


# --- accepted input never makes NaN -----------------------------------------------------------------------
def _valid_vec(bound):
    return st.lists(st.floats(-bound, bound), min_size=3, max_size=3)


@st.composite
def valid_bodies(draw):
    kind = draw(st.sampled_from(["sphere", "box", "capsule", "compound"]))
    size = st.floats(1e-6, 1e6)
    if kind == "sphere":
        shape = mb.Sphere(draw(size))
    elif kind == "box":
        shape = mb.Box(draw(st.lists(size, min_size=3, max_size=3)))
    elif kind == "capsule":
        shape = mb.Capsule(draw(size), draw(size))
    else:
        shape = [(mb.Sphere(draw(size)), draw(_valid_vec(1e6))), (mb.Box(draw(st.lists(size, min_size=3, max_size=3))),
                                                                 draw(_valid_vec(1e6)))]
    kw = dict(position=draw(_valid_vec(1e12)), velocity=draw(_valid_vec(1e9)), angular_velocity=draw(_valid_vec(1e9)),
              orientation=draw(st.lists(st.floats(-1e300, 1e300), min_size=4, max_size=4).filter(any)),
              friction=draw(st.floats(0, 1e3)), restitution=draw(st.floats(0, 1)),
              rolling_friction=draw(st.floats(0, 1e6)), torsional_friction=draw(st.floats(0, 1e6)),
              linear_damping=draw(st.floats(0, 1e6)), angular_damping=draw(st.floats(0, 1e6)))
    if draw(st.booleans()):
        kw["mass"] = draw(st.floats(1e-30, 1e30))
    else:
        kw["density"] = draw(st.floats(1e-6, 1e6))
    return shape, kw


@settings(max_examples=60, database=None)
@given(bodies=st.lists(valid_bodies(), min_size=1, max_size=3), dt=st.floats(1e-6, 1.0),
       gravity=_valid_vec(1e6), force=_valid_vec(1e20), substeps=st.integers(1, 8),
       solver=st.sampled_from(["sequential_impulse", "penalty", "lcp"]), drive=_valid_vec(1e9))
def test_valid_input_never_makes_nan(bodies, dt, gravity, force, substeps, solver, drive):
    w = mb.World(gravity=gravity, substeps=substeps, solver=solver)
    w.add_static(mb.Plane())
    w.add_kinematic(mb.Box((1.0, 0.2, 1.0)), position=(0.0, 1.0, 0.0), velocity=drive, angular_velocity=drive)
    made = []
    for shape, kw in bodies:
        try:
            made.append(w.add_body(shape, **kw))
        except ValueError as e:           # a density that makes the mass leave [1e-30, 1e30] kg
            assert "density" in str(e) or "inertia" in str(e)
    if made:
        made[0].apply_force(force)
        made[0].apply_impulse(force, point=made[0].position)
    for _ in range(5):
        w.step(dt)
        for event in w.contact_events():
            assert np.all(np.isfinite(event.point)) and math.isfinite(event.approach_speed)
    bf = w.snapshot().tables["bf"]
    rows = [b._index for b in made]
    assert np.all(np.isfinite(bf[rows])), "NaN or inf in the bodies' state"
    w.raycast((0.0, 10.0, 0.0), (0.0, -1.0, 0.0))
