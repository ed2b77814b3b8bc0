"""Compiled kernels of the exact 3-D elastic catenary element (docs/theory.md §1-6): the segment
formulas, the element solve, positions, flexibilities and tensions, batched over elements.
The mass kernels are in ``element_mass``; the objects users call are in ``element``.

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
def asinhc(z):
    """asinh(z)/z, stable at z -> 0."""
    az = abs(z)
    if az < 1e-3:
        z2 = z * z
        return 1.0 - z2 / 6.0 + 0.075 * z2 * z2
    return np.arcsinh(z) / z


@njit(cache=True, inline="always")
def segment(hx, hy, v, w, ea, a, b, d, f, want_flex):
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
    p = ell * r * asinhc(w * ell * r)  # ∫ ds/T
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
def partial_solution(h0, h1, h2, w, ea, s_end, ls, lf, k0, k1, d, f, want_flex):
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
            ok = segment(hx, hy, v, w, ea, a, sk, d, f, want_flex) and ok
            a = sk
        hx -= lf[k, 0]
        hy -= lf[k, 1]
        v -= lf[k, 2]
    if s_end > a:
        ok = segment(hx, hy, v, w, ea, a, s_end, d, f, want_flex) and ok
    return ok


@njit(cache=True, inline="always")
def inv_sym3(f, kout):
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
    ok = partial_solution(0.0, 0.0, v, w, ea, l0, np.empty(0), np.empty((0, 3)), 0, 0, d, f, True)
    if ok and np.isfinite(f[0]) and f[0] > 0.0:
        h[0] = c[0] / f[0]
        h[1] = c[1] / f[0]
    else:
        scale = 1e-3 * max(abs(v), w * l0) / max(lh, 1e-300)
        h[0] = c[0] * scale
        h[1] = c[1] * scale
    h[2] = v


@njit(cache=True)
def solve_one(c, l0, ea, w, ls, lf, k0, k1, h, use_h, tol, max_iter, fout, kout,
              polish=True):
    """Newton for one element, warm-started from ``h`` when ``use_h``; a warm start that
    fails (e.g. from a folded vertical state to a taut one) is retried cold.

    ``polish``: once the Newton correction is below ``tol``, take it and evaluate the
    flexibility there once more (h then exact to round-off); without it the last iterate is
    kept, within ``tol`` of the solution, one flexibility evaluation cheaper (the transient
    residual, docs/theory.md §8.2)."""
    it, status = _solve_from(c, l0, ea, w, ls, lf, k0, k1, h, use_h, tol, max_iter, fout, kout,
                             polish)
    if status == NOT_CONVERGED and use_h:
        it2, status = _solve_from(c, l0, ea, w, ls, lf, k0, k1, h, False, tol, max_iter,
                                  fout, kout, polish)
        it += it2
    return it, status


@njit(cache=True)
def _solve_from(c, l0, ea, w, ls, lf, k0, k1, h, use_h, tol, max_iter, fout, kout, polish):
    """Newton with backtracking for one element. Returns (iterations, status)."""
    buf = np.empty(24)  # one allocation for the work vectors (each one costs ~50 ns)
    d = buf[0:3]
    f = buf[3:9]
    dt = buf[9:12]
    ft = buf[12:18]
    ht = buf[18:21]
    dh = buf[21:24]
    kk = kout  # K of the iterates; kout is set from the final flexibility below
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
    ok = partial_solution(h[0], h[1], h[2], w, ea, l0, ls, lf, k0, k1, d, f, True)
    if not ok:
        # a start on a point of zero tension: nudge it
        h[2] += 1e-9 * (hscale_extra + ea * 1e-9)
        ok = partial_solution(h[0], h[1], h[2], w, ea, l0, ls, lf, k0, k1, d, f, True)
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
        if not inv_sym3(f, kk):
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
            if not polish:
                status = CONVERGED
                break
            for m in range(3):
                ht[m] = h[m] + dh[m]
            if partial_solution(ht[0], ht[1], ht[2], w, ea, l0, ls, lf, k0, k1, dt, ft, True):
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
            okt = partial_solution(ht[0], ht[1], ht[2], w, ea, l0, ls, lf, k0, k1, dt, ft, True)
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
        # Hanging straight, its tension vanishing at its lower end (a hanging chain's free
        # end, which the static solve leaves folded by 1e-11 to 1e-9 m: the fold's axial
        # stiffness is only w/2), where Newton met T = 0: within 1e-6 L0 of the hanging length
        # L0 + w L0²/(2 EA), taken as hanging with the tension EA (|Δz| - that) / L0 at its
        # lower end (j if the chord points down, i if up), at least 1e-9 of its weight (the
        # lateral stiffness falls as 1 / log of it), not folded with no lateral stiffness (a
        # spurious zero mode at the free end; tester t78). h: -(w L0 + T_j) or +T_i.
        t_end = ea * (abs(c[2]) - l0 - 0.5 * w * l0 * l0 / ea) / l0
        if abs(t_end) <= 1e-6 * ea:
            h[0] = 0.0
            h[1] = 0.0
            t_low = max(t_end, 1e-9 * w * l0)
            h[2] = -w * l0 - t_low if c[2] < 0.0 else t_low
            if partial_solution(h[0], h[1], h[2], w, ea, l0, ls, lf, k0, k1, d, f, True):
                for m in range(6):
                    fout[m] = f[m]
                if inv_sym3(f, kout):
                    return it, CONVERGED
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
    if not inv_sym3(f, kout):
        kout[:, :] = 0.0
        if status == CONVERGED:
            status = NOT_CONVERGED
    return it, status
