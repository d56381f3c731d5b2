"""A clock that compiled code can read: the processor's cycle counter.

``cycle_counter()`` returns LLVM's ``readcyclecounter`` (the time-stamp counter on x86-64: a constant
rate, a read costs about 20 cycles) and may be called from any kernel, cached or not.  Elsewhere LLVM may
return 0 or read a register user code is not allowed to read, so :data:`AVAILABLE` is true only on
x86-64; ``cycles_per_second`` measures the rate once against ``time.perf_counter`` (about 20 ms).
"""
import platform
import time

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from .jit import njit


@intrinsic
def _read_cycle_counter(typingctx):
    def codegen(context, builder, signature, args):
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.IntType(64), []),
                                            "llvm.readcyclecounter")
        return builder.call(fn, [])
    return types.int64(), codegen


@njit
def cycle_counter():
    """Processor cycles since an arbitrary origin (int), or 0 where the processor has no counter."""
    return _read_cycle_counter()


#: whether this machine's cycle counter can be read (x86-64)
AVAILABLE = platform.machine().lower() in ("x86_64", "amd64")
_RATE = []


def cycles_per_second():
    """Rate of :func:`cycle_counter` (cycles per second), measured once per process; 0.0 if it does not tick."""
    if not _RATE:
        cycle_counter()                       # compile or load before timing
        t0, c0 = time.perf_counter(), cycle_counter()
        while time.perf_counter() - t0 < 0.02:
            pass
        t1, c1 = time.perf_counter(), cycle_counter()
        _RATE.append(max(0.0, (c1 - c0) / (t1 - t0)))
    return _RATE[0]
