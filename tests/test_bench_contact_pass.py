"""The contact pass's solver-limit benchmark (bench/bench_contact_pass.py): its C++ kernel does the engine's pass
bit for bit, so what it times is the same work (no timing is checked).  Without a C++ compiler the tests skip."""
import shutil

import numpy as np
import pytest

import marbellous as mb
from marbellous._numba.wide import LANES
from marbellous.state import layout as L
from bench.bench_contact_pass import ContactPass, build_kernels, main

pytestmark = pytest.mark.skipif(shutil.which("c++") is None, reason="no C++ compiler")

H = 1.0 / 60.0


@pytest.fixture
def kernels(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    return build_kernels()


def _mixed_pile():
    """Long boxes (their world inertia turns with them) and spheres with rolling and torsional friction, fallen
    into a heap: every branch of the pass (turning bundles, rolling bundles, speculative gaps and overlap)."""
    world = mb.World()
    world.add_static(mb.Plane((0.0, 1.0, 0.0)))
    rng = np.random.default_rng(3)
    for k in range(60):
        position = (rng.uniform(-1.0, 1.0), 0.3 + 0.35 * k, rng.uniform(-1.0, 1.0))
        if k % 2:
            axis, angle = rng.normal(size=3), rng.uniform(0.0, np.pi)
            orientation = (np.cos(angle / 2), *(np.sin(angle / 2) * axis / np.linalg.norm(axis)))
            world.add_body(mb.Box((0.3, 0.1, 0.15)), position=position, orientation=orientation)
        else:
            world.add_body(mb.Sphere(0.15), position=position, rolling_friction=0.01, torsional_friction=0.01)
    for _ in range(90):
        world.step(H)
    return world


def test_one_pass_of_the_cpp_kernel_is_the_engines_bit_for_bit(kernels):
    run = ContactPass(_mixed_pile(), kernels)
    flags = run.wide_i[:run.bundles * L.BUNDLE_ROWS * LANES].reshape(run.bundles, L.BUNDLE_ROWS, LANES)
    assert flags[:, L.WI_TURNING, 0].any() and flags[:, L.WI_ROLLING, 0].any()   # both kinds of bundle are there
    assert run.same_result()
    # in single precision a body's velocity takes the rounding of each of its contacts' updates in turn: under a
    # hundred operations each, at 2^-24 of the largest speed (the tables themselves rounded to float first)
    written = np.concatenate([flags[:, L.WI_WRITE_A].ravel(), flags[:, L.WI_WRITE_B].ravel()])
    updates = np.bincount(written[written < run.sb.shape[0] - 1]).max()       # (the sink row left out)
    scale = 1.0 + float(np.max(np.abs(run.sb[:, L.SB_V:L.SB_W + 3])))
    assert run.single_difference() < (updates + 1) * 100 * 2.0**-24 * scale


def test_a_quick_run_reports_both_kernels_on_the_same_contacts(capsys):
    rows = main(["--quick", "--scenes", "pyramid_20_awake", "--no-write"])
    (row,) = rows
    assert row["identical"] and row["bundled"] > 64 and row["lanes"] >= row["bundled"]
    assert row["engine_ns_per_contact"] > 0 and row["limit_ns_per_contact"] > 0 and row["single_ns_per_contact"] > 0
    assert "pyramid_20_awake" in capsys.readouterr().out
