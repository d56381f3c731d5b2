"""GPU buffers of shape meshes, uploaded once per mesh and drawn instanced.

The triangles of a mesh (:class:`~marbellous.render.shape_meshes.ShapeMesh`) go to the GPU the first
time the mesh is drawn, indexed (its shared corners made one vertex: ``geometry.indexed``), and stay there
while it is drawn; per frame only the instances (a model matrix and a colour per shape) are written.  A
131k-triangle mesh is uploaded once, however long it is shown.
"""
import numpy as np

from .geometry import indexed

#: Bytes per instance: a 4 x 4 model matrix and (r, g, b, pattern), float32.
INSTANCE_BYTES = 20 * 4


class InstancedMesh:
    """One mesh's vertex and index buffers (shared) and one instance buffer, with vertex arrays for the lit
    ``solid`` program and the shadow ``depth`` program."""

    def __init__(self, ctx, vertices, indices, solid, depth):
        self.vertices = vertices
        self.instances = ctx.buffer(reserve=64 * INSTANCE_BYTES, dynamic=True)
        self.count = 0
        self.solid = ctx.vertex_array(solid, [(vertices, "3f 3f", "in_pos", "in_normal"),
                                              (self.instances, "16f 4f/i", "in_model", "in_color")],
                                      index_buffer=indices, index_element_size=4)
        self.depth = ctx.vertex_array(depth, [(vertices, "3f 12x", "in_pos"),
                                              (self.instances, "16f 16x/i", "in_model")],
                                      index_buffer=indices, index_element_size=4)

    def write(self, models, colors, patterns):
        """Set the instances: ``models`` (N, 4, 4) (column vectors), ``colors`` (N, 3), ``patterns`` (N,)."""
        n = len(models)
        data = np.empty((n, 20), np.float32)
        data[:, :16] = np.transpose(models, (0, 2, 1)).reshape(n, 16)    # column-major for GLSL
        data[:, 16:19] = colors
        data[:, 19] = patterns
        raw = data.tobytes()
        if len(raw) > self.instances.size:
            self.instances.orphan(max(len(raw), 2 * self.instances.size))
        self.instances.write(raw)
        self.count = n

    def release(self):
        """Free the instance buffer and vertex arrays (the vertex and index buffers belong to the cache)."""
        for obj in (self.solid, self.depth, self.instances):
            obj.release()


class MeshCache:
    """The vertex and index buffers of meshes by key, and an :class:`InstancedMesh` per (key, layer).

    ``solid`` and ``depth`` are the renderer's programs.  :attr:`uploads` counts meshes uploaded so far
    (each mesh once while it is kept).
    """

    def __init__(self, ctx, solid, depth):
        self.ctx, self.solid, self.depth = ctx, solid, depth
        self._vertices = {}     # mesh key -> (vertex buffer, index buffer)
        self._instanced = {}    # (mesh key, layer) -> InstancedMesh
        self.uploads = 0

    def get(self, mesh, layer):
        """The :class:`InstancedMesh` of ``mesh`` (a ``ShapeMesh``) in ``layer`` (any hashable, e.g. the
        opacity), uploading the mesh's triangles if they are not on the GPU yet."""
        entry = self._instanced.get((mesh.key, layer))
        if entry is None:
            buffers = self._vertices.get(mesh.key)
            if buffers is None:
                vertices, indices = indexed(*mesh.triangles())
                buffers = self.ctx.buffer(vertices.tobytes()), self.ctx.buffer(indices.tobytes())
                self._vertices[mesh.key] = buffers
                self.uploads += 1
            entry = self._instanced[(mesh.key, layer)] = InstancedMesh(self.ctx, *buffers, self.solid, self.depth)
        return entry

    def keep_only(self, used):
        """Release every instanced mesh whose (key, layer) is not in ``used``, and the vertex and index buffers
        no kept entry uses."""
        for k in [k for k in self._instanced if k not in used]:
            self._instanced.pop(k).release()
        kept = {key for key, _layer in self._instanced}
        for key in [key for key in self._vertices if key not in kept]:
            for buffer in self._vertices.pop(key):
                buffer.release()
