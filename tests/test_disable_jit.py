"""``NUMBA_DISABLE_JIT=1`` runs every kernel as plain Python (for debugging a kernel with pdb): the step's
record becomes a namespace, borrowed arrays and record addresses become the objects themselves, wide
floats become NumPy arrays, and the physics is the same arithmetic, so the bodies end bit for bit where
the compiled step puts them."""
import json
import os
import subprocess
import sys

SCENE = """
import json, marbellous as mb
w = mb.World()
w.add_static(mb.Plane())
s = w.add_body(mb.Sphere(0.3), position=(0.0, 0.5, 0.0), velocity=(1.0, 0.0, 0.2))
b = w.add_body(mb.Box((0.2, 0.1, 0.3)), position=(0.6, 0.4, 0.1), angular_velocity=(0.5, 1.0, 0.0))
for _ in range(40):
    w.step(1 / 60)
print(json.dumps([list(map(float, s.position)), list(map(float, b.position)), list(map(float, b.orientation))]))
"""


# a 6 x 6 layer of touching spheres and two flat boxes: enough contacts for the wide solver's bundles
LAYER = """
import json, marbellous as mb
from marbellous.dynamics.contact_bundles import MIN_BUNDLED_CONTACTS
w = mb.World()
w.add_static(mb.Plane())
balls = [w.add_body(mb.Sphere(0.5), position=(1.0 * i, 0.5, 1.0 * j)) for i in range(6) for j in range(6)]
slabs = [w.add_body(mb.Box((0.6, 0.15, 0.4)), position=(1.5 + 2 * k, 1.17, 2.5), angular_velocity=(0.3, 0.0, 0.2))
         for k in range(2)]
for _ in range(6):
    w.step(1 / 60)
assert w._state.n_cached > MIN_BUNDLED_CONTACTS    # (so the contact table grew, and the step had its bundle tables)
print(json.dumps([list(map(float, b.position)) + list(map(float, b.velocity)) for b in balls + slabs]))
"""


def run(disable_jit, scene=SCENE):
    env = dict(os.environ)
    env["NUMBA_DISABLE_JIT"] = "1" if disable_jit else "0"
    r = subprocess.run([sys.executable, "-c", scene], capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_plain_python_kernels_give_the_compiled_result():
    assert run(True) == run(False)


def test_plain_python_bundles_give_the_compiled_result():
    assert run(True, LAYER) == run(False, LAYER)
