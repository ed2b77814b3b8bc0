"""The consistent state of a transient at its start and after each breakpoint of the prescribed
motions (docs/theory.md §8): v' from the equations of motion, and the jump of the free
velocities that keeps their generalised momentum when a support velocity jumps. A mixin of
``residual.TransientProblem``, whose configuration, mass and forces it uses."""

from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla

from catdae.errors import SolverError
from catdae.model.snap import unbalance_forces


class ConsistentStart:
    """``initial`` and ``restart`` of a TransientProblem (see the module docstring)."""

    def initial(self, t0: float, X: np.ndarray, V: np.ndarray):
        """Consistent y0, yp0 at the start, from the previous step's positions and velocities."""
        vs_before = np.asarray(V, float).reshape(-1)[self.model.fixed]
        return self._consistent(t0, X.reshape(-1)[self.fidx], V.reshape(-1)[self.fidx],
                                vs_before, "transient start")

    def restart(self, t: float, y: np.ndarray, t_before: float):
        """Consistent y, yp just after a breakpoint of the prescribed motions or loads at t;
        the support velocities before it are those at ``t_before``."""
        vs_before = self.model.support_values(t_before)[1]
        return self._consistent(t, y[0::2], y[1::2], vs_before, f"restart at t = {t:.6g} s")

    def _consistent(self, t0, q0, v0, vs_before, where):
        """y0, yp0 with v'(0) = M⁻¹ (P - C v - F - coupling) on the free dofs.

        A prescribed support velocity that jumps at t0 (A = a sin ωt after a rest, the corner
        of a linear ramp) acts through an impulsive reaction on the supports only: no impulse
        reaches a free dof, so its generalised momentum p_f = M_ff v_f + M_fs v_s is
        continuous and the free velocities jump by -M_ff⁻¹ M_fs Δv_s. (Keeping v_f instead
        would apply an impulse -M_fs Δv_s to the free dofs; with the consistent catenary mass,
        which amplifies chord motion in slack elements, that impulse grows with the mesh.)
        With a lumped mass M_fs = 0 (but for a bar's consistent mass or the water's
        added mass between a support and a free node) and nothing changes.
        """
        m = self.model
        conf = self.configuration(t0, q0)
        if conf is None:
            raise SolverError(f"{where}: an element cannot be solved in the configuration",
                              termination="initial state")
        mdata = self.mass_data(conf)
        mff = self.ff(mdata).tocsc()
        if where == "transient start":  # for the note on loads that come or go (snaps)
            X = self.X.reshape(-1, 3)
            self.lambda2_start = float(m.element_lambda2(conf[0], X).max(initial=0.0))
            # the force out of balance at the start, against the largest tension, where the
            # step adds or removes something (the note's only use): a load removed whose time
            # function is 0 there changes nothing (tester t75)
            if self.step.add or self.step.remove:
                full_v = np.zeros(X.shape)
                full_v.reshape(-1)[self.fidx] = v0
                self.unbalance_start = float(np.linalg.norm(unbalance_forces(
                    m, conf[0], X, t0, full_v), axis=1).max(initial=0.0)) / max(
                    float(m.tensions(conf[0]).max(initial=0.0)), 1e-300)
        vs_after = self._supports(t0)[1]
        dvs = vs_after - vs_before
        # a jump, not the round-off of two evaluations of a smooth motion
        dvs[np.abs(dvs) <= 1e-12 * max(1.0, float(np.abs(vs_after).max(initial=0.0)))] = 0.0
        if np.any(dvs):
            lam2 = m.element_lambda2(conf[0], self.X.reshape(-1, 3))
            self.velocity_jumps.append((float(t0), float(np.abs(dvs).max()),
                                        float(lam2.max())))
        v0 = np.array(v0, float)
        if np.any(dvs):  # M_fs: zero with a lumped mass, unless bars or water couple
            full = m.pattern.matrix(mdata)
            v0 -= spla.spsolve(mff, full[self.fidx][:, m.fixed] @ dvs)
        if self.axial is not None:  # the chords of q0 for the strain rates
            self.X[self.fidx] = q0
            self.X[m.fixed] = self._supports(t0)[0]
        V_full, A_full = self.full_vectors(t0, v0, np.zeros(self.n))
        f = self.dynamic_force(t0, conf, V_full, A_full)  # M_fp a_p + C v + F - P
        a0 = spla.spsolve(mff, -f[self.fidx])
        y0 = np.empty(2 * self.n)
        yp0 = np.empty(2 * self.n)
        y0[0::2], y0[1::2] = q0, v0
        yp0[0::2], yp0[1::2] = v0, a0
        return y0, yp0
