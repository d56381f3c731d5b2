"""Count how the public API answers bad input: every bad value of ``tests/fuzz_catalogue.py`` once.

    PYTHONPATH=<checkout> python tools/fuzz_census.py [--out census.json]

Outcomes of each case: ``refused`` (ValueError or TypeError, world unchanged: the contract), ``accepted``
(no error: bad input taken silently), ``wrong_type`` (another exception), ``...+state_changed`` (an
error, but the world's ``state_hash`` changed), ``crash`` (the process died, e.g. a segfault), ``hang`` (no
answer within the time limit).  Cases run in a worker process (memory capped at 8 GB); a supervisor
restarts it after a crash or a hang and goes on with the next case.  Prints a table of counts by input
class and by entry point.  Runs against any checkout: the catalogue uses only the public API.
"""
import argparse
import collections
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
TESTS = os.path.join(os.path.dirname(HERE), "tests")
CASE_SECONDS = 60.0
MEMORY_LIMIT = 8 << 30


# --- the worker ---------------------------------------------------------------------------------------------
def _outcome(call, ns):
    """Run ``call()``; the outcome class and a short detail."""
    before = ns.w.state_hash() if ns is not None else None
    try:
        call()
        result, detail = "accepted", ""
    except (ValueError, TypeError) as e:
        result, detail = "refused", f"{type(e).__name__}: {e}"[:200]
    except Exception as e:   # noqa: BLE001
        result, detail = "wrong_type", f"{type(e).__name__}: {e}"[:200]
    if ns is not None and result != "accepted":
        try:
            if ns.w.state_hash() != before:
                result, detail = result + "+state_changed", detail
        except Exception as e:   # noqa: BLE001
            result, detail = "wrong_type", f"state_hash after: {type(e).__name__}: {e}"[:200]
    return result, detail


def all_cases():
    """(id, entry, argument, class) of every case, in order."""
    import fuzz_catalogue as fc

    out = []
    for k, (entry, arg, klass, _, _, _) in enumerate(fc.world_cases()):
        out.append((f"w{k}", entry, arg, klass))
    for k, (name, attr, _, _) in enumerate(fc.immutable_cases()):
        out.append((f"i{k}", f"{name} attribute", attr, "assign"))
    for k, (name, _, _) in enumerate(fc.inplace_cases()):
        out.append((f"p{k}", f"{name} in place", name.split(".")[1], "inplace"))
    for k, (klass, name, _) in enumerate(fc.mesh_files()):
        out.append((f"m{k}", "TriangleMesh.load", name, klass))
    for k, (klass, _, _) in enumerate(fc.level_texts()):
        out.append((f"l{k}", "load_level", "file", klass))
    k = 0
    for opt, values in fc.ENV_OPTIONS:
        for klass, _ in values:
            out.append((f"e{k}", "MarbellousEnv()", opt, klass))
            k += 1
    k = 0
    for opt, values in fc.ENV_RESET:
        for klass, _ in values:
            out.append((f"r{k}", "MarbellousEnv.reset", opt, klass))
            k += 1
    for k, (klass, _) in enumerate(fc.KINDS["action"]):
        out.append((f"a{k}", "MarbellousEnv.step", "action", klass))
    for k, (name, _) in enumerate(fc.good_mesh_files()):
        out.append((f"g{k}", "TriangleMesh.load (good file)", name, "good"))
    return out


def run_case(case_id, tmp):
    """The outcome of one case (in this process)."""
    import numpy as np

    import fuzz_catalogue as fc
    import marbellous as mb

    kind, k = case_id[0], int(case_id[1:])
    if kind == "w":
        entry, arg, klass, value, call, world = fc.world_cases()[k]
        ns = fc.make_world() if world else None
        return _outcome(lambda: call(ns, value), ns if world else None)
    if kind == "i":
        name, attr, value, factory = fc.immutable_cases()[k]
        shape = factory()
        try:
            setattr(shape, attr, value)
        except AttributeError as e:
            return "refused", f"AttributeError: {e}"[:200]
        except Exception as e:   # noqa: BLE001
            return "wrong_type", f"{type(e).__name__}: {e}"[:200]
        w = mb.World()
        if shape.is_static_only:
            w.add_static(shape)
            for x in np.linspace(-1, 3, 4):
                w.add_body(mb.Sphere(0.3), position=(x, 0.2, x / 2))
        else:
            w.add_body(shape)
        for _ in range(5):
            w.step(1 / 60)
        return "accepted", "assignment taken; world stepped"
    if kind == "p":
        name, factory, attr = fc.inplace_cases()[k]
        shape = factory()
        before = np.array(getattr(shape, attr))
        try:
            arr = getattr(shape, attr)
            arr[...] = 0
        except (ValueError, TypeError) as e:
            return "refused", f"{type(e).__name__}: {e}"[:200]
        if np.array_equal(np.array(getattr(shape, attr)), before):
            return "refused", "edited a copy"
        return "accepted", "the shape changed in place"
    if kind == "m":
        klass, name, data = fc.mesh_files()[k]
        path = os.path.join(tmp, name)
        with open(path, "wb") as f:
            f.write(data)
        result, detail = _outcome(lambda: mb.TriangleMesh.load(path), None)
        if result == "refused" and name not in detail:
            result = "refused_unnamed"
        return result, detail
    if kind == "g":
        name, data = fc.good_mesh_files()[k]
        path = os.path.join(tmp, name)
        with open(path, "wb") as f:
            f.write(data)
        result, detail = _outcome(lambda: mb.TriangleMesh.load(path), None)
        return ("ok" if result == "accepted" else "good_refused"), detail
    if kind == "l":
        from marbellous.game.level import load_level

        klass, text, files = fc.level_texts()[k]
        d = tempfile.mkdtemp(dir=tmp)
        for name, data in files.items():
            with open(os.path.join(d, name), "wb") as f:
                f.write(data)
        path = os.path.join(d, "lvl.toml")
        with open(path, "wb") as f:
            f.write(text if isinstance(text, bytes) else text.encode())
        loaded = []
        result, detail = _outcome(lambda: loaded.append(load_level(path)), None)
        if result == "accepted":
            # accepted at load: does building the game's world from it fail later, naming nothing?
            from marbellous.game.session import build_world

            result, detail = _outcome(lambda: build_world(loaded[0]), None)
            detail = "at world build: " + detail
        if result == "refused" and "lvl.toml" not in detail:
            result = "refused_unnamed"
        return result, detail
    if kind in "era":
        from marbellous.app.envs.marble_env import MarbellousEnv

        if kind == "e":
            opt, klass, value = [(o, c, v) for o, vs in fc.ENV_OPTIONS for c, v in vs][k]
            kw = {"level": "blocks", opt: value}
            return _outcome(lambda: MarbellousEnv(**kw), None)
        env = MarbellousEnv(level="blocks")
        if kind == "r":
            opt, klass, value = [(o, c, v) for o, vs in fc.ENV_RESET for c, v in vs][k]
            return _outcome(lambda: env.reset(**{opt: value}), None)
        env.reset(seed=0)
        klass, value = fc.KINDS["action"][k]
        return _outcome(lambda: env.step(value), None)
    raise ValueError(case_id)


def worker(ids_file, out_file):
    """Run the cases listed in ``ids_file``, appending ``start``/result lines to ``out_file``."""
    import resource
    import warnings

    warnings.simplefilter("ignore")
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    sys.path.insert(0, TESTS)
    sys.setrecursionlimit(3000)
    with open(ids_file) as f:
        ids = f.read().split()
    tmp = tempfile.mkdtemp()
    with open(out_file, "a", buffering=1) as out:
        for cid in ids:
            out.write(json.dumps({"start": cid}) + "\n")
            try:
                result, detail = run_case(cid, tmp)
            except BaseException as e:   # noqa: BLE001  (the case's set-up failed)
                result, detail = "wrong_type", f"setup {type(e).__name__}: {e}"[:200]
            out.write(json.dumps({"id": cid, "result": result, "detail": detail}) + "\n")


# --- the supervisor -----------------------------------------------------------------------------------------
def supervise(cases):
    """Outcome of every case: runs workers, restarting them after a crash or a hang."""
    tmp = tempfile.mkdtemp()
    results = {}
    todo = [c[0] for c in cases]
    while todo:
        ids_file = os.path.join(tmp, "ids")
        out_file = os.path.join(tmp, "out")
        with open(ids_file, "w") as f:
            f.write("\n".join(todo))
        if os.path.exists(out_file):
            os.remove(out_file)
        proc = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--worker", ids_file, out_file],
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        current, last = None, time.time()
        seen = 0
        while True:
            time.sleep(0.2)
            lines = open(out_file).read().splitlines() if os.path.exists(out_file) else []
            for line in lines[seen:]:
                rec = json.loads(line)
                if "start" in rec:
                    current, last = rec["start"], time.time()
                else:
                    results[rec["id"]] = (rec["result"], rec["detail"])
                    current = None
            seen = len(lines)
            limit = CASE_SECONDS * (10 if current is None else 1)     # (the first case also imports)
            if proc.poll() is not None:
                if current is not None:
                    err = proc.stderr.read().decode(errors="replace").strip().splitlines()[-1:]
                    results[current] = ("crash", f"exit {proc.returncode}: {' '.join(err)}"[:200])
                break
            if time.time() - last > limit and current is not None:
                proc.kill()
                proc.wait()
                results[current] = ("hang", f"no answer in {CASE_SECONDS:.0f} s")
                break
        todo = [cid for cid in todo if cid not in results]
    return results


def main(argv=None):
    if argv and argv[0] == "--worker":
        worker(argv[1], argv[2])
        return 0
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=None, help="write every case's outcome to this JSON file")
    ap.add_argument("--only", default=None, help="run only cases whose id starts with one of these letters")
    ap.add_argument("--report", default=None, metavar="JSON", help="only print the tables of a saved run")
    args = ap.parse_args(argv)
    if args.report:
        with open(args.report) as f:
            saved = json.load(f)
        print(f"package: {saved['package']}; {len(saved['rows'])} cases")
        report(saved["rows"])
        return 0
    sys.path.insert(0, TESTS)
    import marbellous

    cases = all_cases()
    if args.only:
        cases = [c for c in cases if c[0][0] in args.only]
    t0 = time.time()
    results = supervise(cases)
    rows = [dict(id=c[0], entry=c[1], arg=c[2], klass=c[3], result=results[c[0]][0], detail=results[c[0]][1])
            for c in cases]
    if args.out:
        with open(args.out, "w") as f:
            json.dump({"package": marbellous.__file__, "rows": rows}, f, indent=1)
    print(f"package: {marbellous.__file__}; {len(rows)} cases in {time.time() - t0:.0f} s")
    report(rows)
    return 0


def report(rows):
    """Print the tables of counts by input class and by entry point, and every case not refused cleanly."""
    columns = ["refused", "accepted", "wrong_type", "refused+state_changed", "wrong_type+state_changed", "crash",
               "hang", "refused_unnamed", "ok", "good_refused"]
    for title, key in (("input class", "klass"), ("entry point", "entry")):
        table = collections.defaultdict(collections.Counter)
        for r in rows:
            table[r[key]][r["result"]] += 1
        used = [c for c in columns if any(table[k][c] for k in table)]
        short = {c: c.replace("+state_changed", "+changed") for c in used}
        width = {c: max(10, len(short[c]) + 2) for c in used}
        print(f"\n{title:32s}" + "".join(f"{short[c]:>{width[c]}s}" for c in used))
        for k in sorted(table):
            print(f"{k:32s}" + "".join(f"{table[k][c]:{width[c]}d}" for c in used))
        total = collections.Counter(r["result"] for r in rows)
        print(f"{'TOTAL':32s}" + "".join(f"{total[c]:{width[c]}d}" for c in used))
    bad = [r for r in rows if r["result"] not in ("refused", "ok")]
    if bad:
        print("\nnot refused cleanly:")
        for r in bad:
            print(f"  {r['id']:5s} {r['entry']}({r['arg']}) [{r['klass']}] -> {r['result']}: {r['detail']}")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
