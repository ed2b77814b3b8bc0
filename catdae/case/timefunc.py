"""Time functions of the case file: ``constant``, ``ramp``, ``sine``, ``cosine`` and ``table``.

A time function scales a load or prescribes one axis of a support motion. Every function is a
frozen dataclass with

- ``evaluate(t) -> (f, df/dt, d2f/dt2)``, vectorised over ``t`` (a scalar gives three floats, an
  array gives three arrays of its shape), with analytic derivatives: support motions need the
  velocity and acceleration of the prescribed displacement, not only its value;
- ``__call__(t)``, the value ``f`` alone.

Absence convention: a load with no ``time`` is constant, factor ``ONE``; an axis of a support with
no motion does not move, displacement ``ZERO``. ``evaluate_or(func, t, absent=...)`` applies it so
that callers need not special-case ``None``.

The functions are data: they are built from validated numbers by :mod:`catdae.case`, nothing in a
case file is ever evaluated as code.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np

if TYPE_CHECKING:
    from scipy.interpolate import CubicSpline

__all__ = [
    "ONE",
    "ZERO",
    "Constant",
    "Cosine",
    "Ramp",
    "Sine",
    "Table",
    "TimeFunction",
    "evaluate_or",
]

def _pack(t: np.ndarray, f, df, d2f, scalar: bool) -> tuple:
    """Broadcast the three results to the shape of ``t``; plain floats for a scalar ``t``."""
    f, df, d2f = (np.broadcast_to(np.asarray(a, dtype=float), t.shape).copy() for a in (f, df, d2f))
    if scalar:
        return float(f), float(df), float(d2f)
    return f, df, d2f


@dataclass(frozen=True)
class TimeFunction:
    """Base class: a scalar function of time ``f(t)`` with its first two derivatives."""

    kind: ClassVar[str] = ""

    def evaluate(self, t) -> tuple:
        """Return ``(f, df/dt, d2f/dt2)`` at time(s) ``t`` in seconds."""
        if isinstance(t, float | int):  # hot path: one time, called by every residual
            f, df, d2f = self._evaluate(np.float64(t))
            return float(f), float(df), float(d2f)
        t_arr = np.asarray(t, dtype=float)
        f, df, d2f = self._evaluate(t_arr)
        return _pack(t_arr, f, df, d2f, scalar=t_arr.ndim == 0)

    def __call__(self, t):
        """The value ``f(t)``: a float for a scalar ``t``, an array shaped like ``t`` otherwise."""
        return self.evaluate(t)[0]

    def _evaluate(self, t: np.ndarray):  # pragma: no cover - every subclass overrides it
        raise NotImplementedError

    def breakpoints(self) -> tuple[float, ...]:
        """Times where the first or second derivative jumps (none for a smooth function).

        A transient step stops its integrator there and restarts it: a jump in a support's
        velocity is an impulse, handled by momentum balance, and a jump in acceleration is a
        step in force that the integrator should not have to find by trial.
        """
        return ()


@dataclass(frozen=True)
class Constant(TimeFunction):
    """``f(t) = value``."""

    value: float
    kind: ClassVar[str] = "constant"

    def _evaluate(self, t):
        return self.value, 0.0, 0.0


@dataclass(frozen=True)
class Ramp(TimeFunction):
    """A ramp from 0 (before ``start``) to ``amplitude`` (default 1, after ``start + duration``).

    With ``smooth = False`` the ramp is linear: its slope ``1/duration`` jumps at both corners and
    its second derivative is returned as 0 everywhere (the Dirac impulses at the corners are not
    representable); the corners belong to the ramp on the left, ``[start, start + duration)``.
    With ``smooth = True`` it is the quintic smoothstep ``10x³ - 15x⁴ + 6x⁵``, ``x = (t - start) /
    duration``, whose first and second derivatives vanish at both ends: C2, so a support motion
    built on it has a continuous velocity and acceleration.
    """

    duration: float
    start: float = 0.0
    smooth: bool = False
    amplitude: float = 1.0
    kind: ClassVar[str] = "ramp"

    def _evaluate(self, t):
        d = self.duration
        a = self.amplitude
        if isinstance(t, float):  # one time (every residual): Python floats, not numpy calls
            xc = min(max((float(t) - self.start) / d, 0.0), 1.0)
            if self.smooth:
                return (a * xc**3 * (10.0 - 15.0 * xc + 6.0 * xc**2),
                        a * 30.0 * xc**2 * (1.0 - xc) ** 2 / d,
                        a * 60.0 * xc * (1.0 - xc) * (1.0 - 2.0 * xc) / d**2)
            inside = self.start <= t < self.start + d
            return a * xc, a / d if inside else 0.0, 0.0
        x = (t - self.start) / d
        # the corners by time, not by x: exactly at the breakpoints() times, so that the slope
        # is the one after the corner there and the one before it just below (x may round)
        inside = (t >= self.start) & (t < self.start + d)
        xc = np.clip(x, 0.0, 1.0)
        if self.smooth:
            f = xc**3 * (10.0 - 15.0 * xc + 6.0 * xc**2)
            df = 30.0 * xc**2 * (1.0 - xc) ** 2 / d
            d2f = 60.0 * xc * (1.0 - xc) * (1.0 - 2.0 * xc) / d**2
            return a * f, a * df, a * d2f
        return a * xc, np.where(inside, a / d, 0.0), 0.0

    def breakpoints(self) -> tuple[float, ...]:
        # the smoothstep is C2 at both ends; the linear ramp's slope jumps at its corners
        return () if self.smooth else (self.start, self.start + self.duration)


@dataclass(frozen=True)
class Sine(TimeFunction):
    """``f(t) = offset + amplitude sin(2π frequency t + phase)``; frequency in Hz, phase in rad."""

    amplitude: float
    frequency: float
    phase: float = 0.0
    offset: float = 0.0
    kind: ClassVar[str] = "sine"

    def _evaluate(self, t):
        w = 2.0 * math.pi * self.frequency
        arg = w * t + self.phase
        trig = math if isinstance(arg, float) else np  # one time: math, not numpy calls
        s, c = trig.sin(arg), trig.cos(arg)
        a = self.amplitude
        return self.offset + a * s, a * w * c, -a * w * w * s


@dataclass(frozen=True)
class Cosine(TimeFunction):
    """``f(t) = offset + amplitude cos(2π frequency t + phase)``; frequency in Hz, phase in rad."""

    amplitude: float
    frequency: float
    phase: float = 0.0
    offset: float = 0.0
    kind: ClassVar[str] = "cosine"

    def _evaluate(self, t):
        w = 2.0 * math.pi * self.frequency
        arg = w * t + self.phase
        trig = math if isinstance(arg, float) else np  # one time: math, not numpy calls
        s, c = trig.sin(arg), trig.cos(arg)
        a = self.amplitude
        return self.offset + a * c, -a * w * s, -a * w * w * c


@dataclass(frozen=True)
class Table(TimeFunction):
    """Cubic-spline interpolation of the points ``(t[i], value[i])``, ``t`` strictly increasing.

    Inside the record, ``[t[0], t[-1])``, the interpolant is ``scipy.interpolate.CubicSpline``
    with *not-a-knot* ends: it passes through every point, is C2, and takes the slope and
    curvature at the first and last points from the record itself (the first two and the last
    two intervals are one cubic each), so that a smooth motion sampled at a step dt is
    reproduced to O(dt⁴) in value, O(dt³) in velocity and O(dt²) in acceleration up to the ends.
    Nothing is imposed at the ends: a spline clamped to zero slope there would invent an
    acceleration spike wherever the record starts or ends moving. Two points give a straight
    line, three a parabola.

    Outside the record the function is held at its end values, at rest (zero derivatives). A
    record that starts or ends moving therefore has a jump in velocity at ``t[0]`` or ``t[-1]``
    (an impulse at the support, :meth:`breakpoints`); its last point belongs to the hold, as the
    corners of a linear :class:`Ramp` do. ``file`` records where the points came from (as written
    in the case file), or is ``None`` for inline points.
    """

    t: tuple[float, ...]
    value: tuple[float, ...]
    file: str | None = None
    kind: ClassVar[str] = "table"
    _spline: CubicSpline = field(init=False, repr=False, compare=False, hash=False)
    _knots: list = field(init=False, repr=False, compare=False, hash=False)
    _cubics: list = field(init=False, repr=False, compare=False, hash=False)

    def __post_init__(self):
        from scipy.interpolate import CubicSpline  # lazy: only for tables

        spline = CubicSpline(np.asarray(self.t, float), np.asarray(self.value, float),
                             bc_type="not-a-knot")
        # A cache derived from the frozen fields, set once here and never changed.
        object.__setattr__(self, "_spline", spline)
        # one time (every residual): the same cubics in Python floats, found by bisection,
        # not three scipy calls (40 µs a time on a 3000-point heave record)
        object.__setattr__(self, "_knots", [float(x) for x in spline.x])
        object.__setattr__(self, "_cubics", [tuple(map(float, c)) for c in spline.c.T])

    def _evaluate(self, t):
        if isinstance(t, float):
            x = self._knots
            if t >= x[-1] or t < x[0]:  # held at the end values, at rest
                i = 0 if t < x[0] else len(x) - 2
                s = 0.0 if t < x[0] else x[-1] - x[-2]
                a, b, c, d = self._cubics[i]
                return ((a * s + b) * s + c) * s + d, 0.0, 0.0
            i = bisect_right(x, t) - 1
            s = t - x[i]
            a, b, c, d = self._cubics[i]
            return (((a * s + b) * s + c) * s + d, (3.0 * a * s + 2.0 * b) * s + c,
                    6.0 * a * s + 2.0 * b)
        t0, t1 = self.t[0], self.t[-1]
        tc = np.clip(t, t0, t1)
        inside = (t >= t0) & (t < t1)
        sp = self._spline
        return sp(tc), np.where(inside, sp(tc, 1), 0.0), np.where(inside, sp(tc, 2), 0.0)

    def breakpoints(self) -> tuple[float, ...]:
        # the held values meet the record with its end velocity and acceleration, which need
        # not be zero: the integrator stops and restarts at both ends
        return (self.t[0], self.t[-1])


ONE = Constant(1.0)
"""The factor of a load with no ``time``: the load is constant."""

ZERO = Constant(0.0)
"""The displacement of a support axis with no motion."""


def evaluate_or(func: TimeFunction | None, t, *, absent: TimeFunction) -> tuple:
    """``func.evaluate(t)``, or ``absent.evaluate(t)`` when ``func`` is ``None``.

    Use ``absent=ONE`` for load factors and ``absent=ZERO`` for support-motion axes.
    """
    return (absent if func is None else func).evaluate(t)
