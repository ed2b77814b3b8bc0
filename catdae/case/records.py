"""Ground-motion records: support motions given as sampled accelerations or velocities.

A seismic record is a table of accelerations (or velocities) at sample times. The support that
follows it starts from rest at its case position: before the first sample it does not move
(u = v = a = 0). The record is integrated exactly, with no baseline correction, so that the
support sees the record's own values at its samples:

- ``AccelerationRecord``: the acceleration is interpolated piecewise-linearly between samples
  (the convention of the exact piecewise-linear excitation, Nigam & Jennings 1969): it never
  leaves the range of two neighbouring samples, and its integrals, velocity (piecewise quadratic,
  C1) and displacement (piecewise cubic, C2), are exact polynomials, accumulated sample by
  sample. The displacement of a smooth motion sampled at interval Δt is reproduced to O(Δt²).
- ``VelocityRecord``: the velocity is interpolated by a not-a-knot cubic spline (C2: the
  acceleration the support sees is continuous inside the record, so the integrator need not
  stop at every sample, as it would with a piecewise-linear velocity); the displacement is the
  spline's exact antiderivative. A smooth motion is reproduced to O(Δt⁴).

After the last sample the acceleration is zero and the velocity keeps its last value: a record
whose integrated velocity does not end at zero makes the support drift on at that speed. That
is what the record says; correct its baseline before use if it should end at rest.

Both are :class:`~catdae.case.timefunc.TimeFunction` objects (``evaluate(t) -> (u, v, a)``), kept
apart from the displacement ``Table`` interpolant of :mod:`catdae.case.timefunc`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from catdae.case.timefunc import TimeFunction

__all__ = ["AccelerationRecord", "VelocityRecord"]


def _after(t, t1, u1, v1):
    """Motion after the record: zero acceleration, the last velocity kept."""
    return u1 + v1 * (t - t1), v1, 0.0


@dataclass(frozen=True)
class AccelerationRecord(TimeFunction):
    """Support displacement from sampled accelerations ``value`` (m/s²) at times ``t`` (s).

    Piecewise-linear acceleration, integrated exactly from rest at ``t[0]``: on sample interval
    k, with τ = t - t_k and slope s_k = (a_{k+1} - a_k) / (t_{k+1} - t_k),

        a = a_k + s_k τ,   v = v_k + a_k τ + s_k τ²/2,   u = u_k + v_k τ + a_k τ²/2 + s_k τ³/6

    with v_0 = u_0 = 0 and v_k, u_k these expressions at the end of the interval before.
    ``file`` and ``column`` record where the samples came from (``None`` for inline points).
    """

    t: tuple[float, ...]
    value: tuple[float, ...]
    file: str | None = None
    column: str | None = None
    kind: ClassVar[str] = "table"
    quantity: ClassVar[str] = "acceleration"
    _pp: tuple = field(init=False, repr=False, compare=False, hash=False)

    def __post_init__(self):
        ts = np.asarray(self.t, float)  # (n,) s
        a = np.asarray(self.value, float)  # (n,) m/s²
        dt = np.diff(ts)
        slope = np.diff(a) / dt  # (n-1,) m/s³
        dv = a[:-1] * dt + 0.5 * slope * dt**2
        v = np.concatenate([[0.0], np.cumsum(dv)])  # (n,) m/s at the samples
        du = v[:-1] * dt + 0.5 * a[:-1] * dt**2 + slope * dt**3 / 6.0
        u = np.concatenate([[0.0], np.cumsum(du)])  # (n,) m
        # A cache derived from the frozen fields, set once here and never changed.
        object.__setattr__(self, "_pp", (ts, a, slope, v, u))

    def _evaluate(self, t):
        ts, a, slope, v, u = self._pp
        k = np.clip(np.searchsorted(ts, t, side="right") - 1, 0, ts.size - 2)
        tau = t - ts[k]
        ak, sk, vk = a[k], slope[k], v[k]
        f = u[k] + vk * tau + 0.5 * ak * tau**2 + sk * tau**3 / 6.0
        df = vk + ak * tau + 0.5 * sk * tau**2
        d2f = ak + sk * tau
        uf, vf, af = _after(t, ts[-1], u[-1], v[-1])
        before, after = t < ts[0], t > ts[-1]
        return (np.where(before, 0.0, np.where(after, uf, f)),
                np.where(before, 0.0, np.where(after, vf, df)),
                np.where(before, 0.0, np.where(after, af, d2f)))

    def breakpoints(self) -> tuple[float, ...]:
        # the velocity is continuous everywhere; the acceleration jumps at the first sample
        # (from rest) and at the last (to zero) unless the record is zero there
        ends = ((self.t[0], self.value[0]), (self.t[-1], self.value[-1]))
        return tuple(float(tk) for tk, ak in ends if ak != 0.0)


@dataclass(frozen=True)
class VelocityRecord(TimeFunction):
    """Support displacement from sampled velocities ``value`` (m/s) at times ``t`` (s).

    A not-a-knot cubic spline through the samples (C2 inside the record), its derivative the
    acceleration and its exact antiderivative from ``t[0]`` the displacement. Before ``t[0]``
    the support is at rest: a first sample other than zero is a jump in velocity (an impulse,
    which a transient step handles by momentum balance).
    """

    t: tuple[float, ...]
    value: tuple[float, ...]
    file: str | None = None
    column: str | None = None
    kind: ClassVar[str] = "table"
    quantity: ClassVar[str] = "velocity"
    _sp: tuple = field(init=False, repr=False, compare=False, hash=False)

    def __post_init__(self):
        ts = np.asarray(self.t, float)
        from scipy.interpolate import CubicSpline  # lazy: only for records

        spline = CubicSpline(ts, np.asarray(self.value, float), bc_type="not-a-knot")
        disp = spline.antiderivative()  # zero at t[0]
        # A cache derived from the frozen fields, set once here and never changed.
        object.__setattr__(self, "_sp", (ts, spline, disp, float(disp(ts[-1]))))

    def _evaluate(self, t):
        ts, spline, disp, u1 = self._sp
        tc = np.clip(t, ts[0], ts[-1])
        uf, vf, af = _after(t, ts[-1], u1, float(self.value[-1]))
        before, after = t < ts[0], t > ts[-1]
        return (np.where(before, 0.0, np.where(after, uf, disp(tc))),
                np.where(before, 0.0, np.where(after, vf, spline(tc))),
                np.where(before, 0.0, np.where(after, af, spline(tc, 1))))

    def breakpoints(self) -> tuple[float, ...]:
        # from rest to the first sample, and from the spline's slope to zero after the last
        return (float(self.t[0]), float(self.t[-1]))
