"""``marbellous demo``: the autopilot plays a level headless and the run is written to a video.

The physics runs at the game's fixed step; the autopilot decides a control input before every step;
the camera and a video frame advance at ``fps``.  Rendering uses an EGL context (Mesa's llvmpipe
works with no display and no GPU).
"""
import math
import pathlib
import time
from dataclasses import dataclass, field

from ..game.autopilot import Autopilot
from ..game.goal import BestTimes, format_time
from ..game.level import load_level
from ..game.session import Game

#: Frames written after the goal is reached, so the video shows the finish.
FINISH_SECONDS = 1.5


@dataclass
class DemoResult:
    """What a demo run did.  Times in seconds; ``physics_step_seconds`` is the mean wall-clock time of
    one physics step (``World.step``), ``render_frame_seconds`` of rendering and reading back one
    frame; ``steps_per_60hz_frame`` physics steps make one 60 Hz frame."""

    level: str
    reached: bool
    finish_time: float
    simulated: float
    frames: int
    respawns: int
    physics_step_seconds: float
    render_frame_seconds: float
    out: str
    steps_per_60hz_frame: float
    frame_files: list = field(default_factory=list)

    def summary(self):
        """Lines for the terminal; the last says whether and when the goal was reached."""
        lines = [
            f"level: {self.level}",
            f"simulated: {self.simulated:.2f} s, {self.frames} frames, {self.respawns} falls",
            f"physics: {self.physics_step_seconds * 1e6:.1f} us per step, "
            f"{100 * self.physics_step_seconds * self.steps_per_60hz_frame * 60:.1f}% of a 60 Hz frame",
        ]
        if self.frames:
            lines.append(f"render: {self.render_frame_seconds * 1e3:.1f} ms per frame")
        if self.out:
            lines.append(f"video: {self.out}")
        lines.append(f"goal reached in {format_time(self.finish_time)} ({self.finish_time:.2f} s)" if self.reached
                     else f"goal not reached within {self.simulated:.2f} s")
        return lines


def run_demo(level=None, out="marbellous-demo.mp4", seconds=60.0, *, fps=30, size=(640, 360), render=True,
             frames_dir=None, frame_interval=4.0, debug=False, best_times=None):
    """Play ``level`` (a name, a path or a loaded ``Level``) with the autopilot for at most ``seconds``.

    Writes the video to ``out`` (``.mp4`` or ``.gif``; None writes none) unless ``render`` is False.
    With ``frames_dir``, a PNG of every ``frame_interval`` seconds of video and of the last frame is
    saved there as ``frame-NNNN.png``.  The autopilot's finish is not the player's: it is kept in
    ``best_times`` when given, else in memory only (the player's best times are never written).  Returns a
    :class:`DemoResult`.
    """
    lvl = load_level(level) if level is None or not hasattr(level, "colliders") else level
    if lvl.path is None:
        raise ValueError(f"level {lvl.name!r} has no [course] path for the autopilot")
    game = Game(lvl, best_times=best_times if best_times is not None else BestTimes(persistent=False))
    pilot = Autopilot(game.course, game.spec.push)
    steps_per_frame = max(1, int(round(1.0 / (fps * game.dt))))
    renderer = writer = None
    if render:
        from ..render.context import headless_context
        from ..render.renderer import DebugOverlay, Renderer
        from ..render.video import VideoWriter

        renderer = Renderer(headless_context(), lvl, game.spec.radius, size, flag=game.flag,
                            soft_bodies=game.soft_blocks)
        writer = VideoWriter(out, fps) if out else None
    render_seconds, frames, kept = 0.0, 0, []
    every = max(1, int(round(frame_interval * fps)))
    if frames_dir is not None:
        frames_dir = pathlib.Path(frames_dir)
        frames_dir.mkdir(parents=True, exist_ok=True)
    finish_frames = int(FINISH_SECONDS * fps)
    max_frames = math.ceil(seconds * fps - 1e-9)
    try:
        while frames < max_frames or game.finished:
            for _ in range(steps_per_frame):
                pilot.step(game)
            view = game.update_camera(steps_per_frame * game.dt)
            if renderer is not None:
                t0 = time.perf_counter()
                dbg = None
                if debug:
                    pts, nrm = game.contact_points()
                    dbg = DebugOverlay(points=pts, normals=nrm)
                img = renderer.render_to_array(view, game.marble.position, game.marble_rotation(),
                                               game.hud_lines(), dbg)
                render_seconds += time.perf_counter() - t0
                if writer is not None:
                    writer.write(img)
            frames += 1
            last = game.finished and finish_frames <= 1 or not game.finished and frames >= max_frames
            if renderer is not None and frames_dir is not None and ((frames - 1) % every == 0 or last):
                kept.append(_save_png(img, frames_dir / f"frame-{frames - 1:04d}.png"))
            if game.finished:
                finish_frames -= 1
                if finish_frames <= 0:
                    break
    finally:
        if writer is not None:
            writer.close()
    return DemoResult(
        level=lvl.name, reached=game.finished, finish_time=game.finish_time if game.finished else 0.0,
        simulated=game.physics_steps * game.dt, frames=frames if render else 0, respawns=game.respawns,
        physics_step_seconds=game.physics_seconds / max(game.timed_steps, 1),
        render_frame_seconds=render_seconds / max(frames, 1), out=str(out) if (render and out) else "",
        steps_per_60hz_frame=1.0 / (60.0 * game.dt),
        frame_files=kept)


def _save_png(img, path):
    from PIL import Image

    Image.fromarray(img).save(path, optimize=True)
    return str(path)
