"""``NUMBA_DISABLE_JIT=1`` runs every kernel as plain Python (for debugging a kernel with pdb): the step's
record becomes a namespace, borrowed arrays and record addresses become the objects themselves, and the
physics is the same arithmetic, so the bodies end bit for bit where the compiled step puts them."""
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


def run(disable_jit):
    env = dict(os.environ)
    env["NUMBA_DISABLE_JIT"] = "1" if disable_jit else "0"
    r = subprocess.run([sys.executable, "-c", SCENE], capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_plain_python_kernels_give_the_compiled_result():
    assert run(True) == run(False)
