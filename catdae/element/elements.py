"""The exact 3-D elastic catenary element (docs/theory.md §1-7), batched over elements: the
objects the rest of catdae uses (``Elements``, ``ElementState``, ``PointLoads``). The compiled
kernels behind them are in ``catenary`` (segment formulas, solve; its docstring states the
stable forms) and ``element_mass`` (mass, ∂M/∂c, dynamic forces).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from catdae.element.cache import load_lightly
from catdae.element.catenary import (  # noqa: F401  (re-exported)
    CONVERGED,
    NOT_CONVERGED,
    SLACK,
    STATUS_NAMES,
)
from catdae.element.catenary_batch import (  # noqa: F401  (re-exported)
    end_tension_batch,
    energy_batch,
    partial_batch,
    solve_batch,
    tension_batch,
)
from catdae.element.mass import (  # noqa: F401  (re-exported)
    dynamic_forces,
    dynamics_batch,
    mass_batch,
    mass_gradient_batch,
)

load_lightly()  # cached kernels without numba's compiler set-up (catdae/element/cache.py)


def sym_from_upper(f6: np.ndarray) -> np.ndarray:
    """(..., 6) upper triangles -> (..., 3, 3) symmetric matrices."""
    out = np.empty(f6.shape[:-1] + (3, 3))
    out[..., 0, 0] = f6[..., 0]
    out[..., 0, 1] = out[..., 1, 0] = f6[..., 1]
    out[..., 0, 2] = out[..., 2, 0] = f6[..., 2]
    out[..., 1, 1] = f6[..., 3]
    out[..., 1, 2] = out[..., 2, 1] = f6[..., 4]
    out[..., 2, 2] = f6[..., 5]
    return out


# ----------------------------------------------------------------------------------------------
# public objects
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PointLoads:
    """Concentrated loads inside elements, stored compressed by element (CSR).

    Loads of element e are ``s[ptr[e]:ptr[e+1]]`` (sorted, unstrained arc length from node i)
    and ``f[ptr[e]:ptr[e+1]]`` (N, global axes). A load at s_k changes the tension for s > s_k.
    """

    ptr: np.ndarray  # (n+1,) int64
    s: np.ndarray  # (m,) m
    f: np.ndarray  # (m, 3) N

    @classmethod
    def empty(cls, n: int) -> PointLoads:
        return cls(np.zeros(n + 1, np.int64), np.zeros(0), np.zeros((0, 3)))

    @classmethod
    def from_lists(cls, loads: Sequence[Sequence[tuple[float, Sequence[float]]]]) -> PointLoads:
        """From one list per element of (s, (fx, fy, fz)) pairs, in any order."""
        ptr = np.zeros(len(loads) + 1, np.int64)
        s_all: list[float] = []
        f_all: list[Sequence[float]] = []
        for e, items in enumerate(loads):
            items = sorted(items, key=lambda it: it[0])
            s_all.extend(float(si) for si, _ in items)
            f_all.extend(fi for _, fi in items)
            ptr[e + 1] = ptr[e] + len(items)
        f = np.asarray(f_all, float).reshape(-1, 3)
        return cls(ptr, np.asarray(s_all, float), f)

    @property
    def n(self) -> int:
        return len(self.ptr) - 1

    def total(self) -> np.ndarray:
        """Sum of the loads on each element, (n, 3) N."""
        out = np.zeros((self.n, 3))
        counts = np.diff(self.ptr)
        np.add.at(out, np.repeat(np.arange(self.n), counts), self.f)
        return out


@dataclass(frozen=True)
class ElementState:
    """The solved state of a batch of elements for given chords."""

    h: np.ndarray  # (n, 3) N, tension vector at s = 0
    F: np.ndarray  # (n, 3, 3) m/N, flexibility ∂chord/∂h
    K: np.ndarray  # (n, 3, 3) N/m, F⁻¹ (zero for slack elements)
    iterations: np.ndarray  # (n,) Newton iterations
    status: np.ndarray  # (n,) CONVERGED, SLACK or NOT_CONVERGED

    @property
    def converged(self) -> np.ndarray:
        return self.status != NOT_CONVERGED

    @property
    def stiffness6(self) -> np.ndarray:
        """Element tangent stiffness (n, 6, 6) for (u_i, u_j): [[K, -K], [-K, K]] (§4)."""
        k = self.K
        return np.concatenate(
            [np.concatenate([k, -k], axis=2), np.concatenate([-k, k], axis=2)], axis=1
        )


class Elements:
    """A batch of catenary elements with fixed properties.

    Parameters are arrays over elements: ``L0`` unstrained length (m), ``EA`` axial stiffness (N),
    ``w`` weight per unstrained length (N/m, along -z) and optional ``loads`` inside them.
    """

    def __init__(self, L0, EA, w, loads: PointLoads | None = None):
        self.L0 = np.ascontiguousarray(L0, float).reshape(-1)
        n = self.L0.size
        self.EA = np.ascontiguousarray(np.broadcast_to(np.asarray(EA, float), (n,)))
        self.w = np.ascontiguousarray(np.broadcast_to(np.asarray(w, float), (n,)))
        self.loads = PointLoads.empty(n) if loads is None else loads
        if self.loads.n != n:
            raise ValueError(f"loads are given for {self.loads.n} elements, expected {n}")
        self._ls = np.ascontiguousarray(self.loads.s, float)
        self._lf = np.array(self.loads.f, float, copy=True).reshape(-1, 3)
        self._ptr = np.ascontiguousarray(self.loads.ptr, np.int64)
        self._load_total = self.loads.total()  # (n, 3) N

    @property
    def n(self) -> int:
        return self.L0.size

    def set_load_forces(self, f) -> None:
        """Replace the forces of the loads inside the elements (positions unchanged), (m, 3) N."""
        self._lf[:] = np.asarray(f, float).reshape(-1, 3)
        self.loads = PointLoads(self._ptr, self._ls, self._lf)
        self._load_total = self.loads.total()

    def _s(self, s) -> np.ndarray:
        s = np.asarray(s, float)
        if s.ndim == 0:
            s = np.full((self.n, 1), float(s))
        elif s.ndim == 1:
            s = np.broadcast_to(s, (self.n, s.size))
        return np.ascontiguousarray(s)

    def _h(self, h) -> np.ndarray:
        """h as a read-only C-contiguous (n, 3) float array (one h broadcast to every element
        if given as (3,)); an array already so shaped is viewed, not broadcast (a view is all
        the kernels need: the outputs and the envelope ask at every step)."""
        if (type(h) is np.ndarray and h.dtype == np.float64 and h.shape == (self.n, 3)
                and h.flags.c_contiguous):
            v = h.view()
            v.flags.writeable = False
            return v
        return np.ascontiguousarray(np.broadcast_to(np.asarray(h, float), (self.n, 3)))

    def solve(self, chord, h0=None, *, tol: float = 1e-12, max_iter: int = 100) -> ElementState:
        """Tension h such that the element spans ``chord`` (n, 3) = x_j - x_i.

        ``h0`` warm-starts Newton (the previous state's h); without it a cold start is used.
        Elements that fail to converge keep their last finite iterate and are flagged in
        ``status``; the caller decides what a failure means.
        """
        chord = np.ascontiguousarray(np.broadcast_to(np.asarray(chord, float), (self.n, 3)))
        use_h = h0 is not None
        h = np.array(self._h(h0), copy=True) if use_h else np.zeros((self.n, 3))
        f6 = np.empty((self.n, 6))
        kmat = np.empty((self.n, 3, 3))
        its = np.empty(self.n, np.int64)
        stat = np.empty(self.n, np.int64)
        solve_batch(chord, self.L0, self.EA, self.w, self._ptr, self._ls, self._lf, h, use_h,
                     tol, max_iter, f6, kmat, its, stat)
        return ElementState(h, sym_from_upper(f6), kmat, its, stat)

    def solve_dynamic(self, chord, h0, gauss_s, gauss_w, m, c=None, point_masses=None,
                      *, tol: float = 1e-12, max_iter: int = 100, gradient: bool = False):
        """Solve the elements and build their consistent mass (and damping) matrices.

        ``gauss_s``/``gauss_w`` (n, g): points (m) and weights (sum 1 per element); ``m`` and
        ``c`` (n,): mass and damping per unstrained length; ``point_masses`` = (element (p,),
        s (p,), mass (p,)) inside elements. Returns (ElementState, M_e (n, 6, 6),
        C_e (n, 6, 6) or None) in one compiled pass; with ``gradient`` a fourth item, the
        analytic ∂M_e/∂c_k (n, 3, 6, 6) (see :meth:`mass_gradient` for the complex-step one).
        """
        chord = np.ascontiguousarray(chord, float).reshape(self.n, 3)
        use_h = h0 is not None
        h = np.array(h0, float).reshape(self.n, 3) if use_h else np.zeros((self.n, 3))
        f6 = np.empty((self.n, 6))
        kmat = np.empty((self.n, 3, 3))
        its = np.empty(self.n, np.int64)
        stat = np.empty(self.n, np.int64)
        me = np.empty((self.n, 6, 6))
        want_c = c is not None
        ce = np.empty((self.n, 6, 6)) if want_c else np.empty((1, 6, 6))
        cq = np.ascontiguousarray(c, float) if want_c else np.zeros(self.n)
        pmptr, pms, pmm = self._point_mass_csr(point_masses)
        gs = np.ascontiguousarray(gauss_s, float)
        gw = np.ascontiguousarray(gauss_w, float)
        mq = np.ascontiguousarray(m, float)
        dm = np.empty((self.n, 3, 6, 6)) if gradient else np.empty((1, 3, 6, 6))
        dynamics_batch(chord, self.L0, self.EA, self.w, self._ptr, self._ls, self._lf, h,
                        use_h, tol, max_iter, gs, gw, mq, cq, pmptr, pms, pmm, want_c,
                        gradient, f6, kmat, its, stat, me, ce, dm)
        state = ElementState(h, sym_from_upper(f6), kmat, its, stat)
        self._last_dynamic = (gs, gw, mq, pmptr, pms, pmm)
        if gradient:
            return state, me, (ce if want_c else None), dm
        return state, me, (ce if want_c else None)

    def element_masses(self, state: ElementState, gauss_s, gauss_w, per_length,
                       point_masses=None) -> np.ndarray:
        """Σ_g q L0 w_g NᵀN (+ Σ_p m_p NᵀN at point masses), (n, 6, 6), about a solved state.

        ``per_length`` (n,) is the mass (or damping coefficient) per unstrained length; the
        same compiled quadrature as :meth:`solve_dynamic`, without solving the elements.
        """
        pmptr, pms, pmm = self._point_mass_csr(point_masses)
        out = np.empty((self.n, 6, 6))
        mass_batch(np.ascontiguousarray(state.h, float), np.ascontiguousarray(state.K, float),
                    np.ascontiguousarray(state.status, np.int64), self.L0, self.EA, self.w,
                    self._ptr, self._ls, self._lf, np.ascontiguousarray(gauss_s, float),
                    np.ascontiguousarray(gauss_w, float),
                    np.ascontiguousarray(per_length, float), pmptr, pms, pmm, out)
        return out

    def mass_gradient(self, state: ElementState) -> np.ndarray:
        """∂M_e/∂c_k, (n, 3, 6, 6), about the state of the last solve_dynamic (its quadrature
        and point masses)."""
        gs, gw, mq, pmptr, pms, pmm = self._last_dynamic
        out = np.empty((self.n, 3, 6, 6))
        mass_gradient_batch(self.L0, self.EA, self.w, self._ptr, self._ls, self._lf, state.h,
                             state.K, state.status, gs, gw, mq, pmptr, pms, pmm, out)
        return out

    def _point_mass_csr(self, point_masses):
        """(element, s, mass) arrays -> CSR by element; cached on the arrays' identity (the
        caller passes the same loading arrays at every residual, in a new tuple each time)."""
        key = None if point_masses is None else tuple(id(a) for a in point_masses)
        cached = getattr(self, "_pm_cache", None)
        if cached is not None and cached[0] == key:
            return cached[1]
        if point_masses is None or len(point_masses[0]) == 0:
            csr = (np.zeros(self.n + 1, np.int64), np.zeros(0), np.zeros(0))
        else:
            e, s, mass = (np.asarray(a) for a in point_masses)
            order = np.lexsort((s, e))
            ptr = np.concatenate([[0], np.cumsum(np.bincount(e, minlength=self.n))])
            csr = (ptr.astype(np.int64), np.ascontiguousarray(s[order], float),
                   np.ascontiguousarray(mass[order], float))
        self._pm_cache = (key, csr, point_masses)
        return csr

    def _partial(self, h, s, want_flex: bool):
        h = self._h(h)
        s = self._s(s)
        x = np.empty(s.shape + (3,))
        g = np.empty(s.shape + (6,))
        partial_batch(h, self.L0, self.EA, self.w, self._ptr, self._ls, self._lf, s, x, g,
                       want_flex)
        return x, g

    def chord(self, h) -> np.ndarray:
        """ℓ(h) = x(L0) - x(0), (n, 3) m (§2)."""
        return self._partial(h, self.L0[:, None], False)[0][:, 0]

    def flexibility(self, h) -> np.ndarray:
        """F(h) = ∂ℓ/∂h, (n, 3, 3) m/N (§3)."""
        return sym_from_upper(self._partial(h, self.L0[:, None], True)[1][:, 0])

    def position(self, h, s) -> np.ndarray:
        """x(s) - x_i for s (n, q) or (q,), returns (n, q, 3) m."""
        return self._partial(h, s, False)[0]

    def position_in(self, e: int, h_e, s: float) -> np.ndarray:
        """x(s) - x_i of element ``e`` alone for its end force ``h_e`` (3,), m: the same kernel
        on that element's data, for a search along one element (not every element's point)."""
        x = np.empty((1, 1, 3))
        h1 = np.array(h_e, float).reshape(1, 3)
        h1.flags.writeable = False  # as every other call passes it (one compiled signature)
        partial_batch(h1, self.L0[e:e + 1],
                      self.EA[e:e + 1], self.w[e:e + 1], self._ptr[e:e + 2], self._ls,
                      self._lf, np.full((1, 1), float(s)), x, np.empty((1, 1, 6)), False)
        return x[0, 0]

    def partial_flexibility(self, h, s) -> np.ndarray:
        """G(s) = ∂x(s)/∂h, (n, q, 3, 3) m/N (§6)."""
        return sym_from_upper(self._partial(h, s, True)[1])

    def tension_vector(self, h, s) -> np.ndarray:
        """t(s), (n, q, 3) N; at a load position the value just before the load."""
        s = self._s(s)
        out = np.empty(s.shape + (3,))
        tension_batch(self._h(h), self.w, self._ptr, self._ls, self._lf, s, out)
        return out

    def tension(self, h, s) -> np.ndarray:
        """T(s) = |t(s)|, (n, q) N."""
        return np.linalg.norm(self.tension_vector(h, s), axis=-1)

    def end_tensions(self, h) -> np.ndarray:
        """Tension at s = 0 and s = L0 (just inside the element), (n, 2) N."""
        out = np.empty((self.n, 2))  # at j: the end force r_j of end_forces
        end_tension_batch(self._h(h), self._load_total, self.w, self.L0, out)
        return out

    def energies(self, h, xi, wi) -> np.ndarray:
        """Per element (n, 2): the strain energy ∫ T²/(2 EA) ds (exact) and ∫ w (z(s) - z_i) ds
        (Gauss points xi, weights wi on [-1, 1], on each piece between loads), J."""
        out = np.empty((self.n, 2))
        energy_batch(self._h(h), self.L0, self.EA, self.w, self._ptr, self._ls, self._lf,
                      np.ascontiguousarray(xi, float), np.ascontiguousarray(wi, float), out)
        return out

    def end_forces(self, h) -> np.ndarray:
        """Resisting forces r_i = -h, r_j = h - Σ f_k + (0, 0, w L0), (n, 2, 3) N (§4).

        These are the forces the nodes must supply to hold the element: the element's
        contribution to the internal force vector.
        """
        h = self._h(h)
        r = np.empty((self.n, 2, 3))
        r[:, 0] = -h
        r[:, 1] = h - self._load_total
        r[:, 1, 2] += self.w * self.L0
        return r

    def interpolation(self, state: ElementState, s) -> np.ndarray:
        """N(s) = [I - G(s) K, G(s) K], (n, q, 3, 6) (§6).

        Slack elements (no tension, no defined catenary) use the straight-line interpolation
        [(1 - s/L0) I, (s/L0) I], which keeps Φ_i + Φ_j = I and the end values.
        """
        s = self._s(s)
        g = self.partial_flexibility(state.h, s)  # (n, q, 3, 3)
        slack = state.status == SLACK
        if slack.any():
            g[slack] = 0.0
        b = g @ np.asarray(state.K)[:, None]  # (n, q, 3, 3)
        if slack.any():
            frac = s[slack] / self.L0[slack, None]  # (n_slack, q)
            b[slack] = frac[..., None, None] * np.eye(3)
        eye = np.eye(3)
        return np.concatenate([eye - b, b], axis=-1)
