"""The ``marbellous`` command.

    marbellous demo [--level NAME_OR_PATH] [--out FILE.mp4|FILE.gif] [--seconds S]
    marbellous play [--level NAME_OR_PATH]
    marbellous levels
    marbellous sweep [--level NAME ...] [--friction F ...] [--push P ...] [--start-offset M ...]
                     [--seconds S] [--backend serial|processes|ray] [--workers N] [--address ADDR] [--out FILE.csv]

Each subcommand is a :class:`Command`: a name, a one-line help, a function that adds its arguments to
an ``argparse`` parser, and a function that runs it and returns the exit code.  To add one, append a
``Command`` to :data:`COMMANDS`.

Bad arguments and bad level files end in one line on stderr, ``marbellous COMMAND: error: ...``, and
exit status 2 (no traceback).
"""
import argparse
import sys
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class Command:
    """A subcommand of ``marbellous``: ``add_arguments(parser)`` declares its options and
    ``run(args) -> int`` carries it out."""

    name: str
    help: str
    add_arguments: Callable
    run: Callable


def _level_argument(p):
    p.add_argument("--level", default=None, metavar="NAME_OR_PATH",
                   help="a shipped level (see `marbellous levels`) or a level TOML file (default: course)")


def _demo_arguments(p):
    _level_argument(p)
    p.add_argument("--out", default="marbellous-demo.mp4", metavar="FILE",
                   help="video to write, .mp4 or .gif (default: marbellous-demo.mp4)")
    p.add_argument("--seconds", type=float, default=60.0, metavar="S",
                   help="give up after S simulated seconds (default: 60)")
    p.add_argument("--size", default="640x360", metavar="WxH", help="video size in pixels (default: 640x360)")
    p.add_argument("--fps", type=int, default=30, help="video frames per second (default: 30)")
    p.add_argument("--debug", action="store_true", help="draw contacts, normals and the level's 2D grid")
    p.add_argument("--frames", default=None, metavar="DIR",
                   help="also save a PNG every 4 s of video and of the last frame into DIR")


#: Longest demo (simulated seconds) and the range of its frame rate (frames per second).
MAX_DEMO_SECONDS = 3600.0
FPS_RANGE = (1, 240)


def _parse_size(text):
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise ValueError(f"--size must look like 640x360, got {text!r}") from None
    if not (16 <= w <= 4096 and 16 <= h <= 4096):
        raise ValueError(f"--size must be between 16 and 4096 pixels per side, got {text!r}")
    return w, h


def _run_demo(args):
    from .app.demo import run_demo

    if not 0 < args.seconds <= MAX_DEMO_SECONDS:
        raise ValueError(f"--seconds must be > 0 and at most {MAX_DEMO_SECONDS:g}, got {args.seconds}")
    if not FPS_RANGE[0] <= args.fps <= FPS_RANGE[1]:
        raise ValueError(f"--fps must be between {FPS_RANGE[0]} and {FPS_RANGE[1]}, got {args.fps}")
    if not args.out.lower().endswith((".mp4", ".gif")):
        raise ValueError(f"--out must end in .mp4 or .gif, got {args.out!r}")
    result = run_demo(args.level, args.out, args.seconds, fps=args.fps, size=_parse_size(args.size),
                      debug=args.debug, frames_dir=args.frames)
    print("\n".join(result.summary()), flush=True)
    return 0 if result.reached else 1


def _play_arguments(p):
    _level_argument(p)
    p.add_argument("--size", default="1280x720", metavar="WxH", help="window size in pixels (default: 1280x720)")
    p.add_argument("--debug", action="store_true", help="start with the debug overlay on (toggle with F1)")
    p.add_argument("--print-state", action="store_true",
                   help="print the time and the marble's position every half second (for scripts)")


def _run_play(args):
    from .app.window import play

    return play(args.level, size=_parse_size(args.size), debug=args.debug, print_state=args.print_state)


def _levels_arguments(p):
    pass


def _run_levels(args):
    from .game.level_index import level_names, level_summary

    for name in level_names():
        title, description = level_summary(name)
        print(f"{name:10s} {title}: {description}")
    return 0


def _sweep_arguments(p):
    p.add_argument("--level", nargs="+", default=["course"], metavar="NAME_OR_PATH",
                   help="levels to play (default: course)")
    p.add_argument("--friction", nargs="+", type=float, default=[0.5], metavar="F",
                   help="the marble's friction coefficients (default: 0.5)")
    p.add_argument("--push", nargs="+", type=float, default=[9.0], metavar="P",
                   help="control accelerations, m/s^2 (default: 9)")
    p.add_argument("--start-offset", nargs="+", type=float, default=[0.0], metavar="M",
                   help="sideways offsets of the start, m (default: 0)")
    p.add_argument("--seconds", type=float, default=60.0, metavar="S",
                   help="give each run up to S simulated seconds (default: 60)")
    p.add_argument("--backend", default="processes", choices=("serial", "processes", "ray"),
                   help="where the runs are computed (default: processes, one per core)")
    p.add_argument("--workers", type=int, default=None, metavar="N", help="processes or Ray CPUs (default: cores)")
    p.add_argument("--address", default=None, metavar="ADDR",
                   help="a Ray cluster to join (\"auto\", or ray://host:10001); default: a local Ray")
    p.add_argument("--out", default="marbellous-sweep.csv", metavar="FILE",
                   help="the table to write, CSV (default: marbellous-sweep.csv)")


def _run_sweep(args):
    import math

    from .game.level import load_level
    from .game.trial import autopilot_trial, trial_numbers
    from .sweeps import grid, sweep, write_table

    if not args.out.lower().endswith(".csv"):
        raise ValueError(f"--out must end in .csv, got {args.out!r}")
    for level in args.level:
        if load_level(level).path is None:                          # (a bad level fails here, not in a worker)
            raise ValueError(f"level {level!r} has no [course] path for the autopilot")
    runs = grid(level=args.level, friction=args.friction, push=args.push, start_offset=args.start_offset,
                seconds=[args.seconds])
    for run in runs:                                                  # (so does a bad number in any run)
        trial_numbers(**run)
    try:
        rows = sweep(autopilot_trial, runs, backend=args.backend, workers=args.workers, address=args.address)
    except ImportError as e:
        raise ValueError(str(e)) from None
    write_table(rows, args.out)
    reached = [r for r in rows if r["reached"]]
    best = min(reached, key=lambda r: r["time"]) if reached else None
    print(f"{len(rows)} runs, {len(reached)} reached the goal"
          + (f"; fastest {best['time']:.2f} s ({best['level']}, friction {best['friction']:g}, "
             f"push {best['push']:g})" if best else "")
          + f"; falls {sum(r['falls'] for r in rows)}; table: {args.out}", flush=True)
    return 0 if all(math.isfinite(r["progress"]) for r in rows) else 1


COMMANDS = [
    Command("demo", "an autopilot plays a level headless and writes a video", _demo_arguments, _run_demo),
    Command("play", "play a level in a window (arrows/WASD, space jumps, R restarts)", _play_arguments, _run_play),
    Command("levels", "list the shipped levels", _levels_arguments, _run_levels),
    Command("sweep", "the autopilot plays every combination of levels and marble settings; a CSV table",
            _sweep_arguments, _run_sweep),
]


class _Parser(argparse.ArgumentParser):
    """An ``argparse`` parser whose usage errors are one line on stderr (exit status 2)."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser():
    """The ``argparse`` parser with every command in :data:`COMMANDS`."""
    from . import __version__

    parser = _Parser(prog="marbellous", description="Marbellous: a marble game and its physics engine")
    parser.add_argument("--version", action="version", version=f"marbellous {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True, parser_class=_Parser)
    for cmd in COMMANDS:
        cmd.add_arguments(sub.add_parser(cmd.name, help=cmd.help, description=cmd.help))
    return parser


def main(argv=None):
    """Entry point of the ``marbellous`` command; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    run = {c.name: c.run for c in COMMANDS}[args.command]
    try:
        return run(args)
    except (ValueError, OSError, RecursionError, MemoryError) as e:
        text = " ".join(str(e).split()) or type(e).__name__
        if isinstance(e, (RecursionError, MemoryError)):
            text = f"{type(e).__name__}: {text}"
        print(f"marbellous {args.command}: error: {text}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
