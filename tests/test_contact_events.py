"""Contact begin/end events: one per pair of bodies as they start and stop touching, none while they rest,
none for a near miss; the approach speed of a landing is its fall speed."""
import math
import runpy
from pathlib import Path

import numpy as np
import pytest

import marbellous as mb

DT = 1.0 / 60.0
G = 9.81


def _events(w, steps):
    """Step ``steps`` times; every event with the index of the step that reported it."""
    out = []
    for k in range(steps):
        w.step(DT)
        out += [(k, e) for e in w.contact_events()]
    return out


@pytest.mark.parametrize("time_stepping", ["fixed", "retroactive", "conservative"])
def test_a_ball_lands_once_rests_silently_and_ends_once_when_lifted(time_stepping):
    """Dropped from 0.8 m (centre 1 m, radius 0.2 m): one begin, at the fall speed ``sqrt(2 g h)`` less at
    most the ``g dt`` it gains within the landing step (the speed is taken as the step begins); then
    nothing for 4 s of rest (asleep after 0.5 s of it); lifted at 10 m/s: one end; and one begin when it
    comes back down at 10 m/s (less the same ``g dt``; it flies ~2 s)."""
    w = mb.World(time_stepping=time_stepping)
    ground = w.add_static(mb.Plane())
    ball = w.add_body(mb.Sphere(0.2), mass=3.0, position=(0.0, 1.0, 0.0))
    landing = _events(w, 240)
    assert [e.kind for _, e in landing] == ["begin"]
    event = landing[0][1]
    assert (event.body_a, event.body_b) == (ground, ball)
    np.testing.assert_allclose(event.normal, [0.0, 1.0, 0.0], atol=1e-12)
    fall = math.sqrt(2.0 * G * 0.8)
    assert fall - G * DT <= event.approach_speed <= fall + 1e-9
    assert ball.is_sleeping
    ball.apply_impulse((0.0, 30.0, 0.0))
    flight = _events(w, 150)
    assert [e.kind for _, e in flight] == ["end", "begin"]
    assert flight[0][0] <= 1                             # it leaves within a step of the throw
    assert flight[1][1].approach_speed == pytest.approx(10.0, abs=G * DT)


def test_a_box_landing_on_four_corners_begins_once():
    w = mb.World()
    w.add_static(mb.Plane())
    w.add_body(mb.Box((0.5, 0.2, 0.5)), position=(0.0, 1.0, 0.0))
    assert [e.kind for _, e in _events(w, 120)] == ["begin"]


def test_a_near_miss_inside_the_speculative_distance_is_no_event():
    """A ball skimming 1 cm over a box (the speculative distance is 2 cm): contacts are made, none touches."""
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    w.add_static(mb.Box((1.0, 0.5, 1.0)), position=(0.0, -0.5, 0.0))
    ball = w.add_body(mb.Sphere(0.2), position=(-2.0, 0.21, 0.0), velocity=(2.0, 0.0, 0.0))
    seen_contacts = False
    for _ in range(120):
        w.step(DT)
        seen_contacts |= bool(w.contacts())
        assert w.contact_events() == []
    assert seen_contacts and ball.position[0] > 1.5


def test_a_sensor_reports_a_body_passing_through_it():
    w = mb.World()
    gate = w.add_static(mb.Box((1.0, 0.1, 1.0)), position=(0.0, 2.0, 0.0), sensor=True)
    ball = w.add_body(mb.Sphere(0.2), position=(0.0, 3.0, 0.0))
    events = _events(w, 60)
    assert [(e.kind, e.body_a, e.body_b) for _, e in events] == [("begin", gate, ball), ("end", gate, ball)]
    assert events[0][1].approach_speed > 0.0


def test_simultaneous_landings_come_in_the_bodies_order():
    w = mb.World()
    ground = w.add_static(mb.Plane())
    balls = [w.add_body(mb.Sphere(0.2), position=(x, 1.0, 0.0)) for x in (3.0, -3.0, 0.0)]
    events = _events(w, 60)
    assert [(e.kind, e.body_a, e.body_b) for _, e in events] == [("begin", ground, b) for b in balls]
    assert len({k for k, _ in events}) == 1


def test_removal_and_restore_report_nothing_stale():
    """After a body is removed its pair makes no events (not even an end); after a restore, nothing is
    reported until the next step."""
    w = mb.World()
    w.add_static(mb.Plane())
    ball = w.add_body(mb.Sphere(0.2), position=(0.0, 0.4, 0.0))
    other = w.add_body(mb.Sphere(0.2), position=(2.0, 0.4, 0.0))
    assert w.contact_events() == []
    landing = _events(w, 30)
    assert len(landing) == 2
    w.remove(ball)
    assert [e.body_b for e in w.contact_events()] in ([], [other])
    assert _events(w, 30) == []
    before = w.snapshot()
    other.position = (2.0, 3.0, 0.0)
    assert [e.kind for _, e in _events(w, 2)] == ["end"]
    w.restore(before)
    assert w.contact_events() == []


def test_the_example_hears_each_landing_once_at_its_fall_speed():
    """examples/impacts.py: three crates dropped from 0.2, 0.8 and 1.8 m land once each at ``sqrt(2 g h)``
    (less at most ``g dt``); the first, thrown up at 3 m/s, leaves once and lands again at 3 m/s."""
    run = runpy.run_path(str(Path(__file__).parents[1] / "examples" / "impacts.py"))["run"]
    heard = run()
    assert [(kind, crate) for _, kind, crate, _ in heard] == [("begin", 0), ("begin", 1), ("begin", 2),
                                                             ("end", 0), ("begin", 0)]
    for (_, _, _, speed), h in zip(heard, (0.2, 0.8, 1.8)):
        fall = math.sqrt(2.0 * G * h)
        assert fall - G * DT <= speed <= fall + 1e-9
    assert heard[-1][3] == pytest.approx(3.0, abs=G * DT)


def test_a_sleeping_stack_keeps_its_contacts_as_they_were_and_wakes_to_a_new_one():
    """Once a stack of three boxes sleeps, each step keeps its contacts as the last awake step left them (the
    same points, normals and impulses, reported by ``contacts``; no copy: the step keeps its cache in place)
    and makes no event; a ball dropped on top begins touching it, and the step that meets the ball copies the
    resting contacts again."""
    from marbellous.state import layout as L
    w = mb.World()
    w.add_static(mb.Plane())
    boxes = [w.add_body(mb.Box((0.5, 0.5, 0.5)), position=(0.0, 0.5 + k, 0.0)) for k in range(3)]
    for _ in range(600):
        w.step(DT)
        if all(b.is_sleeping for b in boxes):
            break
    assert all(b.is_sleeping for b in boxes)
    w.step(DT)
    asleep = w.contacts()
    assert len(asleep) >= 12                      # four corners or more under each box
    for _ in range(30):
        w.step(DT)
        assert w._state.stats[L.STAT_KEPT] == 1
        assert w.contact_events() == []
        now = w.contacts()
        assert [(c.body_a, c.body_b) for c in now] == [(c.body_a, c.body_b) for c in asleep]
        for c, d in zip(now, asleep):
            np.testing.assert_array_equal(c.point, d.point)
            np.testing.assert_array_equal(c.normal, d.normal)
            assert c.normal_impulse == d.normal_impulse
    ball = w.add_body(mb.Sphere(0.2), position=(0.0, 3.5, 0.0), velocity=(0.0, -3.0, 0.0))
    kinds, kept = [], []
    for _ in range(30):
        w.step(DT)
        kinds += [(e.kind, e.body_a, e.body_b) for e in w.contact_events()]
        kept.append(int(w._state.stats[L.STAT_KEPT]))
    assert ("begin", boxes[2], ball) in kinds
    assert 0 in kept
    assert not boxes[2].is_sleeping
