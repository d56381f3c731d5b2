"""Queries on a world: where will a crate land, what is near it, and what is below it.

- ``w.shape_cast(shape, start, end)`` slides a shape along a line and reports the first body it meets:
  here it predicts where a crate dropped over a ramp of steps will first touch down, before it falls.
- ``w.query_box(lower, upper)`` lists the bodies whose bounding boxes overlap a box.
- ``w.raycast(origin, direction)`` finds the nearest surface along a ray.

Run:  python examples/queries.py
"""
import marbellous as mb

DT = 1.0 / 60.0
CRATE = mb.Box((0.25, 0.25, 0.25))


def run():
    """Predict the crate's touch-down with a shape cast, then drop it; returns (predicted height of its
    centre at touch-down (m), the height it really first touched at (m), the bodies near the landing
    spot, the ray's distance to the ground beside the steps (m))."""
    w = mb.World()
    ground = w.add_static(mb.Plane())
    steps = [w.add_static(mb.Box((0.5, 0.25 * (k + 1), 1.0)), position=(1.0 * k, 0.25 * (k + 1), 0.0))
             for k in range(4)]
    start = (2.2, 5.0, 0.0)
    hit = w.shape_cast(CRATE, start, (2.2, -1.0, 0.0))
    predicted = start[1] - hit.distance
    crate = w.add_body(CRATE, position=start)
    touched = None
    while touched is None:
        w.step(DT)
        if any(e.kind == "begin" for e in w.contact_events()):
            touched = float(crate.position[1])
    near = w.query_box((1.5, 0.0, -0.5), (2.9, 3.0, 0.5))
    beside = w.raycast((6.0, 3.0, 0.0), (0.0, -1.0, 0.0))
    assert beside.body is ground and hit.body is steps[2]
    return predicted, touched, near, beside.distance


if __name__ == "__main__":
    predicted, touched, near, beside = run()
    print(f"shape cast: the crate will touch down with its centre at y = {predicted:.4f} m (the third step's "
          f"top, 1.5 m, plus its half height 0.25 m)")
    print(f"dropped, it first touched with its centre at y = {touched:.4f} m")
    print(f"bodies near the landing spot: {near}")
    print(f"ray beside the steps: ground {beside:.2f} m below")
