"""Nonlinear transient dynamics with SUNDIALS IDA (docs/theory.md §8).

The only module that imports sksundae. Unknowns y = [q, v] of the free dofs, interleaved per dof
(q_k, v_k side by side) after a reverse Cuthill-McKee ordering of the free dofs, so that the
iteration matrix of a single cable is narrowly banded. Residual:

    r_q = q' - v
    r_v = M(q) v' + C(q) v + F(q) - P(t)    (+ the support coupling terms M_fp a_p + C_fp v_p)

M(q), C(q) and F(q) come from the current configuration at every residual evaluation: the
element tensions are re-solved (warm-started) for the current chords, then the consistent mass
of the interpolation functions is assembled. The iteration matrix is analytic:

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

BDF order (``max_order = "auto"``, the default): OrderChoice measures whether order 5 is held
down by the stability of the mesh's fast modes and then goes on at order 2 (docs/theory.md
§8.6).
"""

from __future__ import annotations

import time as _time
import warnings

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
import xarray as xr
from scipy.sparse.csgraph import reverse_cuthill_mckee
from sksundae.ida import IDA

from . import results
from .assembly import Model
from .element import NOT_CONVERGED, ElementState, _dynamic_forces
from .errors import SolverError
from .progress import reporter

INCREMENT_SECONDS = 20.0  # wall time between incremental writes of a long run
STALL_STEP = 1e-12  # a step shorter than this (relative to t or the output interval) ...
STALL_COUNT = 200  # ... this many times in a row stops the step as stuck
_S = np.hstack([-np.eye(3), np.eye(3)])  # ∂c/∂(u_i, u_j): chord c = x_j - x_i
_GAUSS8 = np.polynomial.legendre.leggauss(8)  # energy integrals at the outputs


class TransientProblem:
    """Residual and iteration matrix of one transient step, with evaluation counters."""

    def __init__(self, model: Model, step, X0: np.ndarray, h0: np.ndarray | None):
        self.model = model
        self.step = step
        self.n_dof = model.n_dof
        free = model.free
        if free.size == 0:
            raise SolverError("transient step: the model has no free degree of freedom "
                              "(every node is supported)", termination="no free dof")
        # --- ordering: reverse Cuthill-McKee on the free-free stiffness graph
        pat = model.pattern
        full = sp.csr_matrix((np.ones(pat.nnz), pat.indices, pat.indptr),
                             shape=(self.n_dof, self.n_dof))
        ff = full[free][:, free]
        perm = np.asarray(reverse_cuthill_mckee(ff.tocsr(), symmetric_mode=True), np.int64)
        self.fidx = free[perm]  # full dof of unknown k
        self.n = self.fidx.size
        pos = np.full(self.n_dof, -1, np.int64)
        pos[self.fidx] = np.arange(self.n)
        rows = np.repeat(np.arange(self.n_dof), np.diff(pat.indptr))
        cols = pat.indices.astype(np.int64)
        keep = (pos[rows] >= 0) & (pos[cols] >= 0)
        self.ff_sel = np.flatnonzero(keep)  # entries of the full CSR data in the ff block
        self.ff_a = pos[rows[keep]]
        self.ff_b = pos[cols[keep]]
        self.bandwidth = int(np.abs(self.ff_a - self.ff_b).max(initial=0))
        # --- sparse pattern of J (interleaved): rows 2a (q) and 2a+1 (v)
        a, b = self.ff_a, self.ff_b
        n = self.n
        jr = np.concatenate([2 * np.arange(n), 2 * np.arange(n), 2 * a + 1, 2 * a + 1])
        jc = np.concatenate([2 * np.arange(n), 2 * np.arange(n) + 1, 2 * b, 2 * b + 1])
        keys = jc * (2 * n) + jr  # column-major for CSC
        ukeys, inv = np.unique(keys, return_inverse=True)
        self.j_nnz = ukeys.size
        jcsc_rows = (ukeys % (2 * n)).astype(np.int32)
        jcsc_cols = ukeys // (2 * n)
        indptr = np.concatenate([[0], np.cumsum(np.bincount(jcsc_cols, minlength=2 * n))])
        self.j_pattern = sp.csc_matrix((np.ones(self.j_nnz), jcsc_rows, indptr),
                                       shape=(2 * n, 2 * n))
        m = a.size
        self.jmap_qq = inv[:n]
        self.jmap_qv = inv[n:2 * n]
        self.jmap_vq = inv[2 * n:2 * n + m]
        self.jmap_vv = inv[2 * n + m:]
        # --- damping
        self.damping = step.damping
        self.alpha = self.beta = 0.0
        if self.damping is not None and self.damping.kind == "rayleigh":
            self.alpha, self.beta = self.damping.coefficients()
        self.material = self.damping is not None and self.damping.kind == "material"
        self.lagrangian = step.inertia == "lagrangian" and (
            model.mass_model in ("consistent", "blended"))
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
        self.n_rejected = 0

    # ------------------------------------------------------------------ pieces
    def _supports(self, t: float):
        if self._support_t != t:
            m = self.model
            u, v, a = m.support_values(t)
            self._sup = (m.mesh.X0.reshape(-1)[m.fixed] + u, v, a)
            self._support_t = t
        return self._sup

    def configuration(self, t: float, q: np.ndarray):
        """(state, M_e, C_e) for free positions q at time t, or None if an element fails.

        The last evaluation is cached: IDA calls the iteration matrix at the state of the
        residual it has just evaluated.
        """
        if self._cache_t == t and np.array_equal(self._cache_q, q):
            return self._cache
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

    def full_vectors(self, t: float, v: np.ndarray, vd: np.ndarray):
        m = self.model
        _, vp, ap = self._supports(t)
        V = np.zeros(self.n_dof)
        A = np.zeros(self.n_dof)
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
        damped = self.damping is not None
        _dynamic_forces(m.edofs, state.h, el._load_total, self._wl0,
                        me if me is not None else self._dummy3, me is not None,
                        ce if ce is not None else self._dummy3, ce is not None, state.K,
                        dm if dm is not None else self._dummy4, dm is not None,
                        self.alpha if damped else 0.0, self.beta if damped else 0.0, V, A, out)
        out += self.m_diag * A - m.nodal_load(t)
        if damped:
            out += (self.c_diag + self.alpha * self.m_diag) * V
        return out

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
        return m.pattern.assemble(k6), m.pattern.assemble(vv, diag)

    def mass_data(self, conf) -> np.ndarray:
        """CSR data (full dofs) of M(q)."""
        return self.model.pattern.assemble(conf[1], self.m_diag)

    def ff(self, data: np.ndarray) -> sp.csr_matrix:
        """Free-free block (in the unknowns' order) of full-dof CSR data."""
        return sp.csr_matrix((data[self.ff_sel], (self.ff_a, self.ff_b)), shape=(self.n,) * 2)

    # ------------------------------------------------------------------ IDA callbacks
    def resfn(self, t, y, yp, res):
        self.n_res += 1
        try:
            conf = self.configuration(t, y[0::2])
            if conf is None:
                self.n_rejected += 1
                res[:] = np.nan
                return
            V, A = self.full_vectors(t, y[1::2], yp[1::2])
            f = self.dynamic_force(t, conf, V, A)
            res[0::2] = yp[0::2] - y[1::2]
            res[1::2] = f[self.fidx]
        except (FloatingPointError, ValueError, ZeroDivisionError, np.linalg.LinAlgError):
            self.n_rejected += 1
            res[:] = np.nan

    def _jac_parts(self, t, y, yp, cj):
        conf = self.configuration(t, y[0::2])
        if conf is None:
            return None
        V = A = None
        if conf[3] is not None:
            V, A = self.full_vectors(t, y[1::2], yp[1::2])
        kdata, vdata = self.blocks(conf, cj, V, A)
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

    # ------------------------------------------------------------------ start and output
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
        With a lumped mass M_fs = 0 and nothing changes.
        """
        m = self.model
        conf = self.configuration(t0, q0)
        if conf is None:
            raise SolverError(f"{where}: an element cannot be solved in the configuration",
                              termination="initial state")
        mdata = self.mass_data(conf)
        mff = self.ff(mdata).tocsc()
        vs_after = self._supports(t0)[1]
        dvs = vs_after - vs_before
        # a jump, not the round-off of two evaluations of a smooth motion
        dvs[np.abs(dvs) <= 1e-12 * max(1.0, float(np.abs(vs_after).max(initial=0.0)))] = 0.0
        if np.any(dvs):
            lam2 = m.element_lambda2(conf[0], self.X.reshape(-1, 3))
            self.velocity_jumps.append((float(t0), float(np.abs(dvs).max()),
                                        float(lam2.max())))
        v0 = np.array(v0, float)
        if np.any(dvs) and m.mass_model != "lumped":
            full = m.pattern.matrix(mdata)
            v0 -= spla.spsolve(mff, full[self.fidx][:, m.fixed] @ dvs)
        V_full, A_full = self.full_vectors(t0, v0, np.zeros(self.n))
        f = self.dynamic_force(t0, conf, V_full, A_full)  # M_fp a_p + C v + F - P
        a0 = spla.spsolve(mff, -f[self.fidx])
        y0 = np.empty(2 * self.n)
        yp0 = np.empty(2 * self.n)
        y0[0::2], y0[1::2] = q0, v0
        yp0[0::2], yp0[1::2] = v0, a0
        return y0, yp0

    def observe(self, t: float, y: np.ndarray, yp: np.ndarray):
        """Positions, velocities, accelerations, tensions, reactions and energies at t."""
        m = self.model
        conf = self.configuration(t, y[0::2])
        if conf is None:
            raise SolverError(f"output at t = {t:.6g} s: an element cannot be solved",
                              termination="element failure")
        state = conf[0]
        V, A = self.full_vectors(t, y[1::2], yp[1::2])
        X = self.X.copy()
        f = self.dynamic_force(t, conf, V, A)
        reaction = np.full(self.n_dof, np.nan)
        reaction[m.fixed] = f[m.fixed]
        kinetic = 0.5 * V @ (m.pattern.matrix(self.mass_data(conf)) @ V)
        strain, gravity = _potential(m, X.reshape(-1, 3), state, t)
        return (X, V, A, m.tensions(state), reaction.reshape(-1, 3),
                (kinetic, strain, gravity))


def _potential(model: Model, X: np.ndarray, state: ElementState, t: float):
    """Strain energy ∫T²/(2EA) ds and potential of gravity and constant loads, J (loads with a
    time function have no potential: their work changes the total energy)."""
    mesh = model.mesh
    el = model.elements
    xi, wi = _GAUSS8
    s = 0.5 * (xi + 1.0)[None, :] * mesh.L0[:, None]  # (n_elem, 8)
    wq = 0.5 * wi[None, :] * mesh.L0[:, None]
    tens = el.tension(state.h, s)  # (n_elem, 8)
    strain = float(np.sum(wq * tens**2 / (2.0 * mesh.EA[:, None])))
    z = X[mesh.conn[:, 0], 2][:, None] + el.position(state.h, s)[..., 2]
    gravity = float(np.sum(wq * mesh.w[:, None] * z))
    # loads inside elements (point-mass weights, constant loads) and at nodes
    ld = model.loading
    if ld.internal_s.size:
        counts = np.diff(ld.internal_ptr)
        e_of = np.repeat(np.arange(mesh.n_elements), counts)
        sq = np.zeros((mesh.n_elements, max(int(counts.max()), 1)))
        slot = np.arange(ld.internal_s.size) - ld.internal_ptr[e_of]
        sq[e_of, slot] = ld.internal_s
        xk = X[mesh.conn[:, 0]][:, None, :] + el.position(state.h, sq)
        gravity -= float(np.sum(ld.internal_force * xk[e_of, slot]))
    # only the constant loads have a potential; the work of loads that vary in time (like that
    # of moving supports) changes the total energy instead
    gravity -= float(ld.node_force.reshape(-1) @ X.reshape(-1))
    return strain, gravity


def choose_solver(problem: TransientProblem, requested: str) -> str:
    """'band' when the band is narrow, 'sparse' for networks with a wide band, 'dense' tiny."""
    if requested != "auto":
        return requested
    n2 = 2 * problem.n
    band = 4 * problem.bandwidth + 3
    if n2 <= 24:
        return "dense"
    # measured (benchmarks/transient_speed.md): band is fastest up to ~50 elements; from ~200
    # elements sparse is as fast or faster, and sksundae's band matrix is stored as n x n
    if band <= max(32, n2 // 4) and n2 <= 800:
        return "band"
    return "sparse"


def run_transient(step, model: Model, state, writer, progress) -> xr.Dataset:
    """Integrate one transient step from ``state`` (positions, velocities, tensions)."""
    wall0 = _time.perf_counter()
    prob = TransientProblem(model, step, state.X, state.h)
    t0 = float(state.t)  # one clock for the whole case: a transient continues the time
    t_end = t0 + float(step.duration)
    dt_out = float(step.output_interval)
    n_out = int(np.floor((t_end - t0) / dt_out + 1e-9)) + 1
    times = t0 + dt_out * np.arange(n_out)
    if times[-1] < t_end - 1e-9 * dt_out:
        times = np.append(times, t_end)
    times[-1] = t_end  # exactly: the next step starts there
    y0, yp0 = prob.initial(t0, state.X, state.V)
    linsolver = choose_solver(prob, step.linear_solver)
    omega = _reference_frequency(prob, t0, y0)
    atol = np.empty(2 * prob.n)
    atol[0::2] = step.atol
    atol[1::2] = step.atol * omega
    auto = step.max_order == "auto"
    order_choice = (OrderChoice(_highest_frequency(prob, t0, y0), omega, float(step.rtol))
                    if auto else None)
    options = dict(rtol=step.rtol, atol=atol, max_order=5 if auto else int(step.max_order),
                   max_num_steps=100000, linsolver=linsolver)
    if linsolver == "band":
        bw = prob.bandwidth
        options.update(lband=2 * bw + 1, uband=max(2 * bw, 1), jacfn=prob.jac_dense)
    elif linsolver == "sparse":
        options.update(sparsity=prob.j_pattern, jacfn=prob.jac_sparse)
    else:
        options.update(jacfn=prob.jac_dense)
    def make_solver(max_order):
        with warnings.catch_warnings():
            # sksundae warns that its own sparse approximation is unused when jacfn is given:
            # that is the intent (the analytic iteration matrix)
            warnings.filterwarnings("ignore", "Custom sparse Jacobian approximation",
                                    UserWarning)
            return IDA(prob.resfn, **dict(options, max_order=max_order))

    solver = make_solver(options["max_order"])
    solver.init_step(t0, y0, yp0)

    nn = model.mesh.n_nodes
    ne = model.mesh.n_elements
    out_X = np.full((times.size, nn, 3), np.nan)
    out_V = np.full_like(out_X, np.nan)
    out_A = np.full_like(out_X, np.nan)
    out_T = np.full((times.size, ne, 2), np.nan)
    out_R = np.full_like(out_X, np.nan)
    out_E = np.full((times.size, 3), np.nan)

    def record(k, t, y, yp):
        X, V, A, T, R, E = prob.observe(t, y, yp)
        out_X[k], out_V[k], out_A[k] = X.reshape(-1, 3), V.reshape(-1, 3), A.reshape(-1, 3)
        out_T[k], out_R[k], out_E[k] = T, R, E

    n_steps = 0
    n_restarts = 0
    status = "completed"
    interrupt = None
    k_done = 0
    bar = reporter(progress, step.name, t0, t_end)
    last_write = _time.perf_counter()

    def dataset(n_valid):
        sl = slice(0, n_valid)
        energy = {
            "energy_kinetic": (out_E[sl, 0], "kinetic energy ½ vᵀ M v"),
            "energy_strain": (out_E[sl, 1], "elastic strain energy ∫ T²/(2EA) ds"),
            "energy_potential": (out_E[sl, 2], "potential of gravity and constant loads"),
            "energy_total": (out_E[sl].sum(axis=1), "kinetic + strain + potential"),
        }
        attrs = {
            "n_steps": n_steps, "n_residual_evaluations": prob.n_res,
            "n_jacobian_evaluations": prob.n_jac,
            "n_rejected_states": prob.n_rejected,
            "wall_time": _time.perf_counter() - wall0, "rtol": step.rtol, "atol": step.atol,
            "atol_velocity": step.atol * omega, "status": status, "linear_solver": linsolver,
            "bandwidth": prob.bandwidth,
            "max_order": (order_choice.order if auto else int(step.max_order)),
            "max_order_setting": str(step.max_order),
            "order_choice": order_choice.summary() if auto else "fixed by the step",
            "mass_model": model.mass_model, "mass_model_setting": model.mass_model_setting,
            "mass_model_choice": model.mass_model_choice, "inertia": step.inertia if prob.lagrangian else
            "paper" if model.mass_model in ("consistent", "blended") else "constant mass",
            "damping": "none" if step.damping is None else step.damping.kind,
            "rayleigh_alpha": prob.alpha, "rayleigh_beta": prob.beta,
            "n_outputs": n_valid, "n_restarts": n_restarts, "note": _note(model, prob),
        }
        return results.transient_dataset(model.mesh, times[sl], out_X[sl], out_V[sl],
                                          out_A[sl], out_T[sl], out_R[sl], energy, attrs)

    try:
        record(0, t0, y0, yp0)
        k_done = 1
        t_int = t0
        stalled = 0
        # kinks and jumps of the prescribed motions and loads: the integrator stops at each
        # and restarts from a consistent state (momentum balance across a velocity jump)
        groups = model.breakpoints(t0, t_end)
        end_jump = bool(groups) and groups[-1][1] == t_end
        stops = [at for _, at in groups]
        befores = [before for before, _ in groups]
        if not end_jump:
            stops.append(t_end)
            befores.append(t_end)
        i_stop = 0
        while k_done < times.size:
            t_stop = stops[i_stop]
            res = solver.step(t_stop, method="onestep", tstop=t_stop)
            if not res.success:
                status = f"IDA stopped at t = {t_int:.6g} s: {res.message}"
                break
            t_new = float(np.atleast_1d(res.t)[-1])
            if t_new > t_int:
                n_steps += 1
            # IDA's max_num_steps counts per call; in one-step mode guard the step size
            # ourselves: steps that no longer advance time mean the integration is stuck
            stalled = stalled + 1 if t_new - t_int <= STALL_STEP * max(abs(t_new), dt_out) else 0
            t_int = t_new
            if stalled >= STALL_COUNT:
                status = (f"step size collapsed at t = {t_int:.6g} s (IDA could not advance; "
                          f"{prob.n_rejected} trial states rejected)")
                break
            y_last, yp_last = np.atleast_2d(res.y)[-1], np.atleast_2d(res.yp)[-1]
            at_stop = ((t_stop < t_end or end_jump)
                       and t_int >= t_stop - 1e-13 * max(abs(t_stop), 1.0))
            while k_done < times.size and times[k_done] <= t_int * (1 + 1e-13) + 1e-300:
                tk = times[k_done]
                if abs(tk - t_int) <= 1e-13 * max(abs(t_int), 1.0):
                    if at_stop:
                        break  # recorded after the restart, with the velocities after it
                    yk, ypk = y_last, yp_last
                else:
                    ri = solver.step(tk, method="normal")
                    yk, ypk = np.atleast_2d(ri.y)[-1], np.atleast_2d(ri.yp)[-1]
                record(k_done, tk, yk, ypk)
                k_done += 1
            if at_stop:
                t_int = t_stop
                y_last, yp_last = prob.restart(t_stop, y_last, befores[i_stop])
                n_restarts += 1
                i_stop += 1
                if i_stop < len(stops):
                    solver.init_step(t_stop, y_last, yp_last)
                while (k_done < times.size
                       and abs(times[k_done] - t_int) <= 1e-13 * max(abs(t_int), 1.0)):
                    record(k_done, times[k_done], y_last, yp_last)
                    k_done += 1
            elif order_choice is not None and not order_choice.decided:
                new_order = order_choice.observe(t_int)
                if new_order is not None:
                    solver = make_solver(new_order)
                    solver.init_step(t_int, y_last, yp_last)
            bar.update(t_int)
            if writer is not None and _time.perf_counter() - last_write > INCREMENT_SECONDS:
                writer.write_increment(step.name, dataset(k_done))
                last_write = _time.perf_counter()
    except KeyboardInterrupt as exc:  # goes on after the partial dataset is attached below
        status = f"interrupted at t = {times[max(k_done - 1, 0)]:.6g} s"
        interrupt = exc
    except SolverError as exc:
        status = str(exc)
    except Exception as exc:  # nothing lost: keep what was computed, say what went wrong
        status = (f"stopped after t = {times[max(k_done - 1, 0)]:.6g} s by an unexpected "
                  f"error: {type(exc).__name__}: {exc}")
    finally:
        bar.close()
    ds = dataset(k_done)
    if interrupt is not None:
        interrupt.partial = ds
        raise interrupt
    if status != "completed":
        raise SolverError(f"transient step '{step.name}': {status}", termination=status,
                          partial=ds)
    # hand the final state to the next step
    state.X = out_X[-1].copy()
    state.V = out_V[-1].copy()
    state.h = prob.h
    state.t = t_end
    return ds


def _note(model: Model, prob: TransientProblem) -> str:
    """Advice on the result's accuracy that the run itself found ("" when none)."""
    jumps = [j for j in prob.velocity_jumps if j[2] > 1.0]
    if model.mass_model not in ("consistent", "blended") or not jumps:
        return ""
    t, dv, lam2 = jumps[0]
    return (f"a support velocity jumps by up to {dv:.3g} m/s at t = {t:.6g} s: the axial "
            "(water-hammer) wave it sends is not carried by the consistent catenary mass of "
            f"elements that take a chord change by sag (element λ² up to {lam2:.3g} here, "
            "> 1); tensions may be underestimated (try mass_model = \"lumped\" or \"linear\", "
            "or more elements; README, Accuracy and known limits)")


class OrderChoice:
    """The BDF order cap of ``max_order = "auto"``, chosen by measurement during the run.

    BDF orders 3-5 are not stable along the imaginary axis: undamped modes with h ω of order 1
    (the axial modes of a fine mesh) force their step down, whatever the accuracy needs, and the
    steps per simulated second then grow with the mesh. BDF2 is A-stable (it damps the modes
    far above 1/h). The run starts at order 5; after IDA's start-up window of ``WINDOW`` steps
    the mean step h of the next window decides: order 5 is stability-bound where h ω_max <
    ``STABILITY_HW``, and it is following the mesh's fast modes rather than the motion where it
    also takes more than ``STEPS_PER_PERIOD`` steps per period of the lowest mode (2π/ω₁). Then
    the rest of the step runs at order 2; otherwise, and always at rtol < ``TIGHT_RTOL``, order
    5 stays (docs/theory.md §8.6;
    measurements in benchmarks/speed_accuracy.md). ``order_choice`` says what was measured.
    """

    WINDOW = 150
    STABILITY_HW = 2.5
    STEPS_PER_PERIOD = 1.0e4

    TIGHT_RTOL = 1e-6  # below it order 5 is kept: its steps are set by accuracy there

    def __init__(self, omega_max: float | None, omega_1: float, rtol: float):
        self.omega_max = omega_max
        self.omega_1 = omega_1
        self.order = 5
        self.decided = omega_max is None or rtol < self.TIGHT_RTOL
        self.phase = "start-up"
        self.count = 0
        self.t_mark = None
        self.note = ("no highest frequency: order 5 kept" if omega_max is None else
                     f"order 5: rtol {rtol:g} < {self.TIGHT_RTOL:g} (at tight tolerances order 5 "
                     "takes far fewer steps)" if rtol < self.TIGHT_RTOL else "")

    def observe(self, t: float) -> int | None:
        """Called after every step at time t; returns the new order cap when it changes."""
        self.count += 1
        if self.t_mark is None:
            self.t_mark = t
        if self.count < self.WINDOW:
            return None
        h = (t - self.t_mark) / self.count  # mean step of the window, s
        self.count = 0
        self.t_mark = t
        if self.phase == "start-up":  # a new IDA starts at order 1 with short steps
            self.phase = "order 5"
            return None
        self.decided = True
        hw = h * self.omega_max
        per_period = 2.0 * np.pi / (h * self.omega_1) if h > 0 else np.inf
        if hw < self.STABILITY_HW and per_period > self.STEPS_PER_PERIOD:
            self.order = 2
            self.note = (f"order 2 from t = {t:.6g} s: order 5 was stability-bound (h ω_max = "
                         f"{hw:.3g}) at {per_period:.3g} steps per period of the lowest mode")
            return 2
        self.note = (f"order 5: h ω_max = {hw:.3g}, {per_period:.3g} steps per period of the "
                     "lowest mode")
        return None

    def summary(self) -> str:
        return self.note or f"order {self.order} ({self.phase}: too few steps to measure)"


def _extreme_frequency(prob: TransientProblem, t0: float, y0: np.ndarray,
                       highest: bool) -> float | None:
    """ω (rad/s) of the lowest (or the highest) mode of the free dofs about the start, or None
    if it cannot be had. Dense below 400 unknowns; above, ARPACK from a fixed start vector
    (its default is random, which made identical runs differ in their velocity atol and so in
    their step counts): shift-invert about 0 for the lowest, largest algebraic (to 1 %) for the
    highest."""
    conf = prob.configuration(t0, y0[0::2])
    if conf is None:
        return None
    n = prob.n
    try:
        mff = prob.ff(prob.mass_data(conf))
        kff = prob.ff(prob.model.pattern.assemble(conf[0].stiffness6))
        if n <= 400:
            k = n - 1 if highest else 0
            lam = sla.eigh(kff.toarray(), mff.toarray(), eigvals_only=True,
                           subset_by_index=[k, k])[0]
        else:
            v0 = np.linspace(1.0, 2.0, n)
            opts = dict(which="LA", tol=1e-2) if highest else dict(sigma=0.0, which="LM")
            lam = spla.eigsh(kff.tocsc(), 1, mff.tocsc(), v0=v0, return_eigenvectors=False,
                             **opts)[0]
        if np.isfinite(lam) and lam > 0:
            return float(np.sqrt(lam))
    except (ValueError, RuntimeError, np.linalg.LinAlgError, spla.ArpackError):
        pass
    return None


def _highest_frequency(prob: TransientProblem, t0: float, y0: np.ndarray) -> float | None:
    """ω_max about the start (rad/s), or None: the stability scale of OrderChoice."""
    return _extreme_frequency(prob, t0, y0, highest=True)


def _reference_frequency(prob: TransientProblem, t0: float, y0: np.ndarray) -> float:
    """ω of the lowest mode about the start (rad/s): scales the velocity tolerance (2π if it
    cannot be had)."""
    omega = _extreme_frequency(prob, t0, y0, highest=False)
    return 2.0 * np.pi if omega is None else omega

