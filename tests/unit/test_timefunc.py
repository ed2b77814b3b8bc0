"""Time functions: closed-form values, derivatives against finite differences, table, ramp."""

from __future__ import annotations

import dataclasses
import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import CubicSpline

from catdae.case.timefunc import ONE, ZERO, Constant, Cosine, Ramp, Sine, Table, evaluate_or

finite = st.floats(-10.0, 10.0, allow_nan=False)


def check_derivatives(func, t, scale):
    """df/dt and d2f/dt2 against central differences of f and of df/dt (step h ~ 1e-5 scale)."""
    h = 1e-5 * scale
    f_m, df_m, _ = func.evaluate(t - h)
    f_p, df_p, _ = func.evaluate(t + h)
    _, df, d2f = func.evaluate(t)
    size = 1.0 + np.max(np.abs(func(np.linspace(t - 1, t + 1, 5))))
    np.testing.assert_allclose(df, (f_p - f_m) / (2 * h), atol=1e-6 * size / scale)
    np.testing.assert_allclose(d2f, (df_p - df_m) / (2 * h), atol=1e-6 * size / scale**2)


@settings(max_examples=50, deadline=None)
@given(a=finite, f=st.floats(0.01, 5.0), phase=st.floats(-4.0, 4.0), offset=finite,
       t=st.floats(0.0, 20.0))
def test_sine_cosine_derivatives_match_finite_differences(a, f, phase, offset, t):
    for cls in (Sine, Cosine):
        check_derivatives(cls(a, f, phase, offset), t, scale=1.0 / f)


def test_sine_and_cosine_known_values():
    # quarter period of 0.25 Hz is t = 1 s
    assert Sine(2.0, 0.25)(1.0) == pytest.approx(2.0)
    assert Sine(2.0, 0.25)(0.0) == 0.0
    assert Sine(2.0, 0.25, phase=math.pi / 2)(0.0) == pytest.approx(2.0)
    assert Cosine(2.0, 0.25, offset=1.0)(0.0) == pytest.approx(3.0)
    # the support motion of case-format.md: 3 (1 - cos πt), velocity 3π sin πt, accel. 3π² cos πt
    y = Cosine(-3.0, 0.5, offset=3.0)
    f, df, d2f = y.evaluate(np.array([0.0, 0.5, 1.0]))
    np.testing.assert_allclose(f, [0.0, 3.0, 6.0], atol=1e-12)
    np.testing.assert_allclose(df, [0.0, 3 * math.pi, 0.0], atol=1e-12)
    np.testing.assert_allclose(d2f, [3 * math.pi**2, 0.0, -3 * math.pi**2], atol=1e-12)


@given(d=st.floats(0.01, 100.0), start=st.floats(-10.0, 10.0))
def test_ramp_endpoints(d, start):
    for smooth in (False, True):
        r = Ramp(d, start, smooth)
        assert r(start - 1.0) == 0.0
        assert r(start) == 0.0
        assert r(start + d) == pytest.approx(1.0, abs=1e-12)
        assert r(start + d + 1.0) == 1.0
        assert r(start + d / 2) == pytest.approx(0.5)
    # the smooth ramp starts and ends at rest, with zero acceleration: C2
    for t in (start, start + d):
        _, df, d2f = Ramp(d, start, smooth=True).evaluate(t)
        rounding = 1e-12 * (1.0 + abs(start) / d)  # of x = (t - start) / d near 0 and 1
        assert df == pytest.approx(0.0, abs=rounding / d)
        assert d2f == pytest.approx(0.0, abs=rounding / d**2)
    # the linear ramp has slope 1/d inside and 0 outside
    assert Ramp(d, start).evaluate(start + d / 3)[1] == pytest.approx(1.0 / d)
    assert Ramp(d, start).evaluate(start + 2 * d)[1] == 0.0


@settings(max_examples=50, deadline=None)
@given(d=st.floats(0.1, 10.0), x=st.floats(0.01, 0.99))
def test_smooth_ramp_derivatives_match_finite_differences(d, x):
    check_derivatives(Ramp(d, 1.0, smooth=True), 1.0 + x * d, scale=d * 1e-2)


points = st.lists(st.tuples(st.floats(0.05, 1.0), finite), min_size=2, max_size=8)


@settings(max_examples=50, deadline=None)
@given(points=points)
def test_table_passes_through_points_and_holds_outside(points):
    t = np.cumsum([dt for dt, _ in points])
    v = np.array([val for _, val in points])
    table = Table(tuple(t), tuple(v))
    np.testing.assert_allclose(table(t), v, atol=1e-9)
    # held at the end values outside, at rest; the last point belongs to the hold
    for outside, value in ((t[0] - 1.0, v[0]), (t[-1] + 1.0, v[-1]), (t[-1], v[-1])):
        f, df, d2f = table.evaluate(outside)
        assert (f, df, d2f) == (pytest.approx(value), 0.0, 0.0)
    # the record's own end velocity just inside its ends (a jump there, hence breakpoints)
    sp = CubicSpline(t, v)  # not-a-knot, scipy's default
    for inside in (t[0], np.nextafter(t[-1], -np.inf)):
        assert table.evaluate(inside)[1] == pytest.approx(float(sp(inside, 1)), abs=1e-9)
    assert table.breakpoints() == (t[0], t[-1])


@settings(max_examples=50, deadline=None)
@given(points=points, x=st.floats(0.05, 0.95))
def test_table_derivatives_match_finite_differences(points, x):
    t = np.cumsum([dt for dt, _ in points])
    table = Table(tuple(t), tuple(val for _, val in points))
    check_derivatives(table, t[0] + x * (t[-1] - t[0]), scale=1e-2)


def test_table_is_exact_for_any_cubic_and_for_lines_and_parabolas():
    # not-a-knot ends impose nothing: a cubic with non-zero end slope and curvature is
    # reproduced exactly (a clamped spline would bend it to zero slope at both ends)
    t = np.linspace(0.0, 1.0, 6)
    table = Table(tuple(t), tuple(1.0 + 2.0 * t - t**2 + 0.5 * t**3))
    tt = np.linspace(0.0, 1.0, 101)[:-1]
    f, df, d2f = table.evaluate(tt)
    np.testing.assert_allclose(f, 1.0 + 2.0 * tt - tt**2 + 0.5 * tt**3, atol=1e-12)
    np.testing.assert_allclose(df, 2.0 - 2.0 * tt + 1.5 * tt**2, atol=1e-11)
    np.testing.assert_allclose(d2f, -2.0 + 3.0 * tt, atol=1e-10)
    # two points: the straight line; three: the parabola through them
    f, df, d2f = Table((1.0, 3.0), (4.0, 2.0)).evaluate(np.array([1.0, 2.0, 2.5]))
    np.testing.assert_allclose(f, [4.0, 3.0, 2.5], atol=1e-12)
    np.testing.assert_allclose(df, -1.0, atol=1e-12)
    np.testing.assert_allclose(d2f, 0.0, atol=1e-12)
    f, df, d2f = Table((0.0, 1.0, 2.0), (0.0, 1.0, 4.0)).evaluate(np.array([0.0, 0.5, 1.5]))
    np.testing.assert_allclose(f, [0.0, 0.25, 2.25], atol=1e-12)
    np.testing.assert_allclose(df, [0.0, 1.0, 3.0], atol=1e-12)
    np.testing.assert_allclose(d2f, 2.0, atol=1e-12)


def _sampled_motion(dt):
    """d(t) = 0.5 sin(2t + 0.3) m on [0, 3] s sampled every dt: it starts and ends moving, and
    its acceleration peaks at 2.0 m/s²; the exact (d, v, a) on a fine grid of the record."""
    def exact(t):
        arg = 2.0 * t + 0.3
        return 0.5 * np.sin(arg), 1.0 * np.cos(arg), -2.0 * np.sin(arg)
    ts = np.linspace(0.0, 3.0, round(3.0 / dt) + 1)
    table = Table(tuple(ts), tuple(exact(ts)[0]))
    tt = np.linspace(0.0, 3.0, 6001)[:-1]  # the record, [t0, t1): t1 belongs to the hold
    return table, tt, exact(tt)


def test_table_reproduces_a_smooth_motion_up_to_its_ends_at_spline_rates():
    """Displacement, velocity and acceleration converge at the rates of a cubic spline (4, 3, 2)
    over the whole record, and within two samples of either end the errors stay within the
    same bounds: the interpolant adds nothing at the ends."""
    dts = np.array([0.1, 0.05, 0.025, 0.0125])
    err = []
    for dt in dts:
        table, tt, ref = _sampled_motion(dt)
        got = table.evaluate(tt)
        err.append([np.abs(g - r).max() for g, r in zip(got, ref, strict=True)])
        ends = (tt < 2 * dt) | (tt > 3.0 - 2 * dt)
        # the fourth derivative of the motion is 8 m/s⁴: bounds C |d⁗| dt^(4-k), C = 1
        for k, (g, r) in enumerate(zip(got, ref, strict=True)):
            assert np.abs(g - r)[ends].max() < 8.0 * dt ** (4 - k), (dt, k)
    rates = [np.polyfit(np.log(dts), np.log(e), 1)[0] for e in np.array(err).T]
    np.testing.assert_allclose(rates, [4.0, 3.0, 2.0], atol=0.35)


def test_table_invents_no_acceleration_beyond_the_records_peak():
    # the record's own peak is 2.0 m/s²; the spline may exceed it only by its O(dt²) error
    for dt in (0.1, 0.05, 0.02):
        table, tt, _ = _sampled_motion(dt)
        peak = np.abs(table.evaluate(tt)[2]).max()
        assert peak <= 2.0 * (1.0 + dt**2), (dt, peak)


def test_evaluate_is_vectorised_and_scalar_in_gives_floats():
    funcs = [Constant(2.0), Ramp(1.0), Ramp(1.0, smooth=True), Sine(1.0, 1.0),
             Cosine(1.0, 1.0), Table((0.0, 1.0, 2.0), (0.0, 1.0, 0.0))]
    t = np.linspace(-1.0, 3.0, 12).reshape(3, 4)
    for func in funcs:
        out = func.evaluate(t)
        assert all(isinstance(a, np.ndarray) and a.shape == (3, 4) for a in out)
        for k in range(3):
            for idx in np.ndindex(t.shape):
                assert out[k][idx] == pytest.approx(func.evaluate(float(t[idx]))[k])
        assert all(type(a) is float for a in func.evaluate(0.3))
        assert func(0.3) == func.evaluate(0.3)[0]


def test_table_at_one_time_is_scipys_spline():
    """One time at a time (the residual's path: bisection and the cubics in floats) gives
    scipy's not-a-knot spline and its derivatives, at the knots, between them and at the ends
    of a 3000-point record; outside it the held end values at rest."""
    rng = np.random.default_rng(7)
    t = np.cumsum(rng.uniform(0.05, 0.15, 3000))
    v = np.sin(t) + 0.1 * rng.standard_normal(t.size)
    table = Table(tuple(t), tuple(v))
    sp = CubicSpline(t, v)
    probes = np.concatenate([t[:-1], rng.uniform(t[0], t[-1], 500), [t[0], t[-2]]])
    scale = np.abs(v).max()
    for x in probes:
        got = table.evaluate(float(x))
        for k in range(3):
            assert got[k] == pytest.approx(float(sp(x, k)), rel=1e-12, abs=1e-12 * scale)
    assert table.evaluate(float(t[-1])) == (pytest.approx(v[-1], abs=1e-12), 0.0, 0.0)
    assert table.evaluate(float(t[0] - 1.0)) == (pytest.approx(v[0], abs=1e-12), 0.0, 0.0)


def test_constant_and_absence_convention():
    assert Constant(4.0).evaluate(np.array([0.0, 7.0]))[0].tolist() == [4.0, 4.0]
    assert evaluate_or(None, 3.0, absent=ONE) == (1.0, 0.0, 0.0)
    assert evaluate_or(None, 3.0, absent=ZERO) == (0.0, 0.0, 0.0)
    assert evaluate_or(Sine(2.0, 0.25), 1.0, absent=ZERO)[0] == pytest.approx(2.0)


def test_time_functions_are_frozen_hashable_and_picklable():
    table = Table((0.0, 1.0), (0.0, 2.0), file="points.csv")
    for func in (Ramp(1.0), Sine(1.0, 2.0), table):
        with pytest.raises(dataclasses.FrozenInstanceError):
            func.start = 3.0
        assert pickle.loads(pickle.dumps(func)) == func
        assert hash(func) == hash(pickle.loads(pickle.dumps(func)))
    assert table == Table((0.0, 1.0), (0.0, 2.0), file="points.csv")
    assert pickle.loads(pickle.dumps(table))(0.5) == table(0.5)


@settings(max_examples=30, deadline=None)
@given(d=st.floats(0.1, 10.0), x=st.floats(0.01, 0.99), amp=st.floats(-5.0, 5.0))
def test_ramp_amplitude_scales_value_and_derivatives(d, x, amp):
    t = 1.0 + x * d
    for smooth in (False, True):
        base = np.array(Ramp(d, 1.0, smooth).evaluate(t))
        np.testing.assert_allclose(Ramp(d, 1.0, smooth, amp).evaluate(t), amp * base,
                                   rtol=1e-14, atol=1e-300)
    check_derivatives(Ramp(d, 1.0, smooth=True, amplitude=amp), t, scale=d * 1e-2)


def test_breakpoints_are_where_derivatives_jump():
    """Each listed breakpoint shows a jump in f' or f'' across it; smooth functions list none."""
    table = Table((0.5, 1.0, 2.0), (0.0, 1.0, 0.5))
    for func in (Ramp(0.3, 0.2), table):
        for b in func.breakpoints():
            left = np.array(func.evaluate(b - 1e-9)[1:])
            right = np.array(func.evaluate(b + 1e-9)[1:])
            assert np.abs(left - right).max() > 1e-3, (func, b)
    assert Sine(1.0, 2.0).breakpoints() == () and Constant(1.0).breakpoints() == ()
    assert Ramp(0.3, 0.2, smooth=True).breakpoints() == ()
