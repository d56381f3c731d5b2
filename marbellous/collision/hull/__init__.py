"""Convex hulls: their blob layout, the polytope view the pair tests share, and the pair tests."""
