"""The tension envelope of a transient step: per element end, the largest and the smallest
tension and when, over every accepted integrator step and every output (docs/theory.md §18.3).

The outputs sample the motion every ``output_interval``; a snap's peak lasts about one wave
transit of an element (a fraction of a millisecond on a steel wire) and falls between them. The
integrator's own steps follow it (their error test sees the wave front), so the envelope is
taken at every accepted step. The last residual evaluation of a step is at the corrector's last
Newton iterate q_b, not at the accepted q: the end forces are carried from it to q to first
order, h = h_b + K_b (c - c_b) (K = ∂h/∂c, c the chords), which leaves an error of second order
in the last Newton correction (one compiled pass, a few µs). An element whose end force would
change by more than ``CARRY`` of itself (near the knee between slack and taut, where K changes
fast) is solved again, warm-started; where the buffers hold no state of this time (after a
restart) every element is. With
axial damping the viscous tension c_d ė is included, as in ``tension``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from catdae.element.catenary import NOT_CONVERGED, solve_one
from catdae.element.catenary_batch import carry_tension, end_tensions, solve_batch
from catdae.solvers.axial_damping import element_g, unit_chord

CARRY = 1e-4  # largest relative change of an end force carried to first order


@njit(cache=True)
def carried_tensions(y, fidx, fixed, xp, vp, conn, xb, hb, kb, l0, ea, w, ptr, ls, lf,
                     load_total, cd, g, chord, out, carry, t, first, ext, ext_time):
    """End tensions (n, 2) at the state y (positions and velocities of the unknowns in
    ``fidx``, interleaved; fixed dofs at ``xp``/``vp``) from the end forces ``hb`` and
    stiffnesses ``kb`` solved at positions ``xb``: h = hb + kb (c - c_b) where the change
    |kb (c - c_b)| is below ``CARRY`` |hb|, else the element is solved again (warm-started from
    hb). Plus the viscous tension cd ė, ė = g·ċ (cd zero without axial damping; g taken again
    where solved again; ``chord``: the unit chord). Returns the elements solved (-1: one failed).

    Then the tensions ``out`` at time t are taken into the envelope ``ext`` (2, n, 2: largest,
    smallest) and ``ext_time`` (when; all of ``out`` where ``first``). With ``carry`` False the
    tensions are not computed: ``out`` holds them (an output's), only the envelope is updated."""
    if carry:
        solved = _carry(y, fidx, fixed, xp, vp, conn, xb, hb, kb, l0, ea, w, ptr, ls, lf,
                        load_total, cd, g, chord, out)
        if solved < 0:
            return solved
    else:
        solved = 0
    for e in range(out.shape[0]):
        for k in range(2):
            v = out[e, k]
            if first or v > ext[0, e, k]:
                ext[0, e, k] = v
                ext_time[0, e, k] = t
            if first or v < ext[1, e, k]:
                ext[1, e, k] = v
                ext_time[1, e, k] = t
    return solved


@njit(cache=True)
def _carry(y, fidx, fixed, xp, vp, conn, xb, hb, kb, l0, ea, w, ptr, ls, lf, load_total, cd, g,
           chord, out):
    """The carried tensions of ``carried_tensions`` into ``out``; the elements solved again."""
    X = xb.copy()
    V = np.zeros(xb.shape[0])
    for k in range(fidx.shape[0]):
        X[fidx[k]] = y[2 * k]
        V[fidx[k]] = y[2 * k + 1]
    for k in range(fixed.shape[0]):
        X[fixed[k]] = xp[k]
        V[fixed[k]] = vp[k]
    cb = np.empty(3)
    c = np.empty(3)
    h = np.empty(3)
    ge = np.empty(3)
    f6 = np.empty(6)
    k33 = np.empty((3, 3))
    solved = 0
    for e in range(conn.shape[0]):
        i = 3 * conn[e, 0]
        j = 3 * conn[e, 1]
        for a in range(3):
            c[a] = X[j + a] - X[i + a]
            cb[a] = xb[j + a] - xb[i + a]
            h[a] = hb[e, a]
            ge[a] = g[e, a]
        if not carry_tension(c, cb, h, kb[e], CARRY):
            _its, status = solve_one(c, l0[e], ea[e], w[e], ls, lf, ptr[e], ptr[e + 1], h,
                                      True, 1e-12, 100, f6, k33)
            if status == NOT_CONVERGED:
                return -1
            solved += 1
            if cd[e] != 0.0 and not chord:
                element_g(i, j, X, h, k33, l0[e], ea[e], w[e], ls, lf, ptr[e], ptr[e + 1], ge)
        if chord and cd[e] != 0.0:
            unit_chord(c, 0, ge)
        rate = 0.0
        for a in range(3):
            rate += ge[a] * (V[j + a] - V[i + a])
        visc = cd[e] * rate
        t_i, t_j = end_tensions(h, load_total[e], w[e], l0[e])
        out[e, 0] = t_i + visc
        out[e, 1] = t_j + visc
    return solved


class TensionEnvelope:
    """Running max/min of the element end tensions (n_elements, 2) and their times."""

    def __init__(self, prob):
        self.prob = prob
        m = prob.model
        ne = m.mesh.n_elements
        self._ext = np.full((2, ne, 2), np.nan)  # largest, smallest
        self._ext_time = np.full((2, ne, 2), np.nan)  # when
        self.t_max, self.t_min = self._ext
        self.time_max, self.time_min = self._ext_time
        self._h = None if prob.h is None else np.array(prob.h, float, copy=True)
        self._X = np.zeros(m.n_dof)
        self._chord = np.zeros((ne, 3))
        self._f = np.zeros((ne, 6))
        self._k = np.zeros((ne, 3, 3))
        self._its = np.zeros(ne, np.int64)
        self._stat = np.zeros(ne, np.int64)
        self.n_updates = 0
        self.n_solved = 0  # updates that solved every element afresh
        self.n_elements_solved = 0  # elements solved again in carried updates
        self._out = np.zeros((ne, 2))
        # read-only, as IDA's y: the same compiled signature of carried_tensions (one kernel
        # load per process, not two)
        self._y_unused = self._X.view()
        self._y_unused.flags.writeable = False
        self._zero_cd = np.zeros(ne)
        self._zero_g = np.zeros((ne, 3))

    def _take(self, t: float, y, carry: bool, out: np.ndarray) -> int:
        """One compiled pass (``carried_tensions``): the tensions carried from the last
        residual evaluation into ``out`` when ``carry``, and ``out`` into the envelope; the
        elements solved again, -1 where one failed (the envelope then unchanged)."""
        prob = self.prob
        xp, vp, _ = prob._supports(t)
        ax = prob.axial
        cd, g = (ax.cd, ax.g) if ax is not None else (self._zero_cd, self._zero_g)
        chord = ax is not None and ax.chord
        el = prob.model.elements
        return carried_tensions(y, prob._fidx, prob._fixed, xp, vp, prob._conn, prob._Xb,
                                prob._hw, prob._kmat, el.L0, el.EA, el.w, el._ptr, el._ls,
                                el._lf, el._load_total, cd, g, chord, out, carry, t,
                                self.n_updates == 0, self._ext, self._ext_time)

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
        solve_batch(self._chord, el.L0, el.EA, el.w, el._ptr, el._ls, el._lf, h, use_h,
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

    def update_many(self, times: np.ndarray, tension: np.ndarray) -> None:
        """Take the tensions (n, n_elements, 2) of the outputs at ``times`` (n,) into the
        envelope (a batch of deferred outputs: the same extremes as one ``update`` each; a tie
        keeps the earlier time)."""
        if times.size == 0:
            return
        for i, pick in ((0, np.argmax), (1, np.argmin)):
            k = pick(tension, axis=0)  # (n_elements, 2): the first extreme of the batch
            v = np.take_along_axis(tension, k[None], axis=0)[0]
            t = times[k]
            ext, when = self._ext[i], self._ext_time[i]
            better = (v > ext) if i == 0 else (v < ext)
            better |= np.isnan(ext) | ((v == ext) & (t < when))
            if self.n_updates == 0:
                better[:] = True
            ext[better], when[better] = v[better], t[better]
        self.n_updates += times.size

    def update(self, t: float, y: np.ndarray | None = None,
               tension: np.ndarray | None = None) -> None:
        """Take the state y at t (or its tensions, when known) into the envelope: the
        tensions carried from the step's last Newton iterate when the buffers hold a state of
        this time, else solved afresh."""
        if tension is None:
            at = self.prob._buffers_at
            if at is not None and at[0] == t:
                solved = self._take(t, y, True, self._out)
                if solved >= 0:
                    self.n_elements_solved += solved
                    self.n_updates += 1
                    return
            self.n_solved += 1
            tension = self.tensions(t, y)
            if tension is None:
                return
        # y is unused without the carry: any 1-D float array
        self._take(t, self._y_unused, False, np.ascontiguousarray(tension, float))
        self.n_updates += 1
