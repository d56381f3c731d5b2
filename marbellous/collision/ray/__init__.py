"""Ray casts against primitive shapes, triangles, meshes and height fields."""
