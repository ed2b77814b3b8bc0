"""Compiled mass kernels of the catenary element (docs/theory.md §6-7): consistent element
mass from the interpolation functions, the complex-step reference of its derivative along the
chord (the analytic one is in ``mass_gradient``), and the dynamic forces of the transient
residual. Batched over elements; see ``element``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from catdae.element.catenary import CONVERGED, SLACK, inv_sym3, partial_solution, solve_one
from catdae.element.mass_gradient import gradient_fade, mass_grad_one


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
            partial_solution(he[0], he[1], he[2], w, ea, gs_e[j], ls, lf, k0, k1, x, g6, True)
        _add_ntn(g6, kk, gs_e[j] / l0, slack, scale_e * l0 * wt, out)
    if with_points:
        for p in range(pm0, pm1):
            if not slack:
                partial_solution(he[0], he[1], he[2], w, ea, pms[p], ls, lf, k0, k1, x, g6, True)
            _add_ntn(g6, kk, pms[p] / l0, slack, pmm[p], out)


@njit(cache=True)
def dynamics_work():
    """Work arrays of ``dynamics_one``: x, g6, fg, dkk, gm, bm, fm, nm, dn."""
    return (np.empty(3), np.empty(6), np.empty((6, 3)), np.empty((3, 3, 3)), np.empty((3, 3)),
            np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 6)), np.empty((3, 6)))


@njit(cache=True)
def dynamics_one(e, chord, l0, ea, w, ptr, ls, lf, h, use_h, tol, max_iter, gs, gw, mq, cq,
                  pmptr, pms, pmm, want_m, want_c, want_dm, fflat, kmat, its, stat, mout, cout,
                  dout, x, g6, fg, dkk, gm, bm, fm, nm, dn):
    """Element e of ``dynamics_batch`` (work arrays from the caller); with ``want_m`` False
    only the solve (a lumped or constant mass)."""
    its[e], stat[e] = solve_one(
        chord, l0[e], ea[e], w[e], ls, lf, ptr[e], ptr[e + 1], h[e], use_h, tol,
        max_iter, fflat[e], kmat[e],
    )
    if not want_m:
        return
    slack = stat[e] == SLACK
    done = False
    if want_dm:
        fade = 0.0
        if stat[e] == CONVERGED:
            fade = gradient_fade(h[e], w[e], l0[e], ls, lf, ptr[e], ptr[e + 1])
        if fade > 0.0:
            done = mass_grad_one(h[e], kmat[e], l0[e], ea[e], w[e], ls, lf, ptr[e],
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
def dynamics_batch(chord, l0, ea, w, ptr, ls, lf, h, use_h, tol, max_iter, gs, gw, mq, cq,
                    pmptr, pms, pmm, want_c, want_dm, fflat, kmat, its, stat, mout, cout, dout):
    """Solve every element and build its consistent mass (and damping) matrix (§6-7), and
    with ``want_dm`` the analytic ∂M_e/∂c_k (n, 3, 6, 6) (zero for slack elements).

    M_e = Σ_g m L0 w_g N(s_g)ᵀ N(s_g) + Σ_p m_p N(s_p)ᵀ N(s_p); C_e the same with c for m
    (point masses carry no material damping). Point masses inside elements: CSR ``pmptr``.
    """
    x, g6, fg, dkk, gm, bm, fm, nm, dn = dynamics_work()
    for e in range(chord.shape[0]):
        dynamics_one(e, chord[e], l0, ea, w, ptr, ls, lf, h, use_h, tol, max_iter, gs, gw, mq,
                      cq, pmptr, pms, pmm, True, want_c, want_dm, fflat, kmat, its, stat, mout,
                      cout, dout, x, g6, fg, dkk, gm, bm, fm, nm, dn)


@njit(cache=True)
def mass_batch(h, kmat, stat, l0, ea, w, ptr, ls, lf, gs, gw, mq, pmptr, pms, pmm, out):
    """Consistent element matrices (n, 6, 6) about solved tensions h (§7); see _mass_one."""
    x = np.empty(3)
    g6 = np.empty(6)
    for e in range(h.shape[0]):
        _mass_one(h[e], kmat[e], stat[e] == SLACK, l0[e], ea[e], w[e], ls, lf, ptr[e],
                  ptr[e + 1], gs[e], gw[e], mq[e], pmptr[e], pmptr[e + 1], pms, pmm, True,
                  out[e], x, g6)


@njit(cache=True)
def mass_gradient_batch(l0, ea, w, ptr, ls, lf, h, kmat, stat, gs, gw, mq, pmptr, pms, pmm,
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
        fade = gradient_fade(he, w[e], l0[e], ls, lf, ptr[e], ptr[e + 1])  # near zero tension
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
            ok = partial_solution(ht[0], ht[1], ht[2], w[e], ea[e], l0[e], ls, lf, ptr[e],
                                  ptr[e + 1], d, f6, True)
            if not ok or not inv_sym3(f6, kk):
                continue
            _mass_one(ht, kk, False, l0[e], ea[e], w[e], ls, lf, ptr[e], ptr[e + 1], gs[e],
                      gw[e], mq[e], pmptr[e], pmptr[e + 1], pms, pmm, True, mt, x, g6)
            for r in range(6):
                for c in range(6):
                    dout[e, k, r, c] = fade * mt[r, c].imag / delta


@njit(cache=True)
def dynamic_forces(edofs, h, load_total, wl0, me, use_m, ce, use_c, kmat, dm, use_dm, alpha,
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
