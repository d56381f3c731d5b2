"""The one place where Numba is configured.

Every kernel in Marbellous is a plain function over NumPy arrays decorated with :func:`njit`.
Kernels are compiled on first use and cached on disk (``_numba/cache.py``: where, and why an edit
anywhere in the package never leaves a stale kernel), so the second start of a program is fast; processes
that start cold together compile each kernel once (``_numba/shared_compile.py``).
Tunables travel as arguments, never as globals (the cache freezes globals).  ``NUMBA_DISABLE_JIT=1`` in the
environment runs every kernel as plain Python.
"""
import atexit
import gc

import numba
from numba.core import cgutils, types
from numba.extending import intrinsic

from . import cache, shared_compile

#: whether compiled kernels are cached on disk (not when no cache directory is writable)
CACHING = cache.install()


def _compiled_once(decorator):
    """``decorator`` (a Numba ``njit``), its cached kernels compiled once among processes that need them at the
    same time (``shared_compile.py``)."""
    return lambda func: shared_compile.share(decorator(func))


# At exit the interpreter's last garbage collections would walk every compiler object Numba made (types,
# IR, LLVM modules) and dispose of them one by one: 0.1-0.3 s of every program that compiled or loaded a
# kernel, for memory the process gives back whole anyway.  Frozen, the collector leaves them.  The price:
# objects caught in reference cycles are not finalized at exit, which Python never promises.  Registered
# here, first, so that it runs after every exit handler registered later.
atexit.register(gc.freeze)

#: Compile in nopython mode, cache to disk, no fastmath (results are bit-reproducible).
njit = _compiled_once(numba.njit(cache=CACHING, nogil=True, fastmath=False))

#: As :data:`njit`, but inlined into each caller at the Numba IR level: for small kernels called once per
#: sub-step or iteration, where the call itself (every array argument's fields passed and reference
#: counted) would cost more than the work.  Inlined, its array arguments are still counted where its branches
#: leave them (at every call in a loop: two atomic operations an array) unless the caller passes borrowed
#: arrays (:func:`borrow`).
njit_inline = _compiled_once(numba.njit(cache=CACHING, nogil=True, fastmath=False, inline="always"))

#: As :data:`njit`, with ``prange`` loops run on Numba's threads (the caller keeps a serial path).  Not cached
#: on its own: a kernel compiled against a parallel kernel loaded from the cache is saved broken by Numba
#: 0.68 (it crashes when loaded in the next process), so a parallel kernel is compiled with each caller,
#: whose own cache entry then holds it.
njit_parallel = numba.njit(cache=False, nogil=True, fastmath=False, parallel=True)

#: As :data:`njit`, not cached on its own either: for a kernel that calls a parallel kernel, so that it is
#: never loaded from the cache for another kernel to be compiled against (the bug above, one level up: a
#: step compiled in a process that had loaded its contact passes from the cache crashed the next process
#: that loaded the step).  Its callers' cache entries hold it.
njit_calls_parallel = numba.njit(cache=False, nogil=True, fastmath=False)


def _borrow_codegen(context, builder, signature, args):
    """The array struct of ``args[0]`` with a null memory-info pointer and no parent object."""
    array_type = signature.args[0]
    source = context.make_array(array_type)(context, builder, value=args[0])
    view = context.make_array(array_type)(context, builder)
    view.meminfo = cgutils.get_null_value(view.meminfo.type)
    view.parent = cgutils.get_null_value(view.parent.type)
    view.nitems = source.nitems
    view.itemsize = source.itemsize
    view.data = source.data
    view.shape = source.shape
    view.strides = source.strides
    return view._getvalue()


@intrinsic
def _borrow(typingctx, array):
    if not isinstance(array, types.Array):
        return None
    return array(array), _borrow_codegen


def borrow(array):
    """``array`` as a *borrowed* view inside a kernel: the same data, shape and strides, but no reference
    to its memory.  Numba counts the references of every array a compiled function receives (an atomic
    increment on entry and a decrement on exit, ~4 ns each); a borrowed array skips both, in every
    function it is passed to.  Only for arrays that something else keeps alive for the whole call (the
    step's record does), and never to be stored or returned.  Plain Python (``NUMBA_DISABLE_JIT``): the
    array itself."""
    return array


if not numba.config.DISABLE_JIT:
    borrow = _borrow          # noqa: F811 (the compiled form of the function above)


def _field_codegen(attr, field_type):
    def codegen(context, builder, signature, args):
        from numba.experimental.structref import _Utils
        data = _Utils(context, builder, signature.args[0]).get_data_struct(args[0])
        return _borrow_codegen(context, builder, field_type(field_type), [getattr(data, attr)])
    return codegen


@intrinsic
def _field(typingctx, record, name):
    if not isinstance(name, types.StringLiteral) or not isinstance(record, types.StructRef):
        return None
    attr = name.literal_value
    field_type = record.field_dict.get(attr)
    if not isinstance(field_type, types.Array):
        return None
    return field_type(record, name), _field_codegen(attr, field_type)


def field(record, name):
    """The array field ``name`` (a string literal) of a compiled record, borrowed (see :func:`borrow`):
    ``field(ctx, "bf")`` is ``borrow(ctx.bf)`` without the reference that reading ``ctx.bf`` takes and
    gives back (two atomic operations per read, which the step's stages would otherwise pay dozens of
    times).  Valid while the record is alive.  Plain Python: ``getattr(record, name)``."""
    return getattr(record, name)


if not numba.config.DISABLE_JIT:
    field = _field          # noqa: F811 (the compiled form of the function above)
