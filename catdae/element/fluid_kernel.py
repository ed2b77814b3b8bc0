"""The fluid loads of the cables in one compiled pass (docs/theory.md §13).

Morison loading at the Gauss points of every element, on the straight-line interpolation of the
element's nodes (N = [(1 - ξ) I, ξ I], the tangent τ along the chord): buoyancy, drag on the
velocity of the fluid relative to the line (normal and axial), added mass (normal and axial)
and Froude-Krylov inertia of the fluid acceleration, in water below the instantaneous surface
and in air above it. ``fluid_pass`` returns the nodal force of the fluid and, on request, its
derivatives for the iteration matrix; it is called only when a scene has a fluid.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from catdae.element.fluid_kinematics import profile, surface_elevation, wave_kinematics


@njit(cache=True)
def _buoyancy(e, i, j, c, b, di, dj, gi, gj, want_jac, out, kx):
    """Buoyancy of element e (c = ρ g A L0 N) on its nodes, integrated exactly along the
    straight chord over the part below the surface (the height above the surface, d(ξ) =
    (1 - ξ) d_i + ξ d_j, linear between the nodes' heights above it), less the share ``b`` (1 or
    0) its weight already holds: ∫ N_a χ dξ in closed form, so that it is continuous in the
    node positions (docs/theory.md §13.1); with ``want_jac`` its derivative into ``kx``
    (``gi``, ``gj``: ∂d/∂x at the nodes)."""
    i1 = i2 = 0.0
    d1_di = d1_dj = d2_di = d2_dj = 0.0
    if di <= 0.0 and dj <= 0.0:
        i1 = i2 = 0.5
    elif di <= 0.0 or dj <= 0.0:
        den = di - dj
        xs = di / den  # where the chord meets the surface
        xs_di = -dj / (den * den)
        xs_dj = di / (den * den)
        if di <= 0.0:  # wet on [0, ξ*]
            i1, i2 = xs - 0.5 * xs * xs, 0.5 * xs * xs
            g1, g2 = 1.0 - xs, xs
        else:  # wet on [ξ*, 1]
            i1, i2 = 0.5 * (1.0 - xs) * (1.0 - xs), 0.5 - 0.5 * xs * xs
            g1, g2 = -(1.0 - xs), -xs
        d1_di, d1_dj, d2_di, d2_dj = g1 * xs_di, g1 * xs_dj, g2 * xs_di, g2 * xs_dj
    out[i + 2] -= c * (i1 - 0.5 * b)
    out[j + 2] -= c * (i2 - 0.5 * b)
    if want_jac and (d1_di != 0.0 or d1_dj != 0.0):
        for a in range(3):
            kx[e, 2, a] -= c * d1_di * gi[a]
            kx[e, 2, 3 + a] -= c * d1_dj * gj[a]
            kx[e, 5, a] -= c * d2_di * gi[a]
            kx[e, 5, 3 + a] -= c * d2_dj * gj[a]


@njit(cache=True)
def _wet_split(X, i, j, t, surface, amp, omega, wk, cosb, sinb, phase, ramp, gi, gj):
    """(d_i, d_j, ξ*, ∂ξ*/∂d_i, ∂ξ*/∂d_j): the nodes' heights above the instantaneous surface
    and where the chord meets it (ξ* = d_i / (d_i - d_j), only meaningful when their signs
    differ); ``gi``, ``gj`` receive ∂d/∂x at the nodes, (-∂η/∂x, -∂η/∂y, 1)."""
    ei, gxi, gyi = surface_elevation(X[i], X[i + 1], t, amp, omega, wk, cosb, sinb, phase,
                                     ramp)
    ej, gxj, gyj = surface_elevation(X[j], X[j + 1], t, amp, omega, wk, cosb, sinb, phase,
                                     ramp)
    gi[0], gi[1], gi[2] = -gxi, -gyi, 1.0
    gj[0], gj[1], gj[2] = -gxj, -gyj, 1.0
    di = X[i + 2] - surface - ei
    dj = X[j + 2] - surface - ej
    xs = xs_di = xs_dj = 0.0
    if (di <= 0.0) != (dj <= 0.0):
        den = di - dj
        xs = di / den
        xs_di = -dj / (den * den)
        xs_dj = di / (den * den)
    return di, dj, xs, xs_di, xs_dj


@njit(cache=True)
def fluid_pass(X, V, A, conn, l0, gs, gw, area, diam, cdn, cda, can, caa, in_weight, mu, g,
               rho_w, surface, depth, c_kind, c_vec, c_z, c_v, c_fac,
               amp, omega, wk, cosb, sinb, phase, ramp, dramp,
               rho_a, a_kind, a_vec, a_speed, a_dir, a_expo, a_zref, a_ground, a_fac,
               t, want_jac, out, ma, kx, kv):
    """Fluid forces on the nodes of every element at time t.

    ``out`` (n_dof,) receives M_a A - f: the added-mass force minus the fluid force (buoyancy
    not already in the element's weight, drag, Froude-Krylov), i.e. what the
    fluid adds to the dynamic force M A + C V + F - P of the residual. ``ma`` (n_elem, 6, 6)
    receives the element added-mass matrices; with ``want_jac``, ``kx`` and ``kv`` (n_elem, 6, 6)
    the derivatives of ``out`` with respect to the positions and velocities of the element's
    nodes. docs/theory.md §13.

    The water acts on the part of the chord below the surface, the air on the rest: an element
    the surface crosses at ξ* has the Gauss rule mapped onto [0, ξ*] and [ξ*, 1] (§13.1), so
    that its loads and added mass are continuous in the node positions; their derivative
    through ξ* is in ``kx``.
    """
    ne = conn.shape[0]
    ng = gs.shape[1]
    for d in range(out.shape[0]):
        out[d] = 0.0
    tau = np.empty(3)
    xg = np.empty(3)
    vg = np.empty(3)
    uf = np.empty(3)
    af = np.empty(3)
    du = np.empty(3)
    gu = np.zeros((3, 3))
    ga = np.zeros((3, 3))
    ur = np.empty(3)
    un = np.empty(3)
    fg = np.empty(3)
    fp = np.empty(3)  # ∂f/∂ξ along the element at fixed nodes
    gi = np.empty(3)
    gj = np.empty(3)
    hxi = np.empty(6)  # ∂out/∂ξ* of the element's nodes
    du_m = np.empty((3, 3))  # ∂f/∂u
    dt_m = np.empty((3, 3))  # ∂f/∂τ (drag and Froude-Krylov)
    ptau = np.empty((3, 3))  # ∂τ/∂c
    pm = np.empty((3, 3))  # P(τ) = Ca (I - ττᵀ) + CaAx ττᵀ
    bsum = np.empty((2, 2))
    dbs = np.empty((2, 2))  # ∂bsum/∂ξ*
    has_waves = amp.shape[0] > 0
    for e in range(ne):
        i = 3 * conn[e, 0]
        j = 3 * conn[e, 1]
        lc = 0.0
        for a in range(3):
            tau[a] = X[j + a] - X[i + a]
            lc += tau[a] * tau[a]
        lc = np.sqrt(lc)
        if lc > 0.0:
            for a in range(3):
                tau[a] /= lc
        else:
            tau[0] = 0.0
            tau[1] = 0.0
            tau[2] = 1.0
            lc = 1.0
        for a in range(3):
            for b in range(3):
                ptau[a, b] = ((1.0 if a == b else 0.0) - tau[a] * tau[b]) / lc
                pm[a, b] = can[e] * ((1.0 if a == b else 0.0) - tau[a] * tau[b]) \
                    + caa[e] * tau[a] * tau[b]
        for r in range(6):
            hxi[r] = 0.0
            for c in range(6):
                ma[e, r, c] = 0.0
                if want_jac:
                    kx[e, r, c] = 0.0
                    kv[e, r, c] = 0.0
        for r in range(2):
            for c in range(2):
                bsum[r, c] = 0.0
                dbs[r, c] = 0.0
        # the wet part of the chord [wa, wb] and the dry part [ya, yb] (their ends' ∂/∂ξ*)
        cross = False
        xs_di = xs_dj = 0.0
        wa, wb, dwa, dwb = 0.0, 0.0, 0.0, 0.0
        ya, yb, dya, dyb = 0.0, 1.0, 0.0, 0.0
        if rho_w > 0.0:
            di, dj, xs, xs_di, xs_dj = _wet_split(X, i, j, t, surface, amp, omega, wk, cosb,
                                                  sinb, phase, ramp, gi, gj)
            if area[e] > 0.0:
                _buoyancy(e, i, j, rho_w * g * area[e] * l0[e], in_weight[e], di, dj, gi, gj,
                          want_jac, out, kx)
            if di <= 0.0 and dj <= 0.0:
                wa, wb, ya, yb = 0.0, 1.0, 1.0, 1.0
            elif di <= 0.0:  # wet on [0, ξ*], dry on [ξ*, 1]
                cross = True
                wa, wb, dwa, dwb = 0.0, xs, 0.0, 1.0
                ya, yb, dya, dyb = xs, 1.0, 1.0, 0.0
            elif dj <= 0.0:  # dry on [0, ξ*], wet on [ξ*, 1]
                cross = True
                wa, wb, dwa, dwb = xs, 1.0, 1.0, 0.0
                ya, yb, dya, dyb = 0.0, xs, 0.0, 1.0
        for med in range(2):
            wet = med == 0
            if wet:
                if rho_w <= 0.0 or (wb <= wa and not cross):
                    continue
                rho, ia, ib, dia, dib = rho_w, wa, wb, dwa, dwb
            else:
                if rho_a <= 0.0 or (yb <= ya and not cross):
                    continue
                rho, ia, ib, dia, dib = rho_a, ya, yb, dya, dyb
            span = ib - ia
            for q in range(ng):
                wq = gw[e, q]
                if wq == 0.0:
                    continue
                sq = gs[e, q] / l0[e]
                xi = ia + span * sq
                n1 = 1.0 - xi
                n2 = xi
                for a in range(3):
                    xg[a] = n1 * X[i + a] + n2 * X[j + a]
                    vg[a] = n1 * V[i + a] + n2 * V[j + a]
                    af[a] = 0.0
                if wet:
                    if has_waves:
                        wave_kinematics(xg[0], xg[1], xg[2], t, surface, depth, amp, omega,
                                        wk, cosb, sinb, phase, ramp, dramp, uf, af, gu, ga)
                    profile(c_kind, xg[2], c_vec, c_z, c_v, 0.0, c_vec, 0.0, 1.0, 0.0, ur, du)
                    if has_waves:
                        for a in range(3):
                            uf[a] += c_fac * ur[a]
                            gu[a, 2] += c_fac * du[a]
                    else:
                        for a in range(3):
                            uf[a] = c_fac * ur[a]
                            for b in range(3):
                                gu[a, b] = 0.0
                            gu[a, 2] = c_fac * du[a]
                else:
                    profile(a_kind, xg[2], a_vec, c_z, c_v, a_speed, a_dir, a_expo, a_zref,
                            a_ground, uf, du)
                    for a in range(3):
                        uf[a] *= a_fac
                        for b in range(3):
                            gu[a, b] = 0.0
                        gu[a, 2] = a_fac * du[a]
                wl = wq * span * l0[e]  # m of unstrained line at this point
                # relative velocity, split along τ
                ut = 0.0
                for a in range(3):
                    ur[a] = uf[a] - vg[a]
                    ut += ur[a] * tau[a]
                nn = 0.0
                for a in range(3):
                    un[a] = ur[a] - ut * tau[a]
                    nn += un[a] * un[a]
                nn = np.sqrt(nn)
                kn = 0.5 * rho * cdn[e] * diam[e]
                kt = 0.5 * rho * cda[e] * np.pi * diam[e]
                aft = 0.0
                for a in range(3):
                    aft += af[a] * tau[a]
                fk = rho * area[e]
                for a in range(3):
                    fg[a] = kn * nn * un[a] + kt * abs(ut) * ut * tau[a]
                    if wet:
                        fg[a] += fk * ((1.0 + can[e]) * (af[a] - aft * tau[a])
                                       + (1.0 + caa[e]) * aft * tau[a])
                for a in range(3):
                    out[i + a] -= wl * n1 * fg[a]
                    out[j + a] -= wl * n2 * fg[a]
                # added mass (water only): the element matrix of the point
                if wet:
                    bq00 = (1.0 - mu) * n1 * n1 + mu * n1
                    bq01 = (1.0 - mu) * n1 * n2
                    bq11 = (1.0 - mu) * n2 * n2 + mu * n2
                    s = rho * area[e] * wl
                    bsum[0, 0] += s * bq00
                    bsum[0, 1] += s * bq01
                    bsum[1, 0] += s * bq01
                    bsum[1, 1] += s * bq11
                if not want_jac:
                    continue
                # ∂f/∂u: drag
                for a in range(3):
                    for b in range(3):
                        pn = (1.0 if a == b else 0.0) - tau[a] * tau[b]
                        du_m[a, b] = 2.0 * kt * abs(ut) * tau[a] * tau[b]
                        if nn > 0.0:
                            du_m[a, b] += kn * (nn * pn + un[a] * un[b] / nn)
                # ∂f/∂τ at fixed u: drag (normal, axial) and Froude-Krylov
                for a in range(3):
                    for b in range(3):
                        dab = 1.0 if a == b else 0.0
                        # ∂(|u_n| u_n)/∂u_n (∂u_n/∂τ = -(τ uᵀ + (τ·u) I))
                        acc = 0.0
                        for m in range(3):
                            jn = 0.0
                            if nn > 0.0:
                                jn = kn * (nn * (1.0 if a == m else 0.0) + un[a] * un[m] / nn)
                            acc -= jn * (tau[m] * ur[b] + ut * (1.0 if m == b else 0.0))
                        acc += kt * (2.0 * abs(ut) * tau[a] * ur[b] + abs(ut) * ut * dab)
                        if wet:
                            acc += fk * (caa[e] - can[e]) * (tau[a] * af[b] + aft * dab)
                        dt_m[a, b] = acc
                # out -= wl N_a f:  ∂/∂x_c = -wl N_a (D_u ∇U N_c + D_τ ∂τ/∂c s_c),
                #                   ∂/∂v_c = wl N_a D_u N_c
                for a in range(3):
                    fp[a] = 0.0
                    for b in range(3):
                        dug = 0.0
                        for m in range(3):
                            dug += du_m[a, m] * gu[m, b]
                        if wet and has_waves:  # Froude-Krylov: ρ A P_fk(τ) ∇a_f
                            for m in range(3):
                                pfk = (1.0 + can[e]) * ((1.0 if a == m else 0.0)
                                                        - tau[a] * tau[m]) \
                                    + (1.0 + caa[e]) * tau[a] * tau[m]
                                dug += fk * pfk * ga[m, b]
                        # f along the element: ∂f/∂x_g (X_j - X_i) + ∂f/∂v_g (V_j - V_i)
                        fp[a] += dug * (X[j + b] - X[i + b]) - du_m[a, b] * (V[j + b]
                                                                            - V[i + b])
                        dtp = 0.0
                        for m in range(3):
                            dtp += dt_m[a, m] * ptau[m, b]
                        for r in range(2):
                            nr = n1 if r == 0 else n2
                            kv[e, 3 * r + a, b] += wl * nr * du_m[a, b] * n1
                            kv[e, 3 * r + a, 3 + b] += wl * nr * du_m[a, b] * n2
                            kx[e, 3 * r + a, b] -= wl * nr * (dug * n1 - dtp)
                            kx[e, 3 * r + a, 3 + b] -= wl * nr * (dug * n2 + dtp)
                if cross:  # the point's weight and place move with ξ*: ∂/∂ξ* of the rule
                    dw = wq * l0[e] * (dib - dia)
                    dxi = dia + sq * (dib - dia)
                    for a in range(3):
                        hxi[a] -= dw * n1 * fg[a] + wl * dxi * (-fg[a] + n1 * fp[a])
                        hxi[3 + a] -= dw * n2 * fg[a] + wl * dxi * (fg[a] + n2 * fp[a])
                    if wet:
                        s = rho * area[e]
                        dbs[0, 0] += s * (dw * bq00 + wl * dxi * (
                            -2.0 * (1.0 - mu) * n1 - mu))
                        d01 = s * (dw * bq01 + wl * dxi * (1.0 - mu) * (n1 - n2))
                        dbs[0, 1] += d01
                        dbs[1, 0] += d01
                        dbs[1, 1] += s * (dw * bq11 + wl * dxi * (2.0 * (1.0 - mu) * n2 + mu))
        # added mass of the element: B ⊗ P(τ), and its force on A; ∂(P a_b)/∂τ for the matrix
        for r in range(2):
            for c in range(2):
                for a in range(3):
                    for b in range(3):
                        ma[e, 3 * r + a, 3 * c + b] = bsum[r, c] * pm[a, b]
        for r in range(6):
            acc = 0.0
            for c in range(6):
                acc += ma[e, r, c] * A[(i if c < 3 else j) + c % 3]
            out[(i if r < 3 else j) + r % 3] += acc
        if not want_jac:
            continue
        if cross:  # ∂out/∂ξ* (drag, Froude-Krylov, added-mass force) times ∂ξ*/∂x
            for r in range(2):
                for a in range(3):
                    h = hxi[3 * r + a]
                    for c in range(2):
                        off = i if c == 0 else j
                        for b in range(3):
                            h += dbs[r, c] * pm[a, b] * A[off + b]
                    for b in range(3):
                        kx[e, 3 * r + a, b] += h * xs_di * gi[b]
                        kx[e, 3 * r + a, 3 + b] += h * xs_dj * gj[b]
        if bsum[0, 0] != 0.0 or bsum[1, 1] != 0.0:
            dca = caa[e] - can[e]
            for c in range(2):
                off = i if c == 0 else j
                ta = 0.0
                for m in range(3):
                    ta += tau[m] * A[off + m]
                # Q_c = ∂(P a_c)/∂τ ∂τ/∂c, into dt_m
                for a in range(3):
                    for b in range(3):
                        acc = 0.0
                        for m in range(3):
                            acc += dca * (tau[a] * A[off + m] + ta * (1.0 if a == m else 0.0)) \
                                * ptau[m, b]
                        dt_m[a, b] = acc
                for r in range(2):
                    for a in range(3):
                        for b in range(3):
                            kx[e, 3 * r + a, b] -= bsum[r, c] * dt_m[a, b]
                            kx[e, 3 * r + a, 3 + b] += bsum[r, c] * dt_m[a, b]
