"""Outputs of a transient computed in batches (docs/theory.md §8.9): IDA's state at each output
time is kept as it is reached, and the positions, tensions, reactions and energies of up to
``BATCH`` outputs are then computed in one compiled call (``residual_kernel.output_batch``).
An output computed on its own (``TransientProblem.observe``) cost about 100 µs of Python
around a 20 µs residual pass on a 10-element line, as much as an integration step: at an
output every 0.05 s, half of a long pendulum run (benchmarks/moordyn_parity.md).

Scenes whose outputs need Python at each output time keep that path: water and air, a
seabed, connectors, axial damping, and loads inside elements that vary in time."""

from __future__ import annotations

import numpy as np

from catdae.element.residual_kernel import output_batch
from catdae.errors import SolverError

BATCH = 256  # outputs kept before they are computed (memory: 2 × BATCH states)
GAUSS8 = np.polynomial.legendre.leggauss(8)  # energy integrals at the outputs (also potential's)


def can_defer(prob) -> bool:
    """Whether the outputs of ``prob`` (a TransientProblem) can be computed in batches."""
    m = prob.model
    return (m.fluid is None and prob.seabed is None and prob.connectors is None
            and prob.axial is None and not m.loading.internal_timed)


class DeferredOutputs:
    """The states kept for the outputs not yet computed, and their batch computation into an
    OutputRecord's arrays."""

    def __init__(self, prob, n_out: int):
        self.prob = prob
        m = prob.model
        n2, nf = 2 * prob.n, prob._fixed.size
        size = min(BATCH, n_out)
        self.Y = np.zeros((size, n2))
        self.YP = np.zeros((size, n2))
        self.XP = np.zeros((size, nf))
        self.VP = np.zeros((size, nf))
        self.AP = np.zeros((size, nf))
        self.p_timed = prob._p_const is None
        self.P = np.zeros((size if self.p_timed else 1, prob.n_dof))
        if not self.p_timed:
            self.P[0] = prob._p_const
        self.t = np.zeros(size)
        self.first = 0  # record index of row 0
        self.count = 0  # rows kept
        # the warm start of the next output: the last one's tensions, at first the step's
        # start (not the integration's latest: the outputs do not depend on when a batch is
        # computed, e.g. before a snapshot)
        self.h = None if prob.h is None else np.array(prob.h, float, copy=True)
        ld = m.loading
        counts = np.diff(ld.internal_ptr)
        self.i_elem = np.repeat(np.arange(m.mesh.n_elements), counts).astype(np.int64)
        self.i_slot = (np.arange(ld.internal_s.size) - ld.internal_ptr[self.i_elem]).astype(
            np.int64)
        self.i_s = np.zeros((m.mesh.n_elements, max(int(counts.max(initial=0)), 1)))
        self.i_s[self.i_elem, self.i_slot] = ld.internal_s
        self.i_force = np.ascontiguousarray(ld.internal_force, float).reshape(-1, 3)
        self.node_force = np.ascontiguousarray(ld.node_force, float).reshape(-1)
        self.lin_kin = bool(prob._use_m and not prob._want_m)
        self.load_kernel()

    def _batch(self, n: int, h, use_h: bool, Xo, Vo, Ao, To, Ro, Eo) -> int:
        """``output_batch`` on the first n rows kept."""
        prob, m = self.prob, self.prob.model
        el = m.elements
        pmptr, pms, pmm = prob._pm
        return output_batch(
            0, n, self.Y, self.YP, self.XP, self.VP, self.AP, self.P, self.p_timed, prob._fidx,
            prob._fixed, prob._conn, prob._edofs, el.L0, el.EA, el.w, el._ptr, el._ls, el._lf,
            el._load_total, prob._wl0, h, use_h, m.gauss_s, m.gauss_w, m.mesh.m, m.mesh.c, pmptr,
            pms, pmm, prob._want_m, prob._use_m, prob._want_c, prob._use_c, prob._want_dm,
            prob._scale, prob.alpha, prob.beta, prob.m_diag, prob._v_diag,
            prob._energy_only_output, self.lin_kin, prob._me, prob._ce, GAUSS8[0], GAUSS8[1],
            self.i_elem, self.i_slot, self.i_s, self.i_force, self.node_force, Xo, Vo, Ao, To,
            Ro, Eo)

    def load_kernel(self) -> None:
        """Load (or compile) the batch kernel now, with an empty batch: at the step's set-up, as
        the residual's kernels are, not in the middle of the run, where a signal that arrives
        while numba loads it can be lost in a destructor (a SIGHUP ignored, the run completed)."""
        ne, nd = self.prob.model.mesh.n_elements, self.prob.n_dof
        out = (np.empty((1, nd)), np.empty((1, nd)), np.empty((1, nd)), np.empty((1, ne, 2)),
               np.empty((1, self.prob._fixed.size)), np.empty((1, 3)))
        self._batch(0, np.zeros((ne, 3)), False, *out)

    def keep(self, k: int, t: float, y, yp) -> bool:
        """Keep output k's state (copied: IDA reuses its arrays); True when the batch is full.
        The outputs of a batch are consecutive (the caller computes the batch first when an
        order race's rollback records earlier outputs again)."""
        if self.count == 0:
            self.first = k
        i = self.count
        self.Y[i] = y
        self.YP[i] = yp
        xp, vp, ap = self.prob._supports(t)
        self.XP[i], self.VP[i], self.AP[i] = xp, vp, ap
        if self.p_timed:
            self.P[i] = self.prob.model.nodal_load(t)
        self.t[i] = t
        self.count += 1
        return self.count == self.Y.shape[0]

    def compute(self, rec) -> None:
        """The outputs kept, into ``rec``'s arrays and its tension envelope; the batch is then
        empty. Raises SolverError (the outputs before it written) where an output's elements
        cannot be solved, as ``observe`` does."""
        n = self.count
        if n == 0:
            return
        prob, m = self.prob, self.prob.model
        ne, nd = m.mesh.n_elements, prob.n_dof
        Xo, Vo, Ao = np.empty((n, nd)), np.empty((n, nd)), np.empty((n, nd))
        To, Ro, Eo = np.empty((n, ne, 2)), np.empty((n, prob._fixed.size)), np.empty((n, 3))
        use_h = self.h is not None
        h = self.h.copy() if use_h else np.zeros((ne, 3))  # updated by the batch
        done = self._batch(n, h, use_h, Xo, Vo, Ao, To, Ro, Eo)
        self.h = h if done > 0 else self.h
        k0 = self.first
        sl = slice(k0, k0 + done)
        rec.X[sl], rec.V[sl], rec.A[sl] = (a[:done].reshape(done, -1, 3) for a in (Xo, Vo, Ao))
        rec.T[sl], rec.E[sl] = To[:done], Eo[:done]
        R = np.full((done, nd), np.nan)
        R[:, m.fixed] = Ro[:done]
        rec.R[sl] = R.reshape(done, -1, 3)
        rec.envelope.update_many(self.t[:done], To[:done])
        rec.n_computed = k0 + done
        self.count = 0  # only now: an interrupt (SIGINT, SIGTERM) before leaves the batch kept
        if done < n:
            raise SolverError(f"output at t = {self.t[done]:.6g} s: an element cannot be solved",
                              termination="element failure")
