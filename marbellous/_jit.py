"""The one place where Numba is configured.

Every kernel in Marbellous is a plain function over NumPy arrays decorated with :func:`njit`.
Kernels are compiled on first use and cached on disk next to their source file, so the second
start of a program is fast.  Tunables travel as arguments, never as globals (the cache freezes
globals).  ``NUMBA_DISABLE_JIT=1`` in the environment runs every kernel as plain Python.
"""
import numba

#: Compile in nopython mode, cache to disk, no fastmath (results are bit-reproducible).
njit = numba.njit(cache=True, nogil=True, fastmath=False)

#: As :data:`njit`, but inlined into each caller at the Numba IR level: for small kernels called once per
#: sub-step or iteration, where the call itself (every array argument's fields passed and reference
#: counted) would cost more than the work.
njit_inline = numba.njit(cache=True, nogil=True, fastmath=False, inline="always")

#: As :data:`njit`, with ``prange`` loops run on Numba's threads (the caller keeps a serial path).
njit_parallel = numba.njit(cache=True, nogil=True, fastmath=False, parallel=True)
