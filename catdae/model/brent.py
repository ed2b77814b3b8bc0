"""Brent's two scalar methods, for the few one-dimensional searches of a run.

A static step refines the sag, the lowest point, the midspan and the clearance of every cable on
the exact curve (catdae.model.span, catdae.model.assembly), and form-finding brackets a length
(catdae.model.formfind). These once called ``scipy.optimize``, whose import alone (linear
programming, global optimisers, ``scipy.fft``, ``scipy.special``, ``scipy.spatial``) was about
0.1 s of CPU in every ``catdae run`` (benchmarks/startup.md). The two algorithms are a few lines
each: they are written here step for step as scipy 1.17 performs them (the same arithmetic in
the same order, so the same iterates and the same answers to the last bit; the unit tests
compare with scipy where it is installed).

- :func:`root`: Brent's root finder on a bracket (Brent 1973, ch. 4: inverse quadratic
  interpolation, secant and bisection steps), as ``scipy.optimize.brentq``;
- :func:`minimum`: Brent's bounded minimiser (golden section and parabolic steps, Brent 1973,
  ch. 5), as ``scipy.optimize.minimize_scalar(method="bounded")``.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from typing import NamedTuple

XTOL = 2e-12  # absolute tolerance of root, m (scipy's default)
RTOL = 4 * sys.float_info.epsilon  # relative tolerance of root (scipy's default)
SQRT_EPS = math.sqrt(2.2e-16)
GOLDEN = 0.5 * (3.0 - math.sqrt(5.0))  # the golden section's smaller part of an interval


def _checked(f: Callable[[float], float], x: float) -> float:
    fx = f(x)
    if math.isnan(fx):
        raise ValueError(f"The function value at x={x} is NaN; solver cannot continue.")
    return fx


def root(f: Callable[[float], float], a: float, b: float, xtol: float = XTOL,
         rtol: float = RTOL, maxiter: int = 100) -> float:
    """A root of ``f`` in [a, b], where f(a) and f(b) differ in sign, within
    ``xtol + rtol |x|``. ValueError if the signs agree or f is NaN; RuntimeError if
    ``maxiter`` steps do not converge."""
    if xtol <= 0:
        raise ValueError(f"xtol too small ({xtol:g} <= 0)")
    if rtol < RTOL:
        raise ValueError(f"rtol too small ({rtol:g} < {RTOL:g})")
    xpre, xcur = float(a), float(b)
    xblk = fblk = spre = scur = 0.0
    fpre = float(_checked(f, xpre))
    fcur = float(_checked(f, xcur))
    if fpre == 0:
        return xpre
    if fcur == 0:
        return xcur
    if math.copysign(1.0, fpre) == math.copysign(1.0, fcur):
        raise ValueError("f(a) and f(b) must have different signs")
    for _ in range(maxiter):
        if fpre != 0 and fcur != 0 and math.copysign(1.0, fpre) != math.copysign(1.0, fcur):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):  # the best estimate is the one with the smaller |f|
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + rtol * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # secant
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:  # inverse quadratic interpolation
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            bound = 3 * abs(sbis) - delta
            if 2 * abs(stry) < (abs(spre) if abs(spre) < bound else bound):  # good, short
                spre, scur = scur, stry
            else:
                spre = scur = sbis
        else:
            spre = scur = sbis
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > delta else (delta if sbis > 0 else -delta)
        fcur = float(_checked(f, xcur))
    raise RuntimeError(f"Failed to converge after {maxiter} iterations.")


class Minimum(NamedTuple):
    x: float  # where
    fun: float  # the least value found
    nfev: int  # function evaluations
    converged: bool  # False: maxiter evaluations reached, or NaN met


def _sign(v: float) -> float:
    """sign(v), and 1 for 0 (the step's direction)."""
    return 1.0 if v >= 0.0 else -1.0 if v < 0.0 else math.nan


def minimum(f: Callable[[float], float], bounds: tuple[float, float], xatol: float = 1e-5,
            maxiter: int = 500) -> Minimum:
    """The minimum of ``f`` on ``bounds`` (finite, lower first), within ``xatol``."""
    x1, x2 = bounds
    if not (math.isfinite(x1) and math.isfinite(x2)):
        raise ValueError("Optimization bounds must be finite scalars.")
    if x1 > x2:
        raise ValueError("The lower bound exceeds the upper bound.")
    a, b = x1, x2
    fulc = a + GOLDEN * (b - a)  # v: the previous xf; nfc (w): the one before
    nfc = xf = x = fulc
    rat = e = 0.0
    fx = f(x)
    num = 1
    fu = math.inf
    ffulc = fnfc = fx
    xm = 0.5 * (a + b)
    tol1 = SQRT_EPS * abs(xf) + xatol / 3.0
    tol2 = 2.0 * tol1
    converged = True
    while abs(xf - xm) > (tol2 - 0.5 * (b - a)):
        golden = True
        if abs(e) > tol1:  # try a parabola through the three best points
            golden = False
            r = (xf - nfc) * (fx - ffulc)
            q = (xf - fulc) * (fx - fnfc)
            p = (xf - fulc) * q - (xf - nfc) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            r = e
            e = rat
            if abs(p) < abs(0.5 * q * r) and p > q * (a - xf) and p < q * (b - xf):
                rat = (p + 0.0) / q
                x = xf + rat
                if (x - a) < tol2 or (b - x) < tol2:
                    rat = tol1 * (_sign(xm - xf) if xm != xf else 1.0)
            else:
                golden = True
        if golden:
            e = (a - xf) if xf >= xm else (b - xf)
            rat = GOLDEN * e
        step = abs(rat) if abs(rat) > tol1 or math.isnan(rat) else tol1
        x = xf + _sign(rat) * step
        fu = f(x)
        num += 1
        if fu <= fx:
            if x >= xf:
                a = xf
            else:
                b = xf
            fulc, ffulc = nfc, fnfc
            nfc, fnfc = xf, fx
            xf, fx = x, fu
        else:
            if x < xf:
                a = x
            else:
                b = x
            if fu <= fnfc or nfc == xf:
                fulc, ffulc = nfc, fnfc
                nfc, fnfc = x, fu
            elif fu <= ffulc or fulc == xf or fulc == nfc:
                fulc, ffulc = x, fu
        xm = 0.5 * (a + b)
        tol1 = SQRT_EPS * abs(xf) + xatol / 3.0
        tol2 = 2.0 * tol1
        if num >= maxiter:
            converged = False
            break
    if math.isnan(xf) or math.isnan(fx) or math.isnan(fu):
        converged = False
    return Minimum(float(xf), float(fx), num, converged)
