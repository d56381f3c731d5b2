"""Collision shapes: spheres, boxes, capsules, planes, height fields and triangle meshes."""
from .heightfield import HeightField
from .mesh import TriangleMesh
from .primitives import Box, Capsule, Plane, Shape, Sphere

__all__ = ["Shape", "Sphere", "Box", "Capsule", "Plane", "HeightField", "TriangleMesh"]
