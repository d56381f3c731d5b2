import sys, time, numpy as np, marbellous as mb
from marbellous.cloth import cloth_grid
n=int(sys.argv[1]); selfc=sys.argv[2]=="1"
w = mb.World(gravity=(0, -9.81, 0))
v, t = cloth_grid(1.0, 1.0, n, n)
w.add_static(mb.Plane((0, 1, 0), 0.0)); w.add_static(mb.Sphere(0.3), position=(0, 0.3, 0)); c = w.add_cloth(v, t, mass=0.5, position=(0, 1.1, 0), self_collision=selfc)

w.step(1/60)
t0=time.time()
for s in range(40): w.step(1/60)
print(n, selfc, "ms/step %.1f" % ((time.time()-t0)/40*1000))
