"""Where a cold run's compile time goes: run a script (or ``-m module``) and list the kernels Numba compiled in
this process, each with its own time (s, the nested kernels' compiles taken out) and its time with them.

    MARBELLOUS_CACHE_DIR=$(mktemp -d) python tools/compile_profile.py first.py
    MARBELLOUS_CACHE_DIR=$(mktemp -d) python tools/compile_profile.py -m marbellous demo --out /tmp/d.mp4

Kernels loaded from the cache are not compiles and do not appear.  A helper process
(``pipeline/precompile.py``) compiles its share out of sight: its kernels appear here only as the cache loads
they are, that is, not at all.
"""
import atexit
import runpy
import sys
import time

from numba.core import event

#: how many kernels the table lists
TOP = 30


class CompileTimes(event.Listener):
    """Own and inclusive compile time (s) per kernel, with the nesting of compiles inside compiles."""

    def __init__(self):
        self.stack = []              # [(name, start, time of nested compiles)]
        self.own = {}                # name -> s
        self.inclusive = {}          # name -> s
        self.count = {}              # name -> compiles (one per signature)
        self.first = None
        self.top = []                # (start s, inclusive s, name) of each compile not nested in another

    def on_start(self, ev):
        d = ev.data["dispatcher"]
        name = f"{d.py_func.__module__}.{d.py_func.__qualname__}"
        now = time.perf_counter()
        if self.first is None:
            self.first = now
        self.stack.append([name, now, 0.0])

    def on_end(self, ev):
        name, start, nested = self.stack.pop()
        took = time.perf_counter() - start
        if not self.stack:
            self.top.append((start - self.first, took, name))
        self.own[name] = self.own.get(name, 0.0) + took - nested
        self.inclusive[name] = self.inclusive.get(name, 0.0) + took
        self.count[name] = self.count.get(name, 0) + 1
        if self.stack:
            self.stack[-1][2] += took

    def report(self, out=sys.stderr):
        total = sum(self.own.values())
        print(f"\ncompiled {sum(self.count.values())} kernels ({len(self.own)} functions) in this process: "
              f"{total:.1f} s of compiling", file=out)
        print(f"{'own s':>7} {'with nested s':>13} {'compiles':>8}  kernel", file=out)
        for name in sorted(self.own, key=self.own.get, reverse=True)[:TOP]:
            print(f"{self.own[name]:7.1f} {self.inclusive[name]:13.1f} {self.count[name]:8d}  {name}", file=out)
        print("\nthe compiles not nested in another, in order (start s after the first, s with nested):", file=out)
        for start, took, name in self.top:
            if took >= 0.5:
                print(f"{start:7.1f} {took:7.1f}  {name}", file=out)


def main(argv):
    if not argv:
        raise SystemExit(__doc__)
    times = CompileTimes()
    event.register("numba:compile", times)
    atexit.register(times.report)
    if argv[0] == "-m":
        sys.argv = argv[1:]
        runpy.run_module(argv[1], run_name="__main__", alter_sys=True)
    else:
        sys.argv = argv
        runpy.run_path(argv[0], run_name="__main__")


if __name__ == "__main__":
    main(sys.argv[1:])
