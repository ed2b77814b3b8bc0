"""The catenary element resting on a rigid, frictionless, flat seabed (docs/theory.md §17).

A seabed at height z_b supports the part of an element that lies on it: there the cable is
straight and horizontal, its tension vector is (Hx, Hy, 0), constant, and the seabed carries its
weight, w per unstrained metre. Off the seabed it is Irvine's elastic catenary (§2). Which part
lies is set by the element's ends (``mode``):

- ``AT_I``: node i rests on the seabed and node j is off it. With h = (Hx, Hy, V) the tension
  vector continued from the suspended part to s = 0 ("virtual" V), the vertical component is
  t_z(s) = max(V + w s, 0): the element lies on [0, s*], s* = clamp(-V/w, 0, L0), and rises as a
  catenary with zero slope at the touchdown point s*. V > 0 is an ordinary element pulling
  node i up (its node then leaves the seabed, decided by the statics).
- ``AT_J``: the mirror, t_z(s) = min(V + w s, 0): suspended on [0, s*], lying on [s*, L0].
- ``LYING``: both ends rest on the seabed: a straight bar, t = (Hx, Hy, 0).
- ``FREE``: no contact (the ordinary element, catdae.element.catenary).

Compatibility (chord ℓ(h)) and flexibility F = ∂ℓ/∂h are the sums of the lying stretch,
ℓ_lie = (Hx, Hy, 0) L_lie (1/EA + 1/H), and of the catenary segment of §2-3 on the suspended
stretch. s* moves with V, but the integrand of ℓ is continuous at s* (the tangent is horizontal
from both sides), so the boundary terms cancel and F is the sum of the two stretches'
flexibilities at fixed s*; F is symmetric, K = F⁻¹. One such element spanning a whole line is
the closed-form grounded catenary (MoorPy's ``catenary``, FAST's MAP): the element is exact at
any mesh, with the touchdown point anywhere inside an element.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from catdae.element.catenary import CONVERGED, NOT_CONVERGED, SLACK, inv_sym3, segment

FREE = 0
AT_I = 1
AT_J = 2
LYING = 3


@njit(cache=True, inline="always")
def _lying(hx, hy, ea, ell, d, f, want_flex):
    """Straight stretch of unstrained length ell lying on the seabed with tension (hx, hy, 0)."""
    if ell <= 0.0:
        return True
    h2 = hx * hx + hy * hy
    hh = np.sqrt(h2)
    if not hh > 0.0:
        return False
    c = ell * (1.0 / ea + 1.0 / hh)
    d[0] += hx * c
    d[1] += hy * c
    if want_flex:
        q = ell / (hh * h2)
        f[0] += c - hx * hx * q
        f[1] -= hx * hy * q
        f[3] += c - hy * hy * q
    return True


@njit(cache=True)
def chord_grounded(hx, hy, v, w, ea, l0, mode, d, f, want_flex):
    """Chord and flexibility of an element with a grounded part; mode AT_I: t_z = max(v+ws,0),
    AT_J: t_z = min(v+ws,0)."""
    for m in range(3):
        d[m] = 0.0
    for m in range(6):
        f[m] = 0.0
    s_star = min(max(-v / w, 0.0), l0)
    if mode == AT_I:
        ok = _lying(hx, hy, ea, s_star, d, f, want_flex)
        ok = segment(hx, hy, v, w, ea, s_star, l0, d, f, want_flex) and ok
    else:
        ok = segment(hx, hy, v, w, ea, 0.0, s_star, d, f, want_flex)
        ok = _lying(hx, hy, ea, l0 - s_star, d, f, want_flex) and ok
    return ok


@njit(cache=True)
def _start(c, l0, ea, w, mode, h):
    """Start for AT_I / AT_J: the inextensible grounded catenary through the chord, by
    bisection on the suspended length l_s (H = w (l_s² - dz²) / (2 dz) for a rise dz)."""
    ch = np.sqrt(c[0] * c[0] + c[1] * c[1])
    dz = c[2] if mode == AT_I else -c[2]
    lc = np.sqrt(ch * ch + c[2] * c[2])
    if dz <= 1e-12 * l0 or ch <= 0.0:
        hh = max(ea * (lc / l0 - 1.0), 1e-6 * w * l0)
        ls = l0 if dz > 0.0 else 0.0
    else:
        lo = dz * (1.0 + 1e-12)
        hi = l0
        def span(ls):
            hh_ = w * (ls * ls - dz * dz) / (2.0 * dz)
            return (l0 - ls) + hh_ / w * np.arcsinh(w * ls / hh_), hh_
        if lo >= hi or span(hi)[0] <= ch:
            ls = l0
            hh = max(ea * (lc / l0 - 1.0), w * (l0 * l0 - min(dz, 0.999 * l0) ** 2)
                     / (2.0 * max(dz, 1e-9 * l0)))
        else:
            for _ in range(100):
                mid = 0.5 * (lo + hi)
                if span(mid)[0] > ch:
                    lo = mid
                else:
                    hi = mid
            ls = 0.5 * (lo + hi)
            hh = span(ls)[1]
    h[0] = hh * c[0] / ch if ch > 0.0 else 0.0
    h[1] = hh * c[1] / ch if ch > 0.0 else 0.0
    ls = min(max(ls, 1e-9 * l0), l0 * (1.0 - 1e-9))
    h[2] = w * ls - w * l0 if mode == AT_I else -w * ls


@njit(cache=True)
def _inside(v, w, l0, mode):
    """V keeps a suspended part (the rise or fall at the free end) in the element."""
    if mode == AT_I:
        return v + w * l0 > 0.0
    return v < 0.0


@njit(cache=True)
def solve_grounded(c, l0, ea, w, mode, h, use_h, tol, max_iter, fout, kout):
    """Newton with backtracking for one element in mode AT_I, AT_J or LYING."""
    if mode == LYING:
        ch = np.sqrt(c[0] * c[0] + c[1] * c[1])
        hh = ea * (ch / l0 - 1.0)
        kout[:, :] = 0.0
        fout[:] = 0.0
        if not hh > 0.0:
            h[:] = 0.0
            return 0, SLACK
        ux = c[0] / ch
        uy = c[1] / ch
        h[0] = hh * ux
        h[1] = hh * uy
        h[2] = 0.0
        ka = ea / l0
        kg = hh / ch
        kout[0, 0] = kg + (ka - kg) * ux * ux
        kout[0, 1] = (ka - kg) * ux * uy
        kout[1, 0] = kout[0, 1]
        kout[1, 1] = kg + (ka - kg) * uy * uy
        # flexibility in the plane (z: none, the element lies flat)
        cflex = l0 * (1.0 / ea + 1.0 / hh)
        fout[0] = cflex - l0 * ux * ux / hh
        fout[1] = -l0 * ux * uy / hh
        fout[3] = cflex - l0 * uy * uy / hh
        return 0, CONVERGED
    d = np.empty(3)
    f = np.empty(6)
    dt = np.empty(3)
    ft = np.empty(6)
    ht = np.empty(3)
    dh = np.empty(3)
    kk = np.empty((3, 3))
    lc = np.sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2])
    rscale = max(l0, lc)
    if not (use_h and _inside(h[2], w, l0, mode)):
        _start(c, l0, ea, w, mode, h)
    ok = chord_grounded(h[0], h[1], h[2], w, ea, l0, mode, d, f, True)
    rn = 0.0
    for m in range(3):
        d[m] -= c[m]
        rn += d[m] * d[m]
    rn = np.sqrt(rn)
    status = NOT_CONVERGED
    it = 0
    while it < max_iter and ok:
        if rn <= 1e-15 * rscale:
            status = CONVERGED
            break
        it += 1
        if not inv_sym3(f, kk):
            break
        hn = 0.0
        dn = 0.0
        for m in range(3):
            dh[m] = -(kk[m, 0] * d[0] + kk[m, 1] * d[1] + kk[m, 2] * d[2])
            hn += h[m] * h[m]
            dn += dh[m] * dh[m]
        hn = np.sqrt(hn) + w * l0
        dn = np.sqrt(dn)
        alpha = 1.0
        accepted = False
        for _ in range(60):
            for m in range(3):
                ht[m] = h[m] + alpha * dh[m]
            okt = _inside(ht[2], w, l0, mode) and chord_grounded(
                ht[0], ht[1], ht[2], w, ea, l0, mode, dt, ft, True)
            rt = 0.0
            for m in range(3):
                dt[m] -= c[m]
                rt += dt[m] * dt[m]
            rt = np.sqrt(rt)
            if okt and np.isfinite(rt) and rt < (1.0 - 1e-4 * alpha) * rn:
                accepted = True
                break
            alpha *= 0.5
        if not accepted:
            if rn <= 1e-12 * rscale:
                status = CONVERGED
            break
        for m in range(3):
            h[m] = ht[m]
            d[m] = dt[m]
        for m in range(6):
            f[m] = ft[m]
        rn = rt
        if alpha == 1.0 and dn <= tol * hn:
            status = CONVERGED
            break
    for m in range(6):
        fout[m] = f[m]
    if not inv_sym3(f, kout):
        kout[:, :] = 0.0
        status = NOT_CONVERGED
    return it, status


@njit(cache=True)
def solve_batch(chord, l0, ea, w, mode, idx, h, use_h, tol, max_iter, fflat, kmat, its, stat):
    """Solve the elements ``idx`` (their modes ``mode[e]``) in place."""
    for k in range(idx.shape[0]):
        e = idx[k]
        its[e], stat[e] = solve_grounded(chord[e], l0[e], ea[e], w[e], mode[e], h[e], use_h,
                                         tol, max_iter, fflat[e], kmat[e])


def end_tensions_z(h, w, l0, mode):
    """z components of t(0) and t(L0) of grounded elements, (n, 2)."""
    t0 = h[:, 2].copy()
    t1 = h[:, 2] + w * l0
    ai = mode == AT_I
    aj = mode == AT_J
    ly = mode == LYING
    t0[ai] = np.maximum(t0[ai], 0.0)
    t1[ai] = np.maximum(t1[ai], 0.0)
    t0[aj] = np.minimum(t0[aj], 0.0)
    t1[aj] = np.minimum(t1[aj], 0.0)
    t0[ly] = 0.0
    t1[ly] = 0.0
    return np.stack([t0, t1], axis=1)


@njit(cache=True)
def _position_one(hx, hy, v, w, ea, l0, mode, s, d, f):
    """x(s) - x_i of a grounded element (into d)."""
    for m in range(3):
        d[m] = 0.0
    if mode == LYING:
        hh = np.sqrt(hx * hx + hy * hy)
        if hh > 0.0:
            c = s * (1.0 / ea + 1.0 / hh)
            d[0] = hx * c
            d[1] = hy * c
        else:  # slack: lies along its chord direction is unknown; stays at node i
            pass
        return
    s_star = min(max(-v / w, 0.0), l0)
    if mode == AT_I:
        _lying(hx, hy, ea, min(s, s_star), d, f, False)
        if s > s_star:
            segment(hx, hy, v, w, ea, s_star, s, d, f, False)
    else:
        segment(hx, hy, v, w, ea, 0.0, min(s, s_star), d, f, False)
        if s > s_star:
            _lying(hx, hy, ea, s - s_star, d, f, False)


@njit(cache=True)
def position_batch(h, w, ea, l0, mode, s, out):
    """x(s) - x_i, (n, q, 3), for elements with mode != FREE (others untouched)."""
    f = np.empty(6)
    for e in range(h.shape[0]):
        if mode[e] == FREE:
            continue
        for j in range(s.shape[1]):
            _position_one(h[e, 0], h[e, 1], h[e, 2], w[e], ea[e], l0[e], mode[e], s[e, j],
                          out[e, j], f)


# --------------------------------------------------------------------------------------------
# The seabed's penalty contact at the nodes (catdae.model.seabed.SeabedContact; §17.5)
@njit(cache=True)
def horizontal_direction(X, a, b):
    """(ê_x, ê_y): the horizontal unit direction from node a to node b (zeros when they are
    one above the other), the line's direction at a contact node from its neighbours."""
    ex = X[b, 0] - X[a, 0]
    ey = X[b, 1] - X[a, 1]
    en = np.sqrt(ex * ex + ey * ey)
    if en > 0.0:
        ex /= en
        ey /= en
    return ex, ey


@njit(cache=True)
def contact_forces(X, V, nodes, nb_a, nb_b, area, zb, k, c, mu_a, mu_l, vs, use_v, out):
    """Force of the seabed on each contact node below z_b, into ``out`` (n_nodes, 3), which
    holds zeros there: N = a k δ up, -a c ż with the velocities, and the smoothed Coulomb
    friction -N M u / sqrt(|u|² + v_s²), M = μ_a ê êᵀ + μ_l (I - ê êᵀ) on the horizontal
    velocity u, ê the horizontal direction of the chord through the node's neighbours."""
    friction = use_v and (mu_a > 0.0 or mu_l > 0.0)
    for p in range(nodes.shape[0]):
        i = nodes[p]
        delta = zb - X[i, 2]
        if delta <= 0.0:
            continue
        n = area[p] * k * delta
        fz = n
        if use_v:
            fz -= area[p] * c * V[i, 2]
        out[i, 2] = fz
        if friction:
            ux, uy = V[i, 0], V[i, 1]
            ex, ey = horizontal_direction(X, nb_a[p], nb_b[p])
            ua = ux * ex + uy * ey
            g = n / np.sqrt(ux * ux + uy * uy + vs * vs)
            out[i, 0] = -g * (mu_l * ux + (mu_a - mu_l) * ua * ex)
            out[i, 1] = -g * (mu_l * uy + (mu_a - mu_l) * ua * ey)


@njit(cache=True)
def contact_derivatives(X, V, nodes, nb_a, nb_b, area, zb, k, c, mu_a, mu_l, vs, use_v, kq, kv):
    """-∂F/∂q and -∂F/∂v of ``contact_forces`` as (p, 3, 3) blocks into kq, kv (zeros on
    entry), ê held fixed: -∂F_z/∂z = a k, -∂F_z/∂ż = a c, -∂F_h/∂z = -a k M u / S and
    -∂F_h/∂u = (N/S) (M - M u uᵀ/S²), S = sqrt(|u|² + v_s²)."""
    friction = use_v and (mu_a > 0.0 or mu_l > 0.0)
    for p in range(nodes.shape[0]):
        i = nodes[p]
        delta = zb - X[i, 2]
        if delta <= 0.0:
            continue
        ak = area[p] * k
        kq[p, 2, 2] = ak
        if use_v:
            kv[p, 2, 2] = area[p] * c
        if friction:
            ux, uy = V[i, 0], V[i, 1]
            ex, ey = horizontal_direction(X, nb_a[p], nb_b[p])
            dm = mu_a - mu_l
            ua = ux * ex + uy * ey
            mx = mu_l * ux + dm * ua * ex
            my = mu_l * uy + dm * ua * ey
            s = np.sqrt(ux * ux + uy * uy + vs * vs)
            kq[p, 0, 2] = -(ak / s) * mx
            kq[p, 1, 2] = -(ak / s) * my
            g = ak * delta / s
            s2 = s * s
            kv[p, 0, 0] = g * (mu_l + dm * ex * ex - mx * ux / s2)
            kv[p, 0, 1] = g * (dm * ex * ey - mx * uy / s2)
            kv[p, 1, 0] = g * (dm * ey * ex - my * ux / s2)
            kv[p, 1, 1] = g * (mu_l + dm * ey * ey - my * uy / s2)
