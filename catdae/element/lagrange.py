"""The inertia forces of a consistent-mass element without its matrices (docs/theory.md §7.6):
M_e a and the Lagrangian velocity terms g_e straight from the element's flexibilities and their
derivatives, in registers, for the transient residual pass."""

from __future__ import annotations

import numpy as np
from numba import njit

from catdae.element.catenary import partial_solution
from catdae.element.mass_gradient import partial_grad


# 3-vectors and 3x3 matrices (row-major 9-tuples) held in registers: ``lagrange_one``
@njit(cache=True, inline="always")
def _mv(m, x):
    return (m[0] * x[0] + m[1] * x[1] + m[2] * x[2], m[3] * x[0] + m[4] * x[1] + m[5] * x[2],
            m[6] * x[0] + m[7] * x[1] + m[8] * x[2])


@njit(cache=True, inline="always")
def _mtv(m, x):
    return (m[0] * x[0] + m[3] * x[1] + m[6] * x[2], m[1] * x[0] + m[4] * x[1] + m[7] * x[2],
            m[2] * x[0] + m[5] * x[1] + m[8] * x[2])


@njit(cache=True, inline="always")
def _mm(a, b):
    return (a[0] * b[0] + a[1] * b[3] + a[2] * b[6], a[0] * b[1] + a[1] * b[4] + a[2] * b[7],
            a[0] * b[2] + a[1] * b[5] + a[2] * b[8], a[3] * b[0] + a[4] * b[3] + a[5] * b[6],
            a[3] * b[1] + a[4] * b[4] + a[5] * b[7], a[3] * b[2] + a[4] * b[5] + a[5] * b[8],
            a[6] * b[0] + a[7] * b[3] + a[8] * b[6], a[6] * b[1] + a[7] * b[4] + a[8] * b[7],
            a[6] * b[2] + a[7] * b[5] + a[8] * b[8])


@njit(cache=True, inline="always")
def _sym9(f0, f1, f2, f3, f4, f5):
    """The symmetric 3x3 matrix with upper triangle (f0, ..., f5) as a 9-tuple."""
    return (f0, f1, f2, f1, f3, f4, f2, f4, f5)


@njit(cache=True, inline="always")
def _mat9(kk):
    """A 3x3 array as a 9-tuple."""
    return (kk[0, 0], kk[0, 1], kk[0, 2], kk[1, 0], kk[1, 1], kk[1, 2], kk[2, 0], kk[2, 1],
            kk[2, 2])


@njit(cache=True, inline="always")
def _dsym9(fg, m):
    """∂G/∂h_m (or ∂F/∂h_m) as a 9-tuple, from column m of ``partial_grad``'s fg (6, 3)."""
    return _sym9(fg[0, m], fg[1, m], fg[2, m], fg[3, m], fg[4, m], fg[5, m])


@njit(cache=True, inline="always")
def _comb(a, x, b, y, c, z):
    """a x + b y + c z for 3-tuples x, y, z."""
    return (a * x[0] + b * y[0] + c * z[0], a * x[1] + b * y[1] + c * z[1],
            a * x[2] + b * y[2] + c * z[2])


@njit(cache=True, inline="always")
def _comb9(a, x, b, y, c, z):
    """a x + b y + c z for 9-tuples (3x3 matrices) x, y, z."""
    return (a * x[0] + b * y[0] + c * z[0], a * x[1] + b * y[1] + c * z[1],
            a * x[2] + b * y[2] + c * z[2], a * x[3] + b * y[3] + c * z[3],
            a * x[4] + b * y[4] + c * z[4], a * x[5] + b * y[5] + c * z[5],
            a * x[6] + b * y[6] + c * z[6], a * x[7] + b * y[7] + c * z[7],
            a * x[8] + b * y[8] + c * z[8])


@njit(cache=True, inline="always")
def _quadrature_point(q, nq, gs_e, gw_e, scale_e, l0, pm0, pms, pmm):
    """(s, W) of an element's quadrature point q: the Gauss points (W = scale L0 w_g) first,
    then the point masses inside it (W = m_p); W = 0 for a Gauss point of zero weight."""
    if q < nq:
        return gs_e[q], scale_e * l0 * gw_e[q]
    return pms[pm0 + q - nq], pmm[pm0 + q - nq]


@njit(cache=True, inline="always")
def _dot(x, y):
    return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]


@njit(cache=True)
def lagrange_one(he, kk, l0, ea, w, ls, lf, k0, k1, gs_e, gw_e, scale_e, pm0, pm1, pms, pmm,
                 fade, share, ve, ae, fe, f6, fg):
    """fe (6,) = share [M_e ae + fade g_e], g_e = Σ_k ċ_k ∂M_e/∂c_k ve - ∂T_e/∂u (the
    Lagrangian velocity terms, as ``mass.dynamic_forces`` with ``mass_grad_one``'s matrices),
    without forming M_e or ∂M_e/∂c (docs/theory.md §7.6).

    With M_e = Σ_q W_q N_qᵀ N_q, N = [I - B, B] and ċ = Δv = v_j - v_i, at each quadrature
    point: u = N ve = v_i + B Δv, N ae likewise; ∂B_k = ∂G_k K + G ∂K_k with
    ∂G_k = Σ_m ∂G/∂h_m K[m, k]; a_k = ∂B_k Δv, b_k = ∂B_kᵀ u = K ∂G_k u + ∂K_k G u; then
    Σ_k ċ_k ∂M/∂c_k ve = W [-Ḃᵀu + z - Bᵀz; Ḃᵀu + Bᵀz] with Ḃᵀu = Σ_k Δv_k b_k and
    z = Σ_k Δv_k a_k, and ½ veᵀ ∂M/∂c_k ve = W u·a_k. Returns (ok, share ½ veᵀ M_e ve =
    share ½ Σ W |u|², the kinetic energy); ok False (fe untouched) where a flexibility cannot be
    evaluated. Work arrays: f6 (6,), fg (6, 3).
    """
    if not partial_grad(he[0], he[1], he[2], w, ea, l0, ls, lf, k0, k1, f6, fg):
        return False, 0.0
    K = _mat9(kk)
    # ∂F/∂h_m and ∂K/∂c_k = -K ∂F_k K, ∂F_k = Σ_m ∂F/∂h_m K[m, k]
    F0, F1, F2 = _dsym9(fg, 0), _dsym9(fg, 1), _dsym9(fg, 2)
    dK0 = _mm(K, _mm(_comb9(-K[0], F0, -K[3], F1, -K[6], F2), K))
    dK1 = _mm(K, _mm(_comb9(-K[1], F0, -K[4], F1, -K[7], F2), K))
    dK2 = _mm(K, _mm(_comb9(-K[2], F0, -K[5], F1, -K[8], F2), K))
    vi = (ve[0], ve[1], ve[2])
    ai = (ae[0], ae[1], ae[2])
    dv = (ve[3] - ve[0], ve[4] - ve[1], ve[5] - ve[2])
    da = (ae[3] - ae[0], ae[4] - ae[1], ae[5] - ae[2])
    kdv = _mv(K, dv)
    d0 = _mv(dK0, dv)
    d1 = _mv(dK1, dv)
    d2 = _mv(dK2, dv)
    acc = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)  # M ae
    lag = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)  # g_e
    kin = 0.0
    nq = gs_e.shape[0]
    for q in range(nq + pm1 - pm0):
        s, wq = _quadrature_point(q, nq, gs_e, gw_e, scale_e, l0, pm0, pms, pmm)
        if wq == 0.0:
            continue
        if not partial_grad(he[0], he[1], he[2], w, ea, s, ls, lf, k0, k1, f6, fg):
            return False, 0.0
        G = _sym9(f6[0], f6[1], f6[2], f6[3], f6[4], f6[5])
        B = _mm(G, K)
        bdv = _mv(B, dv)
        u = (vi[0] + bdv[0], vi[1] + bdv[1], vi[2] + bdv[2])
        bda = _mv(B, da)
        na = (ai[0] + bda[0], ai[1] + bda[1], ai[2] + bda[2])
        kin += wq * _dot(u, u)
        btn = _mtv(B, na)  # W Nᵀ (N a) = W [na - Bᵀ na; Bᵀ na]
        acc = (acc[0] + wq * (na[0] - btn[0]), acc[1] + wq * (na[1] - btn[1]),
               acc[2] + wq * (na[2] - btn[2]), acc[3] + wq * btn[0], acc[4] + wq * btn[1],
               acc[5] + wq * btn[2])
        if fade == 0.0:
            continue
        G0, G1, G2 = _dsym9(fg, 0), _dsym9(fg, 1), _dsym9(fg, 2)
        p0 = _mv(G0, kdv)
        p1 = _mv(G1, kdv)
        p2 = _mv(G2, kdv)
        r0 = _mv(G0, u)
        r1 = _mv(G1, u)
        r2 = _mv(G2, u)
        gu = _mv(G, u)
        # a_k = ∂G_k K Δv + G ∂K_k Δv, b_k = K ∂G_k u + ∂K_k G u (∂G_k x = Σ_m K[m, k] ∂G/∂h_m x)
        a0 = _comb(K[0], p0, K[3], p1, K[6], p2)
        a1 = _comb(K[1], p0, K[4], p1, K[7], p2)
        a2 = _comb(K[2], p0, K[5], p1, K[8], p2)
        g0 = _mv(G, d0)
        g1 = _mv(G, d1)
        g2 = _mv(G, d2)
        a0 = (a0[0] + g0[0], a0[1] + g0[1], a0[2] + g0[2])
        a1 = (a1[0] + g1[0], a1[1] + g1[1], a1[2] + g1[2])
        a2 = (a2[0] + g2[0], a2[1] + g2[1], a2[2] + g2[2])
        b0 = _mv(K, _comb(K[0], r0, K[3], r1, K[6], r2))
        b1 = _mv(K, _comb(K[1], r0, K[4], r1, K[7], r2))
        b2 = _mv(K, _comb(K[2], r0, K[5], r1, K[8], r2))
        e0 = _mv(dK0, gu)
        e1 = _mv(dK1, gu)
        e2 = _mv(dK2, gu)
        bdu = _comb(dv[0], (b0[0] + e0[0], b0[1] + e0[1], b0[2] + e0[2]),
                    dv[1], (b1[0] + e1[0], b1[1] + e1[1], b1[2] + e1[2]),
                    dv[2], (b2[0] + e2[0], b2[1] + e2[1], b2[2] + e2[2]))
        z = _comb(dv[0], a0, dv[1], a1, dv[2], a2)
        btz = _mtv(B, z)
        h0 = wq * _dot(u, a0)
        h1 = wq * _dot(u, a1)
        h2 = wq * _dot(u, a2)
        lag = (lag[0] + wq * (z[0] - btz[0] - bdu[0]) + h0,
               lag[1] + wq * (z[1] - btz[1] - bdu[1]) + h1,
               lag[2] + wq * (z[2] - btz[2] - bdu[2]) + h2,
               lag[3] + wq * (btz[0] + bdu[0]) - h0,
               lag[4] + wq * (btz[1] + bdu[1]) - h1,
               lag[5] + wq * (btz[2] + bdu[2]) - h2)
    for i in range(6):
        fe[i] = share * (acc[i] + fade * lag[i])
    return True, 0.5 * share * kin


@njit(cache=True)
def kinetic_one(he, kk, l0, ea, w, ls, lf, k0, k1, gs_e, gw_e, scale_e, pm0, pm1, pms, pmm,
                share, ve, d3, f6):
    """share ½ veᵀ M_e ve = share ½ Σ_q W_q |v_i + B_q Δv|² of a solved taut element, without
    M_e (an output's kinetic energy, where the element's forces are not read); NaN where a
    flexibility cannot be evaluated. Work arrays: d3 (3,), f6 (6,)."""
    dv = (ve[3] - ve[0], ve[4] - ve[1], ve[5] - ve[2])
    kdv = _mv(_mat9(kk), dv)
    kin = 0.0
    nq = gs_e.shape[0]
    for q in range(nq + pm1 - pm0):
        s, wq = _quadrature_point(q, nq, gs_e, gw_e, scale_e, l0, pm0, pms, pmm)
        if wq == 0.0:
            continue
        if not partial_solution(he[0], he[1], he[2], w, ea, s, ls, lf, k0, k1, d3, f6, True):
            return np.nan
        bdv = _mv(_sym9(f6[0], f6[1], f6[2], f6[3], f6[4], f6[5]), kdv)  # B Δv = G (K Δv)
        u = (ve[0] + bdv[0], ve[1] + bdv[1], ve[2] + bdv[2])
        kin += wq * _dot(u, u)
    return 0.5 * share * kin
