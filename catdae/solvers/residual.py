"""The residual and iteration matrix of a transient step for SUNDIALS IDA (docs/theory.md §8).

Unknowns y = [q, v] of the free dofs, interleaved per dof
(q_k, v_k side by side) after a reverse Cuthill-McKee ordering of the free dofs, so that the
iteration matrix of a single cable is narrowly banded. Residual:

    r_q = q' - v
    r_v = M(q) v' + C(q) v + F(q) - P(t)    (+ the support coupling terms M_fp a_p + C_fp v_p)

M(q), C(q) and F(q) come from the current configuration at every residual evaluation: the
element tensions are re-solved (warm-started) for the current chords, then the consistent mass
of the interpolation functions is assembled. The iteration matrix (iteration.py) is analytic:

    J = [[c_j I, -I], [K_t(q), c_j M(q) + C(q)]]

(the derivatives of M(q) v' and C(q) v with respect to q are left out; IDA only needs a good
iteration matrix, docs/theory.md §8). A trial state where an element cannot be solved
is answered with NaN in the residual, which IDA treats as recoverable: it retries with a smaller
step. Output is interpolated by IDA at the output times without shortening its own steps.

Inertia (``inertia`` of a transient step). The paper's form keeps M(q) v' alone. With a
configuration-dependent M(q) that form is not derived from a kinetic energy: the power balance
misses ½ vᵀ Ṁ v, and where M(q) oscillates fast (axial waves in a slack cable change the element
sag, hence N(s) and M, at kHz) this pumps energy into the motion until it blows up (seen on the
paper's example 2, gentle scene, within 3 s). The default ``inertia = "lagrangian"`` adds the
velocity terms of Lagrange's equations for T = ½ vᵀ M(q) v:

    r_v = M v' + Ṁ v - ∂T/∂q + C v + F - P,   Ṁ_e = Σ_k ∂M_e/∂c_k ċ_k

where an element's M_e depends on the nodes only through its chord c = x_j - x_i, so
∂T/∂u_j = -∂T/∂u_i = ½ v_eᵀ (∂M_e/∂c) v_e. ∂M_e/∂c is analytic (forward-mode differentiation of
the segment formulas, in the element pass that builds M_e; docs/theory.md §7.6). The undamped
semi-discrete system is then conservative: the total energy (kinetic + strain + gravity,
recorded as ``energy_total``) drifts only by the integration error, which shrinks as the
tolerance tightens (tests). ``"paper"`` reproduces the paper's equations for comparison; a
lumped mass has no such terms.

"""

from __future__ import annotations

import numpy as np

from catdae.element.elements import NOT_CONVERGED, ElementState, dynamic_forces, sym_from_upper
from catdae.element.residual_kernel import residual_pass
from catdae.errors import SolverError
from catdae.model.assembly import Model
from catdae.model.seabed import SeabedContact
from catdae.model.settings import DampingModel
from catdae.solvers.axial_damping import AxialDamping
from catdae.solvers.connector_terms import ConnectorTerms
from catdae.solvers.iteration import IterationMatrix
from catdae.solvers.layout import UnknownLayout
from catdae.solvers.record import potential
from catdae.solvers.start import ConsistentStart


def _readonly(a: np.ndarray) -> np.ndarray:
    v = np.ascontiguousarray(a, float).view()
    v.flags.writeable = False
    return v


class TransientProblem(ConsistentStart, ConnectorTerms, IterationMatrix):
    """Residual and iteration matrix of one transient step, with evaluation counters."""

    def __init__(self, model: Model, step, X0: np.ndarray, h0: np.ndarray | None):
        self.model = model
        self.step = step
        self.n_dof = model.n_dof
        free = model.free
        if free.size == 0:
            raise SolverError("transient step: the model has no free degree of freedom "
                              "(every node is supported)", termination="no free dof")
        self.layout = UnknownLayout(model.pattern, free, self.n_dof)
        lay = self.layout
        self.fidx, self.n, self.bandwidth = lay.fidx, lay.n, lay.bandwidth
        self.ff_sel, self.ff_a, self.ff_b = lay.ff_sel, lay.ff_a, lay.ff_b
        self.j_pattern, self.j_nnz = lay.j_pattern, lay.j_nnz
        self.jmap_qq, self.jmap_qv = lay.jmap_qq, lay.jmap_qv
        self.jmap_vq, self.jmap_vv = lay.jmap_vq, lay.jmap_vv
        # --- damping
        self.damping = DampingModel.of_step(step.damping)
        self.alpha, self.beta = self.damping.alpha, self.damping.beta
        self.material = self.damping.material
        self.lagrangian = step.inertia == "lagrangian" and model.mass_model.catenary
        nd = model.n_dof
        self.m_diag = model.diagonal_mass()
        self.c_diag = model.diagonal_mass(model.mesh.c) if self.material else np.zeros(nd)
        # --- work arrays and state
        self._wl0 = model.mesh.w * model.mesh.L0
        self._dummy3 = np.zeros((1, 6, 6))
        self._dummy4 = np.zeros((1, 3, 6, 6))
        self._cache_t = None
        self._cache_q = None
        self._cache = None
        self.X = np.array(X0, float).reshape(-1).copy()
        self.h = None if h0 is None else np.array(h0, float, copy=True)
        self._support_t = None
        self.n_res = 0
        self.n_jac = 0
        # (t, largest |Δv_s| m/s, largest element λ²) of each support velocity jump
        self.velocity_jumps: list[tuple[float, float, float]] = []
        self.jump_floor = 0.0  # m/s: smaller support velocity jumps send no wave that counts
        self.n_rejected = 0
        self._fast_setup()
        # the seabed's penalty contact (docs/theory.md §17); None for a scene without one
        self.seabed = SeabedContact.of_step(model)
        self.axial = AxialDamping.of(model, step, self.fidx)  # docs/theory.md §18, or None

    def _fast_setup(self) -> None:
        """Flags and buffers of the compiled residual (``residual_kernel.residual_pass``)."""
        m = self.model
        mm = m.mass_model
        ne = m.mesh.n_elements
        nd = self.n_dof
        consistent = mm.catenary
        self._want_m = consistent
        self._want_c = self.material and consistent
        self._want_dm = self.lagrangian
        self._scale = 1.0 - mm.lumped_fraction if consistent else 1.0
        self._use_m = not mm.lumped
        self._use_c = self.material and not mm.lumped
        self._me = (m.linear_element_mass() if mm.linear else
                    np.zeros((ne, 6, 6)) if consistent else self._dummy3)
        self._ce = (m.linear_element_mass(damping=True) if mm.linear and self.material else
                    np.zeros((ne, 6, 6)) if self._want_c else self._dummy3)
        self._energy_only_none = np.zeros(ne, np.bool_)
        # an output reads the forces at the supports only (reactions)
        self._energy_only_output = ~np.isin(m.edofs, m.fixed).any(axis=1)
        self._fflat = np.zeros((ne, 6))
        self._kmat = np.zeros((ne, 3, 3))
        self._its = np.zeros(ne, np.int64)
        self._stat = np.zeros(ne, np.int64)
        self._hw = np.zeros((ne, 3))
        self._carried = np.zeros(1, np.bool_)  # the buffers hold a whole pass (the kernel's)
        self._kin = np.zeros(ne)  # an output's kinetic energy of the consistent share, per element
        self._no_kin = np.zeros(0)
        self._h_cold = np.zeros((ne, 3))
        self._Xb = np.zeros(nd)
        self._Vb = np.zeros(nd)
        self._Ab = np.zeros(nd)
        self._force = np.zeros(nd)
        damped = self.damping.damped
        self._v_diag = (self.c_diag + self.alpha * self.m_diag) if damped else np.zeros(nd)
        self._buffers_at = None  # (t, q) whose element state the buffers hold
        self._res_scratch = np.zeros(2 * self.n)
        ld = m.loading
        self._pm = m.elements._point_mass_csr((ld.mass_elem, ld.mass_s, ld.mass_value))
        ld = m.loading
        self._p_const = None if ld.node_timed else m.nodal_load(0.0)
        self._fixed = np.ascontiguousarray(m.fixed, np.int64)
        self._x0_fixed = m.mesh.X0.reshape(-1)[m.fixed]  # reference positions of fixed dofs
        self._fidx = np.ascontiguousarray(self.fidx, np.int64)
        self._conn = np.ascontiguousarray(m.mesh.conn, np.int64)
        self._edofs = np.ascontiguousarray(m.edofs, np.int64)

    def evaluate(self, t: float, y: np.ndarray, yp: np.ndarray, res: np.ndarray,
                 output: bool = False) -> bool:
        """The residual at (t, y, yp) into ``res`` in one compiled pass; False (res untouched)
        where an element cannot be solved. The element state stays in the buffers for the
        iteration matrix and the outputs at the same (t, q). ``output``: for ``observe``,
        which reads the forces at the supports only: the inertia forces only of the elements
        that touch a supported dof, the elements' kinetic energies into ``_kin``, and the
        buffers not offered to the iteration matrix or the envelope afterwards."""
        m = self.model
        xp, vp, ap = self._supports(t)
        m.set_time(t)
        el = m.elements
        p = self._p_const if self._p_const is not None else m.nodal_load(t)
        use_h = self.h is not None
        ok = residual_pass(
            y, yp, self._fidx, self._fixed, xp, vp, ap, self._conn, self._edofs, self._Xb,
            self._Vb, self._Ab, el.L0, el.EA, el.w, el._ptr, el._ls, el._lf, el._load_total,
            self._wl0, self.h if use_h else self._h_cold, self._hw, use_h, 1e-12, 100,
            m.gauss_s, m.gauss_w, m.mesh.m, m.mesh.c, *self._pm, self._want_m,
            self._use_m, self._want_c, self._use_c, self._want_dm, self._scale, self.alpha,
            self.beta, self.m_diag, self._v_diag, p, self._fflat, self._kmat, self._its,
            self._stat, self._me, self._ce, self._force, res,
            self._energy_only_output if output else self._energy_only_none, self._carried,
            self._kin if output else self._no_kin)
        if not ok:
            self._buffers_at = None
            return False
        if self.axial is not None:
            self.axial.add_residual(res, self._Xb, self._Vb, self._hw, self._kmat)
        if self.connectors is not None:  # springs, dampers, bars (docs/theory.md §15)
            self._add_connector_force(res)
        self.h = self._hw.copy()
        self.X[:] = self._Xb
        self._buffers_at = None if output else (t, np.array(y[0::2], copy=True))
        if m.fluid is not None:  # water and air: M_a A - f (docs/theory.md §13)
            res[1::2] += m.fluid.evaluate(t, self._Xb, self._Vb, self._Ab)[0][self._fidx]
        if self.seabed is not None:  # the seabed's force on the nodes (docs/theory.md §17)
            res[1::2] -= self.seabed.forces(self._Xb.reshape(-1, 3),
                                            self._Vb.reshape(-1, 3)).ravel()[self._fidx]
        return True

    # what the next evaluation starts from: the last pass's buffers and the carried Newton start
    _START_BUFFERS = ("_hw", "_kmat", "_stat", "_its", "_fflat", "_Xb", "_carried", "X")

    def start_state(self):
        """Copies of what the next ``evaluate`` starts from (the tensions, the last pass's
        buffers with its carried Newton start), for ``restore_start``: an IDA that goes on
        after another ran from the same state (a lost order race) then evaluates exactly as if
        the other had not run."""
        arrays = [getattr(self, name).copy() for name in self._START_BUFFERS]
        # the axial damping's chord rates, which the envelope's carry reads too
        rates = None if self.axial is None else (self.axial.g.copy(), self.axial.edot.copy())
        return (None if self.h is None else self.h.copy(), self._buffers_at, arrays, rates)

    def restore_start(self, saved) -> None:
        h, self._buffers_at, arrays, rates = saved
        self.h = None if h is None else h.copy()
        for name, a in zip(self._START_BUFFERS, arrays, strict=True):
            getattr(self, name)[...] = a
        if rates is not None:
            self.axial.g[...], self.axial.edot[...] = rates

    def _conf_from_buffers(self):
        """(state, M_e, C_e, None) of the last successful ``evaluate`` (copies), without the
        Lagrangian terms (their pass builds no matrices, and is not read here)."""
        state = ElementState(self.h, sym_from_upper(self._fflat), self._kmat.copy(),
                             self._its.copy(), self._stat.copy())
        me = self._me.copy() if self._want_m else (self._me if self._use_m else None)
        ce = self._ce.copy() if self._want_c else (self._ce if self._use_c else None)
        return state, me, ce, None

    # ------------------------------------------------------------------ pieces
    def _supports(self, t: float):
        if self._support_t != t:
            m = self.model
            u, v, a = m.support_values(t)
            self._sup = (self._x0_fixed + u, v, a)
            self._support_t = t
        return self._sup

    def configuration(self, t: float, q: np.ndarray):
        """(state, M_e, C_e) for free positions q at time t, or None if an element fails.

        The last evaluation is cached: IDA calls the iteration matrix at the state of the
        residual it has just evaluated.
        """
        if self.connectors is not None:
            self._place(t, q)
        if self._cache_t == t and np.array_equal(self._cache_q, q):
            return self._cache
        at = self._buffers_at
        # the Lagrangian pass builds no matrices (§7.6): then the elements are solved again
        if (at is not None and not self._want_dm and at[0] == t
                and np.array_equal(at[1], q)):
            out = self._conf_from_buffers()
            self._cache_t, self._cache_q, self._cache = t, at[1], out
            return out
        m = self.model
        xp, _, _ = self._supports(t)
        self.X[self.fidx] = q
        self.X[m.fixed] = xp
        m.set_time(t)
        out = m.dynamic_state(self.X.reshape(-1, 3), self.h, self.material,
                              gradient=self.lagrangian)
        state = out[0]
        if (state.status == NOT_CONVERGED).any() or not np.all(np.isfinite(state.h)):
            out = None
        else:
            self.h = state.h
        self._cache_t, self._cache_q, self._cache = t, np.array(q, copy=True), out
        return out

    def full_vectors(self, t: float, v: np.ndarray, vd: np.ndarray, out=None):
        """Velocities and accelerations of every dof (n_dof,) from those of the unknowns and the
        supports' at t; into ``out`` = (V, A) when given (every entry is overwritten)."""
        m = self.model
        _, vp, ap = self._supports(t)
        V, A = (np.zeros(self.n_dof), np.zeros(self.n_dof)) if out is None else out
        V[self.fidx] = v
        A[self.fidx] = vd
        V[m.fixed] = vp
        A[m.fixed] = ap
        return V, A

    def dynamic_force(self, t, conf, V, A):
        """M A + C V + g + F - P on the full dof set, (n_dof,) N (one compiled pass)."""
        m = self.model
        state, me, ce, dm = conf
        el = m.elements
        out = np.empty(self.n_dof)
        damped = self.damping.damped
        dynamic_forces(m.edofs, state.h, el._load_total, self._wl0,
                        me if me is not None else self._dummy3, me is not None,
                        ce if ce is not None else self._dummy3, ce is not None, state.K,
                        dm if dm is not None else self._dummy4, dm is not None,
                        self.alpha if damped else 0.0, self.beta if damped else 0.0, V, A, out)
        out += self.m_diag * A - m.nodal_load(t)
        if damped:
            out += (self.c_diag + self.alpha * self.m_diag) * V
        if self.connectors is not None:
            out += self.connectors.force(self.X, V, A, self.alpha)
        if m.fluid is not None:
            out += m.fluid.evaluate(t, self._conf_X(), V, A)[0]
        if self.seabed is not None:
            out -= self.seabed.forces(self._conf_X().reshape(-1, 3), V.reshape(-1, 3)).ravel()
        if self.axial is not None:
            self.axial.add_forces(out, self.X, V, state)
        return out

    # ------------------------------------------------------------------ IDA callbacks
    def resfn(self, t, y, yp, res):
        self.n_res += 1
        try:
            if not self.evaluate(t, y, yp, res):
                self.n_rejected += 1
                res[:] = np.nan
        except (FloatingPointError, ValueError, ZeroDivisionError, np.linalg.LinAlgError):
            self.n_rejected += 1
            res[:] = np.nan

    # ------------------------------------------------------------------ output
    def observe(self, t: float, y: np.ndarray, yp: np.ndarray):
        """Positions, velocities, accelerations, tensions, reactions and energies at t (one
        compiled residual pass leaves the element state and forces in the buffers)."""
        # read-only views, as IDA passes them: one compiled signature of the pass, not two
        y, yp = _readonly(y), _readonly(yp)
        # the step's own buffers are put back after: the tension envelope carries the end
        # forces of the step's end from them (§18.3), and IDA evaluates it there after an
        # output inside the step (§8.8); without them it solved every element afresh
        saved = self.start_state()
        try:
            return self._observe(t, y, yp)
        finally:
            self.restore_start(saved)

    def _observe(self, t: float, y: np.ndarray, yp: np.ndarray):
        m = self.model
        if not self.evaluate(t, y, yp, self._res_scratch, output=True):
            raise SolverError(f"output at t = {t:.6g} s: an element cannot be solved",
                              termination="element failure")
        h = self.h  # a copy of the buffer, made by evaluate
        X, V, A = self._Xb.copy(), self._Vb.copy(), self._Ab.copy()
        p = self._p_const if self._p_const is not None else m.nodal_load(t)
        f = self._force + self.m_diag * A + self._v_diag * V - p  # M A + C V + g + F - P
        if m.fluid is not None:
            f += m.fluid.out  # M_a A - f_fluid, left by evaluate
        tension = m.elements.end_tensions(h)
        if self.axial is not None:  # evaluate left the rates of this state
            tension = self.axial.add_to_output(f, tension)
        reaction = np.full(self.n_dof, np.nan)
        reaction[m.fixed] = f[m.fixed]
        kinetic = 0.5 * float(self.m_diag @ (V * V))
        if self._want_m:  # left by evaluate, with or without the element matrices
            kinetic += float(self._kin.sum())
        elif self._use_m:  # a constant (linear) mass
            v_e = V[m.edofs]
            kinetic += 0.5 * float(np.einsum("ei,eij,ej->", v_e, self._me, v_e))
        strain, gravity = potential(m, X.reshape(-1, 3), h, t)
        if self.seabed is not None:  # the contact springs' energy (docs/theory.md §17)
            gravity += self.seabed.energy(X.reshape(-1, 3))
        if self.connectors is not None:
            kinetic, strain = self._connector_energies(X, V, kinetic, strain)
        return (X, V, A, tension, reaction.reshape(-1, 3),
                (kinetic, strain, gravity))

