"""The iteration matrix of the transient residual for IDA (docs/theory.md §8):

    J = [[c_j I, -I], [K_t(q), c_j M(q) + C(q)]]

from the element state the residual's compiled pass left, with the first-order Lagrangian
inertia terms, and the terms of the water, the seabed, the connectors and the axial damping
where a scene has them. A mixin of :class:`~catdae.solvers.residual.TransientProblem`
(it reads the problem's layout, buffers and configuration cache); the dense/band and the
sparse linear solvers get the same entries in their own storage."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

_S = np.hstack([-np.eye(3), np.eye(3)])  # ∂c/∂(u_i, u_j): chord c = x_j - x_i


class IterationMatrix:
    """∂r/∂y + c_j ∂r/∂y' of a transient problem (methods of TransientProblem)."""

    def blocks(self, conf, cj, V=None, A=None):
        """CSR data (full dofs) of ∂r_v/∂q ≈ K_t and of ∂r_v/∂v + cj ∂r_v/∂v' ≈ cj M + C.

        With the Lagrangian inertia terms (and V, A given) their first-order parts are added:
        ∂(M a)/∂u = Σ_k (∂M/∂c_k a) S_k and ∂g/∂v = Σ_k ċ_k ∂M/∂c_k + Qᵀ S - Sᵀ Q, with
        Q_k = ∂M/∂c_k v, S = ∂c/∂u_e = [-I, I] and g = Ṁ v - ∂T/∂q. The derivatives of ∂M/∂c
        themselves are left out.
        """
        m = self.model
        state, me, ce, dm = conf
        k6 = state.stiffness6
        vv = np.zeros_like(k6)
        if me is not None:
            vv += (cj + self.alpha) * me
        if ce is not None:
            vv += ce
        if self.beta:
            vv += self.beta * k6
        if dm is not None and V is not None:
            ed = m.edofs
            v_e = V[ed]
            a_e = A[ed]
            cdot = v_e[:, 3:] - v_e[:, :3]
            qv = (dm @ v_e[:, None, :, None])[..., 0]  # (n_elem, 3, 6)
            qa = (dm @ a_e[:, None, :, None])[..., 0]
            vv += np.einsum("ek,ekij->eij", cdot, dm)
            vv += np.einsum("eki,kj->eij", qv, _S) - np.einsum("ki,ekj->eij", _S, qv)
            k6 = k6 + np.einsum("eki,kj->eij", qa, _S)
        diag = (cj + self.alpha) * self.m_diag + self.c_diag
        if self.connectors is not None:
            k6, vv = self._connector_blocks(k6, vv, V, cj)
        return m.pattern.assemble(k6), m.pattern.assemble(vv, diag)

    def mass_data(self, conf) -> np.ndarray:
        """CSR data (full dofs) of M(q) (with the added mass of the water, if any)."""
        m = self.model
        me = conf[1] if self.connectors is None else self._with_bar_mass(conf[1])
        if m.fluid is not None:
            z = np.zeros(self.n_dof)
            ma = m.fluid.evaluate(self._cache_t, self._conf_X(), z, z)[1]
            return m.pattern.assemble(me, self.m_diag) + m.pattern.assemble(ma)
        return m.pattern.assemble(me, self.m_diag)

    def _conf_X(self) -> np.ndarray:
        """Node positions (n_dof,) of the configuration last returned by ``configuration``."""
        X = self.X.copy()
        X[self.fidx] = self._cache_q
        X[self.model.fixed] = self._supports(self._cache_t)[0]
        return X

    def ff(self, data: np.ndarray) -> sp.csr_matrix:
        """Free-free block (in the unknowns' order) of full-dof CSR data."""
        return sp.csr_matrix((data[self.ff_sel], (self.ff_a, self.ff_b)), shape=(self.n,) * 2)

    def _jac_parts(self, t, y, yp, cj):
        conf = self.configuration(t, y[0::2])
        if conf is None:
            return None
        V = A = None
        if conf[3] is not None or self.connectors is not None:
            V, A = self.full_vectors(t, y[1::2], yp[1::2])
        kdata, vdata = self.blocks(conf, cj, V, A)
        fl = self.model.fluid
        if fl is not None:  # docs/theory.md §13: ∂(M_a a - f)/∂q and cj M_a - ∂f/∂v
            V, A = self.full_vectors(t, y[1::2], yp[1::2])
            _, ma, kx, kv = fl.evaluate(t, self._conf_X(), V, A, want_jac=True)
            pat = self.model.pattern
            kdata = kdata + pat.assemble(kx)
            vdata = vdata + pat.assemble(cj * ma + kv)
        if self.seabed is not None:  # docs/theory.md §17: -∂f/∂q, -∂f/∂v of the contact
            V, _ = self.full_vectors(t, y[1::2], yp[1::2])
            kdata, vdata = self.seabed.add_derivatives(kdata, vdata, self._conf_X(), V)
        if self.axial is not None:
            vdata = vdata + self.axial.velocity_data(self, t, y, yp, conf)
        sel = self.ff_sel
        return kdata[sel], vdata[sel]

    def jac_dense(self, t, y, yp, res, cj, JJ):
        """Iteration matrix into the full (2n, 2n) array (dense and band solvers)."""
        self.n_jac += 1
        parts = self._jac_parts(t, y, yp, cj)
        JJ[:, :] = 0.0
        idx = np.arange(self.n)
        JJ[2 * idx, 2 * idx] = cj
        JJ[2 * idx, 2 * idx + 1] = -1.0
        if parts is None:  # keep a usable matrix; the residual will reject the state
            JJ[2 * idx + 1, 2 * idx + 1] = cj
            return
        kv, vv = parts
        JJ[2 * self.ff_a + 1, 2 * self.ff_b] = kv
        JJ[2 * self.ff_a + 1, 2 * self.ff_b + 1] = vv

    def jac_sparse(self, t, y, yp, res, cj, JJ):
        """Iteration matrix as the CSC data array of ``j_pattern`` (sparse solver)."""
        self.n_jac += 1
        parts = self._jac_parts(t, y, yp, cj)
        data = np.zeros(self.j_nnz)
        data[self.jmap_qq] = cj
        data[self.jmap_qv] = -1.0
        if parts is None:
            data[self.jmap_vv[self.ff_a == self.ff_b]] = cj
        else:
            kv, vv = parts
            np.add.at(data, self.jmap_vq, kv)
            np.add.at(data, self.jmap_vv, vv)
        JJ[:] = data
