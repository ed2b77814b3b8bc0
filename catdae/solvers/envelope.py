"""The tension envelope of a transient step: per element end, the largest and the smallest
tension and when, over every accepted integrator step and every output (docs/theory.md §12.3).

The outputs sample the motion every ``output_interval``; a snap's peak lasts about one wave
transit of an element (a fraction of a millisecond on a steel wire) and falls between them. The
integrator's own steps follow it (their error test sees the wave front), so the envelope is
taken at every accepted step: the element tensions are solved from the accepted positions
(warm-started, one or two Newton iterations per element), not read from the last residual
evaluation, whose state is a Newton iterate. With axial damping the viscous tension c_d ė is
included, as in ``tension``.
"""

from __future__ import annotations

import numpy as np

from catdae.element.catenary import NOT_CONVERGED, _solve_batch


class TensionEnvelope:
    """Running max/min of the element end tensions (n_elements, 2) and their times."""

    def __init__(self, prob):
        self.prob = prob
        m = prob.model
        ne = m.mesh.n_elements
        self.t_max = np.full((ne, 2), np.nan)
        self.t_min = np.full((ne, 2), np.nan)
        self.time_max = np.full((ne, 2), np.nan)
        self.time_min = np.full((ne, 2), np.nan)
        self._h = None if prob.h is None else np.array(prob.h, float, copy=True)
        self._X = np.zeros(m.n_dof)
        self._chord = np.zeros((ne, 3))
        self._f = np.zeros((ne, 6))
        self._k = np.zeros((ne, 3, 3))
        self._its = np.zeros(ne, np.int64)
        self._stat = np.zeros(ne, np.int64)
        self.n_updates = 0

    def tensions(self, t: float, y: np.ndarray) -> np.ndarray | None:
        """End tensions (n, 2) of the state y at t, None where an element cannot be solved."""
        prob = self.prob
        m = prob.model
        X = self._X
        X[prob.fidx] = y[0::2]
        X[m.fixed] = prob._supports(t)[0]
        Xn = X.reshape(-1, 3)
        conn = m.mesh.conn
        np.subtract(Xn[conn[:, 1]], Xn[conn[:, 0]], out=self._chord)
        m.set_time(t)
        el = m.elements
        use_h = self._h is not None
        h = self._h if use_h else np.zeros_like(self._chord)
        _solve_batch(self._chord, el.L0, el.EA, el.w, el._ptr, el._ls, el._lf, h, use_h,
                     1e-12, 100, self._f, self._k, self._its, self._stat)
        if (self._stat == NOT_CONVERGED).any() or not np.all(np.isfinite(h)):
            self._h = None
            return None
        self._h = h
        tension = el.end_tensions(h)
        if prob.axial is not None:
            V = np.zeros(m.n_dof)
            V[prob.fidx] = y[1::2]
            V[m.fixed] = prob._supports(t)[1]
            prob.axial.rates(X, V, h, self._k)
            tension += prob.axial.tension()[:, None]
        return tension

    def update(self, t: float, y: np.ndarray | None = None,
               tension: np.ndarray | None = None) -> None:
        """Take the state y at t (or its tensions, when known) into the envelope."""
        if tension is None:
            tension = self.tensions(t, y)
            if tension is None:
                return
        self.n_updates += 1
        first = self.n_updates == 1
        up = first | (tension > self.t_max)
        self.t_max[up] = tension[up]
        self.time_max[up] = t
        dn = first | (tension < self.t_min)
        self.t_min[dn] = tension[dn]
        self.time_min[dn] = t

    def variables(self) -> dict:
        """The four envelope variables of the step's dataset (dims element, end)."""
        from catdae.output.results import _var
        d = ("element", "end")
        how = "over every accepted integrator step and output"
        return {
            "tension_max": _var(d, self.t_max.copy(), "N",
                                f"largest cable tension at element end, {how}"),
            "tension_min": _var(d, self.t_min.copy(), "N",
                                f"smallest cable tension at element end, {how}"),
            "time_tension_max": _var(d, self.time_max.copy(), "s",
                                     "time of tension_max on the case's clock"),
            "time_tension_min": _var(d, self.time_min.copy(), "s",
                                     "time of tension_min on the case's clock"),
        }
