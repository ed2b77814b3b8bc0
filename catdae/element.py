"""The exact 3-D elastic catenary element (docs/theory.md §1-6), batched over elements.

One element runs from node i to node j; ``s`` in [0, L0] is the unstrained arc length from i.
The unknown of an element is ``h = (Hx, Hy, Vz)``, the tension vector at s = 0 (the force with
which the cable pulls node i). Between concentrated loads the tension vector is linear in s:
``t(s) = h + (0, 0, w s) - sum_{s_k < s} f_k``.

Numerically stable segment formulas
-----------------------------------
On a stretch [a, b] (length L) of one load-free segment, with H² = Hx² + Hy², u = V + w s and
T = sqrt(H² + u²), every term of §2-3 that carries 1/w is an integral of a smooth function:

    (asinh(u_b/H) - asinh(u_a/H))/w = ∫ ds/T    = L R asinhc(w L R)
    (u_b/T_b - u_a/T_a)/(w H²)      = ∫ ds/T³   = L R/(T_a T_b)
    (1/T_a - 1/T_b)/w               = ∫ u/T³ ds = L (u_a+u_b)/((T_a+T_b) T_a T_b)
    (T_b - T_a)/w                   = ∫ u/T ds  = L (u_a+u_b)/(T_a+T_b)

with R = (T_a + T_b)/S, S = H² + T_a T_b + u_a u_b and asinhc(z) = asinh(z)/z. They follow from
asinh(x) - asinh(y) = asinh(x sqrt(1+y²) - y sqrt(1+x²)) and T_b² - T_a² = (u_b - u_a)(u_a + u_b)
with u_b - u_a = w L. S is evaluated without cancellation in both sign cases of u_a u_b (when u
changes sign, S = H² (1 + (H² + u_a² + u_b²)/(T_a T_b - u_a u_b))). No term divides by w or by H,
so the weightless (w -> 0), vertical (H -> 0) and low-point-inside cases need no special branch;
they are exact limits of the same expressions. The only singularity left is physical: zero
tension somewhere on the element (T_a = 0, T_b = 0, or H = 0 with u changing sign).

Solving for h
-------------
ℓ(h) = x(L0) is the gradient of the convex complementary energy ∫ (T + T²/(2 EA)) ds, so the
flexibility F = ∂ℓ/∂h is symmetric positive definite wherever T > 0 and the element equation
ℓ(h) = chord has exactly one solution when one exists. Newton steps on it are damped by
backtracking on the chord residual (a descent direction, since F is non-singular). The cold
start is the classic guess of Peyrot & Goulois (1979) for the total weight, plus the elastic
stretch of a taut chord.

Slack response: a weightless element without loads whose chord is not longer than L0 carries no
tension (no equilibrium with T > 0 exists). It is returned with ``status == SLACK``, h = 0 and a
zero stiffness, a defined answer rather than a failure. Any other failure returns the last finite
iterate with ``status`` NOT_CONVERGED; nothing is NaN.

Speed: the kernels are compiled with numba (loops over elements and load segments; arrays with
the element axis first). See benchmarks/element_speed.py for measured solve rates.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit

CONVERGED = 0
SLACK = 1
NOT_CONVERGED = 2

STATUS_NAMES = {CONVERGED: "converged", SLACK: "slack", NOT_CONVERGED: "not converged"}


# ----------------------------------------------------------------------------------------------
# compiled kernels
# ----------------------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _asinhc(z):
    """asinh(z)/z, stable at z -> 0."""
    az = abs(z)
    if az < 1e-3:
        z2 = z * z
        return 1.0 - z2 / 6.0 + 0.075 * z2 * z2
    return np.arcsinh(z) / z


@njit(cache=True, inline="always")
def _segment(hx, hy, v, w, ea, a, b, d, f, want_flex):
    """Add the chord (and flexibility) of the load-free stretch [a, b] to d (3,) and f (6,).

    f holds the upper triangle (xx, xy, xz, yy, yz, zz). docs/theory.md §2-3 in the stable
    forms of the module docstring. Returns False where the tension vanishes (singular).
    """
    ell = b - a
    if ell <= 0.0:
        return True
    h2 = hx * hx + hy * hy
    ua = v + w * a
    ub = v + w * b
    ta = np.sqrt(h2 + ua * ua)
    tb = np.sqrt(h2 + ub * ub)
    # comparisons on real parts: the same code runs on complex tensions (complex-step ∂M/∂c)
    if (ua * ub).real >= 0.0:
        s_ = h2 + ta * tb + ua * ub
    else:
        s_ = h2 * (1.0 + (h2 + ua * ua + ub * ub) / (ta * tb - ua * ub))
    if not (ta.real > 0.0 and tb.real > 0.0 and s_.real > 0.0):
        return False
    r = (ta + tb) / s_
    le = ell / ea
    p = ell * r * _asinhc(w * ell * r)  # ∫ ds/T
    d[0] += hx * (le + p)
    d[1] += hy * (le + p)
    d[2] += 0.5 * ell * (ua + ub) * (1.0 / ea + 2.0 / (ta + tb))
    if want_flex:
        q = ell * r / (ta * tb)  # ∫ ds/T³
        zz = ell * (ua + ub) / ((ta + tb) * ta * tb)  # ∫ u/T³ ds
        f[0] += le + p - hx * hx * q
        f[1] -= hx * hy * q
        f[2] -= hx * zz
        f[3] += le + p - hy * hy * q
        f[4] -= hy * zz
        f[5] += le + h2 * q
    return True


@njit(cache=True)
def _partial(h0, h1, h2, w, ea, s_end, ls, lf, k0, k1, d, f, want_flex):
    """Position x(s_end) relative to node i (into d) and G(s_end) (into f, upper triangle).

    Loads k0..k1-1 (sorted by s) act on the element; a load at s_k changes t for s > s_k.
    """
    for m in range(3):
        d[m] = 0.0
    for m in range(6):
        f[m] = 0.0
    hx, hy, v = h0, h1, h2
    a = 0.0
    ok = True
    for k in range(k0, k1):
        sk = ls[k]
        if sk >= s_end:
            break
        if sk > a:
            ok = _segment(hx, hy, v, w, ea, a, sk, d, f, want_flex) and ok
            a = sk
        hx -= lf[k, 0]
        hy -= lf[k, 1]
        v -= lf[k, 2]
    if s_end > a:
        ok = _segment(hx, hy, v, w, ea, a, s_end, d, f, want_flex) and ok
    return ok


@njit(cache=True, inline="always")
def _segment_grad(hx, hy, v, w, ea, a, b, f, fg):
    """Add the flexibility of the load-free stretch [a, b] to f (6,) (as ``_segment``) and its
    derivatives with respect to (hx, hy, v) to fg (6, 3).

    Forward-mode differentiation of ``_segment``, line by line, in real arithmetic: the
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
    p = ell * r * _asinhc(z)
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
def _partial_grad(h0, h1, h2, w, ea, s_end, ls, lf, k0, k1, f, fg):
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


@njit(cache=True, inline="always")
def _inv_sym3(f, kout):
    """Inverse of the symmetric 3x3 matrix with upper triangle f (6,), into kout (3, 3)."""
    a, b, c, d, e, g = f[0], f[1], f[2], f[3], f[4], f[5]
    c00 = d * g - e * e
    c01 = c * e - b * g
    c02 = b * e - c * d
    c11 = a * g - c * c
    c12 = b * c - a * e
    c22 = a * d - b * b
    det = a * c00 + b * c01 + c * c02
    if not (det.real > 0.0) or not np.isfinite(det.real):
        return False
    inv = 1.0 / det
    kout[0, 0] = c00 * inv
    kout[0, 1] = c01 * inv
    kout[0, 2] = c02 * inv
    kout[1, 0] = c01 * inv
    kout[1, 1] = c11 * inv
    kout[1, 2] = c12 * inv
    kout[2, 0] = c02 * inv
    kout[2, 1] = c12 * inv
    kout[2, 2] = c22 * inv
    return True


@njit(cache=True)
def _cold_start(c, l0, ea, w, ls, lf, k0, k1, h):
    """Peyrot & Goulois (1979) guess for the total weight, plus a taut chord's stretch."""
    lx, ly, lz = c[0], c[1], c[2]
    lh = np.sqrt(lx * lx + ly * ly)
    lc = np.sqrt(lh * lh + lz * lz)
    wz = w * l0
    fx = 0.0
    fy = 0.0
    for k in range(k0, k1):
        wz -= lf[k, 2]
        fx += lf[k, 0]
        fy += lf[k, 1]
    weff = abs(wz) / l0
    if l0 * l0 <= lc * lc:
        lam = 0.2
    elif lh <= 1e-9 * lc:
        lam = 1e6
    else:
        lam = np.sqrt(max(3.0 * (l0 * l0 - lz * lz) / (lh * lh) - 1.0, 1e-12))
        lam = min(lam, 1e6)
    hh = weff * lh / (2.0 * lam)
    coth = 1.0 / np.tanh(lam) if lam < 20.0 else 1.0
    vz = 0.5 * weff * (lz * coth - l0)
    if wz < 0.0:  # net load upwards: mirror the guess
        vz = -0.5 * weff * (-lz * coth - l0)
    if lh > 0.0:
        h[0] = hh * lx / lh
        h[1] = hh * ly / lh
    else:
        h[0] = 0.0
        h[1] = 0.0
    h[2] = vz
    # horizontal loads: split them between the ends
    h[0] += 0.5 * fx
    h[1] += 0.5 * fy
    if lc > l0:  # taut: elastic stretch along the chord
        t = ea * (lc / l0 - 1.0)
        for m in range(3):
            h[m] += t * c[m] / lc
    elif weff == 0.0 and fx == 0.0 and fy == 0.0 and lc > 0.0:
        # weightless and not taut: slack unless the loads pull it straight; start small
        for m in range(3):
            h[m] = 1e-6 * ea * c[m] / lc
    if k1 == k0 and w > 0.0 and lh < 0.05 * lc:
        _steep_start(c, l0, ea, w, lh, h)


@njit(cache=True)
def _steep_start(c, l0, ea, w, lh, h):
    """Start for a (nearly) vertical chord: the hanging bar, then H from its lateral flexibility.

    With H = 0 and u = V + w s of one sign, Δz = ±L0 + L0 (V + w L0/2)/EA is linear in V;
    if neither sign fits, the cable folds (V of the folded bar). H follows from
    Δx = Hx (L0/EA + ∫ds/T) evaluated on that bar.
    """
    lz = c[2]
    half = 0.5 * w * l0
    v_up = (lz - l0) * ea / l0 - half  # u > 0 everywhere (t points up the cable)
    v_dn = (lz + l0) * ea / l0 - half  # u < 0 everywhere (t points down the cable)
    if v_up > 0.0:
        v = v_up
    elif v_dn + w * l0 < 0.0:
        v = v_dn
    else:
        v = (lz - l0 - half * l0 / ea) / (2.0 / w + l0 / ea)
    d = np.empty(3)
    f = np.empty(6)
    ok = _partial(0.0, 0.0, v, w, ea, l0, np.empty(0), np.empty((0, 3)), 0, 0, d, f, True)
    if ok and np.isfinite(f[0]) and f[0] > 0.0:
        h[0] = c[0] / f[0]
        h[1] = c[1] / f[0]
    else:
        scale = 1e-3 * max(abs(v), w * l0) / max(lh, 1e-300)
        h[0] = c[0] * scale
        h[1] = c[1] * scale
    h[2] = v


@njit(cache=True)
def _solve_one(c, l0, ea, w, ls, lf, k0, k1, h, use_h, tol, max_iter, fout, kout):
    """Newton for one element, warm-started from ``h`` when ``use_h``; a warm start that
    fails (e.g. from a folded vertical state to a taut one) is retried cold."""
    it, status = _solve_from(c, l0, ea, w, ls, lf, k0, k1, h, use_h, tol, max_iter, fout, kout)
    if status == NOT_CONVERGED and use_h:
        it2, status = _solve_from(c, l0, ea, w, ls, lf, k0, k1, h, False, tol, max_iter,
                                  fout, kout)
        it += it2
    return it, status


@njit(cache=True)
def _solve_from(c, l0, ea, w, ls, lf, k0, k1, h, use_h, tol, max_iter, fout, kout):
    """Newton with backtracking for one element. Returns (iterations, status)."""
    d = np.empty(3)
    f = np.empty(6)
    dt = np.empty(3)
    ft = np.empty(6)
    ht = np.empty(3)
    dh = np.empty(3)
    kk = np.empty((3, 3))
    lc = np.sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2])
    # slack: weightless, no loads, chord not longer than L0 (no equilibrium with T > 0)
    if w == 0.0 and k1 == k0 and lc <= l0:
        for m in range(3):
            h[m] = 0.0
        for m in range(6):
            fout[m] = np.inf
        kout[:, :] = 0.0
        return 0, SLACK
    fsum = 0.0
    for k in range(k0, k1):
        fsum += abs(lf[k, 0]) + abs(lf[k, 1]) + abs(lf[k, 2])
    hscale_extra = abs(w) * l0 + fsum
    rscale = max(l0, lc)
    if not use_h:
        _cold_start(c, l0, ea, w, ls, lf, k0, k1, h)
    ok = _partial(h[0], h[1], h[2], w, ea, l0, ls, lf, k0, k1, d, f, True)
    if not ok:
        # a start on a point of zero tension: nudge it
        h[2] += 1e-9 * (hscale_extra + ea * 1e-9)
        ok = _partial(h[0], h[1], h[2], w, ea, l0, ls, lf, k0, k1, d, f, True)
    rn = 0.0
    for m in range(3):
        d[m] -= c[m]
        rn += d[m] * d[m]
    rn = np.sqrt(rn)
    status = NOT_CONVERGED
    it = 0
    if ok and rn <= 1e-15 * rscale:
        status = CONVERGED
    while status != CONVERGED and it < max_iter and ok:
        it += 1
        if not _inv_sym3(f, kk):
            break
        hn = 0.0
        dn = 0.0
        for m in range(3):
            dh[m] = -(kk[m, 0] * d[0] + kk[m, 1] * d[1] + kk[m, 2] * d[2])
            hn += h[m] * h[m]
            dn += dh[m] * dh[m]
        hn = np.sqrt(hn)
        dn = np.sqrt(dn)
        if dn <= tol * (hn + hscale_extra):
            # the Newton correction is below the requested accuracy: take it and stop
            for m in range(3):
                ht[m] = h[m] + dh[m]
            if _partial(ht[0], ht[1], ht[2], w, ea, l0, ls, lf, k0, k1, dt, ft, True):
                for m in range(3):
                    h[m] = ht[m]
                for m in range(6):
                    f[m] = ft[m]
            status = CONVERGED
            break
        alpha = 1.0
        accepted = False
        for _ in range(36):
            for m in range(3):
                ht[m] = h[m] + alpha * dh[m]
            okt = _partial(ht[0], ht[1], ht[2], w, ea, l0, ls, lf, k0, k1, dt, ft, True)
            rt = 0.0
            for m in range(3):
                dt[m] -= c[m]
                rt += dt[m] * dt[m]
            rt = np.sqrt(rt)
            if okt and np.isfinite(rt) and rt < (1.0 - 1e-4 * alpha) * rn:
                accepted = True
                break
            alpha *= 0.5
        step_small = alpha * dn <= tol * (hn + hscale_extra)
        if not accepted:
            # no decrease possible: converged if the residual is at its round-off floor
            if rn <= 1e-12 * rscale:
                status = CONVERGED
            break
        for m in range(3):
            h[m] = ht[m]
            d[m] = dt[m]
        for m in range(6):
            f[m] = ft[m]
        rn = rt
        if (alpha == 1.0 and step_small) or rn <= 1e-15 * rscale:
            status = CONVERGED
    if status == NOT_CONVERGED and k1 == k0 and w > 0.0 and c[0] == 0.0 and c[1] == 0.0:
        # exactly vertical chord shorter than the hanging length: the cable folds, its
        # tension vanishes at s* = -V/w (the limit H -> 0 of the near-vertical U):
        # Δz = L0 - 2 s* + L0 (V + w L0/2)/EA, linear in V; no lateral stiffness.
        fzz = 2.0 / w + l0 / ea
        v = (c[2] - l0 - 0.5 * w * l0 * l0 / ea) / fzz
        if 0.0 < -v / w < l0:
            h[0] = 0.0
            h[1] = 0.0
            h[2] = v
            fout[:] = 0.0
            fout[0] = np.inf
            fout[3] = np.inf
            fout[5] = fzz
            kout[:, :] = 0.0
            kout[2, 2] = 1.0 / fzz
            return it, SLACK
    for m in range(6):
        fout[m] = f[m]
    if not _inv_sym3(f, kout):
        kout[:, :] = 0.0
        if status == CONVERGED:
            status = NOT_CONVERGED
    return it, status


@njit(cache=True)
def _solve_batch(chord, l0, ea, w, ptr, ls, lf, h, use_h, tol, max_iter, fflat, kmat, its, stat):
    for e in range(chord.shape[0]):
        its[e], stat[e] = _solve_one(
            chord[e], l0[e], ea[e], w[e], ls, lf, ptr[e], ptr[e + 1], h[e], use_h, tol,
            max_iter, fflat[e], kmat[e],
        )


@njit(cache=True)
def _partial_batch(h, l0, ea, w, ptr, ls, lf, s, xout, gout, want_flex):
    """x(s) and G(s) at s (n, q) for every element: xout (n, q, 3), gout (n, q, 6)."""
    ok_all = True
    for e in range(h.shape[0]):
        for j in range(s.shape[1]):
            ok = _partial(h[e, 0], h[e, 1], h[e, 2], w[e], ea[e], s[e, j], ls, lf, ptr[e],
                          ptr[e + 1], xout[e, j], gout[e, j], want_flex)
            ok_all = ok_all and ok
    return ok_all


@njit(cache=True)
def _tension_batch(h, w, ptr, ls, lf, s, tout):
    """Tension vector t(s) (n, q, 3); loads at s_k act for s > s_k."""
    for e in range(h.shape[0]):
        for j in range(s.shape[1]):
            sj = s[e, j]
            tx, ty, tz = h[e, 0], h[e, 1], h[e, 2] + w[e] * sj
            for k in range(ptr[e], ptr[e + 1]):
                if ls[k] < sj:
                    tx -= lf[k, 0]
                    ty -= lf[k, 1]
                    tz -= lf[k, 2]
            tout[e, j, 0] = tx
            tout[e, j, 1] = ty
            tout[e, j, 2] = tz


@njit(cache=True, inline="always")
def _add_ntn(g6, kk, frac, slack, scale, out):
    """out (6, 6) += scale * NᵀN with N = [I - B, B], B = G K (§6); slack: B = frac I."""
    b = np.empty((3, 3), out.dtype)
    if slack:
        for r in range(3):
            for c in range(3):
                b[r, c] = frac if r == c else 0.0
    else:
        g00, g01, g02, g11, g12, g22 = g6[0], g6[1], g6[2], g6[3], g6[4], g6[5]
        for c in range(3):
            b[0, c] = g00 * kk[0, c] + g01 * kk[1, c] + g02 * kk[2, c]
            b[1, c] = g01 * kk[0, c] + g11 * kk[1, c] + g12 * kk[2, c]
            b[2, c] = g02 * kk[0, c] + g12 * kk[1, c] + g22 * kk[2, c]
    for r in range(3):
        for c in range(3):
            bb = 0.0
            ab = 0.0
            aa = 0.0
            for k in range(3):
                ak_r = (1.0 if k == r else 0.0) - b[k, r]
                ak_c = (1.0 if k == c else 0.0) - b[k, c]
                bb += b[k, r] * b[k, c]
                ab += ak_r * b[k, c]
                aa += ak_r * ak_c
            out[r, c] += scale * aa
            out[r, 3 + c] += scale * ab
            out[3 + c, r] += scale * ab
            out[3 + r, 3 + c] += scale * bb


@njit(cache=True)
def _mass_one(he, kk, slack, l0, ea, w, ls, lf, k0, k1, gs_e, gw_e, scale_e, pm0, pm1, pms,
              pmm, with_points, out, x, g6):
    """out (6, 6) = Σ_g scale L0 w_g N(s_g)ᵀ N(s_g) (+ Σ_p m_p N(s_p)ᵀ N(s_p)), §6-7."""
    out[:, :] = 0.0
    for j in range(gs_e.shape[0]):
        wt = gw_e[j]
        if wt == 0.0:
            continue
        if not slack:
            _partial(he[0], he[1], he[2], w, ea, gs_e[j], ls, lf, k0, k1, x, g6, True)
        _add_ntn(g6, kk, gs_e[j] / l0, slack, scale_e * l0 * wt, out)
    if with_points:
        for p in range(pm0, pm1):
            if not slack:
                _partial(he[0], he[1], he[2], w, ea, pms[p], ls, lf, k0, k1, x, g6, True)
            _add_ntn(g6, kk, pms[p] / l0, slack, pmm[p], out)


@njit(cache=True)
def _gradient_fade(he, w, l0, ls, lf, k0, k1):
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
def _mass_grad_one(he, kk, l0, ea, w, ls, lf, k0, k1, gs_e, gw_e, scale_e, pm0, pm1, pms,
                   pmm, fade, out, dout, f6, fg, dkk, gm, bm, nm, dn, fm):
    """Consistent element mass (as ``_mass_one``) and fade * ∂M_e/∂c_k (3, 6, 6), analytic.

    ∂K/∂c_k = -K ∂F_k K with ∂F_k = Σ_m ∂F/∂h_m K[m, k]; then ``_add_ntn_grad`` at every
    Gauss point and point mass. Returns False where a flexibility cannot be evaluated."""
    out[:, :] = 0.0
    dout[:, :, :] = 0.0
    if not _partial_grad(he[0], he[1], he[2], w, ea, l0, ls, lf, k0, k1, f6, fg):
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
        ok = _partial_grad(he[0], he[1], he[2], w, ea, gs_e[j], ls, lf, k0, k1, f6, fg) and ok
        _add_ntn_grad(f6, fg, kk, dkk, scale_e * l0 * wt, out, dout, gm, bm, nm, dn)
    for p in range(pm0, pm1):
        ok = _partial_grad(he[0], he[1], he[2], w, ea, pms[p], ls, lf, k0, k1, f6, fg) and ok
        _add_ntn_grad(f6, fg, kk, dkk, pmm[p], out, dout, gm, bm, nm, dn)
    if fade != 1.0:
        for k in range(3):
            for r in range(6):
                for c in range(6):
                    dout[k, r, c] *= fade
    return ok


@njit(cache=True)
def _dynamics_batch(chord, l0, ea, w, ptr, ls, lf, h, use_h, tol, max_iter, gs, gw, mq, cq,
                    pmptr, pms, pmm, want_c, want_dm, fflat, kmat, its, stat, mout, cout, dout):
    """Solve every element and build its consistent mass (and damping) matrix (§6-7), and
    with ``want_dm`` the analytic ∂M_e/∂c_k (n, 3, 6, 6) (zero for slack elements).

    M_e = Σ_g m L0 w_g N(s_g)ᵀ N(s_g) + Σ_p m_p N(s_p)ᵀ N(s_p); C_e the same with c for m
    (point masses carry no material damping). Point masses inside elements: CSR ``pmptr``.
    """
    x = np.empty(3)
    g6 = np.empty(6)
    fg = np.empty((6, 3))
    dkk = np.empty((3, 3, 3))
    gm = np.empty((3, 3))
    bm = np.empty((3, 3))
    fm = np.empty((3, 3))
    nm = np.empty((3, 6))
    dn = np.empty((3, 6))
    for e in range(chord.shape[0]):
        its[e], stat[e] = _solve_one(
            chord[e], l0[e], ea[e], w[e], ls, lf, ptr[e], ptr[e + 1], h[e], use_h, tol,
            max_iter, fflat[e], kmat[e],
        )
        slack = stat[e] == SLACK
        done = False
        if want_dm:
            fade = 0.0
            if stat[e] == CONVERGED:
                fade = _gradient_fade(h[e], w[e], l0[e], ls, lf, ptr[e], ptr[e + 1])
            if fade > 0.0:
                done = _mass_grad_one(h[e], kmat[e], l0[e], ea[e], w[e], ls, lf, ptr[e],
                                      ptr[e + 1], gs[e], gw[e], mq[e], pmptr[e], pmptr[e + 1],
                                      pms, pmm, fade, mout[e], dout[e], g6, fg, dkk, gm, bm,
                                      nm, dn, fm)
            if not done:
                dout[e, :, :, :] = 0.0
        if not done:
            _mass_one(h[e], kmat[e], slack, l0[e], ea[e], w[e], ls, lf, ptr[e], ptr[e + 1],
                      gs[e], gw[e], mq[e], pmptr[e], pmptr[e + 1], pms, pmm, True, mout[e], x,
                      g6)
        if want_c:
            _mass_one(h[e], kmat[e], slack, l0[e], ea[e], w[e], ls, lf, ptr[e], ptr[e + 1],
                      gs[e], gw[e], cq[e], 0, 0, pms, pmm, False, cout[e], x, g6)


@njit(cache=True)
def _mass_batch(h, kmat, stat, l0, ea, w, ptr, ls, lf, gs, gw, mq, pmptr, pms, pmm, out):
    """Consistent element matrices (n, 6, 6) about solved tensions h (§7); see _mass_one."""
    x = np.empty(3)
    g6 = np.empty(6)
    for e in range(h.shape[0]):
        _mass_one(h[e], kmat[e], stat[e] == SLACK, l0[e], ea[e], w[e], ls, lf, ptr[e],
                  ptr[e + 1], gs[e], gw[e], mq[e], pmptr[e], pmptr[e + 1], pms, pmm, True,
                  out[e], x, g6)


@njit(cache=True)
def _mass_gradient_batch(l0, ea, w, ptr, ls, lf, h, kmat, stat, gs, gw, mq, pmptr, pms, pmm,
                         dout):
    """∂M_e/∂c_k (n, 3, 6, 6) by complex steps along the chord c = x_j - x_i.

    M_e depends on the nodes only through the chord, and on the chord through h (∂h/∂c = K):
    ∂M_e/∂c_k = Im M_e(h + i δ K e_k) / δ, with F, K = F⁻¹ and M_e evaluated by the same
    (analytic) formulas in complex arithmetic. No difference is taken, so the derivative is
    exact to round-off for any small δ: no truncation error and no cancellation noise (central
    differences left about 1e-11 of noise, which made IDA take more steps at tight
    tolerances). Slack elements (straight-line interpolation, constant M_e) get zero.
    """
    x = np.empty(3, np.complex128)
    g6 = np.empty(6, np.complex128)
    d = np.empty(3, np.complex128)
    f6 = np.empty(6, np.complex128)
    kk = np.empty((3, 3), np.complex128)
    ht = np.empty(3, np.complex128)
    mt = np.empty((6, 6), np.complex128)
    for e in range(h.shape[0]):
        dout[e, :, :, :] = 0.0
        if stat[e] != CONVERGED:
            continue
        he = h[e]
        fade = _gradient_fade(he, w[e], l0[e], ls, lf, ptr[e], ptr[e + 1])  # near zero tension
        if fade == 0.0:
            continue
        t_max = np.sqrt(he[0] * he[0] + he[1] * he[1] + he[2] * he[2]) + abs(w[e] * l0[e])
        for k in range(3):
            kc = np.sqrt(kmat[e, 0, k] ** 2 + kmat[e, 1, k] ** 2 + kmat[e, 2, k] ** 2)
            if not (kc > 0.0) or not np.isfinite(kc):
                continue
            delta = 1e-30 * t_max / kc  # any small step: the derivative is in Im
            for m in range(3):
                ht[m] = he[m] + 1j * delta * kmat[e, m, k]
            ok = _partial(ht[0], ht[1], ht[2], w[e], ea[e], l0[e], ls, lf, ptr[e], ptr[e + 1],
                          d, f6, True)
            if not ok or not _inv_sym3(f6, kk):
                continue
            _mass_one(ht, kk, False, l0[e], ea[e], w[e], ls, lf, ptr[e], ptr[e + 1], gs[e],
                      gw[e], mq[e], pmptr[e], pmptr[e + 1], pms, pmm, True, mt, x, g6)
            for r in range(6):
                for c in range(6):
                    dout[e, k, r, c] = fade * mt[r, c].imag / delta


@njit(cache=True)
def _dynamic_forces(edofs, h, load_total, wl0, me, use_m, ce, use_c, kmat, dm, use_dm, alpha,
                    beta, vel, acc, out):
    """out (n_dof,) = Σ_e [r_e + M_e a_e + C_e v_e + g_e] with Rayleigh and Lagrangian terms.

    r_e: resisting forces (§4); C_e: material damping, or alpha M_e + beta [[K,-K],[-K,K]];
    g_e = Ṁ_e v_e - ∂T/∂u (velocity terms of Lagrange's equations, dm = ∂M_e/∂c_k).
    """
    out[:] = 0.0
    fe = np.empty(6)
    ve = np.empty(6)
    ae = np.empty(6)
    qv = np.empty(6)
    for e in range(edofs.shape[0]):
        for i in range(6):
            ve[i] = vel[edofs[e, i]]
            ae[i] = acc[edofs[e, i]]
        for i in range(3):
            fe[i] = -h[e, i]
            fe[3 + i] = h[e, i] - load_total[e, i]
        fe[5] += wl0[e]
        if use_m:
            for i in range(6):
                sm = 0.0
                for j in range(6):
                    sm += me[e, i, j] * (ae[j] + alpha * ve[j])
                fe[i] += sm
        if use_c:
            for i in range(6):
                sm = 0.0
                for j in range(6):
                    sm += ce[e, i, j] * ve[j]
                fe[i] += sm
        if beta != 0.0:
            for i in range(3):
                kd = 0.0
                for j in range(3):
                    kd += kmat[e, i, j] * (ve[j] - ve[3 + j])
                fe[i] += beta * kd
                fe[3 + i] -= beta * kd
        if use_dm:
            for k in range(3):
                cdot = ve[3 + k] - ve[k]
                half = 0.0
                for i in range(6):
                    sm = 0.0
                    for j in range(6):
                        sm += dm[e, k, i, j] * ve[j]
                    qv[i] = sm
                    half += ve[i] * sm
                half *= 0.5
                for i in range(6):
                    fe[i] += cdot * qv[i]
                fe[k] += half
                fe[3 + k] -= half
        for i in range(6):
            out[edofs[e, i]] += fe[i]


def _sym_from_upper(f6: np.ndarray) -> np.ndarray:
    """(..., 6) upper triangles -> (..., 3, 3) symmetric matrices."""
    out = np.empty(f6.shape[:-1] + (3, 3))
    out[..., 0, 0] = f6[..., 0]
    out[..., 0, 1] = out[..., 1, 0] = f6[..., 1]
    out[..., 0, 2] = out[..., 2, 0] = f6[..., 2]
    out[..., 1, 1] = f6[..., 3]
    out[..., 1, 2] = out[..., 2, 1] = f6[..., 4]
    out[..., 2, 2] = f6[..., 5]
    return out


# ----------------------------------------------------------------------------------------------
# public objects
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PointLoads:
    """Concentrated loads inside elements, stored compressed by element (CSR).

    Loads of element e are ``s[ptr[e]:ptr[e+1]]`` (sorted, unstrained arc length from node i)
    and ``f[ptr[e]:ptr[e+1]]`` (N, global axes). A load at s_k changes the tension for s > s_k.
    """

    ptr: np.ndarray  # (n+1,) int64
    s: np.ndarray  # (m,) m
    f: np.ndarray  # (m, 3) N

    @classmethod
    def empty(cls, n: int) -> PointLoads:
        return cls(np.zeros(n + 1, np.int64), np.zeros(0), np.zeros((0, 3)))

    @classmethod
    def from_lists(cls, loads: Sequence[Sequence[tuple[float, Sequence[float]]]]) -> PointLoads:
        """From one list per element of (s, (fx, fy, fz)) pairs, in any order."""
        ptr = np.zeros(len(loads) + 1, np.int64)
        s_all: list[float] = []
        f_all: list[Sequence[float]] = []
        for e, items in enumerate(loads):
            items = sorted(items, key=lambda it: it[0])
            s_all.extend(float(si) for si, _ in items)
            f_all.extend(fi for _, fi in items)
            ptr[e + 1] = ptr[e] + len(items)
        f = np.asarray(f_all, float).reshape(-1, 3)
        return cls(ptr, np.asarray(s_all, float), f)

    @property
    def n(self) -> int:
        return len(self.ptr) - 1

    def total(self) -> np.ndarray:
        """Sum of the loads on each element, (n, 3) N."""
        out = np.zeros((self.n, 3))
        counts = np.diff(self.ptr)
        np.add.at(out, np.repeat(np.arange(self.n), counts), self.f)
        return out


@dataclass(frozen=True)
class ElementState:
    """The solved state of a batch of elements for given chords."""

    h: np.ndarray  # (n, 3) N, tension vector at s = 0
    F: np.ndarray  # (n, 3, 3) m/N, flexibility ∂chord/∂h
    K: np.ndarray  # (n, 3, 3) N/m, F⁻¹ (zero for slack elements)
    iterations: np.ndarray  # (n,) Newton iterations
    status: np.ndarray  # (n,) CONVERGED, SLACK or NOT_CONVERGED

    @property
    def converged(self) -> np.ndarray:
        return self.status != NOT_CONVERGED

    @property
    def stiffness6(self) -> np.ndarray:
        """Element tangent stiffness (n, 6, 6) for (u_i, u_j): [[K, -K], [-K, K]] (§4)."""
        k = self.K
        return np.concatenate(
            [np.concatenate([k, -k], axis=2), np.concatenate([-k, k], axis=2)], axis=1
        )


class Elements:
    """A batch of catenary elements with fixed properties.

    Parameters are arrays over elements: ``L0`` unstrained length (m), ``EA`` axial stiffness (N),
    ``w`` weight per unstrained length (N/m, along -z) and optional ``loads`` inside them.
    """

    def __init__(self, L0, EA, w, loads: PointLoads | None = None):
        self.L0 = np.ascontiguousarray(L0, float).reshape(-1)
        n = self.L0.size
        self.EA = np.ascontiguousarray(np.broadcast_to(np.asarray(EA, float), (n,)))
        self.w = np.ascontiguousarray(np.broadcast_to(np.asarray(w, float), (n,)))
        self.loads = PointLoads.empty(n) if loads is None else loads
        if self.loads.n != n:
            raise ValueError(f"loads are given for {self.loads.n} elements, expected {n}")
        self._ls = np.ascontiguousarray(self.loads.s, float)
        self._lf = np.array(self.loads.f, float, copy=True).reshape(-1, 3)
        self._ptr = np.ascontiguousarray(self.loads.ptr, np.int64)
        self._load_total = self.loads.total()  # (n, 3) N

    @property
    def n(self) -> int:
        return self.L0.size

    def set_load_forces(self, f) -> None:
        """Replace the forces of the loads inside the elements (positions unchanged), (m, 3) N."""
        self._lf[:] = np.asarray(f, float).reshape(-1, 3)
        self.loads = PointLoads(self._ptr, self._ls, self._lf)
        self._load_total = self.loads.total()

    def _s(self, s) -> np.ndarray:
        s = np.asarray(s, float)
        if s.ndim == 0:
            s = np.full((self.n, 1), float(s))
        elif s.ndim == 1:
            s = np.broadcast_to(s, (self.n, s.size))
        return np.ascontiguousarray(s)

    def _h(self, h) -> np.ndarray:
        return np.ascontiguousarray(np.broadcast_to(np.asarray(h, float), (self.n, 3)))

    def solve(self, chord, h0=None, *, tol: float = 1e-12, max_iter: int = 100) -> ElementState:
        """Tension h such that the element spans ``chord`` (n, 3) = x_j - x_i.

        ``h0`` warm-starts Newton (the previous state's h); without it a cold start is used.
        Elements that fail to converge keep their last finite iterate and are flagged in
        ``status``; the caller decides what a failure means.
        """
        chord = np.ascontiguousarray(np.broadcast_to(np.asarray(chord, float), (self.n, 3)))
        use_h = h0 is not None
        h = np.array(self._h(h0), copy=True) if use_h else np.zeros((self.n, 3))
        f6 = np.empty((self.n, 6))
        kmat = np.empty((self.n, 3, 3))
        its = np.empty(self.n, np.int64)
        stat = np.empty(self.n, np.int64)
        _solve_batch(chord, self.L0, self.EA, self.w, self._ptr, self._ls, self._lf, h, use_h,
                     tol, max_iter, f6, kmat, its, stat)
        return ElementState(h, _sym_from_upper(f6), kmat, its, stat)

    def solve_dynamic(self, chord, h0, gauss_s, gauss_w, m, c=None, point_masses=None,
                      *, tol: float = 1e-12, max_iter: int = 100, gradient: bool = False):
        """Solve the elements and build their consistent mass (and damping) matrices.

        ``gauss_s``/``gauss_w`` (n, g): points (m) and weights (sum 1 per element); ``m`` and
        ``c`` (n,): mass and damping per unstrained length; ``point_masses`` = (element (p,),
        s (p,), mass (p,)) inside elements. Returns (ElementState, M_e (n, 6, 6),
        C_e (n, 6, 6) or None) in one compiled pass; with ``gradient`` a fourth item, the
        analytic ∂M_e/∂c_k (n, 3, 6, 6) (see :meth:`mass_gradient` for the complex-step one).
        """
        chord = np.ascontiguousarray(chord, float).reshape(self.n, 3)
        use_h = h0 is not None
        h = np.array(h0, float).reshape(self.n, 3) if use_h else np.zeros((self.n, 3))
        f6 = np.empty((self.n, 6))
        kmat = np.empty((self.n, 3, 3))
        its = np.empty(self.n, np.int64)
        stat = np.empty(self.n, np.int64)
        me = np.empty((self.n, 6, 6))
        want_c = c is not None
        ce = np.empty((self.n, 6, 6)) if want_c else np.empty((1, 6, 6))
        cq = np.ascontiguousarray(c, float) if want_c else np.zeros(self.n)
        pmptr, pms, pmm = self._point_mass_csr(point_masses)
        gs = np.ascontiguousarray(gauss_s, float)
        gw = np.ascontiguousarray(gauss_w, float)
        mq = np.ascontiguousarray(m, float)
        dm = np.empty((self.n, 3, 6, 6)) if gradient else np.empty((1, 3, 6, 6))
        _dynamics_batch(chord, self.L0, self.EA, self.w, self._ptr, self._ls, self._lf, h,
                        use_h, tol, max_iter, gs, gw, mq, cq, pmptr, pms, pmm, want_c,
                        gradient, f6, kmat, its, stat, me, ce, dm)
        state = ElementState(h, _sym_from_upper(f6), kmat, its, stat)
        self._last_dynamic = (gs, gw, mq, pmptr, pms, pmm)
        if gradient:
            return state, me, (ce if want_c else None), dm
        return state, me, (ce if want_c else None)

    def element_masses(self, state: ElementState, gauss_s, gauss_w, per_length,
                       point_masses=None) -> np.ndarray:
        """Σ_g q L0 w_g NᵀN (+ Σ_p m_p NᵀN at point masses), (n, 6, 6), about a solved state.

        ``per_length`` (n,) is the mass (or damping coefficient) per unstrained length; the
        same compiled quadrature as :meth:`solve_dynamic`, without solving the elements.
        """
        pmptr, pms, pmm = self._point_mass_csr(point_masses)
        out = np.empty((self.n, 6, 6))
        _mass_batch(np.ascontiguousarray(state.h, float), np.ascontiguousarray(state.K, float),
                    np.ascontiguousarray(state.status, np.int64), self.L0, self.EA, self.w,
                    self._ptr, self._ls, self._lf, np.ascontiguousarray(gauss_s, float),
                    np.ascontiguousarray(gauss_w, float),
                    np.ascontiguousarray(per_length, float), pmptr, pms, pmm, out)
        return out

    def mass_gradient(self, state: ElementState) -> np.ndarray:
        """∂M_e/∂c_k, (n, 3, 6, 6), about the state of the last solve_dynamic (its quadrature
        and point masses)."""
        gs, gw, mq, pmptr, pms, pmm = self._last_dynamic
        out = np.empty((self.n, 3, 6, 6))
        _mass_gradient_batch(self.L0, self.EA, self.w, self._ptr, self._ls, self._lf, state.h,
                             state.K, state.status, gs, gw, mq, pmptr, pms, pmm, out)
        return out

    def _point_mass_csr(self, point_masses):
        """(element, s, mass) arrays -> CSR by element; cached on the arrays' identity (the
        caller passes the same loading arrays at every residual, in a new tuple each time)."""
        key = None if point_masses is None else tuple(id(a) for a in point_masses)
        cached = getattr(self, "_pm_cache", None)
        if cached is not None and cached[0] == key:
            return cached[1]
        if point_masses is None or len(point_masses[0]) == 0:
            csr = (np.zeros(self.n + 1, np.int64), np.zeros(0), np.zeros(0))
        else:
            e, s, mass = (np.asarray(a) for a in point_masses)
            order = np.lexsort((s, e))
            ptr = np.concatenate([[0], np.cumsum(np.bincount(e, minlength=self.n))])
            csr = (ptr.astype(np.int64), np.ascontiguousarray(s[order], float),
                   np.ascontiguousarray(mass[order], float))
        self._pm_cache = (key, csr, point_masses)
        return csr

    def _partial(self, h, s, want_flex: bool):
        h = self._h(h)
        s = self._s(s)
        x = np.empty(s.shape + (3,))
        g = np.empty(s.shape + (6,))
        _partial_batch(h, self.L0, self.EA, self.w, self._ptr, self._ls, self._lf, s, x, g,
                       want_flex)
        return x, g

    def chord(self, h) -> np.ndarray:
        """ℓ(h) = x(L0) - x(0), (n, 3) m (§2)."""
        return self._partial(h, self.L0[:, None], False)[0][:, 0]

    def flexibility(self, h) -> np.ndarray:
        """F(h) = ∂ℓ/∂h, (n, 3, 3) m/N (§3)."""
        return _sym_from_upper(self._partial(h, self.L0[:, None], True)[1][:, 0])

    def position(self, h, s) -> np.ndarray:
        """x(s) - x_i for s (n, q) or (q,), returns (n, q, 3) m."""
        return self._partial(h, s, False)[0]

    def partial_flexibility(self, h, s) -> np.ndarray:
        """G(s) = ∂x(s)/∂h, (n, q, 3, 3) m/N (§6)."""
        return _sym_from_upper(self._partial(h, s, True)[1])

    def tension_vector(self, h, s) -> np.ndarray:
        """t(s), (n, q, 3) N; at a load position the value just before the load."""
        s = self._s(s)
        out = np.empty(s.shape + (3,))
        _tension_batch(self._h(h), self.w, self._ptr, self._ls, self._lf, s, out)
        return out

    def tension(self, h, s) -> np.ndarray:
        """T(s) = |t(s)|, (n, q) N."""
        return np.linalg.norm(self.tension_vector(h, s), axis=-1)

    def end_tensions(self, h) -> np.ndarray:
        """Tension at s = 0 and s = L0 (just inside the element), (n, 2) N."""
        t_i = np.linalg.norm(self._h(h), axis=-1)
        t_j = np.linalg.norm(self.end_forces(h)[:, 1], axis=-1)
        return np.stack([t_i, t_j], axis=1)

    def end_forces(self, h) -> np.ndarray:
        """Resisting forces r_i = -h, r_j = h - Σ f_k + (0, 0, w L0), (n, 2, 3) N (§4).

        These are the forces the nodes must supply to hold the element: the element's
        contribution to the internal force vector.
        """
        h = self._h(h)
        r = np.empty((self.n, 2, 3))
        r[:, 0] = -h
        r[:, 1] = h - self._load_total
        r[:, 1, 2] += self.w * self.L0
        return r

    def interpolation(self, state: ElementState, s) -> np.ndarray:
        """N(s) = [I - G(s) K, G(s) K], (n, q, 3, 6) (§6).

        Slack elements (no tension, no defined catenary) use the straight-line interpolation
        [(1 - s/L0) I, (s/L0) I], which keeps Φ_i + Φ_j = I and the end values.
        """
        s = self._s(s)
        g = self.partial_flexibility(state.h, s)  # (n, q, 3, 3)
        slack = state.status == SLACK
        if slack.any():
            g[slack] = 0.0
        b = g @ np.asarray(state.K)[:, None]  # (n, q, 3, 3)
        if slack.any():
            frac = s[slack] / self.L0[slack, None]  # (n_slack, q)
            b[slack] = frac[..., None, None] * np.eye(3)
        eye = np.eye(3)
        return np.concatenate([eye - b, b], axis=-1)


def kernels_cached() -> bool:
    """Whether numba's on-disk cache already holds the main compiled kernels for this source
    and machine (False: the first call compiles them, about a minute). Uses numba's cache
    index; if that cannot be read, answers True (nothing to announce)."""
    try:
        for f in (_solve_batch, _dynamics_batch, _dynamic_forces, _partial_batch):
            if not f._cache._cache_file._load_index():
                return False
    except Exception:  # numba internals changed: do not guess
        return True
    return True
