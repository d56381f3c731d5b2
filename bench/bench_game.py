"""Time of the game's own step (``marbellous.game.session.Game.step``) on a level, with and without the goal's
cloth flag, as ``marbellous demo`` and ``marbellous play`` step it (1/120 s).

The autopilot plays the level (``--level``, default the course) for ``--seconds`` of game time after one second
untimed (which loads or compiles the kernels); each step is timed in three parts:
- physics: ``World.step`` (the game's own clock of it, ``Game.physics_seconds``);
- push: the flag's wind (``GoalFlag.blow``: the wind at its triangles and the velocity change of its push);
- game: the whole ``Game.step`` with the autopilot's input (control force, push, physics, the goal's test; the
  autopilot's own work, finding the marble on the course, not counted);
- replayed (without the flag): ``World.step`` of the same steps again in a new game, back to back, each with the
  force the play gave the marble and nothing else run between them (its path checked to end bit for bit where the
  play's did).  Played, the step follows the game's and the autopilot's Python, which leave its code and data
  cold; replayed, it does not.
Reported per run: the mean and the median of each over the timed steps (us), and how many steps there were.  The
flag is scenery: ``flag=False`` is the marble's game alone (``autopilot_trial``'s default).

    python bench/bench_game.py                      the course, 20 s of play, with and without the flag
    python bench/bench_game.py --seconds 2          a check of the script
    python bench/bench_game.py --json               also write bench/results/<date>-<host>-game.json
"""
import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from bench.machine import describe, write_results  # noqa: E402

#: the parts of a step timed, in order
PARTS = ("physics", "push", "game", "replayed")


def time_play(level, seconds, flag):
    """``{part: {"mean_us", "median_us"}, "steps": int}``: ``seconds`` (s) of ``level`` played by the autopilot,
    with the goal's flag or without, after one second untimed."""
    from marbellous.game.autopilot import Autopilot
    from marbellous.game.goal import BestTimes
    from marbellous.game.level import load_level
    from marbellous.game.session import Game

    game = Game(load_level(level), best_times=BestTimes(persistent=False), flag=flag)
    pilot = Autopilot(game.course, game.spec.push)
    forces = []                 # the marble's force in each step, for the replay
    for _ in range(round(1.0 / game.dt)):
        pilot.step(game)
        forces.append(game._push_force)
    pushes = []
    if game.flag is not None:
        blow = game.flag.blow

        def timed_blow(t, dt):
            t0 = time.perf_counter()
            blow(t, dt)
            pushes.append(time.perf_counter() - t0)
        game.flag.blow = timed_blow
    physics, whole = [], []
    for _ in range(round(seconds / game.dt)):
        before, respawns, b = game.physics_seconds, game.respawns, game.marble
        move = pilot.move(b.position, b.velocity, game.camera.heading)       # (the autopilot's time not counted)
        t0 = time.perf_counter()
        game.step(move)
        whole.append(time.perf_counter() - t0)
        physics.append(game.physics_seconds - before)
        forces.append(game._push_force)
        if game.respawns != respawns:
            pilot.reset()
    replayed = None if flag or game.respawns else replay(level, forces, len(whole), game.marble)
    columns = {"physics": physics, "push": pushes or [0.0] * len(whole), "game": whole, "replayed": replayed}
    out = {part: None if columns[part] is None else
           {"mean_us": 1e6 * float(np.mean(columns[part])), "median_us": 1e6 * float(np.median(columns[part]))}
           for part in PARTS}
    out["steps"] = len(whole)
    return out


def replay(level, forces, timed, marble):
    """Seconds of each of the last ``timed`` steps of ``World.step`` in a new game of ``level`` (no flag) stepped
    with ``forces`` (N, one per step) on its marble and nothing else between the steps; None if its marble does not
    end where ``marble`` (the played game's) did, bit for bit."""
    from marbellous.game.goal import BestTimes
    from marbellous.game.level import load_level
    from marbellous.game.session import Game

    game = Game(load_level(level), best_times=BestTimes(persistent=False), flag=False)
    world, b, dt = game.world, game.marble, game.dt
    clock = time.perf_counter
    seconds = []
    for force in forces:
        b._add_force(force)
        t0 = clock()
        world.step(dt)
        seconds.append(clock() - t0)
    same = b.position.tobytes() == marble.position.tobytes() and b.velocity.tobytes() == marble.velocity.tobytes()
    return seconds[-timed:] if same else None


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", default="course", help="a shipped level's name or a level file")
    parser.add_argument("--seconds", type=float, default=20.0, help="timed game time (s)")
    parser.add_argument("--json", nargs="?", const="", metavar="FILE",
                        help="write the results to FILE (no FILE: bench/results/<date>-<host>-game.json)")
    args = parser.parse_args(argv)
    results = {("flag" if flag else "no_flag"): time_play(args.level, args.seconds, flag) for flag in (False, True)}
    print(f"{args.level}, {args.seconds:g} s of play by the autopilot at 1/120 s a step; us per step (mean / median)")
    print(f"{'run':>8s} " + " ".join(f"{p:>15s}" for p in PARTS) + "   steps")
    for run, r in results.items():
        cells = [f"{'-':>15s}" if r[p] is None else f"{r[p]['mean_us']:7.1f}/{r[p]['median_us']:7.1f}" for p in PARTS]
        print(f"{run:>8s} " + " ".join(cells) + f"   {r['steps']}")
    out = {"level": args.level, "seconds": args.seconds, "results": results}
    if args.json is not None:
        path = write_results(os.path.join(HERE, "results"), "game",
                             {"benchmark": "game", "machine": describe(os.path.dirname(HERE), {}), **out}, args.json)
        print(f"wrote {path}")
    return out


if __name__ == "__main__":
    main()
