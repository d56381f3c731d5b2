"""A cold step compiled in helper processes, which keep the memory of compiling out of this one.

Numba compiles one kernel at a time, holding the interpreter, so a first world's step (a minute of compiling
for spheres, several for boxes) would use one core however many the machine has; and a process keeps every
kernel it compiled with the LLVM modules behind it (a lean step for spheres over a mesh, with its particle
kernels, grew one process past 800 MB).  The step's stages (``pipeline/step.py``) each take only the step
context's view (and the constant flags a scheme passes some of them), so another process can compile them for
the same types without the world, and whatever it compiles goes to the kernel cache (``_numba/cache.py``).  When
the step's context packing or the step begins to compile (they were not in the cache), this process starts
helpers, one per core up to :data:`HELPERS` (which start up while this process compiles the packing); they go
down one list of kernels (those a program calls before its step, such as the game's ray cast and goal test,
which it waits for at the call, :func:`ahead` and :func:`await_kernel`; the stages, the dearest first, with the
world's particle kernels typed from the arguments they will get; last the step's entry), and each compiles the
kernels it is the first to claim (a file created in a shared directory, which only one process can create)
once the kernels they call are done.  A helper ends after the kernel that takes it past :data:`HELPER_MEMORY`
and a fresh one takes the rest of the list, loading from the cache what the others compiled.  This process
waits, reporting the helpers' kernels on its progress line (``_numba/progress.py``), then loads the step
from the cache: a few hundred megabytes less than compiling it.

The full step's solve and relax stages are not on the list: they are compiled with the entry that calls them
(``njit_calls_parallel``, not cached on their own), by whichever process compiles the entry.  Nothing happens
when the step loads from the cache or when the cache is off; a helper that cannot start or fails leaves its
kernels to this process, which compiles them when it calls them.  ``python -m marbellous.pipeline.precompile
CLAIMS MEMORY`` is a helper (the list is pickled in the directory ``CLAIMS``; it ends past ``MEMORY`` bytes).
"""
import contextlib
import importlib
import os
import pickle
import shutil
import subprocess
import sys
import tempfile
import time
import weakref

import numba
from numba.core import event

from .._numba import cache
from .._numba.progress import PROGRESS, kernel_name
from .._numba.record import RecordView
from ..state.layout import LCP, PENALTY, SEQUENTIAL_IMPULSE
from .context import STEP_CONTEXT
from .step import (FIND_CONTACTS, LEAN, NARROW_PHASE, STEPS, TIME_OF_IMPACT, finish_step, stage_aabbs,
                   stage_break_constraints, stage_broad_phase, stage_broad_phase_lean,
                   stage_integrate_positions, stage_integrate_positions_lean, stage_integrate_velocities,
                   stage_integrate_velocities_lean, stage_islands_and_sleep, stage_match_and_wake, stage_prepare,
                   stage_prepare_lean, stage_relax_lean, stage_restitution, stage_restitution_lean, stage_solve_lcp,
                   stage_solve_lean, stage_store_impulses, stage_store_impulses_lean, stage_sum_impulses,
                   stage_sum_impulses_lean, stage_warm_start, stage_warm_start_lean)


#: the longest wait (s) for the helpers to go down their list: a cold lean step takes them about a minute on two
#: cores, the full step of every pair test about six, so helpers still busy after this are stuck (a machine
#: swapping, a stopped process); they are stopped and this process compiles what is left
HELPER_TIMEOUT = 1800.0

#: the most helpers at once (one per core up to this: the list's kernels that wait for others leave more idle)
HELPERS = 3

#: a helper ends after the kernel that takes its resident memory past this (bytes), and a fresh helper takes
#: the rest of the list: a helper starts at about 170 MB and the dearest stage adds about 200 MB
HELPER_MEMORY = 330 * 2**20

#: seconds between looks at the claims directory (a helper waiting for a kernel it calls; this process
#: waiting for the helpers)
POLL = 0.1

#: the step's entry, after every stage (``pipeline/step.py``: ``STEPS[scheme][coverage][tier]``) takes the
#: addresses of two int64 arrays and a count
ENTRY_ARGUMENTS = (0, 0, 1)

#: the type of the step context's view, every stage's first argument
CONTEXT_VIEW = RecordView(STEP_CONTEXT)


def step_stages(scheme, coverage, tier):
    """The cached stage kernels of the step ``STEPS[scheme][coverage][tier]``, each with the constants the step
    passes it after the context: ``((kernel, constants), ...)``, the dearest to compile first, so that the
    helpers end at about the same time; the contact stages, which call the narrow phase and time-of-impact stages
    (the first two), last (:func:`work_list`).  Measured on a cold cache: for spheres over a mesh (lean) the
    time-of-impact stage ~35 s, the narrow phase ~19 s, relax ~12 s, the broad phase ~11 s, prepare ~7 s, the rest
    0.1 to 5 s; for boxes (full, every pair test) the narrow phase ~260 s, time of impact ~45 s, the broad phase
    ~60 s, warm start, prepare and integrate velocities ~30 s each."""
    if tier == LEAN:
        return tuple((stage, ()) for stage in (
            TIME_OF_IMPACT[coverage], NARROW_PHASE[coverage], stage_relax_lean, stage_broad_phase_lean,
            stage_prepare_lean, stage_integrate_velocities_lean, stage_integrate_positions_lean, stage_solve_lean,
            stage_aabbs, stage_store_impulses_lean, stage_match_and_wake, stage_warm_start_lean,
            stage_islands_and_sleep, stage_sum_impulses_lean, stage_restitution_lean, finish_step,
            FIND_CONTACTS[coverage]))
    # (the flags each scheme's step passes: pipeline/step.py, step_sequential_impulse, step_penalty, step_lcp)
    scheme_stages = {
        SEQUENTIAL_IMPULSE: ((stage_prepare, (True, True, True)), (stage_warm_start, ()),
                             (stage_integrate_velocities, (False,)), (stage_restitution, (False,))),
        PENALTY: ((stage_prepare, (False, True, False)), (stage_integrate_velocities, (True,))),
        LCP: ((stage_solve_lcp, ()), (stage_prepare, (False, True, True)), (stage_integrate_velocities, (False,)),
              (stage_restitution, (True,))),
    }[scheme]
    return (((NARROW_PHASE[coverage], ()), (TIME_OF_IMPACT[coverage], ()), (stage_broad_phase, ()))
            + scheme_stages
            + tuple((stage, ()) for stage in (stage_integrate_positions, stage_aabbs, stage_match_and_wake,
                                              stage_store_impulses, stage_sum_impulses, stage_break_constraints,
                                              stage_islands_and_sleep, finish_step, FIND_CONTACTS[coverage])))


def _path_in(value, kernel):
    """The indices that lead from ``value`` (a kernel, or nested tuples of them) to ``kernel``: ``()`` for the
    kernel itself, None if it is not there."""
    if value is kernel:
        return ()
    if isinstance(value, tuple):
        for k, item in enumerate(value):
            path = _path_in(item, kernel)
            if path is not None:
                return (k,) + path
    return None


def _name(kernel):
    """``(module, name, path)`` of a kernel held by a module-level name, itself (a function: ``path`` is ``()``)
    or in nested tuples at indices ``path`` (variants a factory made, such as ``particle_step.KERNELS``)."""
    module = kernel.py_func.__module__
    for name, value in vars(importlib.import_module(module)).items():
        path = _path_in(value, kernel)
        if path is not None:
            return module, name, path
    raise LookupError(f"{module}.{kernel.py_func.__qualname__} is not held by a module-level name")


def _kernel(module, name, path):
    """The kernel that :func:`_name` names."""
    kernel = getattr(importlib.import_module(module), name)
    for k in path:
        kernel = kernel[k]
    return kernel


def _claim(module, name, path):
    """The claim's file name of the kernel that :func:`_name` names."""
    return ".".join([module, name] + [str(k) for k in path])


def _typed(kernel, arguments):
    """A work item (:func:`work_list`) of ``kernel`` for the types of ``arguments``."""
    return (*_name(kernel), tuple(numba.typeof(a) for a in arguments))


def work_list(step, first, extra):
    """The kernels to share out, ``[(module, name, path, argument types, claims of the kernels it calls)]``:
    the kernels of ``first`` (``[(kernel, arguments)]``, which the program calls before its step,
    :func:`ahead`), then those of ``extra`` (as ``first``: the particles' step, ~25 s) and the stages of
    ``step`` (``(scheme, coverage, tier)``, :func:`step_stages`), the dearest first; then the step's entry, which
    calls every stage (compiled once they are in the cache, it loads them)."""
    scheme, coverage, tier = step
    typed = [_typed(kernel, arguments) for kernel, arguments in extra]
    stages = [(*_name(stage), (CONTEXT_VIEW,) + tuple(numba.types.literal(c) for c in constants))
              for stage, constants in step_stages(scheme, coverage, tier)]
    items = ([_typed(kernel, arguments) for kernel, arguments in first] + typed[:1] + stages + typed[1:]
             + [_typed(STEPS[scheme][coverage][tier], ENTRY_ARGUMENTS)])
    stage_claims = tuple(_claim(*stage[:3]) for stage in stages)
    calls = {stage_claims[-1]: stage_claims[:2],        # (the contact stages: the narrow phase, time of impact)
             _claim(*items[-1][:3]): stage_claims}
    return [item + (calls.get(_claim(*item[:3]), ()),) for item in items]


def _resident():
    """This process's resident memory (bytes); 0 where it cannot be told (not Linux)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError, AttributeError):
        return 0


def _alive(pid):
    """Whether process ``pid`` runs (True where that cannot be told without harm: on Windows a signal kills)."""
    if os.name == "nt":
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _done(claims, claim):
    """Whether the kernel of ``claim`` is done: compiled into the cache, or its claimer ended without it (a
    process that calls it then compiles it itself)."""
    path = os.path.join(claims, claim)
    if os.path.exists(path + ".done"):
        return True
    try:
        with open(path) as f:
            pid = f.read()
    except FileNotFoundError:
        return False           # (not claimed yet)
    return bool(pid) and not _alive(int(pid))


def _load(claims, loaded):
    """The work list pickled in ``claims`` (:func:`work_list`), read again only when it has been replaced
    (``loaded``: ``(its modification time, the list)`` or None)."""
    path = os.path.join(claims, "work")
    stamp = os.stat(path).st_mtime_ns
    if loaded is not None and loaded[0] == stamp:
        return loaded
    with open(path, "rb") as f:
        return stamp, pickle.load(f)


def compile_claimed(claims, memory=None):
    """Compile (or load) each kernel of the work list in directory ``claims`` that this process is the first to
    claim, once the kernels it calls are done (waiting for them while nothing else is left to claim); return
    when no kernel is left to claim, or once this process holds more than ``memory`` bytes."""
    loaded = None
    while True:
        loaded = _load(claims, loaded)
        waiting = False
        for module, name, path, signature, calls in loaded[1]:
            claim = _claim(module, name, path)
            if os.path.exists(os.path.join(claims, claim)):
                continue
            if not all(_done(claims, c) for c in calls):
                waiting = True
                continue
            try:
                fd = os.open(os.path.join(claims, claim), os.O_CREAT | os.O_EXCL | os.O_WRONLY)
            except FileExistsError:
                continue
            os.write(fd, str(os.getpid()).encode())
            os.close(fd)
            _kernel(module, name, path).compile(signature)
            os.close(os.open(os.path.join(claims, claim + ".done"), os.O_CREAT | os.O_WRONLY))
            if memory is not None and _resident() > memory:
                return
            break                  # (the list may have grown meanwhile: from its top again)
        else:
            if not waiting:
                return
            time.sleep(POLL)


def _unclaimed(claims):
    """Whether a kernel of the work list in ``claims`` is still to be claimed."""
    return any(not os.path.exists(os.path.join(claims, _claim(*item[:3]))) for item in _load(claims, None)[1])


def _cores():
    """CPU cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:        # (not on every platform)
        return os.cpu_count() or 1


def _write_work(claims, work):
    """Pickle ``work`` into directory ``claims``, replacing the list there at once (helpers may be reading)."""
    with open(os.path.join(claims, "work.new"), "wb") as f:
        pickle.dump(work, f)
    os.replace(os.path.join(claims, "work.new"), os.path.join(claims, "work"))


def _start_helper(claims):
    """A helper process on the work list in ``claims``, or None where none can start (no interpreter to run)."""
    package_parent = os.path.dirname(cache.PACKAGE_DIR)
    env = dict(os.environ, MARBELLOUS_PROGRESS="0",
               PYTHONPATH=os.pathsep.join([package_parent] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    try:
        return subprocess.Popen([sys.executable, "-m", "marbellous.pipeline.precompile", claims,
                                 str(HELPER_MEMORY)], env=env,
                                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:
        return None


class _Compiled:
    """The kernels the helpers have compiled, read from their logs in the claims directory (a name a line,
    ``compiled-PID``), for this process's progress line."""

    def __init__(self, claims):
        self.claims = claims
        self.read = {}           # log -> characters read

    def report(self):
        """Count the kernels logged since the last call on this process's progress line."""
        for log in sorted(os.listdir(self.claims)):
            if not log.startswith("compiled-"):
                continue
            with open(os.path.join(self.claims, log)) as f:
                f.seek(self.read.get(log, 0))
                text = f.read()
            whole = text[:text.rfind("\n") + 1]
            self.read[log] = self.read.get(log, 0) + len(whole)
            for name in whole.split():
                PROGRESS.compiled_elsewhere(name)


class Sharing:
    """One sharing out of a world's ``step`` (``(scheme, coverage, tier)``, the indices of its entry in
    ``pipeline/step.STEPS``): the helpers and their claims directory, started by :meth:`start`, finished (the
    helpers waited for) by :meth:`finish`."""

    def __init__(self, step):
        self.step = step
        self.helpers = []
        self.claims = None
        self.first = []          # [(kernel, arguments)] the program calls before its step (:func:`ahead`)
        self.work = []
        self.compiled = None     # the helpers' logs read so far (:class:`_Compiled`), once they have started

    def start(self, extra):
        """Start the helpers on :func:`work_list` of ``extra`` (nothing without a cache, or when none starts).
        Started already (:func:`ahead`), the helpers go on with the longer list."""
        self.work = work_list(self.step, self.first, extra)
        if self.claims is not None:
            _write_work(self.claims, self.work)
            return
        if cache.CACHE_DIR is None:
            return
        try:
            self.claims = tempfile.mkdtemp(prefix="marbellous-claims-")
            _write_work(self.claims, self.work)
        except (OSError, pickle.PicklingError):
            self._remove()
            return
        for _ in range(max(1, min(_cores(), HELPERS))):
            helper = _start_helper(self.claims)
            if helper is None:
                break
            self.helpers.append(helper)
        if not self.helpers:
            self._remove()
            return
        self.compiled = _Compiled(self.claims)
        _UNDER_WAY.add(self)
        # (a program that ends before its first step stops the helpers)
        weakref.finalize(self, _stop, self.helpers, self.claims)

    def _remove(self):
        if self.claims is not None:
            shutil.rmtree(self.claims, ignore_errors=True)
        self.claims = None

    def _tend(self, ready):
        """Wait until ``ready()`` or until no helper runs, starting a fresh helper for each that ends for its
        memory while kernels are left to claim, and counting the helpers' kernels on the progress line."""
        deadline = time.monotonic() + HELPER_TIMEOUT
        while self.helpers and not ready() and time.monotonic() < deadline:
            self.compiled.report()
            for helper in [h for h in self.helpers if h.poll() is not None]:
                self.helpers.remove(helper)
                if helper.returncode == 0 and _unclaimed(self.claims):
                    fresh = _start_helper(self.claims)
                    if fresh is not None:
                        self.helpers.append(fresh)
            time.sleep(POLL)
        self.compiled.report()

    def wait(self, kernel):
        """Wait until the helpers have compiled ``kernel``, if it is on their list."""
        if self.claims is None:
            return
        claim = _claim(*_name(kernel))
        if any(_claim(*item[:3]) == claim for item in self.work):
            self._tend(lambda: _done(self.claims, claim))

    def finish(self, here=None):
        """Wait for the helpers to go down their list.  ``here``: a kernel of the list that this process is
        compiling itself, holding its lock (``_numba/shared_compile.py``), so that a helper that took it would wait
        for this process as this process waits for it: the helpers are stopped once the rest of the list is done."""
        if self.claims is None:
            return
        rest = [_claim(*item[:3]) for item in self.work]
        if here is not None and _claim(*_name(here)) in rest:
            rest.remove(_claim(*_name(here)))
        try:
            self._tend(lambda: here is not None and all(_done(self.claims, claim) for claim in rest))
        finally:
            _UNDER_WAY.discard(self)
            _stop(self.helpers, self.claims)
            self.helpers = []
            self.claims = None


#: the sharings under way (:func:`await_kernel` looks through them)
_UNDER_WAY = weakref.WeakSet()


def await_kernel(kernel):
    """Before a call of ``kernel`` (a dispatcher): wait until helpers have compiled it, if a sharing under way
    lists it (:func:`ahead`), so that it loads from the cache rather than compiles here as well."""
    for sharing in list(_UNDER_WAY):
        sharing.wait(kernel)


def _stop(helpers, claims):
    """Stop the ``helpers`` that still run, and remove their claims directory."""
    for helper in helpers:
        if helper.poll() is None:
            helper.kill()
            helper.wait()
    shutil.rmtree(claims, ignore_errors=True)


def _cached(kernel):
    """Whether the kernel cache holds an up-to-date compile of ``kernel`` (a dispatcher); True when that cannot
    be told (it is a hint only)."""
    try:
        return bool(kernel._cache._cache_file._load_index())
    except Exception:      # noqa: BLE001 (Numba's cache internals: any failure means "do not start a helper")
        return True


def ahead(step, first=()):
    """A :class:`Sharing` of ``step`` (``(scheme, coverage, tier)``) started now, before the step is first taken,
    when its dearest stage is not in the cache (for a program that calls something else first, such as a ray cast: the
    helpers compile ``first``, ``[(kernel, arguments)]`` such calls, then the step's stages, and the program
    waits for ``first`` at its call, :func:`await_kernel`); None when they are.  The step's first packing
    (:func:`shared`) finishes it."""
    if _cached(step_stages(*step)[0][0]):
        return None
    sharing = Sharing(step)
    sharing.first = list(first)
    sharing.start([])
    return sharing


class _ShareOnCompile(event.Listener):
    """Starts the sharing out when the first of ``early`` (the context's packing, which compiles before the
    step) or ``entry`` begins to compile (it was not in the cache), so that the helpers start up while this
    process compiles the packing; and finishes it before ``entry`` compiles here (helpers started only then,
    by the entry's compile, leave this process to compile the entry, loading the stages they compiled)."""

    def __init__(self, early, entry, sharing, extra):
        self.early = early
        self.entry = entry
        self.sharing = sharing
        self.extra = extra
        self.started = False

    def on_start(self, ev):
        dispatcher = ev.data.get("dispatcher")
        if not self.started and (dispatcher is self.early or dispatcher is self.entry):
            self.started = True
            self.sharing.start(self.extra())
        if dispatcher is self.entry:
            self.sharing.finish(here=self.entry)

    def on_end(self, ev):
        pass


@contextlib.contextmanager
def shared(early, step, extra, sharing=None):
    """Around the packing of a step's context (``early``, the packing kernel, a dispatcher) and the first call
    of the entry of ``step`` (``(scheme, coverage, tier)``): if either compiles, the step's stages, the kernels
    ``extra()`` lists (``[(kernel, arguments)]``, the world's other kernels of a step) and the entry are shared
    out: helpers start when the first of them begins to compile (or were started by :func:`ahead`:
    ``sharing``).  Yields the :class:`Sharing`, whose :meth:`Sharing.wait` for the entry before its call
    lets the entry load from the cache; on leaving, the helpers have gone down their list."""
    if sharing is None or sharing.step != step:
        if sharing is not None:
            sharing.finish()          # (helpers started for another step: their kernels are in the cache)
        sharing = Sharing(step)
    scheme, coverage, tier = step
    try:
        with event.install_listener("numba:compile",
                                    _ShareOnCompile(early, STEPS[scheme][coverage][tier], sharing, extra)):
            yield sharing
    finally:
        sharing.finish()


class _Log(event.Listener):
    """A helper's log of the package kernels it compiles (for the progress line of the process that waits)."""

    def __init__(self, stream):
        self.stream = stream

    def on_start(self, ev):
        pass

    def on_end(self, ev):
        name = kernel_name(ev.data.get("dispatcher"))
        if name is not None:
            self.stream.write(name + "\n")
            self.stream.flush()


def main(claims, memory):
    """A helper on the list in directory ``claims`` that ends past ``memory`` bytes."""
    with open(os.path.join(claims, f"compiled-{os.getpid()}"), "w") as log:
        event.register("numba:compile", _Log(log))
        compile_claimed(claims, memory)


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]))
