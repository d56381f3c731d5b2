"""A cold lean step compiled on two cores: this process and a helper process share out its stages.

Numba compiles one kernel at a time, holding the interpreter, so a first world's step (about a minute of
compiling) would use one core however many the machine has.  The lean step's stages (``pipeline/step.py``)
each take only the step context's view, so another process can compile them for the same type without
the world, and whatever either process compiles goes to the kernel cache (``_numba/cache.py``).  When
the step's context packing or the step begins to compile (they were not in the cache), this process starts a
helper (which starts up while this process compiles the packing); both go down one list of the stages, the
dearest first, and each compiles the stages it is the first to claim (a file
created in a shared directory, which only one process can create).  When the list is done and the helper
has finished, the step compiles on, loading from the cache the stages the helper compiled.

The world's particle step kernels, which its step calls next, join the list (typed from the arguments
they will get).  Only the lean step is shared out: the full step's solve and relax stages are compiled
with the step (``njit_calls_parallel``), not cached on their own.  Nothing happens when the step loads
from the cache, when the cache is off, or on one core.  ``python -m marbellous.pipeline.precompile CLAIMS``
is the helper (the list is pickled in the directory ``CLAIMS``).
"""
import contextlib
import importlib
import os
import pickle
import shutil
import subprocess
import sys
import tempfile
import weakref

import numba
from numba.core import event

from .._numba import cache
from .._numba.record import RecordView
from .context import STEP_CONTEXT
from .step import (FIND_CONTACTS, NARROW_PHASE, TIME_OF_IMPACT, finish_step, stage_aabbs, stage_broad_phase_lean,
                   stage_integrate_positions_lean, stage_integrate_velocities_lean, stage_islands_and_sleep,
                   stage_match_and_wake, stage_prepare_lean, stage_relax_lean, stage_restitution_lean, stage_solve_lean,
                   stage_store_impulses_lean, stage_sum_impulses_lean, stage_warm_start_lean)


#: the longest wait (s) for the helper once this process has compiled its share: the helper's last stage
#: takes seconds, so a helper still busy then is stuck (a machine swapping, a stopped process)
HELPER_TIMEOUT = 300.0


def lean_stages(coverage):
    """The lean step's stage kernels for ``coverage``, the dearest to compile first (measured on a cold
    cache for spheres over a mesh: the time-of-impact stage ~35 s, the narrow phase ~19 s, relax ~12 s, the broad
    phase ~11 s, prepare ~7 s, the rest 0.1 to 5 s), so that the two processes end at about the same time; the
    contact stages, which call the narrow phase and time-of-impact stages, last, to find them in the cache."""
    return (TIME_OF_IMPACT[coverage], NARROW_PHASE[coverage], stage_relax_lean, stage_broad_phase_lean,
            stage_prepare_lean, stage_integrate_velocities_lean, stage_integrate_positions_lean, stage_solve_lean,
            stage_aabbs, stage_store_impulses_lean, stage_match_and_wake, stage_warm_start_lean,
            stage_islands_and_sleep, stage_sum_impulses_lean, stage_restitution_lean, finish_step,
            FIND_CONTACTS[coverage])


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


def work_list(coverage, extra):
    """The kernels to share out: ``[(module, name, path, argument types or None for the context's view)]``, the
    dearest first: the lean step's stages for ``coverage`` after the kernels of ``extra``
    (``[(kernel, arguments)]``: the particles' step, ~25 s, whose arguments are typed here)."""
    typed = [(*_name(kernel), tuple(numba.typeof(a) for a in arguments)) for kernel, arguments in extra]
    return typed[:1] + [(*_name(stage), None) for stage in lean_stages(coverage)] + typed[1:]


def compile_claimed(work, claims):
    """Compile (or load) each kernel of ``work`` (:func:`work_list`) that this process is the first to claim in
    directory ``claims``."""
    view = (RecordView(STEP_CONTEXT),)
    for module, name, path, signature in work:
        try:     # (claimed by name: a list that grows, :meth:`Sharing.start`, keeps its claims)
            claim = ".".join([module, name] + [str(k) for k in path])
            os.close(os.open(os.path.join(claims, claim), os.O_CREAT | os.O_EXCL | os.O_WRONLY))
        except FileExistsError:
            continue
        _kernel(module, name, path).compile(view if signature is None else signature)


def _cores():
    """CPU cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:        # (not on every platform)
        return os.cpu_count() or 1


def _start_helper(work):
    """``(helper, claims)``: the helper process and its claims directory, where the work list is pickled; or
    ``(None, None)`` where none can start (no writable temporary directory, no interpreter to run): the step
    then compiles its kernels in this process as it meets them."""
    claims = None
    try:
        claims = tempfile.mkdtemp(prefix="marbellous-claims-")
        with open(os.path.join(claims, "work"), "wb") as f:
            pickle.dump(work, f)
        package_parent = os.path.dirname(cache.PACKAGE_DIR)
        env = dict(os.environ, MARBELLOUS_PROGRESS="0",
                   PYTHONPATH=os.pathsep.join([package_parent] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
        helper = subprocess.Popen([sys.executable, "-m", "marbellous.pipeline.precompile", claims], env=env,
                                  stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        return helper, claims
    except (OSError, pickle.PicklingError):
        if claims is not None:
            shutil.rmtree(claims, ignore_errors=True)
        return None, None


class Sharing:
    """One sharing out of a world's lean step of ``coverage``: the helper and its claims directory, started by
    :meth:`start`, finished (this process's claims compiled, the helper waited for) by :meth:`finish`."""

    def __init__(self, coverage):
        self.coverage = coverage
        self.work = self.helper = self.claims = None

    def start(self, extra):
        """Start the helper on :func:`work_list` of ``extra`` (nothing without a cache or a second core, or when
        none starts).  Started already (:func:`ahead`), the helper goes on with its list while this process
        will compile the new list's kernels that no one has claimed."""
        if self.helper is not None:
            self.work = work_list(self.coverage, extra)
            return
        if cache.CACHE_DIR is None or _cores() < 2:
            return
        self.work = work_list(self.coverage, extra)
        self.helper, self.claims = _start_helper(self.work)
        if self.helper is not None:      # (a program that ends before its first step stops the helper)
            weakref.finalize(self, _stop, self.helper, self.claims)

    def finish(self):
        """Compile the kernels this process claims, and wait for the helper."""
        if self.helper is None:
            return
        helper, self.helper = self.helper, None
        try:
            compile_claimed(self.work, self.claims)
        finally:
            # (a helper that failed, or is stopped here, leaves its kernels to this process, which compiles them
            # when it calls them)
            try:
                helper.wait(timeout=HELPER_TIMEOUT)
            except subprocess.TimeoutExpired:
                helper.kill()
                helper.wait()
            shutil.rmtree(self.claims, ignore_errors=True)


def _stop(helper, claims):
    """Stop ``helper`` if it still runs, and remove its claims directory."""
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


def ahead(coverage):
    """A :class:`Sharing` of the lean step of ``coverage`` started now, before the step is first taken, when its
    stages are not in the cache (for a program that compiles something else first, such as a ray cast: the
    helper compiles the step's stages meanwhile); None when they are.  The step's first packing
    (:func:`shared`) finishes it."""
    if _cached(TIME_OF_IMPACT[coverage]):
        return None
    sharing = Sharing(coverage)
    sharing.start([])
    return sharing


class _ShareOnCompile(event.Listener):
    """Starts the sharing out when the first of ``early`` (the context's packing, which compiles before the
    step) or ``entry`` begins to compile (it was not in the cache), and finishes it before ``entry`` compiles:
    the helper starts up while this process compiles the packing."""

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
            self.sharing.finish()

    def on_end(self, ev):
        pass


@contextlib.contextmanager
def shared(early, entry, coverage, lean, extra, sharing=None):
    """Around the packing of a step's context (``early``, the packing kernel, a dispatcher) and the first call
    of step ``entry`` (a dispatcher) of ``coverage``: if either compiles and the step is ``lean``, its stages
    and the kernels ``extra()`` lists (``[(kernel, arguments)]``, the world's other kernels of a step) are
    shared out: a helper starts when the first of them begins to compile (or was started by :func:`ahead`:
    ``sharing``), and the entry compiles once the list is done (the entry loads the stages from the cache)."""
    if sharing is None or sharing.coverage != coverage or not lean:
        if sharing is not None:
            sharing.finish()          # (a helper started for another step: its kernels are in the cache)
        sharing = Sharing(coverage)
    try:
        if lean:
            with event.install_listener("numba:compile", _ShareOnCompile(early, entry, sharing, extra)):
                yield
        else:
            yield
    finally:
        sharing.finish()


def main(claims):
    """The helper."""
    with open(os.path.join(claims, "work"), "rb") as f:
        compile_claimed(pickle.load(f), claims)


if __name__ == "__main__":
    main(sys.argv[1])
