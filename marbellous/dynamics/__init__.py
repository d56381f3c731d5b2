"""Dynamics: forces, integrators, constraint and contact solvers, sleeping."""
