"""Contact events: crates dropped from different heights onto a floor, each landing heard as one "clack"
whose loudness follows its approach speed, and each lift-off as one "end".

``w.contact_events()`` reports, after each step, the pairs of bodies that began or stopped touching: one
event per pair (a crate landing flat on four corners begins once), none while it rests, and a begin's
``approach_speed`` is the speed it fell at, ``sqrt(2 g h)``.

Run:  python examples/impacts.py
"""
import marbellous as mb

DT = 1.0 / 60.0
DROPS = (0.2, 0.8, 1.8)          # heights (m) of the crates' lowest faces above the floor


def run(steps=120):
    """Drop the crates, then throw the first one up; returns the events as (step, kind, crate number,
    approach speed (m/s))."""
    w = mb.World()
    floor = w.add_static(mb.Plane())
    crates = [w.add_body(mb.Box((0.2, 0.2, 0.2)), position=(1.0 * k, 0.2 + h, 0.0)) for k, h in enumerate(DROPS)]
    heard = []
    for step in range(2 * steps):
        if step == steps:
            crates[0].apply_impulse((0.0, 3.0 * crates[0].mass, 0.0))   # thrown up at 3 m/s
        w.step(DT)
        for event in w.contact_events():
            other = event.body_b if event.body_a is floor else event.body_a
            heard.append((step, event.kind, crates.index(other), event.approach_speed))
    return heard


if __name__ == "__main__":
    for step, kind, crate, speed in run():
        if kind == "begin":
            loudness = "!" * max(1, round(speed))
            print(f"{step * DT:5.2f} s  crate {crate} lands at {speed:.2f} m/s  clack{loudness}")
        else:
            print(f"{step * DT:5.2f} s  crate {crate} leaves the floor")
