"""The swing angle of a suspension insulator string (``connector_swing_angle``), against hand
statics and the exact pendulum.

- Statics: a string (a bar of length l, mass m per metre) hangs from a fixed cross-arm point
  and holds a conductor clamp loaded by a vertical load W (the conductors' weight) and a
  lateral load P (the wind on them). The string is a two-force member: it lines up with the
  resultant at the clamp, P across and W plus half its own weight down, so
  tan θ = P / (W + m l g / 2), whatever its stretch. A spring holding the same loads swings by
  atan(P / W). The same scene turned so that gravity is along -x swings by the same angles.
- Transient: a clamp of mass M on a massless, stiff string, held aside by a lateral load
  P = M g tan θ0 and let go, is a pendulum: its swing angle falls from θ0 to 0 at a quarter of
  the exact period T = 4 √(l/g) K(sin²(θ0/2)) (K the complete elliptic integral of the first
  kind, parameter m = k²).
"""

from __future__ import annotations

import contextlib
import io
import math

import numpy as np
import pytest
from scipy.special import ellipk

import catdae
from catdae.cli import main

from scene_toml import bar, damper, load, point_mass, scene, spring, step

G, L, P, W, M_BAR = 9.81, 2.5, 4000.0, 9000.0, 40.0


def _turn(v, turned: bool):
    """A vector of the upright scene, or of the scene turned so that z goes to x, x to y and
    y to z (a rotation: gravity then acts along -x)."""
    x, y, z = (float(c) for c in v)
    return (z, x, y) if turned else (x, y, z)


def strings(turned: bool = False) -> str:
    """Two strings from fixed cross-arm points T1, T2 to clamps J1 (a bar with mass) and J2
    (a spring), each loaded by P across and W down, and a damper beside them."""
    t = lambda v: _turn(v, turned)  # noqa: E731
    return scene(
        head={"gravity": list(t((0.0, 0.0, -G)))}, materials={},
        nodes={"T1": t((0.0, 0.0, 0.0)), "J1": t((0.0, 0.0, -L)),
               "T2": t((5.0, 0.0, 0.0)), "J2": t((5.0, 0.0, -L)), "G": t((5.0, 3.0, -L))},
        supports=("T1", "T2", "G"), cables="",
        extra=(bar("string", ["T1", "J1"], 5.0e7, mass=M_BAR)
               + spring("soft", ["T2", "J2"], 2.0e5)
               + damper("d", ["J2", "G"], 10.0)
               + load("clamp1", list(t((0.0, P, -W))), node="J1")
               + load("clamp2", list(t((0.0, P, -W))), node="J2")),
        steps=step("static", "windy"))


@pytest.mark.parametrize("turned", [False, True], ids=["gravity -z", "gravity -x"])
def test_static_swing_of_a_string_is_atan_of_lateral_over_vertical_load(turned, capsys):
    tree = catdae.run(catdae.load_case(strings(turned)))
    ds = tree["windy"].ds
    angle = ds.connector_swing_angle
    assert angle.attrs["units"] == "degree"
    bar_theta = math.degrees(math.atan(P / (W + 0.5 * M_BAR * L * G)))
    assert float(angle.sel(connector="string")) == pytest.approx(bar_theta, rel=1e-9)
    assert float(angle.sel(connector="soft")) == pytest.approx(
        math.degrees(math.atan(P / W)), rel=1e-9)
    assert np.isnan(float(angle.sel(connector="d")))
    # the side: the clamp swings toward the lateral load (+y upright), which the angle alone
    # does not say: the axis from the cross-arm down to the clamp, in the case's axes
    axis = ds.connector_axis.sel(connector="string").values
    expect = _turn((0.0, math.sin(math.radians(bar_theta)), -math.cos(math.radians(bar_theta))),
                   turned)
    np.testing.assert_allclose(axis, expect, atol=1e-9)
    from catdae.output.summary import summary

    text = summary(tree)
    assert (f"bar string: force {float(ds.connector_force.sel(connector='string')):.6g} N, "
            f"swing angle {bar_theta:.6g} deg (axis a to b "
            f"{', '.join(f'{x:+.4f}' for x in expect)})") in text, text


def pendulum(theta0_deg: float, mass: float = 100.0):
    """A clamp of ``mass`` on a stiff massless string of length L, held by P = M g tan θ0,
    then let go for 0.4 of the exact period. Returns (case text, period T)."""
    theta0 = math.radians(theta0_deg)
    period = 4.0 * math.sqrt(L / G) * float(ellipk(math.sin(theta0 / 2.0) ** 2))
    text = scene(
        head={"gravity": G}, materials={}, nodes={"T": (0.0, 0.0, 0.0), "J": (0.0, 0.0, -L)},
        supports=("T",), cables="",
        extra=(bar("string", ["T", "J"], 1.0e9) + point_mass("clamp", mass, node="J")
               + load("wind", [0.0, mass * G * math.tan(theta0), 0.0], node="J")),
        steps=step("static", "held")
        + step("transient", "let go", remove=["wind"], duration=round(0.4 * period, 3),
               output_interval=round(period / 400.0, 5), rtol=1e-8, atol=1e-10))
    return text, period


def test_swing_angle_history_of_a_pendulum_string(tmp_path):
    theta0 = 30.0
    text, period = pendulum(theta0)
    path = tmp_path / "pendulum.toml"
    path.write_text(text)
    out = tmp_path / "pendulum.nc"
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(["run", str(path), "-o", str(out), "--no-progress"]) == 0
    tree = catdae.read_results(out)
    assert float(tree["held"].ds.connector_swing_angle.sel(connector="string")) == \
        pytest.approx(theta0, rel=1e-9)  # atan(P / (M g))
    ds = tree["let go"].ds
    hist = ds.connector_swing_angle.sel(connector="string")
    assert hist.dims == ("time",)
    # the history is the angle of the line from T to J in the stored positions
    d = (ds.position.sel(node="J") - ds.position.sel(node="T")).values
    np.testing.assert_allclose(hist.values, np.degrees(np.arctan2(
        np.hypot(d[:, 0], d[:, 1]), np.abs(d[:, 2]))), rtol=1e-12, atol=1e-12)
    t0, dt = float(ds.time[0]), float(ds.time[1] - ds.time[0])
    top = ds.connector_swing_angle_max.sel(connector="string")
    assert float(top) == pytest.approx(theta0, rel=1e-6)  # let go from rest at θ0
    assert float(ds.connector_swing_angle_max_time.sel(connector="string")) == t0
    low = float(ds.connector_swing_angle_min.sel(connector="string"))
    when = float(ds.connector_swing_angle_min_time.sel(connector="string"))
    # through the vertical at a quarter period: within one output interval of it, where the
    # angle changes by θ0 ω dt at most (ω = 2π/T times about 1.1 for 30°)
    assert abs(when - (t0 + period / 4.0)) <= dt
    assert low <= theta0 * 1.1 * 2.0 * math.pi * dt / period
    assert ds.connector_swing_angle_max.attrs["units"] == "degree"
    assert ds.connector_swing_angle_min_time.attrs["units"] == "s"
    printed = buf.getvalue()
    assert f"bar string: swing angle {low:.6g} to {float(top):.6g} deg, largest at t = " \
        f"{t0:.6g} s" in printed, printed
