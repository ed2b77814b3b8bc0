"""IDA's position unknowns as displacements from the step's start (docs/theory.md §18.7).

IDA's error test weighs each unknown by 1 / (rtol |y_i| + atol_i). With the nodes' coordinates
as unknowns, rtol |x| grows with the distance from the case's origin: a motion of centimetres
50 m from it was tested to 5 mm at rtol 1e-4, and the same scene moved 1 km away to 10 cm.
IDA therefore works on u = q - q_0, the free positions less those at the step's start, so
that rtol weighs the motion itself and the answer does not depend on where the origin is;
the velocities are unchanged (u' = q'). The problem (catdae.solvers.residual) keeps the
coordinates: :class:`Shift` converts at the calls between the two. q = u + q_0 is formed in
floating point as the coordinates were, so no precision is lost.
"""

from __future__ import annotations

import numpy as np


class Shift:
    """The step's start positions ``q0`` (the free dofs) and the conversions; the absolute
    state is handed to the problem as a read-only array (as IDA hands its own: one compiled
    signature of the kernels), from a buffer per caller (``slot``) that the next call of
    the same caller overwrites."""

    def __init__(self, y0: np.ndarray, resfn):
        self.q0 = np.array(y0[0::2], dtype=float, copy=True)
        self._buffers: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self.resfn = self.residual(resfn)  # the problem's residual, as IDA calls it

    def to_ida(self, y: np.ndarray) -> np.ndarray:
        u = np.array(y, dtype=float, copy=True)
        u[0::2] -= self.q0
        return u

    def from_ida(self, u: np.ndarray) -> np.ndarray:
        """A new array of the coordinates (IDA's results, kept by the caller)."""
        y = np.array(u, dtype=float, copy=True)
        y[0::2] += self.q0
        return y

    def view(self, u: np.ndarray, slot: str) -> np.ndarray:
        """The coordinates of IDA's u, read-only, valid until the next call with ``slot``."""
        if slot not in self._buffers:
            buf = np.empty(len(u))
            view = buf.view()
            view.flags.writeable = False
            self._buffers[slot] = (buf, view)
        buf, view = self._buffers[slot]
        np.copyto(buf, u)
        buf[0::2] += self.q0
        return view

    def residual(self, fn):
        """The problem's ``resfn(t, y, yp, res)`` as IDA calls it, with u."""
        view = self.view

        def resfn(t, u, yp, res):
            return fn(t, view(u, "res"), yp, res)

        return resfn

    def jacobian(self, fn):
        """The problem's ``jacfn(t, y, yp, res, cj, JJ)`` as IDA calls it, with u."""
        view = self.view

        def jacfn(t, u, yp, res, cj, JJ):
            return fn(t, view(u, "jac"), yp, res, cj, JJ)

        return jacfn
