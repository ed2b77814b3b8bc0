"""catdae.model.brent against closed forms, and against scipy.optimize (an independent
implementation of the same two algorithms): the same answers to the last bit, so the span
quantities, sags and form-found lengths of a run did not change when scipy.optimize stopped
being imported."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catdae.model import brent

FUNCTIONS = [  # (f, bracket of a sign change, bounds of a minimum)
    (lambda x: x * x - 2.0, (0.0, 3.0), (-1.0, 2.5)),
    (lambda x: math.cos(x) - x, (0.0, 1.0), (2.0, 5.0)),
    (lambda x: math.exp(x) - 5.0 + 0.1 * x**3, (-2.0, 3.0), (-3.0, 0.7)),
    (lambda x: (x - 0.3) ** 3 + 1e-3 * (x - 0.3), (-1.0, 1.0), (0.2, 0.9)),
    (lambda x: 1e4 * math.cosh((x - 40.0) / 800.0) - 1e4 - 0.05, (40.0, 90.0), (0.0, 80.0)),
    (lambda x: math.atan(50.0 * (x - 0.123456789)), (-1.0, 2.0), (-1.0, 2.0)),
    (lambda x: -math.sin(x) * x, (2.0, 4.0), (0.0, 3.0)),
]


def test_root_and_minimum_meet_closed_forms():
    assert abs(brent.root(lambda x: x * x - 2.0, 0.0, 3.0) - math.sqrt(2.0)) < 4e-12
    m = brent.minimum(lambda x: (x - 0.7) ** 2 + 1.0, (0.0, 2.0), xatol=1e-10)
    # a smooth minimum is located to about sqrt(eps) relative (the values there are equal)
    assert abs(m.x - 0.7) < 3e-8 and m.fun == pytest.approx(1.0, abs=1e-15) and m.converged
    # the minimum at a bound: the search ends within 2 (sqrt(eps) |x| + xatol / 3) of it
    m = brent.minimum(lambda x: x, (1.0, 2.0), xatol=1e-9)
    assert 1.0 <= m.x < 1.0 + 4e-8
    with pytest.raises(ValueError, match="different signs"):
        brent.root(lambda x: x * x + 1.0, -1.0, 1.0)
    with pytest.raises(ValueError, match="NaN"):
        brent.root(lambda x: math.nan, -1.0, 1.0)
    with pytest.raises(ValueError, match="exceeds"):
        brent.minimum(lambda x: x, (2.0, 1.0))


def _logged(f, log):
    def g(x):
        log.append(x)
        return f(x)
    return g


@pytest.mark.parametrize("k", range(len(FUNCTIONS)))
def test_the_same_iterates_as_scipy(k):
    opt = pytest.importorskip("scipy.optimize")
    f, bracket, bounds = FUNCTIONS[k]
    for xtol in (2e-12, 1e-9, 1e-6 * (1 + abs(bracket[1]))):
        calls, ours = [], []
        assert brent.root(_logged(f, ours), *bracket, xtol=xtol) == \
            opt.brentq(_logged(f, calls), *bracket, xtol=xtol)
        assert ours == calls
    if k == 0:  # no convergence in 100 steps, for both (a triple root)
        for solver in (brent.root, opt.brentq):
            with pytest.raises(RuntimeError, match="Failed to converge after 100 iter"):
                solver(lambda x: (x - 0.3) ** 3, -1.0, 1.0)
    for xatol in (1e-5, 1e-10 * (bounds[1] - bounds[0]), 1e-13):
        for lo, hi in (bounds, (np.float64(bounds[0]), np.float64(bounds[1]))):
            calls, ours = [], []
            mine = brent.minimum(_logged(f, ours), (lo, hi), xatol=xatol)
            ref = opt.minimize_scalar(_logged(f, calls), bounds=(lo, hi),
                                      method="bounded", options={"xatol": xatol})
            assert (mine.x, mine.fun, mine.nfev) == (float(ref.x), float(ref.fun), ref.nfev)
            assert ours == calls
