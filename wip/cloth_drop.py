import sys, numpy as np, marbellous as mb
from marbellous.cloth import cloth_grid
n=int(sys.argv[1]); sub=int(sys.argv[2])
w = mb.World(gravity=(0, -9.81, 0)); w.particle_substeps=sub
w.add_static(mb.Plane((0, 1, 0), 0.0))
w.add_static(mb.Sphere(0.3), position=(0, 0.3, 0))
v, t = cloth_grid(1.0, 1.0, n, n)
c = w.add_cloth(v, t, mass=0.5, position=(0, 1.1, 0), friction=float(sys.argv[3]))
e = np.unique(np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1), axis=0)
L0 = np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1)
for k in range(40):
    w.step(1/60)
    x = c.positions; vel=c.velocities
    L = np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1)
    if k>15: print(k, "strain %.3g speed %.3g inside %.3g" % ((L/L0-1).max(), np.linalg.norm(vel,axis=1).max(), (0.3 - np.linalg.norm(x - [0, 0.3, 0], axis=1)).max()))
    if not np.all(np.abs(x)<10): break
