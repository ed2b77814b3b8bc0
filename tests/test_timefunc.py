"""Time functions: closed-form values, derivatives against finite differences, table, ramp."""

from __future__ import annotations

import dataclasses
import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from catdae.timefunc import ONE, ZERO, Constant, Cosine, Ramp, Sine, Table, evaluate_or

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
    # held at the end values outside, with zero derivatives
    for outside, value in ((t[0] - 1.0, v[0]), (t[-1] + 1.0, v[-1])):
        f, df, d2f = table.evaluate(outside)
        assert (f, df, d2f) == (pytest.approx(value), 0.0, 0.0)
    # clamped ends: the slope is zero at the first and last points, so velocity is continuous
    assert table.evaluate(t[0])[1] == pytest.approx(0.0, abs=1e-9)
    assert table.evaluate(t[-1])[1] == pytest.approx(0.0, abs=1e-9)


@settings(max_examples=50, deadline=None)
@given(points=points, x=st.floats(0.05, 0.95))
def test_table_derivatives_match_finite_differences(points, x):
    t = np.cumsum([dt for dt, _ in points])
    table = Table(tuple(t), tuple(val for _, val in points))
    check_derivatives(table, t[0] + x * (t[-1] - t[0]), scale=1e-2)


def test_table_is_exact_for_a_cubic_with_zero_end_slopes():
    # p(t) = 3t² - 2t³ has p'(0) = p'(1) = 0: the clamped spline reproduces it exactly
    t = np.linspace(0.0, 1.0, 6)
    table = Table(tuple(t), tuple(3 * t**2 - 2 * t**3))
    tt = np.linspace(0.0, 1.0, 101)
    f, df, d2f = table.evaluate(tt)
    np.testing.assert_allclose(f, 3 * tt**2 - 2 * tt**3, atol=1e-12)
    np.testing.assert_allclose(df, 6 * tt - 6 * tt**2, atol=1e-11)
    np.testing.assert_allclose(d2f, 6 - 12 * tt, atol=1e-10)


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
