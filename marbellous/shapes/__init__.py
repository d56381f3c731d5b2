"""Collision shapes: spheres, boxes, capsules, convex hulls, planes, height fields and triangle meshes."""
from .heightfield import HeightField
from .hull import ConvexHull
from .mesh import TriangleMesh
from .primitives import Box, Capsule, Plane, Shape, Sphere

__all__ = ["Shape", "Sphere", "Box", "Capsule", "ConvexHull", "Plane", "HeightField", "TriangleMesh"]
