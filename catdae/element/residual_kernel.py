"""The transient residual in one compiled pass (docs/theory.md §8).

IDA calls the residual thousands of times per simulated second. Done as separate NumPy steps
(scatter the unknowns, chords, element solve, mass, forces, gather) it spent as much time in
Python between the compiled kernels as in them on meshes of tens of elements
(benchmarks/speed_accuracy.md §7). ``residual_pass`` does all of it in one call and leaves the
element state (tensions, flexibilities, stiffnesses; the masses where asked for) in
the caller's buffers, where the iteration matrix, the envelope and the outputs find it. With
the Lagrangian terms the taut elements' inertia forces are taken without their matrices
(``lagrange.lagrange_one``, docs/theory.md §7.6).

The element work is written out here rather than through ``mass.dynamics_one``: a call
between compiled functions with some forty array arguments cost about 0.6 µs per element
(more than a warm element solve), so the pass calls the solve and the mass kernels directly
and skips the mass entirely for a lumped or constant mass (benchmarks/cheaper_steps.md; the
residuals are bit-identical).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from catdae.element.catenary import CONVERGED, NOT_CONVERGED, SLACK, solve_one
from catdae.element.catenary_batch import (
    carry_tension,
    end_tension_batch,
    energy_batch,
    partial_batch,
)
from catdae.element.lagrange import kinetic_one, lagrange_one
from catdae.element.mass import dynamic_forces, mass_one
from catdae.element.mass_gradient import gradient_fade

CARRY = 0.25  # largest carried change of an element's end force, relative to it


@njit(cache=True)
def residual_pass(y, yp, fidx, fixed, xp, vp, ap, conn, edofs, X, V, A, l0, ea, w, ptr, ls, lf,
                  load_total, wl0, h, hw, use_h, tol, max_iter, gs, gw, mq, cq, pmptr, pms, pmm,
                  want_m, use_m, want_c, use_c, want_dm, scale, alpha, beta, m_diag, v_diag,
                  p_nodal, fflat, kmat, its, stat, me, ce, force, res, energy_only, carried,
                  kin):
    """r_q = q' - v and r_v = M v' + C v + g + F - P on the free dofs, into ``res`` (2n,).

    y = [q, v] and yp interleaved per unknown; unknown k is full dof ``fidx[k]``; the fixed
    dofs ``fixed`` have positions, velocities and accelerations ``xp, vp, ap``. The element
    tensions start from ``h`` and are solved into ``hw``. ``want_m``/``want_c``: build the
    consistent mass and material damping of the elements into ``me``/``ce`` (times ``scale``:
    the consistent share of a blended mass); ``use_m``/``use_c``: use ``me``/``ce`` in the
    forces (given, when constant). ``m_diag`` and ``v_diag`` are the diagonal mass and the
    diagonal damping (lumped parts, Rayleigh α M), ``p_nodal`` the nodal loads.

    ``want_dm`` (the Lagrangian velocity terms): the taut elements' M a and velocity terms go
    straight into the forces (``lagrange_one``, docs/theory.md §7.6) and their ``me`` is not
    built (left as it was); the iteration matrix builds the matrices itself. ``energy_only``
    (n_elements,): elements that get no inertia force at all, only their kinetic energy (an
    output's pass, whose forces are read at the supports only, marks those that touch no
    supported dof; every residual IDA sees has none marked). ``kin`` (n_elements, or empty):
    the elements' kinetic energy ½ v_eᵀ M_e v_e of the consistent share, when given.

    ``carried`` (1,) bool: the buffers ``X``, ``hw``, ``kmat`` and ``stat`` hold a whole
    successful pass (set here). Each taut element's Newton then starts from the tension carried
    from that pass, hw + kmat (c - c_last), whose error is second order in the chord's change
    (one Newton iteration fewer), where that change is below ``CARRY`` of the tension; else
    from ``h`` (docs/theory.md §8.2).

    Returns False, with ``res`` untouched, where an element cannot be solved: the caller
    rejects the trial state.
    """
    n = fidx.shape[0]
    ne = conn.shape[0]
    carry = carried[0] and use_h
    carried[0] = False
    last = np.empty((ne, 3)) if carry else np.empty((0, 3))
    if carry:  # the chords of the last pass, before X is overwritten
        for e in range(ne):
            for a in range(3):
                last[e, a] = X[3 * conn[e, 1] + a] - X[3 * conn[e, 0] + a]
    for k in range(n):
        d = fidx[k]
        X[d] = y[2 * k]
        V[d] = y[2 * k + 1]
        A[d] = yp[2 * k + 1]
    for k in range(fixed.shape[0]):
        d = fixed[k]
        X[d] = xp[k]
        V[d] = vp[k]
        A[d] = ap[k]
    xw = np.empty(3)  # work arrays of the element kernels
    g6 = np.empty(6)
    fg = np.empty((6, 3))
    chord = np.empty(3)
    fx = np.zeros((ne, 6)) if want_dm else np.zeros((0, 6))  # the matrix-free inertia forces
    freed = np.zeros(ne, np.bool_)  # elements whose inertia is in fx, their me not built
    ve6 = np.empty(6)
    ae6 = np.empty(6)
    want_kin = kin.shape[0] == ne
    for e in range(ne):
        if want_kin:
            kin[e] = 0.0
        i = 3 * conn[e, 0]
        j = 3 * conn[e, 1]
        for a in range(3):
            chord[a] = X[j + a] - X[i + a]
        carried_e = carry and stat[e] == CONVERGED
        if not (carried_e and carry_tension(chord, last[e], hw[e], kmat[e], CARRY)):
            for a in range(3):
                hw[e, a] = h[e, a]
        if not want_m:  # a lumped or constant mass: the solve alone
            its[e], stat[e] = solve_one(chord, l0[e], ea[e], w[e], ls, lf, ptr[e], ptr[e + 1],
                                         hw[e], use_h, tol, max_iter, fflat[e], kmat[e], False)
        else:
            its[e], stat[e] = solve_one(chord, l0[e], ea[e], w[e], ls, lf, ptr[e], ptr[e + 1],
                                         hw[e], use_h, tol, max_iter, fflat[e], kmat[e], False)
            if stat[e] == NOT_CONVERGED:
                return False
            k0, k1 = ptr[e], ptr[e + 1]
            done = False
            if want_dm and stat[e] == CONVERGED:
                fade = gradient_fade(hw[e], w[e], l0[e], ls, lf, k0, k1)
                if fade > 0.0:
                    for a in range(6):
                        ve6[a] = V[edofs[e, a]]
                        ae6[a] = A[edofs[e, a]] + alpha * V[edofs[e, a]]
                    if energy_only[e]:  # an output's element off the supports: its energy alone
                        ke = kinetic_one(hw[e], kmat[e], l0[e], ea[e], w[e], ls, lf, k0, k1,
                                         gs[e], gw[e], mq[e], pmptr[e], pmptr[e + 1], pms, pmm,
                                         scale, ve6, xw, g6)
                        done = np.isfinite(ke)
                    else:
                        done, ke = lagrange_one(hw[e], kmat[e], l0[e], ea[e], w[e], ls, lf, k0,
                                                k1, gs[e], gw[e], mq[e], pmptr[e], pmptr[e + 1],
                                                pms, pmm, fade, scale, ve6, ae6, fx[e], g6, fg)
                    if done:
                        freed[e] = True
                        if want_kin:
                            kin[e] = ke
            slack = stat[e] == SLACK
            if not done:
                mass_one(hw[e], kmat[e], slack, l0[e], ea[e], w[e], ls, lf, k0, k1, gs[e],
                          gw[e], mq[e], pmptr[e], pmptr[e + 1], pms, pmm, True, me[e], xw, g6)
            if want_c:
                mass_one(hw[e], kmat[e], slack, l0[e], ea[e], w[e], ls, lf, k0, k1, gs[e],
                          gw[e], cq[e], 0, 0, pms, pmm, False, ce[e], xw, g6)
        if stat[e] == NOT_CONVERGED:
            return False
        for a in range(3):
            if not np.isfinite(hw[e, a]):
                return False
        if scale != 1.0:
            if want_m and not freed[e]:
                for r in range(6):
                    for c in range(6):
                        me[e, r, c] *= scale
            if want_c:
                for r in range(6):
                    for c in range(6):
                        ce[e, r, c] *= scale
    if want_m:  # the elements whose matrix was built: kinetic energy, and M (a + α v) into fx
        for e in range(ne):
            if freed[e]:
                continue
            for r in range(6):
                ve6[r] = V[edofs[e, r]]
                ae6[r] = A[edofs[e, r]] + alpha * ve6[r]
            if want_kin:
                acc = 0.0
                for r in range(6):
                    for c in range(6):
                        acc += ve6[r] * me[e, r, c] * ve6[c]
                kin[e] += 0.5 * acc
            if want_dm:
                for r in range(6):
                    acc = 0.0
                    for c in range(6):
                        acc += me[e, r, c] * ae6[c]
                    fx[e, r] += acc
    # the element matrices in fx where the Lagrangian terms are (no ∂M/∂c matrices here)
    dynamic_forces(edofs, hw, load_total, wl0, me, use_m and not want_dm, ce, use_c, kmat,
                    np.empty((0, 3, 6, 6)), False, alpha, beta, V, A, force)
    for e in range(fx.shape[0]):
        for a in range(6):
            force[edofs[e, a]] += fx[e, a]
    for k in range(n):
        d = fidx[k]
        res[2 * k] = yp[2 * k] - y[2 * k + 1]
        res[2 * k + 1] = force[d] + m_diag[d] * A[d] + v_diag[d] * V[d] - p_nodal[d]
    carried[0] = True
    return True


@njit(cache=True)
def output_batch(k0, k1, Y, YP, XP, VP, AP, P, p_timed, fidx, fixed, conn, edofs, l0, ea, w,
                 ptr, ls, lf, load_total, wl0, h, use_h, gs, gw, mq, cq, pmptr, pms, pmm,
                 want_m, use_m, want_c, use_c, want_dm, scale, alpha, beta, m_diag, v_diag,
                 energy_only, lin_kin, me, ce, xi, wi, i_elem, i_slot, i_s, i_force, node_force,
                 Xo, Vo, Ao, To, Ro, Eo):
    """The outputs k0 <= k < k1 of a transient step from their states Y[k], YP[k] (IDA's y and
    y' interleaved) at support values XP, VP, AP[k] and nodal loads P[k] (P[0] when not
    ``p_timed``): positions, velocities and accelerations (Xo, Vo, Ao, full dofs), end
    tensions To (n_elem, 2), support reactions Ro (the fixed dofs' M A + C V + g + F - P) and
    the energies Eo (kinetic, strain, potential of gravity and constant loads). Each output is
    one ``residual_pass`` (as an output's ``observe`` does, ``energy_only`` the elements off the
    supports) warm-started from the tensions of the one before (``h``, updated), then the
    energies of ``record.potential`` (``i_*``: the loads inside elements, at slot ``i_slot`` of
    element ``i_elem``, arc length in ``i_s`` (n_elem, q)). ``lin_kin``: the kinetic energy of
    a constant (linear) element mass ``me``. Returns k1, or the first output whose elements
    cannot be solved (nothing written for it)."""
    ne = conn.shape[0]
    nd = m_diag.shape[0]
    X = np.zeros(nd)
    V = np.zeros(nd)
    A = np.zeros(nd)
    hw = np.zeros((ne, 3))
    fflat = np.zeros((ne, 6))
    kmat = np.zeros((ne, 3, 3))
    its = np.zeros(ne, np.int64)
    stat = np.zeros(ne, np.int64)
    force = np.zeros(nd)
    res = np.zeros(Y.shape[1])
    carried = np.zeros(1, np.bool_)
    kin = np.zeros(ne)
    en = np.zeros((ne, 2))
    xs = np.zeros((ne, i_s.shape[1], 3))
    gs6 = np.zeros((ne, i_s.shape[1], 6))
    for k in range(k0, k1):
        carried[0] = False
        pk = P[k] if p_timed else P[0]
        if not residual_pass(Y[k], YP[k], fidx, fixed, XP[k], VP[k], AP[k], conn, edofs, X, V, A,
                             l0, ea, w, ptr, ls, lf, load_total, wl0, h, hw, use_h, 1e-12, 100,
                             gs, gw, mq, cq, pmptr, pms, pmm, want_m, use_m, want_c, use_c,
                             want_dm, scale, alpha, beta, m_diag, v_diag, pk, fflat, kmat, its,
                             stat, me, ce, force, res, energy_only, carried, kin):
            return k
        for e in range(ne):
            for a in range(3):
                h[e, a] = hw[e, a]
        use_h = True
        kinetic = 0.0
        for d in range(nd):
            Xo[k, d] = X[d]
            Vo[k, d] = V[d]
            Ao[k, d] = A[d]
            kinetic += 0.5 * m_diag[d] * V[d] * V[d]
        for j in range(fixed.shape[0]):
            d = fixed[j]
            Ro[k, j] = force[d] + m_diag[d] * A[d] + v_diag[d] * V[d] - pk[d]
        end_tension_batch(hw, load_total, w, l0, To[k])
        if want_m:
            for e in range(ne):
                kinetic += kin[e]
        elif lin_kin:
            for e in range(ne):
                acc = 0.0
                for r in range(6):
                    for c in range(6):
                        acc += V[edofs[e, r]] * me[e, r, c] * V[edofs[e, c]]
                kinetic += 0.5 * acc
        energy_batch(hw, l0, ea, w, ptr, ls, lf, xi, wi, en)
        strain = 0.0
        gravity = 0.0
        for e in range(ne):
            strain += en[e, 0]
            gravity += en[e, 1] + wl0[e] * X[3 * conn[e, 0] + 2]
        if i_elem.shape[0] > 0:
            partial_batch(hw, l0, ea, w, ptr, ls, lf, i_s, xs, gs6, False)
            for m in range(i_elem.shape[0]):
                e = i_elem[m]
                for a in range(3):
                    gravity -= i_force[m, a] * (X[3 * conn[e, 0] + a] + xs[e, i_slot[m], a])
        for d in range(nd):
            gravity -= node_force[d] * X[d]
        Eo[k, 0] = kinetic
        Eo[k, 1] = strain
        Eo[k, 2] = gravity
    return k1
