"""Static triangle meshes and height fields: their acceleration structures (the lecture's 2D grid, a
BVH), their validity checks and their collision with convex shapes."""
