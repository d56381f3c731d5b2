"""Reading triangle meshes from files: OBJ by its own strict reader, STL, PLY and GLB/GLTF through trimesh.

``read_mesh_file(path, max_triangles)`` returns ``(vertices (V, 3) float64, triangles (T, 3) int64)`` or raises
``ValueError`` naming the file (and, for OBJ, the line).  Limits: files up to ``MAX_FILE_BYTES``, at most
``max_triangles`` triangles and vertices.

OBJ is read here rather than by trimesh because trimesh decodes the whole text first and, for anything
but UTF-8, needs an optional charset detector; and it silently drops a face with fewer than three
vertices (a file cut short).  This reader works on bytes: the tags and numbers of ``v`` and ``f`` lines
are ASCII, and names or comments in any encoding (UTF-8, Latin-1, ...) are skipped without decoding
(a file starting with a UTF-16 byte order mark is converted first).
Faces are polygons of 3 or more vertex references ``i``, ``i/t``, ``i//n`` or ``i/t/n`` (1-based, or
negative: relative to the last vertex read), split into a fan of triangles; other statements (``vt``,
``vn``, ``o``, ``g``, ``usemtl``, ``l``, ...) are ignored.  A ``v`` line with fewer than 3 numbers, a
face with fewer than 3 vertices, a reference that is not an integer, or a reference to vertex 0 is
an error naming the line: such a file is truncated or malformed, and guessing would lose geometry.
"""
import codecs
import io
import os
import warnings
from array import array

import numpy as np

#: Largest mesh file read, bytes.
MAX_FILE_BYTES = 1 << 30
#: File types read: OBJ here, the others through trimesh.
FILE_TYPES = (".obj", ".stl", ".ply", ".glb", ".gltf")


def check_mesh_path(path, max_bytes=MAX_FILE_BYTES):
    """``path`` as a string after checking it names an existing, non-empty mesh file of a known type no
    larger than ``max_bytes``; ValueError naming it otherwise."""
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"path must be a file name (str or path), got {type(path).__name__}")
    p = os.fsdecode(path)
    ext = os.path.splitext(p)[1].lower()
    if ext not in FILE_TYPES:
        raise ValueError(f"path must name a {', '.join(FILE_TYPES)} file, got {p!r}")
    if not os.path.isfile(p):
        raise ValueError(f"path: no such file {p!r}")
    size = os.path.getsize(p)
    if size > max_bytes:
        raise ValueError(f"path: file {p!r} is {size} bytes, more than the limit {max_bytes}")
    if size == 0:
        raise ValueError(f"path: file {p!r} is empty")
    return p


def read_mesh_file(path, max_triangles, max_bytes=MAX_FILE_BYTES):
    """``(vertices, triangles)`` of the mesh file ``path`` (see the module docstring); at most
    ``max_triangles`` triangles and as many vertices, files of at most ``max_bytes``."""
    p = check_mesh_path(path, max_bytes)
    if p.lower().endswith(".obj"):
        verts, faces = _read_obj(p, max_triangles)
    else:
        verts, faces = _read_with_trimesh(p)
    if verts.ndim != 2 or verts.shape[-1] != 3 or faces.ndim != 2 or faces.shape[0] == 0:
        raise ValueError(f"path: file {p!r} contains no triangles")
    if faces.shape[0] > max_triangles or verts.shape[0] > max_triangles:
        raise ValueError(f"path: file {p!r} has {faces.shape[0]} triangles and {verts.shape[0]} vertices, "
                         f"more than the limit {max_triangles}")
    return verts, faces


def _read_with_trimesh(p):
    import trimesh

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            loaded = trimesh.load(p, force="mesh", process=False)
        verts = np.asarray(getattr(loaded, "vertices", np.zeros((0, 3))), dtype=np.float64)
        faces = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.int64)
    except Exception as exc:   # noqa: BLE001  (trimesh raises many kinds of errors for malformed files)
        raise ValueError(f"path: could not read mesh file {p!r}: {type(exc).__name__}: {exc}") from None
    return verts, faces


def _obj_error(p, lineno, message):
    return ValueError(f"path: OBJ file {p!r}, line {lineno}: {message}")


def _read_obj(p, max_triangles):
    verts = array("d")
    faces = array("q")
    n_verts = 0
    pending = b""
    lineno = 0
    with open(p, "rb") as f:
        head = f.read(2)
        f.seek(0)
        if head in (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE):
            try:
                lines = io.BytesIO(f.read().decode("utf-16").encode("utf-8"))
            except UnicodeDecodeError as e:
                raise _obj_error(p, 1, f"not valid UTF-16 text ({e})") from None
        else:
            lines = f
        for lineno, raw in enumerate(lines, 1):
            line = pending + raw
            stripped = line.rstrip()
            if stripped.endswith(b"\\"):          # a statement continued on the next line
                pending = stripped[:-1] + b" "
                continue
            pending = b""
            parts = line.split()
            if not parts:
                continue
            tag = parts[0]
            if tag == b"v":
                if len(parts) < 4:
                    raise _obj_error(p, lineno, f"a vertex needs 3 coordinates, got {len(parts) - 1} "
                                                "(is the file truncated?)")
                try:
                    verts.extend((float(parts[1]), float(parts[2]), float(parts[3])))
                except ValueError:
                    raise _obj_error(p, lineno, "vertex coordinates must be numbers") from None
                n_verts += 1
                if n_verts > max_triangles:
                    raise _obj_error(p, lineno, f"more than the limit of {max_triangles} vertices")
            elif tag == b"f":
                refs = parts[1:]
                if len(refs) < 3:
                    raise _obj_error(p, lineno, f"a face needs at least 3 vertices, got {len(refs)} "
                                                "(is the file truncated?)")
                idx = []
                for ref in refs:
                    try:
                        i = int(ref.split(b"/", 1)[0])
                    except ValueError:
                        raise _obj_error(p, lineno, f"vertex reference {ref.decode('latin-1')!r} is not an "
                                                    "integer") from None
                    if i == 0:
                        raise _obj_error(p, lineno, "vertex references start at 1 (0 is not a vertex)")
                    idx.append(i - 1 if i > 0 else n_verts + i)
                if max(idx) >= n_verts or min(idx) < 0:
                    raise _obj_error(p, lineno, f"a face refers to a vertex not defined before it (vertices "
                                                f"1..{n_verts} so far)")
                for k in range(1, len(idx) - 1):
                    faces.extend((idx[0], idx[k], idx[k + 1]))
                if len(faces) > 3 * max_triangles:
                    raise _obj_error(p, lineno, f"more than the limit of {max_triangles} triangles")
    if pending:
        raise _obj_error(p, lineno, "the file ends inside a continued line (is it truncated?)")
    return (np.frombuffer(verts, np.float64).reshape(-1, 3).copy(),
            np.frombuffer(faces, np.int64).reshape(-1, 3).copy())
