"""The work done on the cables by the water and the air during a transient step
(docs/theory.md §13.5): W(t) = ∫ P dt with P = f_fluid · v - (M_a a) · v, the power of the
drag, Froude-Krylov and buoyancy forces the element weights do not hold, and of the added-mass
force, summed by the trapezoidal rule over IDA's own steps. With it the energy balance of a
step in a fluid reads energy_total(t) - energy_total(t0) = W(t) (no damping, fixed supports,
constant loads)."""

from __future__ import annotations

import numpy as np


class FluidWork:
    """Accumulates W over the steps of one transient; ``at`` gives it at a time inside the
    last step."""

    def __init__(self, prob):
        self.prob = prob
        self.fluid = prob.model.fluid
        self.W = 0.0  # J, at time self.t
        self.t: float | None = None
        self.P = 0.0  # W, power at self.t
        n = prob.n_dof
        self._X, self._V, self._A = np.zeros(n), np.zeros(n), np.zeros(n)  # full dofs

    def power(self, t: float, y: np.ndarray, yp: np.ndarray) -> float:
        prob = self.prob
        V, A = prob.full_vectors(t, y[1::2], yp[1::2], out=(self._V, self._A))
        X = self._X  # every dof is free or fixed: all overwritten
        X[prob.fidx] = y[0::2]
        X[prob.model.fixed] = prob._supports(t)[0]
        out = self.fluid.evaluate(t, X, V, A)[0]  # M_a A - f
        return -float(out @ V)

    def at(self, t: float, y: np.ndarray, yp: np.ndarray, power: float | None = None) -> float:
        """W at t >= self.t (trapezoid from the last step's end); ``power`` P at (t, y, yp)
        if the caller has it (an output: the residual pass there left the fluid's forces)."""
        p = self.power(t, y, yp) if power is None else power
        if self.t is None:
            return 0.0
        return self.W + 0.5 * (self.P + p) * (t - self.t)

    def advance(self, t: float, y: np.ndarray, yp: np.ndarray) -> None:
        """A step of IDA ended (or restarted) at t with state y, yp."""
        p = self.power(t, y, yp)
        if self.t is not None:
            self.W += 0.5 * (self.P + p) * (t - self.t)
        self.t, self.P = t, p
