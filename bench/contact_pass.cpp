// The solver limit for one velocity pass of sequential impulses over contact bundles: Marbellous'
// ``contact_bundles.solve_bundles`` written again in C++ with GCC's vector extensions (8 doubles a value,
// one AVX-512 register), compiled with -O3 -march=native, on the very tables the engine solves (``wide_f``,
// ``wide_i``, the solver bodies ``sb``).  The arithmetic is the engine's, term for term and in the same order
// (no fused multiply-add: -ffp-contract=off), so one pass gives bit for bit what the engine's pass gives;
// ``bench/bench_contact_pass.py`` checks that before it times the two.
//
// Per contact (normal n, tangents t1, t2, offsets ra, rb):
//     dv = (v_b + w_b x rb) - (v_a + w_a x ra)
//     lambda_n := max(lambda_n - m_n s_m (dv.n + bias) - s_i lambda_n, 0)        (soft or speculative bias)
//     (lambda_1, lambda_2) := clamp((lambda_1, lambda_2) - (m_1 dv.t1, m_2 dv.t2), mu lambda_n)   (Coulomb disc)
//     lambda_r := clamp_rolling(lambda_r - K^-1 (w_b - w_a)),  K = I_a^-1 + I_b^-1   (rolling, torsion)
// each change applied to both bodies at once: v += +-p / m, w += +-I^-1 (r x p).
//
// The layout's constants (field offsets, LANES, SB_COLS, ...) come from marbellous.state.layout as -D
// definitions at compile time.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

// The kernel is written once for the scalar type T (double: the engine's; float: single precision, as the
// wide solvers of Box2D v3 and Jolt use); ``v8`` is LANES values of T.  The functions are static members of
// ``Pass<T>``.
#define INLINE static inline __attribute__((always_inline))

template <typename T> struct Pass {
typedef T v8 __attribute__((vector_size(LANES * sizeof(T))));

INLINE v8 splat(T x) {
    v8 r;
    for (int l = 0; l < LANES; ++l) r[l] = x;
    return r;
}
INLINE v8 load(const T *p) { v8 r; std::memcpy(&r, p, sizeof r); return r; }
INLINE void store(T *p, v8 v) { std::memcpy(p, &v, sizeof v); }
// lane-wise x if a > b else y; max and min as Python's: b if b > a else a, b if b < a else a
INLINE v8 where_gt(v8 a, v8 b, v8 x, v8 y) { return a > b ? x : y; }
INLINE v8 vmax(v8 a, v8 b) { return b > a ? b : a; }
INLINE v8 vmin(v8 a, v8 b) { return b < a ? b : a; }
INLINE v8 vabs(v8 a) { v8 r; for (int l = 0; l < LANES; ++l) r[l] = std::fabs(a[l]); return r; }
INLINE v8 vsqrt(v8 a) { v8 r; for (int l = 0; l < LANES; ++l) r[l] = std::sqrt(a[l]); return r; }

struct V3 { v8 x, y, z; };
struct U8 { v8 u[8]; };          // (v, omega) of each lane's body, and the two columns after them
struct I9 { v8 m[9]; };          // row-major world inverse inertia of each lane's body

INLINE T *at(T *wide_f, int64_t bundle, int field) {
    return wide_f + (bundle * BUNDLE_FIELDS + field) * LANES;
}
INLINE V3 vec(T *wide_f, int64_t bundle, int field) {
    return {load(at(wide_f, bundle, field)), load(at(wide_f, bundle, field + 1)), load(at(wide_f, bundle, field + 2))};
}
INLINE v8 dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// Each lane's row is read as one vector of 8 values (v, omega and the next two columns, carried unchanged
// and written back as they were) and the 8 x 8 block transposed with shuffles, as the engine's gather_w and
// scatter_w do; the transposition is its own inverse.
typedef typename std::conditional<sizeof(T) == 8, int64_t, int32_t>::type Index;
typedef Index m8 __attribute__((vector_size(LANES * sizeof(T))));

INLINE void transpose(v8 *r) {
    static_assert(LANES == 8, "the transposition is written for 8 lanes");
    v8 t[8], s[8];
    for (int i = 0; i < 8; i += 2) {
        t[i] = __builtin_shuffle(r[i], r[i + 1], m8{0, 8, 2, 10, 4, 12, 6, 14});
        t[i + 1] = __builtin_shuffle(r[i], r[i + 1], m8{1, 9, 3, 11, 5, 13, 7, 15});
    }
    const int firsts[4] = {0, 1, 4, 5};
    for (int i : firsts) {
        s[i] = __builtin_shuffle(t[i], t[i + 2], m8{0, 1, 8, 9, 4, 5, 12, 13});
        s[i + 2] = __builtin_shuffle(t[i], t[i + 2], m8{2, 3, 10, 11, 6, 7, 14, 15});
    }
    for (int i = 0; i < 4; ++i) {
        r[i] = __builtin_shuffle(s[i], s[i + 4], m8{0, 1, 2, 3, 8, 9, 10, 11});
        r[i + 4] = __builtin_shuffle(s[i], s[i + 4], m8{4, 5, 6, 7, 12, 13, 14, 15});
    }
}
INLINE U8 gather_u(const T *sb, const int64_t *rows) {
    U8 r;
    for (int l = 0; l < LANES; ++l) r.u[l] = load(sb + rows[l] * SB_COLS + SB_V);
    transpose(r.u);
    return r;
}
INLINE void scatter_u(T *sb, const int64_t *rows, U8 u) {
    transpose(u.u);
    for (int l = 0; l < LANES; ++l) store(sb + rows[l] * SB_COLS + SB_V, u.u[l]);
}

// (v_b + w_b x rb) - (v_a + w_a x ra)
INLINE V3 relative_velocity(const U8 &a, V3 ra, const U8 &b, V3 rb) {
    return {(b.u[0] + b.u[4] * rb.z - b.u[5] * rb.y) - (a.u[0] + a.u[4] * ra.z - a.u[5] * ra.y),
            (b.u[1] + b.u[5] * rb.x - b.u[3] * rb.z) - (a.u[1] + a.u[5] * ra.x - a.u[3] * ra.z),
            (b.u[2] + b.u[3] * rb.y - b.u[4] * rb.x) - (a.u[2] + a.u[3] * ra.y - a.u[4] * ra.x)};
}

// u after the impulse sign p at offset r:  v += sign p / m,  omega += sign I^-1 (r x p)
INLINE U8 push(const U8 &u, v8 inv_mass, const I9 &inv_i, V3 r, V3 p, T sign, bool turning) {
    v8 cx = r.y * p.z - r.z * p.y, cy = r.z * p.x - r.x * p.z, cz = r.x * p.y - r.y * p.x;
    v8 im = inv_mass * sign;
    U8 o;
    o.u[0] = u.u[0] + im * p.x;
    o.u[1] = u.u[1] + im * p.y;
    o.u[2] = u.u[2] + im * p.z;
    if (!turning) {
        v8 s = inv_i.m[0] * sign;
        o.u[3] = u.u[3] + s * cx;
        o.u[4] = u.u[4] + s * cy;
        o.u[5] = u.u[5] + s * cz;
    } else {
        o.u[3] = u.u[3] + (inv_i.m[0] * cx + inv_i.m[1] * cy + inv_i.m[2] * cz) * sign;
        o.u[4] = u.u[4] + (inv_i.m[3] * cx + inv_i.m[4] * cy + inv_i.m[5] * cz) * sign;
        o.u[5] = u.u[5] + (inv_i.m[6] * cx + inv_i.m[7] * cy + inv_i.m[8] * cz) * sign;
    }
    return o;
}

// omega += sign I^-1 l
INLINE U8 twist(const U8 &u, const I9 &i, V3 l, T sign) {
    U8 o = u;
    o.u[3] = u.u[3] + sign * (i.m[0] * l.x + i.m[1] * l.y + i.m[2] * l.z);
    o.u[4] = u.u[4] + sign * (i.m[3] * l.x + i.m[4] * l.y + i.m[5] * l.z);
    o.u[5] = u.u[5] + sign * (i.m[6] * l.x + i.m[7] * l.y + i.m[8] * l.z);
    return o;
}

// Unless turning, every lane's inverse inertia is s E and only the first block is read.
INLINE I9 inertia(T *wide_f, int64_t bundle, int field, bool turning) {
    I9 r;
    r.m[0] = load(at(wide_f, bundle, field));
    if (!turning) {
        v8 zero = splat(0.0);
        r.m[1] = r.m[2] = r.m[3] = r.m[5] = r.m[6] = r.m[7] = zero;
        r.m[4] = r.m[8] = r.m[0];
        return r;
    }
    for (int k = 1; k < 9; ++k) r.m[k] = load(at(wide_f, bundle, field + k));
    return r;
}

// Rolling and torsional friction: lambda_r := lambda_r - K^-1 (w_b - w_a), K^-1 = adj(K) / det K,
// then its part across n clamped to rho lambda_n and its part along n to tau lambda_n.
static void solve_rolling(T *wide_f, int64_t bundle, U8 &ua, const I9 &ia, U8 &ub, const I9 &ib,
                          v8 normal_impulse) {
    v8 zero = splat(0.0);
    const v8 *a = ia.m, *b = ib.m;
    v8 k0 = a[0] + b[0], k1 = a[1] + b[1], k2 = a[2] + b[2];
    v8 k3 = a[3] + b[3], k4 = a[4] + b[4], k5 = a[5] + b[5];
    v8 k6 = a[6] + b[6], k7 = a[7] + b[7], k8 = a[8] + b[8];
    v8 c0 = k4 * k8 - k5 * k7, c1 = k5 * k6 - k3 * k8, c2 = k3 * k7 - k4 * k6;
    v8 c3 = k2 * k7 - k1 * k8, c4 = k0 * k8 - k2 * k6, c5 = k1 * k6 - k0 * k7;
    v8 c6 = k1 * k5 - k2 * k4, c7 = k2 * k3 - k0 * k5, c8 = k0 * k4 - k1 * k3;
    v8 det = k0 * c0 + k1 * c1 + k2 * c2;
    V3 old = vec(wide_f, bundle, WB_LAMBDA_R), n = vec(wide_f, bundle, WB_NORMAL);
    V3 w = {ub.u[3] - ua.u[3], ub.u[4] - ua.u[4], ub.u[5] - ua.u[5]};
    v8 r0 = old.x - (c0 * w.x + c3 * w.y + c6 * w.z) / det;
    v8 r1 = old.y - (c1 * w.x + c4 * w.y + c7 * w.z) / det;
    v8 r2 = old.z - (c2 * w.x + c5 * w.y + c8 * w.z) / det;
    v8 spin = r0 * n.x + r1 * n.y + r2 * n.z;
    V3 across = {r0 - spin * n.x, r1 - spin * n.y, r2 - spin * n.z};
    v8 roll = load(at(wide_f, bundle, WB_ROLL)), torsion = load(at(wide_f, bundle, WB_TORSION));
    v8 rolling_bound = roll * normal_impulse, torsion_bound = torsion * normal_impulse;
    v8 length = vsqrt(dot(across, across));
    v8 scale = where_gt(length, rolling_bound, rolling_bound / length, splat(1.0));
    spin = vmin(vmax(spin, -torsion_bound), torsion_bound);
    v8 solved = where_gt(det, zero, vmax(roll, torsion), zero);
    V3 next = {where_gt(solved, zero, across.x * scale + spin * n.x, old.x),
               where_gt(solved, zero, across.y * scale + spin * n.y, old.y),
               where_gt(solved, zero, across.z * scale + spin * n.z, old.z)};
    store(at(wide_f, bundle, WB_LAMBDA_R), next.x);
    store(at(wide_f, bundle, WB_LAMBDA_R + 1), next.y);
    store(at(wide_f, bundle, WB_LAMBDA_R + 2), next.z);
    V3 change = {next.x - old.x, next.y - old.y, next.z - old.z};
    ua = twist(ua, ia, change, -1.0);
    ub = twist(ub, ib, change, 1.0);
}

// One pass over the bundles first..last (soft = bias_rate, mass_scale, impulse_scale, max_bias); returns
// the largest velocity change (m/s).
static T solve_pass(T *wide_f, const int64_t *wide_i, int64_t first, int64_t last, T *sb, T h,
                         const T *soft) {
    v8 zero = splat(0.0), one = splat(1.0);
    T bias_rate = soft[0];
    v8 twice_max_bias = splat(2.0 * soft[3]);
    v8 touching_mass = splat(soft[1]), touching_impulse = splat(soft[2]);
    v8 largest = zero;
    for (int64_t bundle = first; bundle < last; ++bundle) {
        const int64_t *rows = wide_i + bundle * BUNDLE_ROWS * LANES;
        U8 ua = gather_u(sb, rows + WI_READ_A * LANES), ub = gather_u(sb, rows + WI_READ_B * LANES);
        v8 ima = load(at(wide_f, bundle, WB_INV_MASS_A)), imb = load(at(wide_f, bundle, WB_INV_MASS_B));
        bool turning = rows[WI_TURNING * LANES] != 0;
        I9 ia = inertia(wide_f, bundle, WB_INV_I_A, turning), ib = inertia(wide_f, bundle, WB_INV_I_B, turning);
        V3 ra = vec(wide_f, bundle, WB_RA), rb = vec(wide_f, bundle, WB_RB), n = vec(wide_f, bundle, WB_NORMAL);
        // normal: a speculative gap s > 0 closes exactly in the sub-step; shallow overlap opens softly
        v8 s = load(at(wide_f, bundle, WB_SEPARATION));
        v8 r = (zero - s) * bias_rate;
        v8 bias = where_gt(s, zero, s / h, zero - vmax(vmin(r, twice_max_bias - r), zero));
        v8 soft_mass = where_gt(s, zero, one, touching_mass);
        v8 soft_impulse = where_gt(s, zero, zero, touching_impulse);
        v8 vn = dot(relative_velocity(ua, ra, ub, rb), n);
        v8 mass_n = load(at(wide_f, bundle, WB_MASS_N));
        v8 old = load(at(wide_f, bundle, WB_LAMBDA_N));
        v8 next = vmax(old - mass_n * soft_mass * (vn + bias) - soft_impulse * old, zero);
        store(at(wide_f, bundle, WB_LAMBDA_N), next);
        v8 max_n = load(at(wide_f, bundle, WB_MAX_N)), vn0 = load(at(wide_f, bundle, WB_VN0));
        v8 engaging = where_gt(next, zero, where_gt(max_n, zero, zero, load(at(wide_f, bundle, WB_NEW))), zero);
        store(at(wide_f, bundle, WB_VN0), where_gt(engaging, zero, vmin(vn, vn0), vn0));
        store(at(wide_f, bundle, WB_MAX_N), vmax(next, max_n));
        v8 d = next - old;
        largest = vmax(largest, where_gt(mass_n, zero, vabs(d) / mass_n, zero));
        V3 p = {d * n.x, d * n.y, d * n.z};
        ua = push(ua, ima, ia, ra, p, -1.0, turning);
        ub = push(ub, imb, ib, rb, p, 1.0, turning);
        // friction: Coulomb disc on the tangent plane
        v8 bound = load(at(wide_f, bundle, WB_MU)) * next;
        V3 t1 = vec(wide_f, bundle, WB_T1), t2 = vec(wide_f, bundle, WB_T2);
        V3 dv = relative_velocity(ua, ra, ub, rb);
        v8 o1 = load(at(wide_f, bundle, WB_LAMBDA_T1)), o2 = load(at(wide_f, bundle, WB_LAMBDA_T2));
        v8 n1 = o1 - load(at(wide_f, bundle, WB_MASS_T1)) * dot(dv, t1);
        v8 n2 = o2 - load(at(wide_f, bundle, WB_MASS_T2)) * dot(dv, t2);
        v8 length = vsqrt(n1 * n1 + n2 * n2);
        v8 scale = where_gt(length, bound, bound / length, one);
        n1 = n1 * scale;
        n2 = n2 * scale;
        store(at(wide_f, bundle, WB_LAMBDA_T1), n1);
        store(at(wide_f, bundle, WB_LAMBDA_T2), n2);
        v8 d1 = n1 - o1, d2 = n2 - o2;
        p = {d1 * t1.x + d2 * t2.x, d1 * t1.y + d2 * t2.y, d1 * t1.z + d2 * t2.z};
        ua = push(ua, ima, ia, ra, p, -1.0, turning);
        ub = push(ub, imb, ib, rb, p, 1.0, turning);
        // rolling and torsional friction, in bundles that have them
        if (rows[WI_ROLLING * LANES] != 0) solve_rolling(wide_f, bundle, ua, ia, ub, ib, next);
        scatter_u(sb, rows + WI_WRITE_A * LANES, ua);
        scatter_u(sb, rows + WI_WRITE_B * LANES, ub);
    }
    T change = 0.0;
    for (int l = 0; l < LANES; ++l) change = largest[l] > change ? largest[l] : change;
    return change;
}

};  // struct Pass

// ``passes`` passes over the bundles first..last; returns the last pass's largest velocity change.
template <typename T> static T solve_passes(T *wide_f, const int64_t *wide_i, int64_t first, int64_t last, T *sb,
                                            T h, const T *soft, int64_t passes) {
    T change = 0;
    for (int64_t k = 0; k < passes; ++k) change = Pass<T>::solve_pass(wide_f, wide_i, first, last, sb, h, soft);
    return change;
}

// In double precision, on the engine's own tables.
extern "C" double solve_passes_double(double *wide_f, const int64_t *wide_i, int64_t first, int64_t last, double *sb,
                                      double h, const double *soft, int64_t passes) {
    return solve_passes<double>(wide_f, wide_i, first, last, sb, h, soft, passes);
}

// In single precision, on float copies of them.
extern "C" float solve_passes_float(float *wide_f, const int64_t *wide_i, int64_t first, int64_t last, float *sb,
                                    float h, const float *soft, int64_t passes) {
    return solve_passes<float>(wide_f, wide_i, first, last, sb, h, soft, passes);
}
