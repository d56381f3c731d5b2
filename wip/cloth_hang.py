import sys, numpy as np, marbellous as mb
from marbellous.cloth import cloth_grid
n=int(sys.argv[1]); k=float(sys.argv[2]); sub=int(sys.argv[3])
w = mb.World(gravity=(0, -9.81, 0)); w.particle_substeps=sub
v, t = cloth_grid(1.0, 1.0, n, n)
c = w.add_cloth(v, t, mass=0.5, position=(0, 1.1, 0), stretch_stiffness=k, self_collision=False, bend_stiffness=float(sys.argv[4]))
c.pin([0, (n-1)*n])
e = np.unique(np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1), axis=0)
L0 = np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1)
for s in range(300):
    w.step(1/60)
    x=c.positions
    if not np.all(np.abs(x)<10): print("blew", s); break
L = np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1)
print(n,k,sub,"strain max %.3f mean %.4f speed %.3g" % ((L/L0-1).max(), (L/L0-1).mean(), np.linalg.norm(c.velocities,axis=1).max()))
