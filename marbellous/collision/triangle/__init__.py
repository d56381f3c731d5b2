"""Tests of one triangle against a convex shape (separating axes over faces, edges and vertices) and the
mesh adjacency that tells true features from internal ones."""
