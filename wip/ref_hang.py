import sys, numpy as np, numba
from marbellous.cloth import cloth_grid
n=int(sys.argv[1]); k=float(sys.argv[2]); sub=int(sys.argv[3])
v, t = cloth_grid(1.0, 1.0, n, n)
e = np.unique(np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1), axis=0)
L0 = np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1)
x = v + [0, 1.1, 0]; vel = np.zeros_like(x); w = np.full(n*n, n*n/0.5); w[[0,(n-1)*n]] = 0
@numba.njit
def run(x, vel, w, e, L0, k, sub, steps):
    h = 1/60/sub
    for s in range(steps*sub):
        prev = x.copy()
        for p in range(x.shape[0]):
            if w[p] > 0:
                vel[p,1] -= 9.81*h
                x[p] += h*vel[p]
        for j in range(e.shape[0]):
            a,b = e[j,0], e[j,1]
            d = x[a]-x[b]; l = np.sqrt((d*d).sum())
            den = w[a]+w[b]+1/(k*h*h)
            if den == 0 or l < 1e-12: continue
            dl = -(l-L0[j])/den
            x[a] += w[a]*dl*d/l; x[b] -= w[b]*dl*d/l
        for p in range(x.shape[0]):
            vel[p] = (x[p]-prev[p])/h
run(x, vel, w, e, L0, k, sub, 300)
L = np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1)
print("ref", n, k, sub, "strain max %.3f mean %.4f speed %.3g" % ((L/L0-1).max(), (L/L0-1).mean(), np.linalg.norm(vel,axis=1).max()))
