"""Checks of the reference solutions in ``tests/reference.py`` against independent facts.

These tests never import ``catdae``: they validate the yardstick itself (rigid-catenary closed
forms, direct quadrature of the cable ODE, equilibrium, small-sag limits, and the limits of Irvine's
frequency equation).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.optimize import brentq, minimize_scalar

from reference import (
    irvine_catenary,
    irvine_catenary_inclined_3d,
    irvine_caughey_frequencies,
    irvine_symmetric_roots,
    taut_string_frequencies,
)


def _ode_position(sol, s, w, EA, scale):
    """x(s), z(s) by direct quadrature of dx/ds = H/T + H/EA, dz/ds = u/T + u/EA."""
    H, V_i = sol["H"], sol["V_i"]
    flex = 0.0 if math.isinf(EA) else 1.0 / EA

    def u(t):
        return V_i + w * t

    def T(t):
        return math.hypot(H, u(t))

    s_low = -V_i / w  # u = 0: split there (the integrand of z changes sign)
    pts = [s_low] if 0.0 < s_low < s else None
    # full_output=1 silences QUADPACK's round-off warnings; the error estimate is checked instead
    opts = dict(epsabs=1e-14 * scale, epsrel=1e-13, limit=200, points=pts, full_output=1)
    px, ex = quad(lambda t: H / T(t) + H * flex, 0.0, s, **opts)[:2]
    pz, ez = quad(lambda t: u(t) / T(t) + u(t) * flex, 0.0, s, **opts)[:2]
    assert max(ex, ez) < 1e-12 * scale
    return px, pz


# ----------------------------------------------------------------------------------------------
# Statics: closed-form limits
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("span, L0, w",
                         [(100.0, 101.0, 10.0), (50.0, 80.0, 3.0), (10.0, 15.0, 49.05)])
def test_inextensible_level_matches_rigid_catenary(span, L0, w):
    sol = irvine_catenary(span, 0.0, L0, math.inf, w)
    H = sol["H"]
    # rigid catenary: L0 = (2H/w) sinh(w l / (2H))
    assert (2 * H / w) * math.sinh(w * span / (2 * H)) == pytest.approx(L0, rel=1e-13)
    # independent solve of the same transcendental equation for H
    H_ref = brentq(lambda h: (2 * h / w) * math.sinh(w * span / (2 * h)) - L0,
                   1e-3 * w * L0, 1e6 * w * L0, xtol=1e-300, rtol=1e-15)
    assert H == pytest.approx(H_ref, rel=1e-12)
    assert sol["V_i"] == pytest.approx(-w * L0 / 2, rel=1e-13)
    assert sol["V_j"] == pytest.approx(w * L0 / 2, rel=1e-13)
    # sag of the rigid level catenary: (H/w)(cosh(w l/(2H)) - 1)
    assert sol["sag"] == pytest.approx((H / w) * (math.cosh(w * span / (2 * H)) - 1), rel=1e-12)
    assert sol["lowest_z"] == pytest.approx(-sol["sag"], rel=1e-12)
    # a huge but finite EA approaches the inextensible solution
    stiff = irvine_catenary(span, 0.0, L0, 1e18 * w * L0, w)
    assert stiff["H"] == pytest.approx(H, rel=1e-9)


@pytest.mark.parametrize("span, dz, L0", [(100.0, 30.0, 120.0), (100.0, -60.0, 130.0),
                                          (20.0, 200.0, 205.0)])
def test_inextensible_inclined_matches_rigid_catenary(span, dz, L0):
    w = 7.0
    sol = irvine_catenary(span, dz, L0, math.inf, w)
    H = sol["H"]
    # rigid catenary between unequal supports: sqrt(L0^2 - dz^2) = (2H/w) sinh(w l/(2H))
    lhs = math.sqrt(L0**2 - dz**2)
    assert (2 * H / w) * math.sinh(w * span / (2 * H)) == pytest.approx(lhs, rel=1e-12)
    # inextensible catenary: tension difference equals w times the height difference
    assert sol["T_j"] - sol["T_i"] == pytest.approx(w * dz, rel=1e-11, abs=1e-9 * w * L0)
    # and the stretched length is L0
    assert sol["stretched_length"] == L0


@pytest.mark.parametrize("EA", [1e4, 1e6, 1e9])
def test_elastic_level_closed_form(EA):
    span, L0, w = 100.0, 102.0, 20.0
    sol = irvine_catenary(span, 0.0, L0, EA, w)
    H = sol["H"]
    W = w * L0
    # Irvine (1981) level elastic catenary: l = H L0/EA + (2H/w) asinh(W/(2H))
    assert H * L0 / EA + (2 * H / w) * math.asinh(W / (2 * H)) == pytest.approx(span, rel=1e-13)
    # midspan sag: (H/w)(sqrt(1 + (W/2H)^2) - 1) + w L0^2/(8 EA)
    d = (H / w) * (math.sqrt(1 + (W / (2 * H)) ** 2) - 1) + w * L0**2 / (8 * EA)
    assert sol["sag"] == pytest.approx(d, rel=1e-12)
    assert sol["s_sag"] == pytest.approx(L0 / 2, rel=1e-13)


def test_taut_cable_shorter_than_chord():
    # unstrained length shorter than the chord: the cable is stretched
    span, L0, w, EA = 10.0, 9.99, 50.0, 3.4e7
    sol = irvine_catenary(span, 0.0, L0, EA, w)
    assert sol["stretched_length"] > span
    assert sol["H"] > EA * (span - L0) / L0 * 0.99


@pytest.mark.parametrize("ratio", [1e-2, 3e-3])
def test_parabolic_small_sag_limit(ratio):
    # w l / H = ratio: parabola sag w l^2/(8H); relative error O(ratio^2)
    span, w, EA = 200.0, 10.0, 1e12
    H_target = w * span / ratio
    # unstrained length of the rigid catenary with that H (EA large: small correction)
    L0 = (2 * H_target / w) * math.sinh(w * span / (2 * H_target))
    sol = irvine_catenary(span, 0.0, L0, EA, w)
    parab = w * span**2 / (8 * sol["H"])
    assert sol["sag"] == pytest.approx(parab, rel=ratio**2)
    # inclined: the sag measured vertically is still w l^2/(8 H) to leading order when w is
    # taken per unit span (w L0 / l)
    dz = 0.3 * span
    L0i = math.hypot(L0, dz)  # sqrt(L0^2 + dz^2) = rigid-catenary length for the same H
    sol_i = irvine_catenary(span, dz, L0i, EA, w)
    parab_i = (w * L0i / span) * span**2 / (8 * sol_i["H"])
    assert sol_i["sag"] == pytest.approx(parab_i, rel=10 * ratio)


# ----------------------------------------------------------------------------------------------
# Statics: ODE quadrature, equilibrium, sag/low point by brute force
# ----------------------------------------------------------------------------------------------
geometry = st.tuples(
    st.floats(1.0, 500.0),   # span
    st.floats(-2.0, 2.0),    # dz / span
    st.floats(1.0, 2.5),     # L0 / chord
    st.floats(1.0, 8.0),     # log10(EA / (w L0))
    st.floats(0.1, 500.0),   # w
)


@settings(max_examples=25, deadline=None)
@given(geometry)
def test_quadrature_equilibrium_and_sag(g):
    span, dzr, Lr, logEA, w = g
    dz = dzr * span
    L0 = Lr * math.hypot(span, dz)
    EA = 10.0**logEA * w * L0
    sol = irvine_catenary(span, dz, L0, EA, w)
    H, V_i, V_j = sol["H"], sol["V_i"], sol["V_j"]
    scale = max(span, abs(dz), L0)
    assert H > 0
    # exact up to the rounding of the larger end value (taut cables: |V| >> w L0)
    assert V_j - V_i == pytest.approx(w * L0, rel=1e-14, abs=4e-16 * max(abs(V_i), abs(V_j)))
    assert sol["T_i"] == pytest.approx(math.hypot(H, V_i), rel=1e-15)
    assert sol["T_j"] == pytest.approx(math.hypot(H, V_j), rel=1e-15)
    assert sol["residual"] <= 1e-13 * scale

    # the ODE integrated numerically ends at support j and agrees along the way
    for s in (0.3 * L0, 0.77 * L0, L0):
        px, pz = _ode_position(sol, s, w, EA, scale)
        cx, cz = sol["x"](s)
        assert abs(px - cx) < 1e-11 * scale
        assert abs(pz - cz) < 1e-11 * scale
    px, pz = _ode_position(sol, L0, w, EA, scale)
    assert abs(px - span) < 1e-11 * scale
    assert abs(pz - dz) < 1e-11 * scale
    assert sol["x"](0.0) == (0.0, 0.0)

    # vectorised evaluation equals scalar evaluation
    ss = np.linspace(0.0, L0, 7)
    vx, vz = sol["x"](ss)
    assert np.allclose(vx, [sol["x"](s)[0] for s in ss], rtol=0, atol=1e-14 * scale)
    assert np.allclose(vz, [sol["x"](s)[1] for s in ss], rtol=0, atol=1e-14 * scale)

    # stretched length by quadrature
    stretched = quad(lambda t: 1.0 + math.hypot(H, V_i + w * t) / EA, 0.0, L0,
                     epsabs=0.0, epsrel=1e-13)[0]
    assert sol["stretched_length"] == pytest.approx(stretched, rel=1e-12)

    # sag and low point by brute-force maximisation / minimisation over s
    def below_chord(s):
        cx, cz = sol["x"](s)
        return dz / span * cx - cz

    grid = np.linspace(0.0, L0, 2001)
    gx, gz = sol["x"](grid)
    k = int(np.argmax(dz / span * gx - gz))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    best = minimize_scalar(lambda s: -below_chord(s), bounds=(lo, hi), method="bounded",
                           options=dict(xatol=1e-10 * L0))
    assert sol["sag"] >= -best.fun - 1e-13 * scale
    assert sol["sag"] == pytest.approx(-best.fun, rel=1e-9, abs=1e-12 * scale)
    assert sol["sag"] > 0
    assert sol["lowest_z"] <= gz.min() + 1e-13 * scale
    assert sol["lowest_z"] == pytest.approx(gz.min(), rel=1e-5, abs=1e-6 * scale)


def test_rejects_bad_input():
    with pytest.raises(ValueError):
        irvine_catenary(0.0, 1.0, 2.0, 1e6, 1.0)
    with pytest.raises(ValueError):
        irvine_catenary(1.0, 0.0, 2.0, 1e6, 0.0)
    with pytest.raises(ValueError):
        irvine_catenary(3.0, 4.0, 5.0, math.inf, 1.0)


# ----------------------------------------------------------------------------------------------
# 3-D wrapper
# ----------------------------------------------------------------------------------------------
def test_inclined_3d_wrapper():
    w, EA, L0 = 5.0 * 9.81, 3.4e7, 15.0
    A = np.array([1.0, -2.0, 0.5])
    d = np.array([6.0, 8.0, 2.0])  # horizontal span 10, rising 2
    B = A + d
    sol = irvine_catenary_inclined_3d(A, B, L0, EA, w)
    ref = irvine_catenary(10.0, 2.0, L0, EA, w)
    e = np.array([0.6, 0.8, 0.0])
    assert np.allclose(sol["e"], e, rtol=0, atol=1e-15)
    assert np.allclose(sol["h"], [ref["H"] * 0.6, ref["H"] * 0.8, ref["V_i"]], rtol=1e-14)
    assert np.allclose(sol["t_B"] - sol["h"], [0.0, 0.0, w * L0], rtol=0, atol=1e-10 * w * L0)
    assert sol["T_A"] == pytest.approx(np.linalg.norm(sol["h"]), rel=1e-14)
    assert sol["T_B"] == pytest.approx(np.linalg.norm(sol["t_B"]), rel=1e-14)
    assert np.allclose(sol["x"](L0), B, rtol=0, atol=1e-12)
    assert np.allclose(sol["x"](0.0), A, rtol=0, atol=0)
    pts = sol["x"](np.linspace(0, L0, 5))
    assert pts.shape == (5, 3)
    # all points in the vertical plane through A and B
    normal = np.array([-0.8, 0.6, 0.0])
    assert np.allclose((pts - A) @ normal, 0.0, atol=1e-13)
    # swapping the supports mirrors the solution: h_BA = -t_B
    back = irvine_catenary_inclined_3d(B, A, L0, EA, w)
    assert np.allclose(back["h"], -sol["t_B"], rtol=1e-11)
    with pytest.raises(ValueError):
        irvine_catenary_inclined_3d(A, A + [0, 0, 3.0], L0, EA, w)


# ----------------------------------------------------------------------------------------------
# Linear free vibration
# ----------------------------------------------------------------------------------------------
def test_symmetric_roots_limits():
    # lambda2 -> 0: taut string modes 1, 3, 5 -> wb = pi, 3 pi, 5 pi
    assert np.allclose(irvine_symmetric_roots(1e-12, 3), [math.pi, 3 * math.pi, 5 * math.pi],
                       rtol=1e-10)
    # crossover lambda2 = 4 pi^2: first symmetric = first antisymmetric, wb = 2 pi
    assert irvine_symmetric_roots(4 * math.pi**2, 1)[0] == pytest.approx(2 * math.pi, rel=1e-14)
    # just below / above the crossover the first symmetric root is below / above 2 pi
    assert irvine_symmetric_roots(4 * math.pi**2 * (1 - 1e-6), 1)[0] < 2 * math.pi
    assert irvine_symmetric_roots(4 * math.pi**2 * (1 + 1e-6), 1)[0] > 2 * math.pi
    # lambda2 -> inf: roots of tan(y) = y, y = 4.4934..., 7.7253... (wb = 2 y)
    y_ref = [4.493409457909064, 7.725251836937707, 10.904121659428899]
    assert np.allclose(irvine_symmetric_roots(math.inf, 3), 2 * np.array(y_ref), rtol=1e-14)
    assert np.allclose(irvine_symmetric_roots(1e14, 3), 2 * np.array(y_ref), rtol=1e-12)
    # second crossover: second symmetric root equals 4 pi at lambda2 = 16 pi^2
    assert irvine_symmetric_roots(16 * math.pi**2, 2)[1] == pytest.approx(4 * math.pi, rel=1e-14)


@settings(max_examples=40, deadline=None)
@given(st.floats(-6.0, 8.0))
def test_symmetric_roots_solve_equation(log_lambda2):
    lambda2 = 10.0**log_lambda2
    wb = irvine_symmetric_roots(lambda2, 4)
    y = wb / 2
    # residual of the pole-free form sin y - (y - 4 y^3/lambda2) cos y, relative to its terms
    res = np.sin(y) - (y - 4 * y**3 / lambda2) * np.cos(y)
    size = 1 + y + 4 * y**3 / lambda2
    assert np.all(np.abs(res) <= 1e-13 * size)
    # one root per branch of tan, increasing
    k = np.arange(1, 5)
    assert np.all(wb > (2 * k - 1) * math.pi - 1e-12)
    assert np.all(wb < (2 * k + 1) * math.pi)
    assert np.all(np.diff(wb) > 0)
    # roots grow with lambda2
    assert np.all(irvine_symmetric_roots(lambda2 * 1.5, 4) >= wb)


def test_caughey_frequencies_families_and_crossover():
    span, m, g = 100.0, 10.0, 9.81
    w = m * g
    H = 5e4
    wave = math.sqrt(H / m)
    # choose EA so that lambda2 = 4 pi^2 exactly
    d = w * span**2 / (8 * H)
    Le = span * (1 + 8 * (d / span) ** 2)
    EA = 4 * math.pi**2 * H * Le / ((w * span / H) ** 2 * span)
    f = irvine_caughey_frequencies(span, H, m, w, EA, n=4)
    assert f["lambda2"] == pytest.approx(4 * math.pi**2, rel=1e-14)
    assert f["sag"] == pytest.approx(d) and f["Le"] == pytest.approx(Le)
    f1 = wave / (2 * span)
    assert np.allclose(f["out_of_plane"], f1 * np.arange(1, 5), rtol=1e-15)
    assert np.allclose(f["antisymmetric"], 2 * f1 * np.arange(1, 5), rtol=1e-15)
    assert np.allclose(f["out_of_plane"], taut_string_frequencies(span, H, m, 4), rtol=1e-15)
    assert f["symmetric"][0] == pytest.approx(f["antisymmetric"][0], rel=1e-13)
    assert np.allclose(f["symmetric"], f["wb_symmetric"] * wave / (2 * math.pi * span))

    # nearly inextensible-free (EA -> 0): lambda2 -> 0, symmetric = odd taut-string modes
    soft = irvine_caughey_frequencies(span, H, m, w, EA * 1e-12, n=3)
    assert np.allclose(soft["symmetric"], f1 * np.array([1, 3, 5]), rtol=1e-9)
    # EA = inf is allowed (lambda2 = inf)
    rigid = irvine_caughey_frequencies(span, H, m, w, math.inf, n=1)
    assert rigid["lambda2"] == math.inf
    assert rigid["symmetric"][0] == pytest.approx(2 * 4.493409457909064 / math.pi * f1, rel=1e-13)

    # L0 given: m, w per unstrained length are spread over the span
    L0 = 1.01 * span
    a = irvine_caughey_frequencies(span, H, m, w, EA, L0=L0, n=2)
    b = irvine_caughey_frequencies(span, H, m * L0 / span, w * L0 / span, EA, n=2)
    for key in ("out_of_plane", "antisymmetric", "symmetric"):
        assert np.allclose(a[key], b[key], rtol=1e-15)
    assert a["lambda2"] == pytest.approx(b["lambda2"], rel=1e-15)


def test_koh_cable_frequencies_match_measurement_roughly():
    # Section 10 example 1: linear theory with the stated chord 44.335 m should land near the
    # measured first symmetric frequency 1.51 Hz (a plausibility check on units/conventions).
    EA, m, L0, span = 200e9 * 2348e-6, 20.3, 44.304, 44.335
    w = m * 9.81
    st_ = irvine_catenary(span, 0.0, L0, EA, w)
    f = irvine_caughey_frequencies(span, st_["H"], m, w, EA, L0=L0, n=3)
    assert 0.5 < f["lambda2"] < 2.0
    assert f["symmetric"][0] == pytest.approx(1.51, rel=0.03)
    assert f["antisymmetric"][0] == pytest.approx(2 * f["out_of_plane"][0], rel=1e-15)


def test_taut_string():
    f = taut_string_frequencies(2.0, 400.0, 1.0, 3)
    assert np.allclose(f, [5.0, 10.0, 15.0], rtol=1e-15)


@pytest.mark.parametrize("span, dz, L0, EA, w", [
    (100.0, 0.0, 101.0, 1e8, 10.0),
    (100.0, 30.0, 110.0, 1e6, 50.0),
    (100.0, -300.0, 400.0, 1e9, 50.0),
    (10.0, 0.0, 9.99, 3.4e7, 49.05),        # shorter than the chord: taut
    (44.335, 0.0, 44.304, 4.696e8, 199.143),  # paper example 1 with the stated chord
])
def test_against_multiprecision(span, dz, L0, EA, w):
    """Precision claim: agree with a 40-digit solve of the same two end conditions."""
    mp = pytest.importorskip("mpmath")
    sol = irvine_catenary(span, dz, L0, EA, w)
    with mp.workdps(40):
        S, D, L, E, W = (mp.mpf(v) for v in (span, dz, L0, EA, w))

        def ends(H, V):
            Vj = V + W * L
            Ti, Tj = mp.sqrt(H**2 + V**2), mp.sqrt(H**2 + Vj**2)
            x = H * L / E + (H / W) * (mp.asinh(Vj / H) - mp.asinh(V / H))
            z = (V * L + W * L**2 / 2) / E + (Tj - Ti) / W
            return [x - S, z - D]

        H, V = mp.findroot(ends, (mp.mpf(sol["H"]), mp.mpf(sol["V_i"])))
        T = mp.sqrt(H**2 + V**2)
        # taut cables are ill-conditioned (H ~ EA (chord - L0)/L0): allow eps * EA/H
        tol = max(1e-13, 64 * 2.2e-16 * EA / sol["H"])
        assert abs(float((H - sol["H"]) / H)) < tol
        assert abs(float((V - sol["V_i"]) / T)) < tol
