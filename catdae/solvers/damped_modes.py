"""Damped modes about a static state: the quadratic eigenproblem (docs/theory.md §16).

(s² M + s C + K) φ = 0 on the free dofs, with the tangent stiffness K, the mass M and the
damping C (dampers, material or Rayleigh damping) of the static state. It is solved as the
linear pencil of twice the size

    [[0, I], [-K, -C]] z = s [[I, 0], [0, M]] z,     z = [φ, s φ],

densely (LAPACK's generalised eigensolver) for small models, else by Arnoldi iteration on
A⁻¹ B (ARPACK, shift-invert about s = 0: the lowest modes have the largest |1/s|). An
underdamped mode is a pair s, s̄; the one with Im s > 0 is kept. Its damped frequency is
Im s / 2π and its damping ratio ζ = -Re s / |s|; overdamped (real) roots are left out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from catdae.element.elements import ElementState
from catdae.errors import ConvergenceError
from catdae.model.assembly import Model
from catdae.model.connectors import extend
from catdae.model.settings import DampingModel

DENSE_LIMIT = 200  # size 2 n_free of the pencil up to which the dense solver is used
DENSE_FALLBACK = 4000  # up to which size the dense solver takes over when ARPACK fails


@dataclass
class DampedModes:
    s: np.ndarray  # (n_modes,) complex eigenvalues, 1/s, Im s > 0, by |s|
    shape: np.ndarray  # (n_modes, n_free) complex, largest component = 1
    solver: str
    note: str = ""  # a damping so large that the eigenproblem cannot be trusted

    @property
    def frequency(self) -> np.ndarray:
        """Damped frequency Im s / 2π, (n_modes,) Hz."""
        return self.s.imag / (2.0 * np.pi)

    @property
    def damping_ratio(self) -> np.ndarray:
        """ζ = -Re s / |s|, (n_modes,)."""
        return -self.s.real / np.abs(self.s)


def solve_quadratic(k, c, m, n_modes: int) -> DampedModes:
    """The n_modes underdamped modes of lowest |s| of (s² M + s C + K) φ = 0 (sparse or
    dense square matrices of one size)."""
    n = k.shape[0]
    s = None
    if 2 * n > DENSE_LIMIT and 2 * n_modes + 4 < 2 * n - 1:
        ks, cs, ms = (sp.csc_matrix(x) for x in (k, c, m))
        eye = sp.identity(n, format="csc")
        a = sp.bmat([[None, eye], [-ks, -cs]], format="csc")
        b = sp.bmat([[eye, None], [None, ms]], format="csc")
        lu = spla.splu(a)
        op = spla.LinearOperator(a.shape, matvec=lambda x: lu.solve(b @ x), dtype=float)
        nev = min(2 * n_modes + 4, 2 * n - 2)
        try:  # a fixed start vector: identical runs give identical modes
            nu, z = spla.eigs(op, k=nev, which="LM", ncv=min(2 * n - 1, max(2 * nev + 1, 40)),
                              v0=np.linspace(1.0, 2.0, 2 * n), maxiter=100 * n)
            with np.errstate(divide="ignore", invalid="ignore"):
                s = 1.0 / nu
            solver = "sparse shift-invert"
        except (RuntimeError, spla.ArpackNoConvergence) as exc:
            if 2 * n > DENSE_FALLBACK:
                raise ConvergenceError(f"modal step: quadratic eigensolver failed ({exc})") \
                    from exc
    if s is None:  # small, or ARPACK did not converge on clustered pairs: LAPACK
        kd, cd, md = (_dense(x) for x in (k, c, m))
        eye = np.eye(n)
        a = np.block([[np.zeros((n, n)), eye], [-kd, -cd]])
        b = np.block([[eye, np.zeros((n, n))], [np.zeros((n, n)), md]])
        s, z = sla.eig(a, b)
        solver = "dense"
    ok = np.isfinite(s)
    scale = np.abs(s[ok]).max(initial=1.0)
    keep = np.flatnonzero(ok & (s.imag > 1e-9 * scale))
    keep = keep[np.argsort(np.abs(s[keep]))][:n_modes]
    phi = z[:n, keep].T  # (n_modes, n)
    big = np.argmax(np.abs(phi), axis=1)
    phi = phi / phi[np.arange(keep.size), big][:, None]
    return DampedModes(s[keep], phi, solver)


def _dense(x) -> np.ndarray:
    return x.toarray() if sp.issparse(x) else np.asarray(x, float)


def fluid_flow(model: Model, X: np.ndarray):
    """The fluid's linearisation about the line at rest in the steady flow of a static or
    modal step (current and wind, no waves), (-∂f/∂x, -∂f/∂v) per element (n_elem, 6, 6);
    None without a current or a wind (in still water the drag has no first-order term)."""
    fl = model.fluid
    if fl is None or not fl.has_flow:
        return None
    z = np.zeros(np.size(X))
    _, _, kx, kv = fl.evaluate(fl.t, np.asarray(X, float).reshape(-1), z, z, want_jac=True,
                               waves=False)
    if not np.any(kv):
        return None
    return kx.copy(), kv.copy()


def damping_matrix(model: Model, X: np.ndarray, state: ElementState, damping,
                   flow=None) -> sp.csr_matrix | None:
    """C on the full dof set about positions X: the dampers' c e eᵀ, the step's ``damping``
    (material: the cables' damping per length with the mass model's interpolation; Rayleigh:
    α M + β K) and the fluid's ``flow`` (:func:`fluid_flow`). None when the scene has no
    damping at all."""
    cn = model.connectors
    has_dampers = cn is not None and "damper" in cn.kinds  # (a sweep may start at c = 0)
    if damping is None and not has_dampers and flow is None:
        return None
    data = np.zeros(model.pattern.nnz)
    if flow is not None:  # the drag on the relative velocity: -∂f/∂v (docs/theory.md §13.4)
        data += model.pattern.assemble(flow[1])
    if has_dampers:
        data += model.pattern.assemble(
            extend(None, cn.damping_blocks(X), model.mesh.n_elements))
    dm = DampingModel.of_step(damping)
    if dm.damped and not dm.material:  # Rayleigh
        alpha, beta = dm.alpha, dm.beta
        # β K on the elements' stiffness alone, as in the transient residual (docs/theory.md §15)
        data += alpha * model.mass_data(state) + beta * model.stiffness_data(state)
    elif dm.material:
        ce = None
        if model.mass_model.linear:
            ce = model.linear_element_mass(damping=True)
        elif not model.mass_model.lumped:
            ce = model.dynamic_state(X, state.h, True)[2]
        data += model.pattern.assemble(ce, model.diagonal_mass(model.mesh.c))
    return model.pattern.matrix(data)


LOCK_RATIO = 1e8  # C_ii / sqrt(K_ii M_ii) beyond which the quadratic eigenproblem fails


def lock_note(k, c, m) -> str:
    """A note where a degree of freedom is damped LOCK_RATIO times beyond its own critical
    damping sqrt(K_ii M_ii) (a damper that locks its point): the pencil's scales then differ by
    more than double precision keeps, and the damping ratios are round-off (an independent
    tester's taut cable: exact up to a damper of 1e10 N s/m, ratio about 1e6; negative ζ at
    1e13, frequencies 0.9 % off at 1e15)."""
    kd, cd, md = (np.abs(np.asarray(a.diagonal(), float)) for a in (k, c, m))
    scale = np.sqrt(kd * md)
    ratio = np.where(scale > 0.0, cd / np.where(scale > 0.0, scale, 1.0), 0.0)
    worst = float(ratio.max(initial=0.0))
    if worst <= LOCK_RATIO:
        return ""
    return (f"a damping {worst:.2g} times the critical damping of a degree of freedom of its "
            "own (a damper that locks its point): the damped eigenproblem loses its accuracy "
            "there (damping ratios of round-off, of either sign; frequencies off by up to 1 %); "
            "model a locked point as a support or a stiff spring")


def solve_damped(model: Model, X: np.ndarray, state: ElementState, n_modes: int,
                 damping) -> tuple[DampedModes, np.ndarray] | None:
    """The damped modes about (X, state), or None when the scene has no damping. Returns the
    modes and their complex shapes on the nodes, (n_modes, n_nodes, 3)."""
    flow = fluid_flow(model, X)  # one fluid pass for C and K
    c = damping_matrix(model, X, state, damping, flow)
    if c is None:
        return None
    free = model.free
    k = model.stiffness_data(state, X)
    if flow is not None:  # the drag's stiffness in the flow, as the static Newton has it
        k = k + model.pattern.assemble(flow[0])
    k = model.pattern.matrix(k)[free][:, free]
    m = model.mass(state)
    if model.fluid is not None:  # the added mass of the water, as in the undamped modes
        m = m + model.pattern.matrix(model.pattern.assemble(model.fluid.mass(X)))
    m = m[free][:, free]
    c = c[free][:, free]
    modes = solve_quadratic(k, c, m, min(int(n_modes), free.size))
    modes.note = lock_note(k, c, m)
    shapes = np.zeros((modes.s.size, model.n_dof), complex)
    if modes.s.size:  # none found underdamped: every mode NaN (with_damped_modes pads)
        shapes[:, free] = modes.shape
    return modes, shapes.reshape(modes.s.size, model.mesh.n_nodes, 3)
