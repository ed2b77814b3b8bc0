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
from catdae.element.catenary_batch import carry_tension
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
