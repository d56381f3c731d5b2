"""Linear tetrahedral finite elements with the rotation removed per element (corotated linear elasticity).

An element has four corners ``x_0 .. x_3`` (rest places ``X_0 .. X_3``) and linear shape functions ``N_i``
with constant gradients ``g_i`` (1/m): ``g_1, g_2, g_3`` are the rows of ``Dm^-1``,
``Dm = [X_1 - X_0, X_2 - X_0, X_3 - X_0]``, and ``g_0 = -(g_1 + g_2 + g_3)``.  For values ``w_j`` at the
corners, ``sum_j w_j g_j^T = Dw Dm^-1`` with ``Dw = [w_1 - w_0, w_2 - w_0, w_3 - w_0]``: the positions give
the deformation gradient ``F``.  ``R``, the rotation of ``F``'s polar decomposition ``F = R S``, is found by
Mueller et al.'s iteration (2016, "A robust method to extract the rotational part of deformations"), started
from the element's last rotation.  In the element's rest frame the displacement gradient is
``H = R^T F - I``, the small strain ``eps = (H + H^T) / 2`` and Hooke's law with the Lame parameters gives

    sigma = lambda tr(eps) I + 2 mu eps
    f_i   = -V R sigma g_i                 (the force on corner i: minus the gradient of the element's energy
                                            V (mu eps:eps + lambda tr(eps)^2 / 2))

Held at this ``R``, the forces are linear in the corners' places, with the stiffness ``K = R K_0 R^T``: for
values ``w`` at the corners ``(K w)_i = V R sigma(R^T sum_j w_j g_j^T) g_i``, and the diagonal 3 x 3 block
of corner ``i`` is ``V ((lambda + mu) (R g_i)(R g_i)^T + mu |g_i|^2 I)``.
"""
from .._numba.jit import njit
from ..math3d import quat_step, quat_to_matrix
from .particle_layout import S_DM_INV, S_LAMBDA, S_MU, S_NODES, S_QUAT, S_VOLUME

#: most iterations of the rotation search per element and step (it starts from the last step's rotation and
#: stops when the remaining misalignment is below 1e-12 rad, in one or two iterations for a body at rest; a
#: 0.1 rad turn within a step takes about ten)
ROTATION_ITERATIONS = 20


@njit
def deformation_gradient(pos, tf, ti, e, out):
    """``out`` (3 x 3) = ``F = Ds Dm^-1`` of element ``e`` at the places ``pos`` (rows: particle rows)."""
    a = ti[e, S_NODES]
    for r in range(3):
        d1 = pos[ti[e, S_NODES + 1], r] - pos[a, r]
        d2 = pos[ti[e, S_NODES + 2], r] - pos[a, r]
        d3 = pos[ti[e, S_NODES + 3], r] - pos[a, r]
        for c in range(3):
            out[r, c] = d1 * tf[e, S_DM_INV + c] + d2 * tf[e, S_DM_INV + 3 + c] + d3 * tf[e, S_DM_INV + 6 + c]


@njit
def update_rotation(tf, e, f, scratch, rot):
    """Turn element ``e``'s rotation (``S_QUAT``) towards the rotation of the deformation gradient ``f`` and
    write it, row-major, into row ``e`` of ``rot`` (elements, 9): each iteration rotates by
    ``omega = sum_k r_k x f_k / (|sum_k r_k . f_k| + 1e-9)`` (``r_k``, ``f_k`` the columns).  ``scratch``:
    3 x 3."""
    q = tf[e, S_QUAT:S_QUAT + 4]
    for _ in range(ROTATION_ITERATIONS):
        quat_to_matrix(q, scratch)
        ox = oy = oz = 0.0
        along = 0.0
        for k in range(3):
            ox += scratch[1, k] * f[2, k] - scratch[2, k] * f[1, k]
            oy += scratch[2, k] * f[0, k] - scratch[0, k] * f[2, k]
            oz += scratch[0, k] * f[1, k] - scratch[1, k] * f[0, k]
            along += scratch[0, k] * f[0, k] + scratch[1, k] * f[1, k] + scratch[2, k] * f[2, k]
        scale = 1.0 / (abs(along) + 1e-9)
        ox, oy, oz = ox * scale, oy * scale, oz * scale
        if ox * ox + oy * oy + oz * oz < 1e-24:
            break
        q[0], q[1], q[2], q[3] = quat_step(q, (ox, oy, oz), 1.0)
    quat_to_matrix(q, scratch)
    for r in range(3):
        for c in range(3):
            rot[e, 3 * r + c] = scratch[r, c]


@njit
def add_element_forces(w, tf, ti, e, rot, strain_only, scale, out):
    """``out_i += scale V R sigma(H) g_i`` for the four corners of element ``e``, where
    ``H = R^T sum_j w_j g_j^T`` for the values ``w`` at the corners (rows: particle rows), less the identity
    when ``strain_only``: with ``w`` the velocities (or any field) these are ``scale (K w)_i``; with ``w`` the
    places, ``strain_only`` and ``scale = -1``, the elastic forces ``f_i`` (module docstring).  ``rot``:
    the elements' rotations, row-major (elements, 9)."""
    a, b, c, d = ti[e, S_NODES], ti[e, S_NODES + 1], ti[e, S_NODES + 2], ti[e, S_NODES + 3]
    g10, g11, g12 = tf[e, S_DM_INV], tf[e, S_DM_INV + 1], tf[e, S_DM_INV + 2]
    g20, g21, g22 = tf[e, S_DM_INV + 3], tf[e, S_DM_INV + 4], tf[e, S_DM_INV + 5]
    g30, g31, g32 = tf[e, S_DM_INV + 6], tf[e, S_DM_INV + 7], tf[e, S_DM_INV + 8]
    r00, r01, r02 = rot[e, 0], rot[e, 1], rot[e, 2]
    r10, r11, r12 = rot[e, 3], rot[e, 4], rot[e, 5]
    r20, r21, r22 = rot[e, 6], rot[e, 7], rot[e, 8]
    # the world gradient G = sum_j w_j g_j^T (row k: component k of w), then H = R^T G
    h00 = h01 = h02 = h10 = h11 = h12 = h20 = h21 = h22 = 0.0
    for k in range(3):
        d1, d2, d3 = w[b, k] - w[a, k], w[c, k] - w[a, k], w[d, k] - w[a, k]
        gk0 = d1 * g10 + d2 * g20 + d3 * g30
        gk1 = d1 * g11 + d2 * g21 + d3 * g31
        gk2 = d1 * g12 + d2 * g22 + d3 * g32
        rk0, rk1, rk2 = rot[e, 3 * k], rot[e, 3 * k + 1], rot[e, 3 * k + 2]
        h00 += rk0 * gk0
        h01 += rk0 * gk1
        h02 += rk0 * gk2
        h10 += rk1 * gk0
        h11 += rk1 * gk1
        h12 += rk1 * gk2
        h20 += rk2 * gk0
        h21 += rk2 * gk1
        h22 += rk2 * gk2
    if strain_only:
        h00 -= 1.0
        h11 -= 1.0
        h22 -= 1.0
    # sigma = lambda tr(eps) I + 2 mu eps, eps = (H + H^T) / 2
    lam, mu = tf[e, S_LAMBDA], tf[e, S_MU]
    trace = lam * (h00 + h11 + h22)
    s00, s11, s22 = 2.0 * mu * h00 + trace, 2.0 * mu * h11 + trace, 2.0 * mu * h22 + trace
    s01, s02, s12 = mu * (h01 + h10), mu * (h02 + h20), mu * (h12 + h21)
    # P = scale V R sigma, then f_i = P g_i for corners 1..3 and corner 0 the negative sum
    v = scale * tf[e, S_VOLUME]
    p00, p01, p02 = v * (r00 * s00 + r01 * s01 + r02 * s02), v * (r00 * s01 + r01 * s11 + r02 * s12), \
        v * (r00 * s02 + r01 * s12 + r02 * s22)
    p10, p11, p12 = v * (r10 * s00 + r11 * s01 + r12 * s02), v * (r10 * s01 + r11 * s11 + r12 * s12), \
        v * (r10 * s02 + r11 * s12 + r12 * s22)
    p20, p21, p22 = v * (r20 * s00 + r21 * s01 + r22 * s02), v * (r20 * s01 + r21 * s11 + r22 * s12), \
        v * (r20 * s02 + r21 * s12 + r22 * s22)
    f1x = p00 * g10 + p01 * g11 + p02 * g12
    f1y = p10 * g10 + p11 * g11 + p12 * g12
    f1z = p20 * g10 + p21 * g11 + p22 * g12
    f2x = p00 * g20 + p01 * g21 + p02 * g22
    f2y = p10 * g20 + p11 * g21 + p12 * g22
    f2z = p20 * g20 + p21 * g21 + p22 * g22
    f3x = p00 * g30 + p01 * g31 + p02 * g32
    f3y = p10 * g30 + p11 * g31 + p12 * g32
    f3z = p20 * g30 + p21 * g31 + p22 * g32
    out[b, 0] += f1x
    out[b, 1] += f1y
    out[b, 2] += f1z
    out[c, 0] += f2x
    out[c, 1] += f2y
    out[c, 2] += f2z
    out[d, 0] += f3x
    out[d, 1] += f3y
    out[d, 2] += f3z
    out[a, 0] -= f1x + f2x + f3x
    out[a, 1] -= f1y + f2y + f3y
    out[a, 2] -= f1z + f2z + f3z


@njit
def add_stiffness_diagonal(tf, ti, e, rot, scale, out):
    """``out_i += scale diag(K_ii)`` for the four corners of element ``e`` (module docstring; ``rot`` as in
    :func:`add_element_forces`)."""
    lam, mu, volume = tf[e, S_LAMBDA], tf[e, S_MU], tf[e, S_VOLUME]
    g0x = g0y = g0z = 0.0
    for i in range(4):
        if i < 3:
            gx, gy, gz = tf[e, S_DM_INV + 3 * i], tf[e, S_DM_INV + 3 * i + 1], tf[e, S_DM_INV + 3 * i + 2]
            g0x -= gx
            g0y -= gy
            g0z -= gz
            p = ti[e, S_NODES + 1 + i]
        else:
            gx, gy, gz = g0x, g0y, g0z
            p = ti[e, S_NODES]
        g2 = gx * gx + gy * gy + gz * gz
        for r in range(3):
            rg = rot[e, 3 * r] * gx + rot[e, 3 * r + 1] * gy + rot[e, 3 * r + 2] * gz
            out[p, r] += scale * volume * ((lam + mu) * rg * rg + mu * g2)
