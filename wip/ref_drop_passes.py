import sys, numpy as np, numba
from marbellous.cloth import cloth_grid
n=int(sys.argv[1]); k=float(sys.argv[2]); sub=int(sys.argv[3]); PASSES=int(sys.argv[4])
v, t = cloth_grid(1.0, 1.0, n, n)
e = np.unique(np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1), axis=0)
L0 = np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1)
x = v + [0, 1.1, 0]; vel = np.zeros_like(x); w = np.full(n*n, n*n/0.5)
# per-edge k as in the cloth: axis edges k, diagonals k/2 (A/L^2)
kk = np.where(L0 > 1.2/(n-1), k/2, k)
@numba.njit
def run(x, vel, w, e, L0, kk, sub, steps, out, PASSES):
    h = 1/60/sub
    c = np.array([0.0, 0.3, 0.0]); R = 0.305
    for s in range(steps*sub):
        prev = x.copy()
        for p in range(x.shape[0]):
            vel[p,1] -= 9.81*h
            x[p] += h*vel[p]
        for it in range(PASSES):
         for j in range(e.shape[0]):
             a,b = e[j,0], e[j,1]
             d = x[a]-x[b]; l = np.sqrt((d*d).sum())
             den = w[a]+w[b]+1/(kk[j]*h*h)
             dl = -(l-L0[j])/den
             x[a] += w[a]*dl*d/l; x[b] -= w[b]*dl*d/l
        for p in range(x.shape[0]):
            r = x[p]-c; rl = np.sqrt((r*r).sum())
            if rl < R: x[p] = c + r/rl*R
            if x[p,1] < 0.005: x[p,1] = 0.005
        for p in range(x.shape[0]):
            vel[p] = (x[p]-prev[p])/h
        if s % sub == sub-1:
            out[s//sub] = np.sqrt((vel*vel).sum(1)).max()
out = np.zeros(60)
run(x, vel, w, e, L0, kk, sub, 60, out, PASSES)
print("ref drop", n, k, sub, "speeds", np.round(out[16:40:2],1))
