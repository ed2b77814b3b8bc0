"""Time functions built from others: ``product`` (a sine inside a ramp envelope, so that a
test rig starts with no velocity jump), ``trapezoid`` (ramp up, hold, ramp down) and the
scaled function behind a support motion along a ``direction`` (docs/theory.md §12).

Each evaluates exact first and second derivatives from those of its parts (the product rule,
Leibniz's rule for the second derivative), so a support motion built from them stays exact.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from catdae.case.timefunc import Ramp, TimeFunction


@dataclass(frozen=True)
class Product(TimeFunction):
    """``f(t) = f1(t) f2(t) ... fn(t)``: (f g)' = f' g + f g', (f g)'' = f'' g + 2 f' g' + f g''."""

    factors: tuple[TimeFunction, ...]
    kind: ClassVar[str] = "product"

    def _evaluate(self, t):
        f, df, d2f = self.factors[0]._evaluate(t)
        for g_fun in self.factors[1:]:
            g, dg, d2g = g_fun._evaluate(t)
            f, df, d2f = f * g, df * g + f * dg, d2f * g + 2.0 * df * dg + f * d2g
        return f, df, d2f

    def breakpoints(self) -> tuple[float, ...]:
        return tuple(sorted({b for g in self.factors for b in g.breakpoints()}))


@dataclass(frozen=True)
class Scaled(TimeFunction):
    """``f(t) = factor g(t)``: one axis of a support motion along a direction."""

    function: TimeFunction
    factor: float
    kind: ClassVar[str] = "scaled"

    def _evaluate(self, t):
        f, df, d2f = self.function._evaluate(t)
        return self.factor * f, self.factor * df, self.factor * d2f

    def breakpoints(self) -> tuple[float, ...]:
        return self.function.breakpoints()


@dataclass(frozen=True)
class Trapezoid(TimeFunction):
    """0 before ``start``, up to ``amplitude`` over ``rise`` s, held for ``hold`` s, down to 0
    over ``fall`` s: a ramp up less a ramp down (both linear, or both the C2 smoothstep with
    ``smooth = True``, see :class:`~catdae.case.timefunc.Ramp`)."""

    rise: float
    hold: float
    fall: float
    start: float = 0.0
    amplitude: float = 1.0
    smooth: bool = False
    kind: ClassVar[str] = "trapezoid"

    def _ramps(self) -> tuple[Ramp, Ramp]:
        up = Ramp(self.rise, self.start, self.smooth, self.amplitude)
        down = Ramp(self.fall, self.start + self.rise + self.hold, self.smooth, self.amplitude)
        return up, down

    def _evaluate(self, t):
        up, down = self._ramps()
        return tuple(np.asarray(a) - np.asarray(b)
                     for a, b in zip(up._evaluate(t), down._evaluate(t), strict=True))

    def breakpoints(self) -> tuple[float, ...]:
        up, down = self._ramps()
        return tuple(sorted(set(up.breakpoints()) | set(down.breakpoints())))
