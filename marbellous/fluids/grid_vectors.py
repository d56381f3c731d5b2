"""Vector operations of the grids' conjugate-gradient solves, on flat views of contiguous arrays (plain loops:
NumPy array expressions over 3- and 4-dimensional arrays take Numba tens of seconds to compile)."""
from .._numba.jit import njit


@njit
def dot(a, b):
    """``sum a * b``."""
    af = a.reshape(a.size)
    bf = b.reshape(b.size)
    total = 0.0
    for index in range(af.size):
        total += af[index] * bf[index]
    return total


@njit
def add_scaled(y, alpha, x):
    """``y += alpha x``."""
    yf = y.reshape(y.size)
    xf = x.reshape(x.size)
    for index in range(yf.size):
        yf[index] += alpha * xf[index]


@njit
def scale_add(y, beta, x):
    """``y = x + beta y``."""
    yf = y.reshape(y.size)
    xf = x.reshape(x.size)
    for index in range(yf.size):
        yf[index] = xf[index] + beta * yf[index]


@njit
def largest_magnitude(a):
    """``max |a|`` (0 for an empty array)."""
    af = a.reshape(a.size)
    largest = 0.0
    for index in range(af.size):
        largest = max(largest, abs(af[index]))
    return largest


@njit
def assign(y, x):
    """``y = x``."""
    yf = y.reshape(y.size)
    xf = x.reshape(x.size)
    for index in range(yf.size):
        yf[index] = xf[index]
