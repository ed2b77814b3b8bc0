"""Compiled batch kernels of the catenary element (docs/theory.md §2-5): the element loop
over a mesh for the end forces and stiffness, the partial flexibility and positions along the
element, the energies and the tensions, and two relations of one element that the transient
kernels share (the end force carried to first order, the end tensions). The other relations of
one element are in ``catenary``."""

from __future__ import annotations

import numpy as np
from numba import njit

from catdae.element.catenary import partial_solution, solve_one


@njit(cache=True, inline="always")
def carry_tension(chord, last, he, ke, limit):
    """he += ke (chord - last): the end force he, solved at chord ``last`` with stiffness ke,
    carried to first order to ``chord``, where that change is at most ``limit`` |he|; False
    (he untouched) else, or where it is not finite."""
    d0 = chord[0] - last[0]
    d1 = chord[1] - last[1]
    d2 = chord[2] - last[2]
    g0 = ke[0, 0] * d0 + ke[0, 1] * d1 + ke[0, 2] * d2
    g1 = ke[1, 0] * d0 + ke[1, 1] * d1 + ke[1, 2] * d2
    g2 = ke[2, 0] * d0 + ke[2, 1] * d1 + ke[2, 2] * d2
    change = g0 * g0 + g1 * g1 + g2 * g2
    if not change <= limit * limit * (he[0] * he[0] + he[1] * he[1] + he[2] * he[2]):
        return False
    he[0] += g0
    he[1] += g1
    he[2] += g2
    return True


@njit(cache=True, inline="always")
def end_tensions(he, load_total_e, w, l0):
    """(|h|, |h - Σ f_k + (0, 0, w L0)|): the tensions just inside both ends of an element
    whose end force at i is he (the second is r_j of the end forces, §4)."""
    jx = he[0] - load_total_e[0]
    jy = he[1] - load_total_e[1]
    jz = he[2] - load_total_e[2] + w * l0
    return (np.sqrt(he[0] * he[0] + he[1] * he[1] + he[2] * he[2]),
            np.sqrt(jx * jx + jy * jy + jz * jz))


@njit(cache=True)
def solve_batch(chord, l0, ea, w, ptr, ls, lf, h, use_h, tol, max_iter, fflat, kmat, its, stat):
    for e in range(chord.shape[0]):
        its[e], stat[e] = solve_one(
            chord[e], l0[e], ea[e], w[e], ls, lf, ptr[e], ptr[e + 1], h[e], use_h, tol,
            max_iter, fflat[e], kmat[e],
        )


@njit(cache=True)
def partial_batch(h, l0, ea, w, ptr, ls, lf, s, xout, gout, want_flex):
    """x(s) and G(s) at s (n, q) for every element: xout (n, q, 3), gout (n, q, 6)."""
    ok_all = True
    for e in range(h.shape[0]):
        for j in range(s.shape[1]):
            ok = partial_solution(h[e, 0], h[e, 1], h[e, 2], w[e], ea[e], s[e, j], ls, lf, ptr[e],
                          ptr[e + 1], xout[e, j], gout[e, j], want_flex)
            ok_all = ok_all and ok
    return ok_all


@njit(cache=True)
def energy_batch(h, l0, ea, w, ptr, ls, lf, xi, wi, out):
    """Per element, out[e, 0]: strain energy ∫ T²/(2 EA) ds, exact (T² is a quadratic in s
    between the loads); out[e, 1]: ∫ w (z(s) - z_i) ds by the Gauss points xi, wi (on [-1, 1])
    on each smooth piece between the loads."""
    d = np.empty(3)
    f = np.empty(6)
    for e in range(h.shape[0]):
        hx, hy, v = h[e, 0], h[e, 1], h[e, 2]
        we = w[e]
        a = 0.0
        acc = 0.0
        for k in range(ptr[e], ptr[e + 1] + 1):
            b = l0[e] if k == ptr[e + 1] else min(max(ls[k], a), l0[e])
            if b > a:  # ∫_a^b hx² + hy² + (v + w s)² ds
                acc += ((hx * hx + hy * hy + v * v) * (b - a) + v * we * (b * b - a * a)
                        + we * we * (b * b * b - a * a * a) / 3.0)
                a = b
            if k < ptr[e + 1]:
                hx -= lf[k, 0]
                hy -= lf[k, 1]
                v -= lf[k, 2]
        out[e, 0] = acc / (2.0 * ea[e])
        g = 0.0
        a = 0.0
        for k in range(ptr[e], ptr[e + 1] + 1):  # Gauss on each smooth piece between loads
            b = l0[e] if k == ptr[e + 1] else min(max(ls[k], a), l0[e])
            if b > a and we != 0.0:
                for j in range(xi.shape[0]):
                    sj = a + 0.5 * (xi[j] + 1.0) * (b - a)
                    partial_solution(h[e, 0], h[e, 1], h[e, 2], we, ea[e], sj, ls, lf, ptr[e],
                             ptr[e + 1], d, f, False)
                    g += 0.5 * wi[j] * (b - a) * we * d[2]
                a = b
        out[e, 1] = g


@njit(cache=True)
def tension_batch(h, w, ptr, ls, lf, s, tout):
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


@njit(cache=True)
def end_tension_batch(h, load_total, w, l0, out):
    """|h| and |h - Σ f_k + (0, 0, w L0)|, the tensions at both ends, into out (n, 2)."""
    for e in range(h.shape[0]):
        out[e, 0], out[e, 1] = end_tensions(h[e], load_total[e], w[e], l0[e])
