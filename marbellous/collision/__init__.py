"""Marbellous collision detection: a standalone library that never imports the dynamics.

Shapes' geometry, broad phases, narrow-phase pair tests, mesh and height-field acceleration,
ray casts.  Pair tests are Numba kernels named ``collide_<a>_<b>`` with the fixed shape order
sphere < capsule < box < plane < heightfield < mesh.
"""
