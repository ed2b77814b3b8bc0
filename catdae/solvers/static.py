"""Static equilibrium: Newton on the free dofs with the assembled sparse tangent stiffness.

R(X) = Σ_e r_e(X) - P = 0 on the free dofs (docs/theory.md §4). Each Newton step solves
K_t dX = -R with the sparse tangent stiffness, and is damped by a line search on the slope of the
total potential energy along the step (:func:`_line_search`). Loads beyond the self-weight (point
loads, point masses, distributed loads) are applied in load steps; a load step that fails is
halved, so that hard starts (a large point load on a slack cable) still converge.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from catdae.element.elements import NOT_CONVERGED, ElementState
from catdae.errors import ConvergenceError
from catdae.model.assembly import Model


@dataclass
class StaticSolution:
    X: np.ndarray  # (n_nodes, 3) m
    state: ElementState
    iterations: int  # Newton iterations, all load steps
    residual_norm: float  # N, max |R| on free dofs at the end
    load_steps: int  # load increments used


def _residual(model: Model, state: ElementState, p: np.ndarray, X: np.ndarray) -> np.ndarray:
    r = model.internal_force(state, X) - p
    if model.fluid is not None:  # buoyancy, steady current and wind drag (theory §13)
        r += model.fluid.static(X)[0]
    return r[model.free]


def _stiffness(model: Model, state: ElementState, X: np.ndarray):
    if model.fluid is None:
        return model.stiffness(state, X)
    return model.pattern.matrix(model.stiffness_data(state, X)
                                + model.pattern.assemble(model.fluid.static(X)[1]))


def solve_static(model: Model, X: np.ndarray, h0: np.ndarray | None = None, t: float = 0.0,
                 load_steps: int = 1, rtol: float = 1e-11, max_iter: int = 200) -> StaticSolution:
    """Equilibrium of ``model`` at time ``t`` starting from node positions ``X`` (n_nodes, 3)."""
    X = np.array(X, float, copy=True)
    X.reshape(-1)[model.fixed] = model.support_positions(t)
    model.set_time(t)
    if model.fluid is not None:
        model.fluid.t = t
    p_full = model.nodal_load(t)
    f_full = model.elements.loads.f.copy()
    state = model.element_state(X, h0)
    if (state.status == NOT_CONVERGED).any():
        state = model.element_state(X)
    weight = float((model.mesh.w * model.mesh.L0).sum())
    fscale = max(weight + np.abs(p_full).sum() + np.abs(f_full).sum(), 1e-300)
    total_iter = 0
    lam = 0.0
    dlam = 1.0 / max(int(load_steps), 1)
    n_inc = 0
    if not model.has_internal_loads and not np.any(p_full):
        dlam = 1.0
    while lam < 1.0:
        target = min(1.0, lam + dlam)
        model.elements.set_load_forces(target * f_full)
        p = target * p_full
        start = model.element_state(X, state.h)  # the loads inside elements changed
        if (start.status == NOT_CONVERGED).any():
            start = model.element_state(X)
        ok, X_new, state_new, its, rnorm = _newton(model, X, start, p, fscale, rtol, max_iter)
        total_iter += its
        if ok:
            X, state, lam = X_new, state_new, target
            n_inc += 1
            dlam = min(2.0 * dlam, 1.0 - lam) if lam < 1.0 else dlam
            continue
        dlam *= 0.5
        model.elements.set_load_forces(lam * f_full)
        # nothing to ramp (no loads): a smaller increment is the same Newton from the same start
        if dlam < 1e-6 or not (model.has_internal_loads or np.any(p_full)):
            model.elements.set_load_forces(f_full)
            raise ConvergenceError(
                f"static equilibrium not found: the step's loads ramped up to "
                f"{100 * lam:.4g} % of their full value, no further "
                f"(|R| = {rnorm:.3g} N after {total_iter} Newton iterations"
                f"{_largest_residual(model, X_new, state_new, p)})")
    r = _residual(model, state, p_full, X)
    return StaticSolution(X, state, total_iter, float(np.abs(r).max(initial=0.0)), n_inc)


def _largest_residual(model: Model, X, state, p) -> str:
    """Where the out-of-balance force of the last iterate is largest: its node and axis, and
    the elements there that could not be solved, for the failure's message."""
    try:
        r = _residual(model, state, p, X)
    except (ValueError, FloatingPointError):
        return ""
    mesh = model.mesh
    if r.size == 0 or not np.isfinite(r).any():
        return ""
    k = int(model.free[np.nanargmax(np.abs(r))])
    node = k // 3
    big = float(np.nanmax(np.abs(r)))
    out = f"; largest at node {mesh.node_names[node]!r}, {'xyz'[k % 3]}: {big:.3g} N"
    near = np.flatnonzero((mesh.conn == node).any(axis=1) & (state.status == NOT_CONVERGED))
    if near.size:
        out += ", next to element(s) " + ", ".join(repr(mesh.element_names[e]) for e in near)
        out += " that cannot be solved there"
    return out


def _newton(model: Model, X, state, p, fscale, rtol, max_iter):
    """Damped Newton at a fixed load. Returns (ok, X, state, iterations, |R|)."""
    free = model.free
    r = _residual(model, state, p, X)
    rn = np.linalg.norm(r)
    if free.size == 0:
        return True, X, state, 0, rn
    cap = float(model.mesh.L0.max(initial=1.0))  # m, the longest Newton step
    for it in range(1, max_iter + 1):
        tscale = max(fscale, float(np.abs(state.h).max(initial=0.0)))
        if rn <= rtol * tscale:
            return True, X, state, it - 1, rn
        k = _stiffness(model, state, X)[free][:, free].tocsc()
        dx = _solve(k, -r)
        if dx is None:
            return False, X, state, it, rn
        # a step longer than an element (a load across a cable that carries no tension yet:
        # K nearly singular) is shortened to one: the line search then starts where the
        # elements can still be solved
        big = float(np.abs(dx).max())
        if big > cap:
            dx *= cap / big
        step = _line_search(model, X, state, dx, r, rn, p)
        if step is None and rn > 1e3 * rtol * tscale:
            step = _regularised_step(model, X, state, k, r, rn, p, cap)
        if step is None:
            # no decrease: converged to round-off, or stuck
            return rn <= 1e3 * rtol * tscale, X, state, it, rn
        alpha, X, state, r = step
        rn = np.linalg.norm(r)
        if alpha == 1.0 and np.abs(dx).max() <= 1e-14 * max(1.0, np.abs(X).max()):
            return True, X, state, it, rn
    return rn <= rtol * fscale, X, state, max_iter, rn


def _regularised_step(model: Model, X, state, k, r, rn: float, p, cap: float):
    """A Levenberg-Marquardt step where the Newton direction found no decrease: the Newton
    direction of a cable that carries almost no tension yet (a line hanging straight down,
    pulled aside) is its mechanism, a lateral sweep of the inner nodes; K + μ I with μ = |R| /
    cap (the stiffness that moves a node by the longest element under the whole residual)
    turns it towards the residual, and the stiff directions keep Newton's step."""
    kk = k + (rn / cap) * sp.identity(k.shape[0], format="csc")
    dx = _solve(kk, -r)
    return None if dx is None else _line_search(model, X, state, dx, r, rn, p)


def _line_search(model: Model, X, state, dx, r, rn, p):
    """Step length along the Newton direction ``dx``. Returns (alpha, X, state, R) or None.

    R is the gradient of the total potential energy Π (conservative loads, hyperelastic
    elements: K_t is symmetric), so φ'(α) = R(X + α dx)·dx is the slope of Π along the step and
    φ'(0) = -Rᵀ K_t⁻¹ R < 0 when K_t is positive definite. The step is accepted where the slope
    has fallen to half its start (|φ'(α)| <= |φ'(0)|/2, found by safeguarded secant steps on
    φ'), or at α = 1 while Π still descends there. Backtracking on |R| instead would accept only
    tiny steps along the near-inextensional motions of a slack cable: a straight step stretches
    the elements at second order and |R| jumps by EA times that, although Π falls. Trial
    states where an element cannot be solved halve the step. When φ'(0) >= 0 (K_t not
    positive definite) the step backtracks on |R|.
    """
    free = model.free
    d0 = float(r @ dx)

    def trial(alpha):
        Xt = X.copy()
        Xt.reshape(-1)[free] += alpha * dx
        st = model.element_state(Xt, state.h)
        if (st.status == NOT_CONVERGED).any():
            return None
        rt = _residual(model, st, p, Xt)
        if not np.all(np.isfinite(rt)):
            return None
        return Xt, st, rt

    if not d0 < 0.0:
        alpha = 1.0
        for _ in range(40):
            t = trial(alpha)
            if t is not None and np.linalg.norm(t[2]) <= (1.0 - 1e-4 * alpha) * rn:
                return (alpha, *t)
            alpha *= 0.5
        return None
    lo, d_lo = 0.0, d0
    hi, d_hi = None, None
    alpha = 1.0
    for _ in range(40):
        t = trial(alpha)
        if t is None:
            hi, d_hi = alpha, None
            alpha = 0.5 * (lo + alpha)
            continue
        d = float(t[2] @ dx)
        if abs(d) <= 0.5 * abs(d0) or (d < 0.0 and alpha == 1.0):
            return (alpha, *t)
        if d < 0.0:
            lo, d_lo = alpha, d
        else:
            hi, d_hi = alpha, d
        if d_hi is None:
            alpha = 0.5 * (lo + hi)
            continue
        # secant on the slope, kept inside the middle 80 % of the bracket
        a = lo - d_lo * (hi - lo) / (d_hi - d_lo)
        alpha = min(max(a, lo + 0.1 * (hi - lo)), hi - 0.1 * (hi - lo))
    return None


def _solve(k, rhs):
    """K dx = rhs; a singular K (a slack element has no lateral stiffness, e.g. a hanging line
    started folded) is regularised by a small multiple of its largest diagonal, which leaves
    the directions that have stiffness unchanged to round-off and gives the others a finite
    step that the line search then judges."""
    for mu in (0.0, 1e-10, 1e-6):
        kk = k
        if mu:
            kk = (k + mu * abs(k.diagonal()).max() * sp.identity(k.shape[0], format="csc"))
        with warnings.catch_warnings():
            warnings.simplefilter("error", spla.MatrixRankWarning)
            try:
                dx = spla.spsolve(kk.tocsc(), rhs)
            except (RuntimeError, spla.MatrixRankWarning):
                continue
        if np.all(np.isfinite(dx)):
            return dx
    return None
