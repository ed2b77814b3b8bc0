"""Compiled kernels of ∂M_e/∂c, the derivative of the consistent element mass along the chord
(docs/theory.md §7.6): forward-mode differentiation of the segment formulas, the fade near
zero tension and the element's mass with its gradient. Used by ``mass`` in the transient pass
with the Lagrangian velocity terms."""

from __future__ import annotations

import numpy as np
from numba import njit

from catdae.element.catenary import asinhc


@njit(cache=True, inline="always")
def _segment_grad(hx, hy, v, w, ea, a, b, f, fg):
    """Add the flexibility of the load-free stretch [a, b] to f (6,) (as
    ``catenary.segment``) and its derivatives with respect to (hx, hy, v) to fg (6, 3).

    Forward-mode differentiation of ``catenary.segment``, line by line, in real arithmetic: the
    transcendental functions are evaluated once and shared by the three directions (the
    complex-step ``_mass_gradient_batch`` evaluates complex ones three times). Returns False
    where the tension vanishes.
    """
    ell = b - a
    if ell <= 0.0:
        return True
    h2 = hx * hx + hy * hy
    ua = v + w * a
    ub = v + w * b
    ta = np.sqrt(h2 + ua * ua)
    tb = np.sqrt(h2 + ub * ub)
    same = ua * ub >= 0.0
    nn = 0.0
    dd = 1.0
    if same:
        s_ = h2 + ta * tb + ua * ub
    else:
        nn = h2 + ua * ua + ub * ub
        dd = ta * tb - ua * ub
        s_ = h2 * (1.0 + nn / dd)
    if not (ta > 0.0 and tb > 0.0 and s_ > 0.0):
        return False
    r = (ta + tb) / s_
    le = ell / ea
    z = w * ell * r
    p = ell * r * asinhc(z)
    q = ell * r / (ta * tb)
    pp = (ta + tb) * ta * tb
    zz = ell * (ua + ub) / pp
    f[0] += le + p - hx * hx * q
    f[1] -= hx * hy * q
    f[2] -= hx * zz
    f[3] += le + p - hy * hy * q
    f[4] -= hy * zz
    f[5] += le + h2 * q
    dpdr = ell / np.sqrt(1.0 + z * z)  # d(ℓ r asinhc(w ℓ r))/dr = ℓ / sqrt(1 + z²)
    for m in range(3):
        ghx = 1.0 if m == 0 else 0.0
        ghy = 1.0 if m == 1 else 0.0
        gu = 1.0 if m == 2 else 0.0  # ∂u_a = ∂u_b
        gh2 = 2.0 * (hx * ghx + hy * ghy)
        gta = (0.5 * gh2 + ua * gu) / ta
        gtb = (0.5 * gh2 + ub * gu) / tb
        if same:
            gs = gh2 + gta * tb + ta * gtb + gu * (ua + ub)
        else:
            gn = gh2 + 2.0 * (ua + ub) * gu
            gd = gta * tb + ta * gtb - gu * (ua + ub)
            gs = gh2 * (1.0 + nn / dd) + h2 * (gn * dd - nn * gd) / (dd * dd)
        gr = (gta + gtb - r * gs) / s_
        gp = dpdr * gr
        gq = q * (gr / r - gta / ta - gtb / tb)
        gpp = (gta + gtb) * ta * tb + (ta + tb) * (gta * tb + ta * gtb)
        gzz = (2.0 * ell * gu - zz * gpp) / pp
        fg[0, m] += gp - 2.0 * hx * ghx * q - hx * hx * gq
        fg[1, m] -= (ghx * hy + hx * ghy) * q + hx * hy * gq
        fg[2, m] -= ghx * zz + hx * gzz
        fg[3, m] += gp - 2.0 * hy * ghy * q - hy * hy * gq
        fg[4, m] -= ghy * zz + hy * gzz
        fg[5, m] += gh2 * q + h2 * gq
    return True


@njit(cache=True)
def partial_grad(h0, h1, h2, w, ea, s_end, ls, lf, k0, k1, f, fg):
    """G(s_end) (into f, upper triangle) and ∂G/∂h_m (into fg (6, 3)); see ``_partial``.

    A load inside the element shifts the tension by a constant, so ∂(hx, hy, v)/∂h = I on
    every segment."""
    for m in range(6):
        f[m] = 0.0
        for k in range(3):
            fg[m, k] = 0.0
    hx, hy, v = h0, h1, h2
    a = 0.0
    ok = True
    for k in range(k0, k1):
        sk = ls[k]
        if sk >= s_end:
            break
        if sk > a:
            ok = _segment_grad(hx, hy, v, w, ea, a, sk, f, fg) and ok
            a = sk
        hx -= lf[k, 0]
        hy -= lf[k, 1]
        v -= lf[k, 2]
    if s_end > a:
        ok = _segment_grad(hx, hy, v, w, ea, a, s_end, f, fg) and ok
    return ok


_UPPER = np.array([[0, 1, 2], [1, 3, 4], [2, 4, 5]], np.int64)  # (r, c) -> upper triangle


@njit(cache=True, inline="always")
def _sym3(f, out):
    """The symmetric 3x3 matrix with upper triangle f (6,), into out (3, 3)."""
    out[0, 0] = f[0]
    out[0, 1] = f[1]
    out[0, 2] = f[2]
    out[1, 0] = f[1]
    out[1, 1] = f[3]
    out[1, 2] = f[4]
    out[2, 0] = f[2]
    out[2, 1] = f[4]
    out[2, 2] = f[5]


@njit(cache=True)
def gradient_fade(he, w, l0, ls, lf, k0, k1):
    """Weight (0..1) of ∂M/∂c for an element of end tension ``he``: the least tension along
    the element relative to the largest, t_min/t_max; ∂M/∂c grows like 1/t_min near a free
    end and is undefined at zero tension, so it is faded out smoothly (C1) between t_min/t_max
    = 1e-2 and 1e-3, keeping the residual continuous; those elements then follow the paper's
    M(q) v' form."""
    hx = he[0]
    hy = he[1]
    vi = he[2]
    vj = he[2] + w * l0
    for k in range(k0, k1):
        hx -= lf[k, 0]
        hy -= lf[k, 1]
        vj -= lf[k, 2]
    t_i = np.sqrt(he[0] * he[0] + he[1] * he[1] + vi * vi)
    t_j = np.sqrt(hx * hx + hy * hy + vj * vj)
    t_min = min(t_i, t_j)
    if vi * vj < 0.0:
        t_min = min(t_min, np.sqrt(min(he[0] * he[0] + he[1] * he[1], hx * hx + hy * hy)))
    t_max = max(t_i, t_j)
    ratio = t_min / t_max if t_max > 0.0 else 0.0
    if not ratio > 1e-3:
        return 0.0
    if ratio < 1e-2:
        xf = np.log10(ratio) + 3.0  # 0 .. 1
        return xf * xf * (3.0 - 2.0 * xf)
    return 1.0


@njit(cache=True, inline="always")
def _add_ntn_grad(g6, gg, kk, dkk, scale, out, dout, gm, bm, nm, dn):
    """out (6, 6) += scale NᵀN and dout (3, 6, 6) += scale ∂(NᵀN)/∂c_k, with N = [I - B, B],
    B = G K (§6) and ∂B/∂c_k = ∂G_k K + G ∂K_k, ∂G_k = Σ_m ∂G/∂h_m K[m, k] (∂h/∂c = K).

    g6 (6,), gg (6, 3): G(s) and ∂G/∂h_m as upper triangles; dkk (3, 3, 3): ∂K/∂c_k.
    gm, bm (3, 3), nm, dn (3, 6): work arrays.
    """
    _sym3(g6, gm)
    for r in range(3):
        for c in range(3):
            bb = 0.0
            for k in range(3):
                bb += gm[r, k] * kk[k, c]
            bm[r, c] = bb
            nm[r, c] = (1.0 if r == c else 0.0) - bb
            nm[r, 3 + c] = bb
    for r in range(6):
        for c in range(r, 6):
            acc = 0.0
            for i in range(3):
                acc += nm[i, r] * nm[i, c]
            out[r, c] += scale * acc
            if c != r:
                out[c, r] += scale * acc
    for k in range(3):
        # ∂G_k (3, 3) = Σ_m ∂G/∂h_m K[m, k], into dn[:, :3] as scratch, then ∂B_k
        for r in range(3):
            for c in range(3):
                idx = _UPPER[r, c]
                dn[r, c] = gg[idx, 0] * kk[0, k] + gg[idx, 1] * kk[1, k] + gg[idx, 2] * kk[2, k]
        for r in range(3):
            for c in range(3):
                db = 0.0
                for m in range(3):
                    db += dn[r, m] * kk[m, c] + gm[r, m] * dkk[k, m, c]
                dn[r, 3 + c] = db
        for r in range(3):
            for c in range(3):
                dn[r, c] = -dn[r, 3 + c]
        for r in range(6):
            for c in range(r, 6):
                acc = 0.0
                for i in range(3):
                    acc += dn[i, r] * nm[i, c] + nm[i, r] * dn[i, c]
                dout[k, r, c] += scale * acc
                if c != r:
                    dout[k, c, r] += scale * acc


@njit(cache=True)
def mass_grad_one(he, kk, l0, ea, w, ls, lf, k0, k1, gs_e, gw_e, scale_e, pm0, pm1, pms,
                   pmm, fade, out, dout, f6, fg, dkk, gm, bm, nm, dn, fm):
    """Consistent element mass (as ``mass_one``) and fade * ∂M_e/∂c_k (3, 6, 6), analytic.

    ∂K/∂c_k = -K ∂F_k K with ∂F_k = Σ_m ∂F/∂h_m K[m, k]; then ``_add_ntn_grad`` at every
    Gauss point and point mass. Returns False where a flexibility cannot be evaluated."""
    out[:, :] = 0.0
    dout[:, :, :] = 0.0
    if not partial_grad(he[0], he[1], he[2], w, ea, l0, ls, lf, k0, k1, f6, fg):
        return False
    for k in range(3):
        for r in range(3):
            for c in range(3):
                idx = _UPPER[r, c]
                fm[r, c] = fg[idx, 0] * kk[0, k] + fg[idx, 1] * kk[1, k] + fg[idx, 2] * kk[2, k]
        for r in range(3):  # bm = ∂F_k K
            for c in range(3):
                bm[r, c] = fm[r, 0] * kk[0, c] + fm[r, 1] * kk[1, c] + fm[r, 2] * kk[2, c]
        for r in range(3):
            for c in range(3):
                dkk[k, r, c] = -(kk[r, 0] * bm[0, c] + kk[r, 1] * bm[1, c] + kk[r, 2] * bm[2, c])
    ok = True
    for j in range(gs_e.shape[0]):
        wt = gw_e[j]
        if wt == 0.0:
            continue
        ok = partial_grad(he[0], he[1], he[2], w, ea, gs_e[j], ls, lf, k0, k1, f6, fg) and ok
        _add_ntn_grad(f6, fg, kk, dkk, scale_e * l0 * wt, out, dout, gm, bm, nm, dn)
    for p in range(pm0, pm1):
        ok = partial_grad(he[0], he[1], he[2], w, ea, pms[p], ls, lf, k0, k1, f6, fg) and ok
        _add_ntn_grad(f6, fg, kk, dkk, pmm[p], out, dout, gm, bm, nm, dn)
    if fade != 1.0:
        for k in range(3):
            for r in range(6):
                for c in range(6):
                    dout[k, r, c] *= fade
    return ok
