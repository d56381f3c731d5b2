"""One play-through of a level: the world, the marble, the controls, the camera, the goal and timer.

The game steps the physics with a fixed step ``dt`` (default 1/120 s).  Each step applies the control
force (and a jump impulse) to the marble and the wind to the goal's flag (``flag.py``), advances the world,
respawns the marble at the start when it falls below the level's ``fall_height``, and tests the goal box.
A window's frame loop calls :meth:`Game.advance` with the frame time; an autopilot or a learning agent
calls :meth:`Game.step`.
"""
import functools
import time

import numpy as np

from ..fluid import Fluid
from ..soft import tet_box
from ..world import World
from .camera import FollowCamera
from .controls import control_force
from .course import CoursePath
from .flag import GoalFlag, blow_call
from .goal import BestTimes, GoalArea, format_time
from .level import LevelError
from .marble import MarbleSpec


def add_soft_block(world, block):
    """The soft block ``block`` (a level's ``SoftBlock``) added to ``world`` at rest, its bottom face pinned if
    it asks; returns the ``SoftBody``."""
    vertices, tetrahedra = tet_box(block.half_extents, block.cells)
    body = world.add_soft_body(vertices, tetrahedra, density=block.density, young_modulus=block.young_modulus,
                               poisson_ratio=block.poisson_ratio, damping=block.damping,
                               friction=block.material.friction, position=block.position)
    if block.pinned:
        body.pin(np.nonzero(vertices[:, 1] < -block.half_extents[1] + 1e-9)[0])
    return body


#: how fast (s) a stream's pump brings its mean velocity back to the level's after the marble slows it
PUMP_TIME = 0.5


def add_stream(world, stream):
    """The level's ``stream`` as a fluid of ``world`` (periodic along x and z, walls below and above), flowing
    at its velocity; returns the ``Fluid``."""
    fluid = Fluid(stream.resolution, stream.cell, origin=stream.lower, density=stream.density,
                  viscosity=stream.viscosity, boundary=("periodic", "wall", "periodic"), surface=stream.surface)
    fluid.velocity = np.broadcast_to(stream.velocity, fluid.resolution + (3,))
    return world.add_fluid(fluid)


def pump(fluid, velocity):
    """Hold ``fluid``'s mean velocity at ``velocity`` (m/s): a body force that makes up the difference in
    ``PUMP_TIME`` (the marble, an obstacle, slows the water it pushes through)."""
    fluid.body_force = (np.asarray(velocity) - fluid.velocity.mean(axis=(0, 1, 2))) / PUMP_TIME


def build_world(level):
    """A new ``marbellous.World`` holding the level's colliders as static bodies; returns ``(world,
    statics)``."""
    world = World()
    statics = []
    for c in level.colliders:
        m = c.material
        statics.append(world.add_static(c.shape(), position=c.position, orientation=c.orientation,
                                        friction=m.friction, static_friction=m.static_friction,
                                        restitution=m.restitution, rolling_friction=m.rolling_friction))
    return world, statics


class Game:
    """The game state for one ``level`` (a loaded ``Level``).

    ``marble`` is a :class:`MarbleSpec`; ``dt`` the physics step (s); ``best_times`` a
    :class:`BestTimes` store (None: the user's default one); ``flag`` puts a cloth flag by the goal
    (:attr:`flag`, a :class:`GoalFlag`; None without).
    """

    #: Up to this many physics steps are taken per rendered frame; slower frames slow the game down.
    MAX_STEPS_PER_FRAME = 8
    #: A contact supports the marble when its normal towards the marble is this close to +y.
    GROUND_COS = 0.5
    #: Speculative contacts with a gap up to this (m) still count as touching the ground.
    GROUND_GAP = 0.03

    def __init__(self, level, *, marble=None, dt=1.0 / 120.0, best_times=None, flag=True):
        self.level = level
        self.spec = marble if marble is not None else MarbleSpec()
        self.dt = float(dt)
        self.best_times = best_times if best_times is not None else BestTimes()
        self.world, self.statics = build_world(level)
        self.marble = self.spec.add_to(self.world, level.start_position)
        #: the level's soft blocks (``SoftBody`` handles, in the order of the level file)
        self.soft_blocks = [add_soft_block(self.world, block) for block in level.soft_blocks]
        self._soft_rest = [body.positions for body in self.soft_blocks]
        #: the level's streams (``Fluid`` handles, in the order of the level file)
        self.streams = [add_stream(self.world, stream) for stream in level.streams]
        self._stream_rest = [fluid._state() for fluid in self.streams]
        self.goal = GoalArea(level.goal_center, level.goal_half_extents)
        start = np.asarray(level.start_position, np.float64)
        # on a first run, helper processes compile the flag's ray cast and wind, the goal's test and the step's
        # kernels
        self.world._compile_ahead(self.dt, [self.goal.test_call(start, self.spec.radius)]
                                  + ([blow_call()] if flag else []))
        self.flag = (GoalFlag(self.world, level.goal_center, level.goal_half_extents, self.ground_height,
                              self._approach()) if flag else None)
        if self.goal.reached(start, self.spec.radius):
            raise LevelError(f"level {level.name!r}: the marble starts in the goal")
        self.course = CoursePath(level.path, level.speeds) if level.path is not None else None
        self.camera = FollowCamera(heading=level.start_heading)
        #: Wall-clock seconds spent in ``World.step`` and the number of steps timed; the first step
        #: (which compiles or loads the kernels) is taken but not timed.
        self.physics_seconds = 0.0
        self.physics_steps = 0
        self.timed_steps = 0
        self._accumulator = 0.0
        self._push_key = self._push_force = None   # the last control input and its force (push)
        self.restart()

    # ------------------------------------------------------------------ state changes
    def restart(self):
        """Back to the start with the timer at zero."""
        self.elapsed = 0.0
        self.finished = False
        self.finish_time = None
        self.new_best = False
        self.respawns = 0
        self._place_at_start()

    def respawn(self):
        """Put the marble back at the start after a fall; the timer keeps running."""
        self.respawns += 1
        self._place_at_start()

    def _place_at_start(self):
        for body, rest in zip(self.soft_blocks, self._soft_rest):
            body.positions = rest
            body.velocities = np.zeros_like(rest)
        for fluid, rest in zip(self.streams, self._stream_rest):
            fluid._load(rest)
        b = self.marble
        b.position = self.level.start_position
        b.orientation = (1.0, 0.0, 0.0, 0.0)
        b.velocity = (0.0, 0.0, 0.0)
        b.angular_velocity = (0.0, 0.0, 0.0)
        self._jump_cooldown = 0.0
        self.camera.reset(self.level.start_position, self.level.start_heading)

    # ------------------------------------------------------------------ stepping
    def step(self, move=(0.0, 0.0), jump=False):
        """One physics step of :attr:`dt` with the control input ``move = (forward, right)`` relative
        to the camera and an optional jump (only when the marble touches the ground)."""
        self.push(move, jump)
        t0 = time.perf_counter()
        self.world.step(self.dt)
        if self.physics_steps:
            self.physics_seconds += time.perf_counter() - t0
            self.timed_steps += 1
        self.judge()

    def push(self, move=(0.0, 0.0), jump=False):
        """The part of :meth:`step` before the world's step: the control force and the jump on the marble,
        the wind on the flag, the pumps of the streams."""
        b = self.marble
        # the same input over the steps of a frame or an action makes the same force: worked out once
        try:
            key = (len(move), float(move[0]), float(move[1]), self.camera.heading)
        except (TypeError, ValueError, IndexError):
            key = None
        if key is None or key != self._push_key:
            self._push_force = control_force(move, self.camera.heading, b.mass, self.spec.push)
            self._push_key = key
        b._add_force(self._push_force)     # (a force of finite, bounded input: checked when worked out)
        self._jump_cooldown = max(0.0, self._jump_cooldown - self.dt)
        if jump and self._jump_cooldown == 0.0 and self.on_ground():
            b.apply_impulse((0.0, b.mass * self.spec.jump_speed, 0.0))
            self._jump_cooldown = 0.25
        if self.flag is not None:
            self.flag.blow(self.world.time, self.dt)
        for fluid, stream in zip(self.streams, self.level.streams):
            pump(fluid, stream.velocity)

    def judge(self):
        """The part of :meth:`step` after the world's step: the clock, a fall (back to the start) or the goal
        reached."""
        self.physics_steps += 1
        if not self.finished:
            self.elapsed += self.dt
        p = self.marble.position
        if p[1] < self.level.fall_height:
            self.respawn()
        elif not self.finished and self.goal.reached(p, self.spec.radius):
            self.finish()

    def finish(self):
        """The goal reached now: the clock stops and the time is recorded."""
        self.finished = True
        self.finish_time = self.elapsed
        self.new_best = self.best_times.record(self.level.key, self.elapsed)

    def advance(self, frame_time, move=(0.0, 0.0), jump=False):
        """Step the physics through ``frame_time`` seconds of a rendered frame (fixed steps, the rest
        carried over); returns the number of steps taken."""
        self._accumulator = min(self._accumulator + float(frame_time), self.MAX_STEPS_PER_FRAME * self.dt)
        n = 0
        while self._accumulator >= self.dt:
            self.step(move, jump and n == 0)
            self._accumulator -= self.dt
            n += 1
        return n

    def on_ground(self):
        """True when a contact from the last step supports the marble from below."""
        for c in self.world.contacts():
            if c.body_b is self.marble:
                n = c.normal
            elif c.body_a is self.marble:
                n = -c.normal
            else:
                continue
            if n[1] >= self.GROUND_COS and c.depth >= -self.GROUND_GAP:
                return True
        return False

    # ------------------------------------------------------------------ camera and display
    @functools.cached_property
    def scenery(self):
        """A world holding only the level, never stepped, for rays that must not hit the marble (made when
        first needed: by the camera, the flag; an environment that is not drawn never needs it)."""
        return build_world(self.level)[0]

    def raycast_level(self, origin, direction, max_distance):
        """Distance (m) along the unit ``direction`` to the nearest level geometry, or None.

        Rays are cast in :attr:`scenery`, a world holding only the level (never stepped), so the
        marble itself is never hit.
        """
        hit = self.scenery.raycast(origin, direction, max_distance)
        return None if hit is None else hit.distance

    def _approach(self):
        """A point (m) the marble comes to the goal from: the course's last point before it enters the goal
        box, else the start."""
        came_from = self.level.start_position
        for p in self.level.path if self.level.path is not None else ():
            if np.all(np.abs(p - self.level.goal_center) <= self.level.goal_half_extents):
                break
            came_from = p
        return came_from

    def ground_height(self, x, z, y_from, depth):
        """Height (m) of the level below ``(x, y_from, z)`` (m), at most ``depth`` metres down, or None."""
        d = self.raycast_level(np.array([x, y_from, z], np.float64), np.array([0.0, -1.0, 0.0]), depth)
        return None if d is None else y_from - d

    def update_camera(self, frame_time):
        """Move the follow camera by ``frame_time`` seconds; returns its ``CameraView``."""
        b = self.marble
        return self.camera.update(frame_time, b.position, b.velocity, self.raycast_level)

    def marble_rotation(self):
        """The marble's rotation matrix (3, 3)."""
        from ..render.transforms import quat_to_matrix

        return quat_to_matrix(self.marble.orientation)

    def contact_points(self):
        """``(points, normals)`` (K, 3) of the last step's contacts, for the debug overlay."""
        cs = self.world.contacts()
        if not cs:
            return np.zeros((0, 3)), np.zeros((0, 3))
        return np.array([c.point for c in cs]), np.array([c.normal for c in cs])

    def hud_lines(self):
        """The HUD: level, timer, best time, and the goal message once finished."""
        best = self.best_times.get(self.level.key)
        lines = [f"{self.level.name}   time {format_time(self.elapsed)}",
                 f"best {format_time(best) if best is not None else '--'}   falls {self.respawns}"]
        if self.finished:
            lines.append(f"GOAL in {format_time(self.finish_time)}" + ("  new best!" if self.new_best else ""))
        return lines
