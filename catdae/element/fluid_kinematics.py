"""The kinematics of the fluid around the cables, compiled (docs/theory.md §13.3): current and
wind profiles, linear (Airy) wave components with finite-depth dispersion, and the surface
elevation and fluid velocity at given points. Used by ``fluid_kernel``."""

from __future__ import annotations

import numpy as np
from numba import njit

# kinds of current and wind
NONE, UNIFORM, PROFILE, POWER, LOG = 0, 1, 2, 3, 4


@njit(cache=True, inline="always")
def profile(kind, z, vec, zs, vs, speed, direction, expo, z_ref, ground, u, du):
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
def surface_elevation(x, y, t, amp, omega, wk, cosb, sinb, phase, ramp):
    """(η, ∂η/∂x, ∂η/∂y): the wave elevation above the still level at (x, y) and its slope."""
    eta = 0.0
    gx = 0.0
    gy = 0.0
    for c in range(amp.shape[0]):
        kx = wk[c] * cosb[c]
        ky = wk[c] * sinb[c]
        th = kx * x + ky * y - omega[c] * t + phase[c]
        eta += amp[c] * np.cos(th)
        s = amp[c] * np.sin(th)
        gx -= s * kx
        gy -= s * ky
    return ramp * eta, ramp * gx, ramp * gy


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
            profile(c_kind, pts[p, 2], c_vec, c_z, c_v, 0.0, c_vec, 0.0, 1.0, 0.0, ur, du)
            for k in range(3):
                vel_out[p, k] = u[k] + c_fac * ur[k]
        elif rho_a > 0.0:
            profile(a_kind, pts[p, 2], a_vec, c_z, c_v, a_speed, a_dir, a_expo, a_zref,
                     a_ground, ur, du)
            for k in range(3):
                vel_out[p, k] = a_fac * ur[k]
        else:
            for k in range(3):
                vel_out[p, k] = 0.0
