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

# kinds of current and wind
NONE, UNIFORM, PROFILE, POWER, LOG = 0, 1, 2, 3, 4


@njit(cache=True, inline="always")
def _profile(kind, z, vec, zs, vs, speed, direction, expo, z_ref, ground, u, du):
    """Velocity u (3,) and its derivative along z du (3,) of a current or wind at height z."""
    for a in range(3):
        u[a] = 0.0
        du[a] = 0.0
    if kind == UNIFORM:
        for a in range(3):
            u[a] = vec[a]
    elif kind == PROFILE:
        n = zs.shape[0]
        if z <= zs[0]:
            for a in range(3):
                u[a] = vs[0, a]
        elif z >= zs[n - 1]:
            for a in range(3):
                u[a] = vs[n - 1, a]
        else:
            k = np.searchsorted(zs, z) - 1
            dz = zs[k + 1] - zs[k]
            r = (z - zs[k]) / dz
            for a in range(3):
                u[a] = vs[k, a] + r * (vs[k + 1, a] - vs[k, a])
                du[a] = (vs[k + 1, a] - vs[k, a]) / dz
    elif kind == POWER or kind == LOG:
        height = z - ground
        if height <= 0.0:
            return
        if kind == POWER:
            f = (height / z_ref) ** expo
            df = expo * f / height
        else:  # expo holds the roughness length z0
            if height <= expo:
                return
            c = 1.0 / np.log(z_ref / expo)
            f = np.log(height / expo) * c
            df = c / height
        for a in range(3):
            u[a] = speed * f * direction[a]
            du[a] = speed * df * direction[a]


@njit(cache=True, inline="always")
def _depth_ratios(k, z, depth):
    """cosh(k (z + d)) / sinh(k d) and sinh(k (z + d)) / sinh(k d) for z <= 0, without
    overflow (deep water: depth = inf gives exp(k z) for both)."""
    e = np.exp(k * z)
    if np.isinf(depth):
        return e, e
    em = np.exp(-k * (z + 2.0 * depth))
    den = 1.0 - np.exp(-2.0 * k * depth)
    return (e + em) / den, (e - em) / den


@njit(cache=True)
def wave_kinematics(x, y, z, t, surface, depth, amp, omega, wk, cosb, sinb, phase, ramp, dramp,
                    u, a, gu, ga):
    """Surface elevation above the still level at (x, y) and, at height z (local z relative to
    the still level, taken at min(z, 0) above it), the wave particle velocity u (3,),
    acceleration a (3,), velocity gradient gu (3, 3) [gu[i, j] = ∂u_i/∂x_j] and acceleration
    gradient ga (3, 3) of a sum of
    linear (Airy) components with finite-depth dispersion, times the ramp factor ``ramp``
    (with time derivative ``dramp``). docs/theory.md §13.3."""
    zr = z - surface
    clip = zr > 0.0
    if clip:
        zr = 0.0
    eta = 0.0
    for i in range(3):
        u[i] = 0.0
        a[i] = 0.0
        for j in range(3):
            gu[i, j] = 0.0
            ga[i, j] = 0.0
    for c in range(amp.shape[0]):
        kx = wk[c] * cosb[c]
        ky = wk[c] * sinb[c]
        th = kx * x + ky * y - omega[c] * t + phase[c]
        ct = np.cos(th)
        st = np.sin(th)
        eta += amp[c] * ct
        ch, sh = _depth_ratios(wk[c], zr, depth)
        aw = amp[c] * omega[c]
        uh = aw * ch * ct  # horizontal speed along the heading
        uz = aw * sh * st
        duh_dt = aw * omega[c] * ch * st
        duz_dt = -aw * omega[c] * sh * ct
        u[0] += uh * cosb[c]
        u[1] += uh * sinb[c]
        u[2] += uz
        a[0] += ramp * duh_dt * cosb[c] + dramp * uh * cosb[c]
        a[1] += ramp * duh_dt * sinb[c] + dramp * uh * sinb[c]
        a[2] += ramp * duz_dt + dramp * uz
        # gradients: ∂/∂x_h of cos θ = -k_h sin θ; ∂/∂z of ch = k sh, of sh = k ch
        dh_dx = -aw * ch * st
        dz_dx = aw * sh * ct
        kz_h = 0.0 if clip else aw * wk[c] * sh * ct
        kz_z = 0.0 if clip else aw * wk[c] * ch * st
        gu[0, 0] += dh_dx * kx * cosb[c]
        gu[0, 1] += dh_dx * ky * cosb[c]
        gu[0, 2] += kz_h * cosb[c]
        gu[1, 0] += dh_dx * kx * sinb[c]
        gu[1, 1] += dh_dx * ky * sinb[c]
        gu[1, 2] += kz_h * sinb[c]
        gu[2, 0] += dz_dx * kx
        gu[2, 1] += dz_dx * ky
        gu[2, 2] += kz_z
        # acceleration gradient: a = ramp ∂u/∂t + dramp u
        w_ = omega[c]
        hx_ = ramp * aw * w_ * ch * ct - dramp * aw * ch * st  # ∂a_h/∂θ
        zx_ = ramp * aw * w_ * sh * st + dramp * aw * sh * ct  # ∂a_z/∂θ
        hz_ = 0.0 if clip else wk[c] * (ramp * aw * w_ * sh * st + dramp * aw * sh * ct)
        zz_ = 0.0 if clip else wk[c] * (-ramp * aw * w_ * ch * ct + dramp * aw * ch * st)
        ga[0, 0] += hx_ * kx * cosb[c]
        ga[0, 1] += hx_ * ky * cosb[c]
        ga[0, 2] += hz_ * cosb[c]
        ga[1, 0] += hx_ * kx * sinb[c]
        ga[1, 1] += hx_ * ky * sinb[c]
        ga[1, 2] += hz_ * sinb[c]
        ga[2, 0] += zx_ * kx
        ga[2, 1] += zx_ * ky
        ga[2, 2] += zz_
    for i in range(3):
        u[i] *= ramp
        for j in range(3):
            gu[i, j] *= ramp
    return ramp * eta


@njit(cache=True)
def fluid_pass(X, V, A, conn, l0, gs, gw, area, diam, cdn, cda, can, caa, in_weight, mu, g,
               rho_w, surface, depth, c_kind, c_vec, c_z, c_v, c_fac,
               amp, omega, wk, cosb, sinb, phase, ramp, dramp,
               rho_a, a_kind, a_vec, a_speed, a_dir, a_expo, a_zref, a_ground, a_fac,
               t, want_jac, out, ma, kx, kv):
    """Fluid forces on the nodes of every element at time t.

    ``out`` (n_dof,) receives M_a A - f: the added-mass force minus the fluid force (buoyancy
    of the Gauss points not already in the element's weight, drag, Froude-Krylov), i.e. what the
    fluid adds to the dynamic force M A + C V + F - P of the residual. ``ma`` (n_elem, 6, 6)
    receives the element added-mass matrices; with ``want_jac``, ``kx`` and ``kv`` (n_elem, 6, 6)
    the derivatives of ``out`` with respect to the positions and velocities of the element's
    nodes. docs/theory.md §13.
    """
    ne = conn.shape[0]
    ng = gs.shape[1]
    for d in range(out.shape[0]):
        out[d] = 0.0
    tau = np.empty(3)
    xg = np.empty(3)
    vg = np.empty(3)
    ag = np.empty(3)
    uf = np.empty(3)
    af = np.empty(3)
    du = np.empty(3)
    gu = np.zeros((3, 3))
    ga = np.zeros((3, 3))
    ur = np.empty(3)
    un = np.empty(3)
    fg = np.empty(3)
    du_m = np.empty((3, 3))  # ∂f/∂u
    dt_m = np.empty((3, 3))  # ∂f/∂τ (drag and Froude-Krylov)
    ptau = np.empty((3, 3))  # ∂τ/∂c
    pm = np.empty((3, 3))  # P(τ) = Ca (I - ττᵀ) + CaAx ττᵀ
    bsum = np.empty((2, 2))
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
            for c in range(6):
                ma[e, r, c] = 0.0
                if want_jac:
                    kx[e, r, c] = 0.0
                    kv[e, r, c] = 0.0
        bsum[0, 0] = bsum[0, 1] = bsum[1, 0] = bsum[1, 1] = 0.0
        for q in range(ng):
            wq = gw[e, q]
            if wq == 0.0:
                continue
            xi = gs[e, q] / l0[e]
            n1 = 1.0 - xi
            n2 = xi
            for a in range(3):
                xg[a] = n1 * X[i + a] + n2 * X[j + a]
                vg[a] = n1 * V[i + a] + n2 * V[j + a]
                ag[a] = n1 * A[i + a] + n2 * A[j + a]
            eta = 0.0
            for a in range(3):
                af[a] = 0.0
            if has_waves:
                eta = wave_kinematics(xg[0], xg[1], xg[2], t, surface, depth, amp, omega, wk,
                                      cosb, sinb, phase, ramp, dramp, uf, af, gu, ga)
            wet = rho_w > 0.0 and xg[2] <= surface + eta
            if wet:
                rho = rho_w
                _profile(c_kind, xg[2], c_vec, c_z, c_v, 0.0, c_vec, 0.0, 1.0, 0.0, ur, du)
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
            elif rho_a > 0.0:
                rho = rho_a
                _profile(a_kind, xg[2], a_vec, c_z, c_v, a_speed, a_dir, a_expo, a_zref,
                         a_ground, uf, du)
                for a in range(3):
                    uf[a] *= a_fac
                    af[a] = 0.0
                    for b in range(3):
                        gu[a, b] = 0.0
                    gu[a, 2] = a_fac * du[a]
            else:
                rho = 0.0
            wl = wq * l0[e]  # m of unstrained line at this point
            # buoyancy of the point, less what the element's weight already holds
            fb = rho_w * g * area[e] * ((1.0 if wet else 0.0) - in_weight[e])
            if rho == 0.0:
                if fb != 0.0:
                    out[i + 2] -= wl * n1 * fb
                    out[j + 2] -= wl * n2 * fb
                continue
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
            fg[2] += fb
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
                for b in range(3):
                    dug = 0.0
                    for m in range(3):
                        dug += du_m[a, m] * gu[m, b]
                    if wet and has_waves:  # Froude-Krylov: ρ A P_fk(τ) ∇a_f
                        for m in range(3):
                            pfk = (1.0 + can[e]) * ((1.0 if a == m else 0.0) - tau[a] * tau[m]) \
                                + (1.0 + caa[e]) * tau[a] * tau[m]
                            dug += fk * pfk * ga[m, b]
                    dtp = 0.0
                    for m in range(3):
                        dtp += dt_m[a, m] * ptau[m, b]
                    for r in range(2):
                        nr = n1 if r == 0 else n2
                        kv[e, 3 * r + a, b] += wl * nr * du_m[a, b] * n1
                        kv[e, 3 * r + a, 3 + b] += wl * nr * du_m[a, b] * n2
                        kx[e, 3 * r + a, b] -= wl * nr * (dug * n1 - dtp)
                        kx[e, 3 * r + a, 3 + b] -= wl * nr * (dug * n2 + dtp)
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
        if want_jac and (bsum[0, 0] != 0.0 or bsum[1, 1] != 0.0):
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


@njit(cache=True)
def point_kinematics(pts, t, rho_w, surface, depth, c_kind, c_vec, c_z, c_v, c_fac,
                     amp, omega, wk, cosb, sinb, phase, ramp, dramp,
                     rho_a, a_kind, a_vec, a_speed, a_dir, a_expo, a_zref, a_ground, a_fac,
                     eta_out, vel_out):
    """Surface elevation above the still level at the points' (x, y), ``eta_out`` (n,), and the
    fluid velocity at the points, ``vel_out`` (n, 3): current and waves below the surface, wind
    above it (the same kinematics as ``fluid_pass``)."""
    u = np.empty(3)
    a = np.empty(3)
    du = np.empty(3)
    ur = np.empty(3)
    gu = np.zeros((3, 3))
    ga = np.zeros((3, 3))
    for p in range(pts.shape[0]):
        eta = 0.0
        for k in range(3):
            u[k] = 0.0
        if amp.shape[0] > 0:
            eta = wave_kinematics(pts[p, 0], pts[p, 1], pts[p, 2], t, surface, depth, amp,
                                  omega, wk, cosb, sinb, phase, ramp, dramp, u, a, gu, ga)
        eta_out[p] = eta
        if rho_w > 0.0 and pts[p, 2] <= surface + eta:
            _profile(c_kind, pts[p, 2], c_vec, c_z, c_v, 0.0, c_vec, 0.0, 1.0, 0.0, ur, du)
            for k in range(3):
                vel_out[p, k] = u[k] + c_fac * ur[k]
        elif rho_a > 0.0:
            _profile(a_kind, pts[p, 2], a_vec, c_z, c_v, a_speed, a_dir, a_expo, a_zref,
                     a_ground, ur, du)
            for k in range(3):
                vel_out[p, k] = a_fac * ur[k]
        else:
            for k in range(3):
                vel_out[p, k] = 0.0
