"""Kernels of the incompressible Navier-Stokes grid (:class:`marbellous.Fluid`): the staggered grid's
boundary values and interpolation, advection, viscosity, the pressure projection and the coupling to bodies."""
