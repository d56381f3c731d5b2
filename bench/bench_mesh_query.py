"""Sphere-vs-mesh query benchmark: Marbellous (brute, grid2d, bvh) against PyBullet, same meshes, same run.

Terrain meshes of about 10k, 131k and 1M triangles (a hilly grid, 0.5 m spacing); a marble of
radius 0.3 m resting 1 cm into the surface (every query finds contacts), at two kinds of places:
"random" (uniform over the level: every query misses the CPU caches) and "path" (a marble rolling
along a curve in 4 cm steps, 5 m/s at 120 Hz: what a game asks).

Measured per mesh and acceleration:
- build: constructing the ``TriangleMesh`` (validation, check, adjacency, acceleration), s;
- kernel: ``collide_convex_mesh`` called in a compiled loop over all queries, us per query;
- python: the same kernel called once per query from Python (argument unboxing included), us;
- PyBullet: ``resetBasePositionAndOrientation`` + ``getClosestPoints`` of a sphere body against a
  static ``GEOM_MESH`` body (its BVH), us per query (a Python call each), and its build time.

Prints a table and writes ``bench/results/<date>-<hostname>-mesh_query.json``.
Run: ``python bench/bench_mesh_query.py [--sizes 10k,131k,1m] [--queries N]``.
"""
import argparse
import datetime
import json
import os
import platform
import socket
import tempfile
import time

import numpy as np

from marbellous._numba.jit import njit
from marbellous.collision import shape_types as st
from marbellous.collision.mesh.mesh_collide import collide_convex_mesh
from marbellous.shapes.mesh import TriangleMesh

SIZES = {"10k": 71, "131k": 256, "1m": 708}      # quads per side: 2 n^2 triangles
SPACING = 0.5
RADIUS = 0.3


def terrain(n, seed=0):
    """A hilly grid terrain with 2 n^2 triangles (vertices (V, 3), triangles (T, 3))."""
    rng = np.random.default_rng(seed)
    xs, zs = np.meshgrid(np.arange(n + 1) * SPACING, np.arange(n + 1) * SPACING, indexing="ij")
    ys = 2.0 * np.sin(0.05 * xs) * np.cos(0.07 * zs) + 0.05 * rng.standard_normal(xs.shape)
    v = np.stack([xs.ravel(), ys.ravel(), zs.ravel()], axis=1)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (i * (n + 1) + j).ravel()
    b, c, d = a + 1, a + n + 1, a + n + 2
    t = np.concatenate([np.stack([a, b, c], 1), np.stack([c, b, d], 1)])
    return v, t


@njit
def query_loop(centres, params_a, pos_b, rot_b, params_b, geom_f, geom_i, out_f, out_i):
    """Every query in compiled code; returns the total number of contacts."""
    rot = np.eye(3)
    total = 0
    for q in range(centres.shape[0]):
        total += collide_convex_mesh(st.SPHERE, centres[q], rot, params_a, pos_b, rot_b, params_b, geom_f,
                                     geom_i, 0, 0, 0.0, out_f, out_i, 0)
    return total


def marble_positions(mesh, count, seed=1):
    """Centres resting 0.01 m into the surface at random x-z points (heights by ray cast)."""
    rng = np.random.default_rng(seed)
    lo, hi = mesh.local_aabb()
    out = np.empty((count, 3))
    k = 0
    while k < count:
        x, z = rng.uniform(lo[[0, 2]] + 1.0, hi[[0, 2]] - 1.0)
        hit = mesh.raycast((x, hi[1] + 1.0, z), (0.0, -1.0, 0.0))
        if hit is not None:
            out[k] = hit[1] + hit[2] * (RADIUS - 0.01)
            k += 1
    return out


def path_positions(mesh, count, step=0.04):
    """Centres along a closed curve across the level, ``step`` metres apart, resting 1 cm in."""
    lo, hi = mesh.local_aabb()
    mid = 0.5 * (lo + hi)
    half = 0.4 * (hi - lo)
    s = np.linspace(0.0, 2.0 * np.pi, 20001)
    xz = np.stack([mid[0] + half[0] * np.sin(3 * s), mid[2] + half[2] * np.sin(2 * s)], axis=1)
    arc = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(xz, axis=0), axis=1))]
    want = np.arange(count) * step % arc[-1]
    out = np.empty((count, 3))
    for k, a in enumerate(want):
        x, z = np.interp(a, arc, xz[:, 0]), np.interp(a, arc, xz[:, 1])
        hit = mesh.raycast((x, hi[1] + 1.0, z), (0.0, -1.0, 0.0))
        out[k] = hit[1] + hit[2] * (RADIUS - 0.01)
    return out


def time_kernel(mesh, centres):
    """Microseconds per query with the loop in compiled code, and contacts per query."""
    params_a = np.zeros(st.N_SHAPE_PARAMS)
    params_a[0] = RADIUS
    gf, gi = mesh._geometry()
    out_f = np.zeros((64, 7))
    out_i = np.zeros(64, np.int64)
    args = (params_a, np.zeros(3), np.eye(3), mesh._params(), gf, gi, out_f, out_i)
    query_loop(centres[:2], *args)     # compile / warm
    t0 = time.perf_counter()
    contacts = query_loop(centres, *args)
    return (time.perf_counter() - t0) / len(centres) * 1e6, contacts / len(centres)


def time_python(mesh, centres):
    """Microseconds per query, one Python call of the kernel each."""
    params_a = np.zeros(st.N_SHAPE_PARAMS)
    params_a[0] = RADIUS
    gf, gi = mesh._geometry()
    pb, rb, prm = np.zeros(3), np.eye(3), mesh._params()
    out_f = np.zeros((64, 7))
    out_i = np.zeros(64, np.int64)
    rot = np.eye(3)
    collide_convex_mesh(st.SPHERE, centres[0], rot, params_a, pb, rb, prm, gf, gi, 0, 0, 0.0, out_f, out_i, 0)
    t0 = time.perf_counter()
    for c in centres:
        collide_convex_mesh(st.SPHERE, c, rot, params_a, pb, rb, prm, gf, gi, 0, 0, 0.0, out_f, out_i, 0)
    return (time.perf_counter() - t0) / len(centres) * 1e6


def time_pybullet(v, t, scenarios):
    try:
        import pybullet as p
    except ImportError:
        return None
    cid = p.connect(p.DIRECT)
    try:
        t0 = time.perf_counter()
        try:
            shape = p.createCollisionShape(p.GEOM_MESH, vertices=v.tolist(), indices=t.ravel().tolist(),
                                           physicsClientId=cid)
            how = "vertices"
        except p.error:
            shape = -1
        if shape < 0:               # too many vertices for the in-memory path: go through an OBJ file
            with tempfile.TemporaryDirectory() as tmp:
                path = os.path.join(tmp, "terrain.obj")
                with open(path, "w") as fh:
                    np.savetxt(fh, v, fmt="v %.9g %.9g %.9g")
                    np.savetxt(fh, t + 1, fmt="f %d %d %d")
                t0 = time.perf_counter()
                shape = p.createCollisionShape(p.GEOM_MESH, fileName=path, flags=p.GEOM_FORCE_CONCAVE_TRIMESH,
                                               physicsClientId=cid)
            how = "obj file"
        ground = p.createMultiBody(0, shape, physicsClientId=cid)
        build = time.perf_counter() - t0
        ball_shape = p.createCollisionShape(p.GEOM_SPHERE, radius=RADIUS, physicsClientId=cid)
        ball = p.createMultiBody(1.0, ball_shape, physicsClientId=cid)
        result = {"build_s": build, "mesh_input": how}
        for name, centres in scenarios.items():
            found = 0
            pos = centres.tolist()
            t0 = time.perf_counter()
            for c in pos:
                p.resetBasePositionAndOrientation(ball, c, (0, 0, 0, 1), physicsClientId=cid)
                found += len(p.getClosestPoints(ball, ground, 0.0, physicsClientId=cid))
            result[name + "_us"] = (time.perf_counter() - t0) / len(pos) * 1e6
            result[name + "_contacts"] = found / len(pos)
        return result
    finally:
        p.disconnect(cid)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="10k,131k,1m")
    ap.add_argument("--queries", type=int, default=100_000)
    args = ap.parse_args()
    rows = []
    n_py = min(args.queries, 20_000)
    for name in args.sizes.split(","):
        v, t = terrain(SIZES[name])
        scenarios = None
        for accel in ("grid2d", "bvh", "brute"):
            t0 = time.perf_counter()
            mesh = TriangleMesh(v, t, accel=accel)
            build = time.perf_counter() - t0
            if scenarios is None:
                scenarios = {"random": marble_positions(mesh, args.queries),
                             "path": path_positions(mesh, args.queries)}
            # brute force tests every triangle: a few hundred queries are plenty
            n = args.queries if accel != "brute" else max(50, min(args.queries, 2_000_000 // len(t)))
            row = {"mesh": name, "triangles": int(len(t)), "engine": "marbellous", "accel": accel,
                   "build_s": build, "queries": n}
            for scen, centres in scenarios.items():
                row[scen + "_kernel_us"], row[scen + "_contacts"] = time_kernel(mesh, centres[:n])
            row["random_python_us"] = time_python(mesh, scenarios["random"][:min(n, n_py)])
            rows.append(row)
            print(f"{name:>5} {len(t):>8} marbellous {accel:<7} build {build:7.2f} s  kernel random "
                  f"{row['random_kernel_us']:9.3f} us  path {row['path_kernel_us']:9.3f} us  python "
                  f"{row['random_python_us']:9.3f} us  contacts/query {row['random_contacts']:.2f}", flush=True)
        pb = time_pybullet(v, t, {k: c[:n_py] for k, c in scenarios.items()})
        if pb is not None:
            row = {"mesh": name, "triangles": int(len(t)), "engine": "pybullet", "accel": "bvh",
                   "build_s": pb["build_s"], "queries": n_py, "mesh_input": pb["mesh_input"],
                   "random_python_us": pb["random_us"], "path_python_us": pb["path_us"],
                   "random_contacts": pb["random_contacts"], "path_contacts": pb["path_contacts"]}
            rows.append(row)
            print(f"{name:>5} {len(t):>8} pybullet   bvh     build {pb['build_s']:7.2f} s  python random "
                  f"{pb['random_us']:9.3f} us  path {pb['path_us']:9.3f} us", flush=True)
    print()
    print("us per sphere query (kernel: loop in compiled code; python: one Python call per query)")
    print(f"{'mesh':>5} {'triangles':>9} {'engine':<11}{'accel':<7}{'build s':>9}{'kernel rnd':>11}"
          f"{'kernel path':>12}{'python rnd':>11}{'python path':>12}")
    for r in rows:
        cells = [r.get(k) for k in ("random_kernel_us", "path_kernel_us", "random_python_us", "path_python_us")]
        text = [f"{c:.3f}" if c is not None else "-" for c in cells]
        print(f"{r['mesh']:>5} {r['triangles']:>9} {r['engine']:<11}{r['accel']:<7}{r['build_s']:>9.2f}"
              f"{text[0]:>11}{text[1]:>12}{text[2]:>11}{text[3]:>12}")
    host = socket.gethostname()
    date = datetime.date.today().isoformat()
    out_dir = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, f"{date}-{host}-mesh_query.json")
    machine = {"host": host, "platform": platform.platform(), "processor": platform.processor(),
               "python": platform.python_version(), "cpus": os.cpu_count()}
    with open(path, "w") as fh:
        json.dump({"benchmark": "mesh_query", "machine": machine, "radius": RADIUS, "rows": rows}, fh, indent=1)
    print(f"\nwrote {path}")


if __name__ == "__main__":
    main()
