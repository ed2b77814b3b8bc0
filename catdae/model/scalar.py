"""Two scalar searches on one element's exact curve: the extreme of a smooth function in a
bracket (sag, lowest point, clearance) and a bracketed root (the midspan point).

They replace scipy.optimize's ``minimize_scalar(method="bounded")`` and ``brentq`` here only
because importing scipy.optimize costs about 0.19 s of CPU in every process that calls them
(every static step computes the sag; benchmarks/startup.md), for a search of a few dozen
evaluations. Both are textbook methods with a guaranteed bracket: golden-section search
(Kiefer 1953) and the Illinois variant of regula falsi (Dowell & Jarratt 1971) with bisection
as a safeguard. tests/unit/test_scalar.py checks them against closed forms.
"""

from __future__ import annotations

import math
from collections.abc import Callable

_INV_PHI = (math.sqrt(5.0) - 1.0) / 2.0  # 0.618...


def minimize_bounded(f: Callable[[float], float], lo: float, hi: float,
                     xatol: float) -> tuple[float, float]:
    """(x, f(x)) at the minimum of ``f`` on [lo, hi], f unimodal there, x within ``xatol`` of
    the minimiser (golden-section search: the bracket shrinks by 0.618 per evaluation); an end
    of the interval where the minimum is there."""
    a, b = (lo, hi) if lo <= hi else (hi, lo)
    c = b - _INV_PHI * (b - a)
    d = a + _INV_PHI * (b - a)
    fc, fd = f(c), f(d)
    while b - a > 2.0 * xatol:
        if fc <= fd:
            b, d, fd = d, c, fc
            c = b - _INV_PHI * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + _INV_PHI * (b - a)
            fd = f(d)
    candidates = [(fc, c), (fd, d), (f(a), a), (f(b), b)]
    fx, x = min(candidates)
    return x, fx


def root_bracketed(f: Callable[[float], float], a: float, b: float, xtol: float,
                   max_iter: int = 200) -> float:
    """The root of ``f`` in [a, b] with f(a) f(b) <= 0, within ``xtol`` (Illinois regula falsi;
    a bisection step wherever two steps did not halve the bracket). ValueError when f has the
    same sign at both ends."""
    fa, fb = f(a), f(b)
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    if (fa > 0.0) == (fb > 0.0):
        raise ValueError("f(a) and f(b) must have different signs")
    side = 0  # which end was kept last: -1 a, +1 b (Illinois halves a kept end's value)
    widths = [abs(b - a)] * 2
    for _ in range(max_iter):
        if abs(b - a) <= 2.0 * xtol:
            return 0.5 * (a + b)
        x = b - fb * (b - a) / (fb - fa)
        if abs(b - a) > 0.5 * widths[0] or not (min(a, b) < x < max(a, b)):
            x = 0.5 * (a + b)  # too slow (or round-off): bisect
        widths = [widths[1], abs(b - a)]
        fx = f(x)
        if fx == 0.0:
            return x
        if (fx > 0.0) == (fb > 0.0):  # the root lies between a and x: a kept
            b, fb = x, fx
            if side == -1:
                fa *= 0.5
            side = -1
        else:  # between x and b: b kept
            a, fa = x, fx
            if side == 1:
                fb *= 0.5
            side = 1
    return 0.5 * (a + b)
