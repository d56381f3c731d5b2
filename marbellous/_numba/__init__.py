"""The compiler extensions in one place: Numba's settings (``jit``), borrowed arrays, wide floats, the cycle
counter.  Nothing else in the package configures Numba."""
