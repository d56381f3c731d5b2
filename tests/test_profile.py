"""World.profile: per-stage times measured inside the compiled step, and the step's counts."""
import time

import pytest

import marbellous as mb
from marbellous.pipeline.stages import STAGE_NAMES


def resting_sphere(**options):
    w = mb.World(**options)
    w.add_static(mb.Plane())
    w.add_body(mb.Sphere(0.5), position=(0.0, 0.5, 0.0))
    return w


def test_off_by_default_and_empty():
    w = resting_sphere()
    assert w.profiling is False
    for _ in range(5):
        w.step(1 / 60)
    p = w.profile
    assert p.steps == 0 and p.total == 0.0
    assert "no steps profiled" in str(p)


def test_stages_counts_and_wall_time():
    w = resting_sphere(sleeping=False)
    for _ in range(10):
        w.step(1 / 60)
    w.profiling = True
    n = 50
    t0 = time.perf_counter()
    for _ in range(n):
        w.step(1 / 60)
    wall = time.perf_counter() - t0
    p = w.profile
    assert p.steps == n
    assert list(p.seconds) == list(STAGE_NAMES)
    assert all(v >= 0.0 for v in p.seconds.values())
    assert p.seconds["solve"] > 0.0 and p.seconds["narrow_phase"] > 0.0
    # the stages run inside the timed loop: their sum cannot exceed its wall time (the counter's rate is
    # measured against the same clock, to well under 1%)
    assert 0.0 < p.total <= 1.01 * wall
    # one sphere resting on a plane: one candidate pair and one contact point in every step; at least one
    # velocity iteration per sub-step and at most `iterations` per sub-step
    assert p.pairs == 1.0 and p.contacts == 1.0
    assert w.substeps <= p.iterations <= w.substeps * w.iterations
    per = p.per_step()
    assert per["solve"] == pytest.approx(p.seconds["solve"] / n)
    text = str(p)
    for name in STAGE_NAMES:
        assert name in text


def test_reset_and_profiling_does_not_change_physics():
    a = resting_sphere()
    b = resting_sphere()
    b.profiling = True
    for _ in range(30):
        a.step(1 / 60)
        b.step(1 / 60)
    assert a.state_hash() == b.state_hash()
    assert b.profile.steps == 30
    b.reset_profile()
    assert b.profile.steps == 0 and b.profile.total == 0.0
    b.profiling = False
    b.step(1 / 60)
    assert b.profile.steps == 0


def test_bad_flag_is_refused_and_changes_nothing():
    w = resting_sphere()
    with pytest.raises(TypeError, match="profiling"):
        w.profiling = 1
    assert w.profiling is False


def test_the_docs_list_the_stages_the_step_runs():
    """docs/architecture.md's table of stages is pipeline/stages.py's list, in order, with the same words;
    the step's docstring is made from the same list."""
    import pathlib
    import re

    from marbellous.pipeline import step
    from marbellous.pipeline.stages import STAGES

    doc = (pathlib.Path(mb.__file__).parent.parent / "docs" / "architecture.md").read_text()
    table = re.search(r"<!-- stages -->\n\| stage \| what it does \|\n\| --- \| --- \|\n((?:\|.*\|\n)+)", doc).group(1)
    rows = [re.match(r"\| `(\w+)`(?: \(each sub-step\))? \| (.*) \|", line).groups() for line in table.splitlines()]
    assert rows == [(name, what) for name, what in STAGES]
    for name, what in STAGES:
        assert name in step.__doc__ and what.split()[0] in step.__doc__
