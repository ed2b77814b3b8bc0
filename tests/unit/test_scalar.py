"""The scalar searches on an element's curve (catdae/model/scalar.py) against closed forms,
and a transient run that no longer imports scipy.optimize (catdae/solvers/transient.py)."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

from catdae.model.scalar import minimize_bounded, root_bracketed

from scene_toml import cable_scene, load, static_step, step

# a wire of 4 elements tapped at its middle: a static and a short transient step
CASE = cable_scene(B=(10.0, 0.0, 1.0), L0=11.0, EA=3.4e7, mass=5.0, elements=4,
                   title="No scipy.optimize",
                   extra=load("tap", [0.0, 20.0, -30.0], node="c.2",
                              time={"kind": "ramp", "duration": 0.02}),
                   steps=static_step("first") + step("transient", "tapped", duration=0.04,
                                                     output_interval=0.01))


@pytest.mark.parametrize("f, lo, hi, x_true", [
    (lambda x: (x - 0.3) ** 2 + 2.0, 0.0, 1.0, 0.3),
    (lambda x: (x - 0.3) ** 4, 0.0, 1.0, 0.3),
    (lambda x: math.exp(x) - 3.0 * x, 0.0, 2.0, math.log(3.0)),
    (lambda x: x * x + 1e-3 / x, 0.01, 1.0, (5e-4) ** (1.0 / 3.0)),
])
def test_minimum_within_xatol_of_the_closed_form(f, lo, hi, x_true):
    """Minimisers with a curvature: located to the requested tolerance (golden section stops
    on the bracket, not on round-off, where the curvature is not small)."""
    for xatol in (1e-4, 1e-7):
        x, fx = minimize_bounded(f, lo, hi, xatol)
        assert abs(x - x_true) <= xatol, (x, x_true, xatol)
        assert fx == f(x)
        assert fx - f(x_true) <= 50.0 * xatol**2 + 1e-15  # curvatures here are below 100


def test_minimum_at_an_end_and_reversed_bounds():
    x, fx = minimize_bounded(lambda x: x, 0.0, 1.0, 1e-10)
    assert x == 0.0 and fx == 0.0
    x, fx = minimize_bounded(lambda x: -x, 1.0, 0.0, 1e-10)  # bounds in either order
    assert x == 1.0 and fx == -1.0


def test_flat_minimum_value_to_round_off():
    """A minimum whose function is flat to round-off (a cosh about its bottom, like a cable's
    lowest point): the value is exact to round-off, the place to sqrt(eps) of the scale."""
    x, fx = minimize_bounded(lambda v: math.cosh(v - 0.1), -1.0, 1.0, 1e-11)
    assert abs(fx - 1.0) <= 4e-16
    assert abs(x - 0.1) <= 3e-8


@pytest.mark.parametrize("f, a, b, root", [
    (lambda x: x ** 3 - 2.0, 0.0, 3.0, 2.0 ** (1.0 / 3.0)),
    (math.cos, 0.0, 3.0, math.pi / 2.0),
    (lambda x: math.exp(x) - 10.0, -5.0, 5.0, math.log(10.0)),
    (lambda x: math.atan(50.0 * (x - 0.3)), -10.0, 1.0, 0.3),
    (lambda x: (x - 1e-3) ** 3, -1.0, 2.0, 1e-3),  # a triple root: brentq fails on it
    (lambda x: 2.0 - x ** 3, 0.0, 3.0, 2.0 ** (1.0 / 3.0)),  # decreasing
])
def test_root_within_xtol_of_the_closed_form(f, a, b, root):
    calls = []

    def counted(x):
        calls.append(x)
        return f(x)

    for xtol in (1e-6, 1e-12):
        calls.clear()
        x = root_bracketed(counted, a, b, xtol)
        assert abs(x - root) <= xtol + 4e-16 * abs(root), (x, root, xtol)
        assert len(calls) <= 120  # bisection's bound is log2(11/2e-12) = 43 per halving pair
        assert all(min(a, b) <= c <= max(a, b) for c in calls)  # never leaves the bracket


def test_root_needs_a_sign_change():
    with pytest.raises(ValueError, match="different signs"):
        root_bracketed(lambda x: x * x + 1.0, -1.0, 1.0, 1e-9)
    assert root_bracketed(lambda x: x, 0.0, 1.0, 1e-9) == 0.0  # a root at an end


_PROBE = r"""
import sys
import catdae
tree = catdae.run(sys.argv[1], progress=False)
assert "scipy.optimize" not in sys.modules, "a static and transient run imported scipy.optimize"
import scipy.optimize
import scipy.sparse as sp
import numpy as np
import sksundae._cy_ida as ida
g = ida.group_columns(sp.csc_matrix(np.array([[1.0, 0, 1], [0, 1, 0], [1, 0, 1]])))
assert list(g) == list(scipy.optimize._numdiff.group_columns(sp.csc_matrix(
    np.array([[1.0, 0, 1], [0, 1, 0], [1, 0, 1]])))), g
print("ok", float(tree["tapped"].ds.time[-1]))
"""


def test_a_transient_run_does_not_import_scipy_optimize(tmp_path):
    """scikit-sundae imports scipy.optimize (0.19 s of CPU) for a helper catdae never calls; the
    static step's sag and span quantities used scipy.optimize too. In a fresh process a static
    and transient run leaves scipy.optimize unimported, and afterwards scikit-sundae's helper is
    scipy's own (the same column groups)."""
    case = tmp_path / "case.toml"
    case.write_text(CASE)
    proc = subprocess.run([sys.executable, "-c", _PROBE, str(case)], capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.startswith("ok")
