"""Drawing any World headless (EGL): each part of a world appears where the camera puts it, in the colour
of what it is; the overlays draw contacts, boxes and constraint lines; meshes are uploaded once."""
import numpy as np
import pytest
import viewer_scene

import marbellous as mb
from marbellous.render import palette
from marbellous.render.draw_lists import Points
from marbellous.render.drawables import DRAWABLES, Drawable, register
from marbellous.render.orbit_camera import OrbitCamera
from marbellous.render.transforms import look_at, perspective, quat_to_matrix
from marbellous.render.world_renderer import WorldRenderer

SIZE = (480, 270)


@pytest.fixture(scope="module")
def renderer():
    from marbellous.render.context import headless_context

    ctx = headless_context()
    yield WorldRenderer(ctx, SIZE)
    ctx.release()


@pytest.fixture
def scene():
    w, parts = viewer_scene.build()
    for _ in range(10):
        w.step(1 / 60)
    return w, parts


VIEW = OrbitCamera.looking(*viewer_scene.CAMERA).view()


def project(point, view=VIEW, size=SIZE):
    """Pixel (column, row from the top) of a world point (m) with the renderer's camera matrices."""
    c = perspective(view.fov, size[0] / size[1], 0.05, 400.0) @ look_at(view.eye, view.target) @ np.append(point, 1)
    ndc = c[:3] / c[3]
    return int(round((ndc[0] + 1) / 2 * size[0])), int(round((1 - ndc[1]) / 2 * size[1]))


def patch(img, point, r=2, view=VIEW):
    """Pixels (K, 3) int of the (2 r + 1)^2 square around the projection of ``point`` seen from ``view``."""
    x, y = project(point, view)
    return img[y - r:y + r + 1, x - r:x + r + 1].reshape(-1, 3).astype(int)


def warm(px):
    """Warm hues (dynamic bodies), lit or in shade."""
    return (px[:, 0] >= px[:, 1]) & (px[:, 0] > 2 * px[:, 2] + 15)


def grey(px):
    """Neutral greys brighter than the background (static bodies), lit or in shade."""
    return (px.max(axis=1) - px.min(axis=1) < 30) & (px.mean(axis=1) > 65)


def near(px, color, tol=40):
    return np.all(np.abs(px - 255 * np.asarray(color)) < tol, axis=1)


def test_every_part_is_drawn_where_the_camera_puts_it(renderer, scene):
    w, parts = scene
    img = renderer.render_to_array(w, VIEW)
    assert img.shape == (SIZE[1], SIZE[0], 3) and img.dtype == np.uint8
    # the stack's boxes: warm dynamic colours, each a different hue from its neighbour
    centres = [patch(img, b.position) for b in parts["stack"]]
    assert all(warm(p).all() for p in centres)
    assert not np.array_equal(centres[0].mean(axis=0).round(), centres[1].mean(axis=0).round())
    # the triangle-mesh floor: grey, between the stack and the camera
    assert grey(patch(img, (0.5, 0.0, 3.5))).all()
    # the background above the scene
    assert near(img[:5, -5:].reshape(-1, 3).astype(int), palette.BACKGROUND, 3).all()
    # the hanging ball and the ball on the spring (without the constraints' dots over their centres)
    bodies = renderer.render_to_array(w, VIEW, layers=("bodies",))
    assert warm(patch(bodies, parts["bob"].position, 2)).all()
    assert warm(patch(bodies, parts["ball"].position, 2)).all()
    # the sensor: translucent green over the floor
    px = patch(img, parts["sensor"].position, 1)
    assert np.all((px[:, 1] > px[:, 0] + 25) & (px[:, 1] > px[:, 2] + 25))
    # lit and shaded: many shades in the picture
    assert len(np.unique(img.reshape(-1, 3) // 8, axis=0)) > 40


@pytest.mark.parametrize("name, color", [("rod", palette.ROD), ("spring", palette.SPRING)])
def test_constraints_are_lines_between_their_world_anchors(renderer, scene, name, color):
    w, parts = scene
    c = parts[name]
    img = renderer.render_to_array(w, VIEW)
    a = c.body_a.position + quat_to_matrix(c.body_a.orientation) @ c.anchor_a
    b = c.anchor_b
    for t in (0.2, 0.35, 0.5, 0.65, 0.8):
        assert near(patch(img, a + t * (b - a), 2), color, 45).any(), t
    off = np.array([0.6, 0.0, 0.0])
    assert not near(patch(img, 0.5 * (a + b) + off, 1), color, 45).any()
    # without the constraints layer the line is gone
    bare = renderer.render_to_array(w, VIEW, layers=("bodies",))
    assert not near(patch(bare, 0.5 * (a + b), 1), color, 45).any()


def test_a_joint_is_drawn_as_an_arm_from_its_body_and_its_axis(renderer, scene):
    w, parts = scene
    hinge, bar = parts["hinge"], parts["bar"]
    img = renderer.render_to_array(w, VIEW)
    anchor = hinge.anchor
    for t in (0.5, 0.7, 0.9):           # (the axis crosses the arm near the anchor)
        assert near(patch(img, anchor + t * (bar.position - anchor), 1), palette.JOINT, 45).any(), t
    assert near(patch(img, anchor, 3), palette.JOINT_AXIS, 45).any()
    bare = renderer.render_to_array(w, VIEW, layers=("bodies",))
    assert not near(patch(bare, 0.5 * (anchor + bar.position), 1), palette.JOINT, 45).any()


def test_contacts_overlay_marks_the_contact_points(renderer, scene):
    w, _ = scene
    contacts = w.contacts()
    assert contacts
    plain = renderer.render_to_array(w, VIEW)
    marked = renderer.render_to_array(w, VIEW, layers=("bodies", "constraints", "contacts"))
    changed = np.any(plain != marked, axis=-1)
    assert changed.sum() > 50
    assert near(marked[changed].astype(int), palette.CONTACT, 60).mean() > 0.5
    hits = [near(patch(marked, c.point, 3), palette.CONTACT, 60).any() for c in contacts]
    assert np.mean(hits) > 0.8          # (a few may hide under other dots' dark rims)


def test_boxes_overlay_outlines_the_broad_phase_boxes(renderer, scene):
    w, parts = scene
    plain = renderer.render_to_array(w, VIEW, layers=("bodies",))
    boxed = renderer.render_to_array(w, VIEW, layers=("bodies", "boxes"))
    changed = np.any(plain != boxed, axis=-1)
    assert near(boxed[changed].astype(int), palette.BOX, 60).mean() > 0.6
    top = parts["stack"][-1]
    corner = top.position + (0.4, 0.3, 0.4)
    assert near(patch(boxed, corner, 4), palette.BOX, 60).any()


def test_sleeping_bodies_turn_blue(renderer, scene):
    w, parts = scene
    for _ in range(120):
        w.step(1 / 60)
    assert parts["stack"][0].is_sleeping
    px = patch(renderer.render_to_array(w, VIEW), parts["stack"][0].position)
    assert np.all(px[:, 2] > px[:, 0] + 30)


def test_a_kinematic_platform_is_drawn_violet_where_it_has_moved(renderer):
    """A kinematic body is drawn in its own colour (violet: red and blue over green), at its pose now."""
    w = mb.World()
    w.add_static(mb.Plane())
    platform = w.add_kinematic(mb.Box((1.0, 0.1, 1.0)), position=(-1.0, 1.0, 0.0), velocity=(1.0, 0.0, 0.0))
    for _ in range(60):
        w.step(1 / 60)
    view = OrbitCamera.looking((3.0, 5.0, 6.0), (0.0, 1.0, 0.0)).view()
    px = patch(renderer.render_to_array(w, view), platform.position + (0.0, 0.1, 0.0), view=view)
    assert platform.position[0] == pytest.approx(0.0, abs=1e-12)
    assert np.all(px[:, 2] > px[:, 1] + 25) and np.all(px[:, 0] > px[:, 1] + 10)


def test_contact_events_are_dots_where_pairs_began_touching(renderer):
    """The "events" layer draws a red dot at a landing's contact point in the step it began."""
    w = mb.World()
    w.add_static(mb.Plane())
    ball = w.add_body(mb.Sphere(0.3), position=(0.0, 0.6, 0.0))
    while not w.contact_events():
        w.step(1 / 60)
    (event,) = w.contact_events()
    view = OrbitCamera.looking((0.0, 2.0, 4.0), (0.0, 0.0, 0.0)).view()
    with_events = renderer.render_to_array(w, view, layers=("bodies", "events"))
    without = renderer.render_to_array(w, view, layers=("bodies",))
    px, before = patch(with_events, event.point, view=view), patch(without, event.point, view=view)
    assert event.kind == "begin" and ball.position[1] < 0.31
    assert np.all(near(px, palette.EVENT_BEGIN)) and not np.all(near(before, palette.EVENT_BEGIN))


def test_a_registered_drawable_is_drawn_in_its_layer(renderer, scene):
    w, parts = scene
    spot = np.array([0.0, 2.5, 0.0])
    register(Drawable("test-dot", lambda frame: [Points(spot[None], np.array([[0.1, 1.0, 0.1]]), 12.0)],
                      shown=False, help="a green dot"))
    try:
        img = renderer.render_to_array(w, VIEW, layers=("bodies", "test-dot"))
        assert near(patch(img, spot, 2), (0.1, 1.0, 0.1), 30).all()
        with pytest.raises(ValueError, match="already registered"):
            register(DRAWABLES["test-dot"])
    finally:
        del DRAWABLES["test-dot"]
    with pytest.raises(ValueError, match="layers: unknown 'test-dot'"):
        renderer.render_to_array(w, VIEW, layers=("bodies", "test-dot"))


def test_heightfields_capsules_and_planes_are_drawn(renderer):
    heights = np.fromfunction(lambda i, j: 0.4 + 0.15 * np.sin(i / 2.0) * np.cos(j / 3.0), (12, 12))
    field = mb.HeightField(heights, spacing=(0.4, 0.4), origin=(-2.2, 0.0, -2.2))
    view = OrbitCamera.looking((4.0, 3.0, 4.0), (0.0, 0.5, 0.0)).view()
    w = mb.World()
    w.add_static(field)
    cap = w.add_body(mb.Capsule(0.2, 0.5), position=(0.0, 1.2, 0.0), orientation=(0.7071, 0.0, 0.0, 0.7071))
    img = renderer.render_to_array(w, view)
    assert warm(patch(img, cap.position, 2, view)).all() and warm(patch(img, cap.position + (0.4, 0, 0), 1, view)).all()
    # the field's surface is grey where the field is, and there is nothing beyond its edges
    for x, z in ((1.2, 1.6), (-1.4, 1.0), (1.0, -1.4)):     # (none behind the capsule)
        assert grey(patch(img, (x, field.height_at(x, z), z), 1, view)).all()
    for p in ((3.0, 0.0, 0.0), (0.0, 0.0, 3.0)):
        assert near(patch(img, p, 1, view), palette.BACKGROUND, 3).all()
    # an infinite plane reaches far beyond: grey ground, fading to the background at the horizon
    w.add_static(mb.Plane())
    img = renderer.render_to_array(w, view)
    for p in ((3.0, 0.0, 0.0), (0.0, 0.0, 3.0), (-6.0, 0.0, 6.0)):
        assert grey(patch(img, p, 1, view)).all()
    assert near(img[2, SIZE[0] // 2][None].astype(int), palette.BACKGROUND, 3).all()


def test_a_fluid_is_drawn_as_its_box_dye_and_flow(renderer):
    """The "fluids" layer draws the box's edges and the dye as blue puffs, the "flow" layer the velocity as
    lines, white where it is fastest."""
    w = mb.World(gravity=(0.0, 0.0, 0.0))
    f = w.add_fluid(mb.Fluid((8, 8, 8), 0.25, origin=(-1.0, 0.0, -1.0), boundary="periodic"))
    dye = np.zeros((8, 8, 8))
    dye[3:5, 3:5, 3:5] = 1.0
    f.dye = dye
    f.velocity = np.tile([2.0, 0.0, 0.0], (8, 8, 8, 1))
    w.step(1 / 60)
    view = OrbitCamera.looking((0.0, 1.0, 6.0), (0.0, 1.0, 0.0)).view()
    puffs = renderer.render_to_array(w, view, layers=("fluids",))
    empty = renderer.render_to_array(w, view, layers=())
    px = patch(puffs, np.array([0.0, 1.0, 0.0]), 3, view=view)
    bare = patch(empty, np.array([0.0, 1.0, 0.0]), 3, view=view)
    assert np.sum(px[:, 2] > px[:, 0] + 40) >= 10 and not np.any(bare[:, 2] > bare[:, 0] + 40)   # blue puffs
    corner = patch(puffs, np.array([-1.0, 2.0, 1.0]), 1, view=view)
    assert np.any(near(corner, palette.FLUID_BOX, 60))                                   # the box's edge
    flow = renderer.render_to_array(w, view, layers=("flow",))
    assert np.any(near(flow.reshape(-1, 3).astype(int), palette.FLUID_FAST, 25)) and not np.array_equal(flow, empty)


def test_meshes_are_uploaded_once_and_only_poses_change():
    from marbellous.render.context import headless_context

    terrain = viewer_scene.floor_mesh(half=20.0, cells=256)          # 131072 triangles
    assert len(terrain.triangles) == 131072
    w = mb.World()
    w.add_static(terrain)
    boxes = [w.add_body(mb.Box((0.3, 0.3, 0.3)), position=(0.8 * k, 0.3, 0.0)) for k in range(5)]
    w.add_body(mb.Sphere(0.3), position=(0.0, 2.0, 0.0))
    r = WorldRenderer(headless_context(), (160, 90))      # its own cache, counted from zero
    frames = []
    for _ in range(4):
        frames.append(r.render_to_array(w, VIEW))
        w.step(1 / 60)
        boxes[0].position = boxes[0].position + (0.0, 0.0, 0.05)
    assert r.meshes.uploads == 3                          # the terrain, the box and the sphere, once each
    assert all(np.any(a != b) for a, b in zip(frames, frames[1:]))
    r.ctx.release()


def test_a_renderer_draws_the_world_as_it_is_after_another_context_came_and_went(renderer, scene):
    """Each renderer makes its own context current to draw: one made (and released) since must not leave it
    drawing nothing and reading back its last picture, or undefined pixels."""
    from marbellous.render.context import headless_context

    w, parts = scene
    before = renderer.render_to_array(w, VIEW)
    parts["ball"].position = parts["ball"].position + (0.0, 1.0, 0.0)
    other = WorldRenderer(headless_context(), SIZE)
    expected = other.render_to_array(w, VIEW)
    other.ctx.release()
    after = renderer.render_to_array(w, VIEW)
    assert np.any(after != before)
    assert np.array_equal(after, expected)


def test_every_antialiasing_draws_the_scene_and_fxaa_leaves_the_overlays_sharp(renderer, scene):
    """Each mode draws the same scene (bar its edges); FXAA changes edges only, and the contacts drawn after it
    are the very pixels they are without it; an unknown mode is refused."""
    from marbellous.render.context import headless_context
    from marbellous.render.antialiasing import ANTIALIASING

    w, _ = scene
    layers = ("bodies", "constraints", "contacts")
    imgs = {}
    for aa in ANTIALIASING:
        r = WorldRenderer(headless_context(), SIZE, antialiasing=aa)
        imgs[aa] = (r.render_to_array(w, VIEW, layers=("bodies", "constraints")),
                    r.render_to_array(w, VIEW, layers=layers))
        r.ctx.release()
    for plain, _ in imgs.values():
        assert np.any(plain != imgs["none"][0], axis=-1).mean() < 0.1
    changed = np.any(imgs["fxaa"][0] != imgs["none"][0], axis=-1)
    assert changed.sum() > 100                 # the edges are smoothed
    marked = np.any(imgs["none"][1] != imgs["none"][0], axis=-1)       # the contacts' lines and dots
    assert marked.sum() > 50
    assert np.array_equal(imgs["fxaa"][1][marked], imgs["none"][1][marked])
    with pytest.raises(ValueError, match="antialiasing"):
        WorldRenderer(renderer.ctx, SIZE, antialiasing="ssaa")
