"""Loads that come and go (active = false, add, remove) and distributed loads over part of a
cable, checked against independent references: the weightless taut string in closed form, the
suddenly applied load on a one-degree-of-freedom oscillator (peak = twice the static deflection),
and the elastic catenary with a piecewise-constant weight (tests/reference.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import catdae

from reference import piecewise_catenary
from scene_toml import cable_scene, distributed_load, load, point_mass, static_step, step

# a weightless taut string, 10 m span, strain 1e-3, with a heavy mass at midspan (node c.1)
SPAN, L0, EA = 10.0, 9.99, 1.0e7
MASS, M_CABLE = 100.0, 0.01  # kg at midspan; kg/m of cable (0.1 % of the mass in all)
P = 20.0  # N, along y on the mass


def string_deflection(p):
    """Exact static deflection (m) of a weightless elastic string under a transverse load p at
    midspan: each half is a straight bar of unstrained length L0/2 and length l = hypot(SPAN/2,
    δ), tension EA (2 l / L0 - 1), and 2 T δ / l = p."""
    def residual(d):
        ll = math.hypot(SPAN / 2, d)
        return 2.0 * EA * (2.0 * ll / L0 - 1.0) * d / ll - p
    return brentq(residual, 0.0, 1.0, xtol=1e-15, rtol=1e-14)


def string_scene(extra_loads: str, steps: str) -> str:
    return cable_scene(B=(SPAN, 0.0, 0.0), L0=L0, EA=EA, mass=M_CABLE, elements=2, gravity=0.0,
                       extra=extra_loads, steps=steps)


def mass_and_load(active_mass: bool = True) -> str:
    return (point_mass("M", MASS, node="c.1", active=active_mass)
            + load("P", [0.0, P, 0.0], node="c.1", active=False))


# the cable's share of the midspan node's mass, per mass model: consistent 2 x (2/6) m L0/2 =
# m L0/3 (a straight weightless element interpolates linearly), lumped 2 x m L0/4 = m L0/2,
# blended the mean of the two, 5 m L0/12
SHARE = {"consistent": 1.0 / 3.0, "lumped": 1.0 / 2.0, "blended": 5.0 / 12.0}


def string_frequency(mass, mass_model="consistent"):
    """Natural frequency (Hz) of the midspan node: transverse stiffness 4T/SPAN of the two
    straight prestressed halves (T/length each), mass ``mass`` plus the cable's share
    (``SHARE``) under ``mass_model``."""
    tension = EA * (SPAN / L0 - 1.0)
    share = SHARE[mass_model] * M_CABLE * L0
    return math.sqrt(4.0 * tension / SPAN / (mass + share)) / (2.0 * math.pi)


@pytest.mark.parametrize("mass_model", ["consistent", "blended"])
def test_suddenly_applied_load_peaks_at_twice_the_static_deflection(mass_model):
    delta = string_deflection(P)
    omega = 2.0 * math.pi * string_frequency(MASS, mass_model)
    period = 2.0 * math.pi / omega
    steps = (static_step("before")
             + step("transient", "sudden", duration=1.2 * period, output_interval=period / 1000,
                    rtol=1e-9, atol=1e-12, add=["P"], mass_model=mass_model)
             + static_step("after"))
    tree = catdae.run(string_scene(mass_and_load(), steps))
    y0 = tree["before"].ds["displacement"].sel(node="c.1", axis="y").item()
    assert y0 == 0.0  # the load is absent until a step adds it
    after = tree["after"].ds["displacement"].sel(node="c.1", axis="y").item()
    assert after == pytest.approx(delta, rel=1e-9)  # the static step sees it: the exact string
    tr = tree["sudden"].ds
    y = tr["displacement"].sel(node="c.1", axis="y").values
    k = int(np.argmax(y))
    # a one-degree-of-freedom oscillator under a step load: y = δ (1 - cos ωt), peak 2 δ at
    # π/ω; the string stiffens with δ only at second order (strain 5e-7 against 1e-3)
    assert y[k] == pytest.approx(2.0 * delta, rel=1e-3)
    assert tr["time"].values[k] == pytest.approx(math.pi / omega, rel=2e-3)
    assert y[0] == 0.0 and tr["velocity"].sel(node="c.1", axis="y").values[0] == 0.0
    # the load acts at full value from the first instant: a = P / M at t = 0
    a0 = tr["acceleration"].sel(node="c.1", axis="y").values[0]
    assert a0 == pytest.approx(P / (MASS + SHARE[mass_model] * M_CABLE * L0), rel=1e-9)
    # undamped, a constant load with its potential: the total energy is conserved
    e = tr["energy_total"].values
    assert np.ptp(e) < 1e-4 * P * delta


@pytest.mark.parametrize("mass_model", ["consistent", "blended"])
def test_added_mass_lowers_the_frequency_and_a_removed_load_releases(mass_model):
    # the mass is absent at first (a light string), then added; the load comes and goes
    steps = (step("modal", "bare", modes=1, mass_model=mass_model)
             + step("modal", "loaded", modes=1, add=["M"], mass_model=mass_model)
             + step("static", "pushed", add=["P"])
             + step("transient", "released", remove=["P"],
                    duration=1.2 / string_frequency(MASS, mass_model), output_interval=0.001,
                    rtol=1e-9, atol=1e-12, mass_model=mass_model))
    tree = catdae.run(string_scene(mass_and_load(active_mass=False), steps))
    assert tree["bare"].ds["frequency"].values[0] == pytest.approx(
        string_frequency(0.0, mass_model), rel=1e-6)
    assert tree["loaded"].ds["frequency"].values[0] == pytest.approx(
        string_frequency(MASS, mass_model), rel=1e-6)
    delta = string_deflection(P)
    pushed = tree["pushed"].ds["displacement"].sel(node="c.1", axis="y").item()
    assert pushed == pytest.approx(delta, rel=1e-9)
    # released from rest at δ: y = δ cos ωt, swinging through -δ
    y = tree["released"].ds["displacement"].sel(node="c.1", axis="y").values
    assert y[0] == pytest.approx(delta, rel=1e-9)
    assert y.min() == pytest.approx(-delta, rel=1e-3)


# ---------------------------------------------------------------------------------------------
# Distributed loads over part of a cable
# ---------------------------------------------------------------------------------------------
SAG_SPAN, SAG_L0, SAG_EA, W = 100.0, 102.0, 1.0e8, 10.0  # m, m, N, N/m
FROM, TO, Q = 13.7, 61.2, 40.0  # m, m, N/m downwards


def sagging_scene(elements, gauss_points, per_metre, **coverage):
    """The sagging cable under the distributed load "snow" of ``per_metre`` N/m over ``coverage``
    (from_s, to_s; the whole cable when not given)."""
    return cable_scene(B=(SAG_SPAN, 0.0, 0.0), L0=SAG_L0, EA=SAG_EA, mass=W / 9.81, weight=W,
                       elements=elements, gauss_points=gauss_points,
                       extra=distributed_load("c", per_metre, name="snow", **coverage),
                       steps=static_step())


def test_partial_distributed_load_against_the_piecewise_catenary():
    ref = piecewise_catenary(SAG_SPAN, 0.0, SAG_EA,
                             [(FROM, W), (TO - FROM, W + Q), (SAG_L0 - TO, W)])
    errs = []
    ns = np.array([4, 8, 16, 32])
    for n in ns:
        ds = catdae.run(sagging_scene(int(n), 3, [0.0, 0.0, -Q], from_s=FROM, to_s=TO))["st"].ds
        rz = ds["reaction"].sel(axis="z")
        # equilibrium: the supports carry the weight and the load (to the Newton tolerance)
        total = rz.sel(node="A").item() + rz.sel(node="B").item()
        assert total == pytest.approx(W * SAG_L0 + Q * (TO - FROM), rel=1e-10)
        # the load sits left of midspan: A carries more, as the closed form says
        err_v = abs(rz.sel(node="A").item() + ref["V_i"]) / abs(ref["V_i"])
        err_h = abs(ds["horizontal_tension"].item() / ref["H"] - 1.0)
        pos = ds["position"]
        err_x = max(math.dist((pos.sel(node=f"c.{k}", axis="x").item(),
                               pos.sel(node=f"c.{k}", axis="z").item()),
                              ref["position"](k * SAG_L0 / n)) for k in range(1, n))
        errs.append((err_h, err_v, err_x))
    errs = np.array(errs)
    # the Gauss-point loads of §5 make the tension piecewise constant where it is linear:
    # second order in the element length, as for a load over the whole cable (fitted from 8
    # elements on: 4 elements of 25.5 m are not yet in the asymptotic range)
    rates = [np.polyfit(np.log(ns[1:]), np.log(errs[1:, j]), 1)[0] for j in range(3)]
    assert rates == pytest.approx([-2.0, -2.0, -2.0], abs=0.15), errs
    assert errs[2, 0] < 2e-4 and errs[2, 2] < 2e-3, errs


def test_partial_coverage_is_as_accurate_as_a_whole_cable_load():
    # the same load per metre over the whole cable is the uniform catenary of weight W + Q;
    # over the first 50 m, ending inside an element (16 elements of 6.375 m: 50 m is 84 % into
    # the 8th), the split Gauss rule keeps the error of the whole-cable load, not a larger one
    # (1.9e-4 against 1.6e-4; keeping the whole element's Gauss points that fall inside the
    # coverage instead gives 1.4e-2)
    n, end = 16, 50.0
    ref_all = piecewise_catenary(SAG_SPAN, 0.0, SAG_EA, [(SAG_L0, W + Q)])
    ref_part = piecewise_catenary(SAG_SPAN, 0.0, SAG_EA, [(end, W + Q), (SAG_L0 - end, W)])
    ds_all = catdae.run(sagging_scene(n, 3, [0.0, 0.0, -Q]))["st"].ds
    ds_part = catdae.run(sagging_scene(n, 3, [0.0, 0.0, -Q], to_s=end))
    e_all = abs(ds_all["horizontal_tension"].item() / ref_all["H"] - 1)
    e_part = abs(ds_part["st"].ds["horizontal_tension"].item() / ref_part["H"] - 1)
    assert e_part < 1.5 * e_all, (e_part, e_all)


def test_partial_horizontal_load_reactions_balance():
    ds = catdae.run(sagging_scene(8, 3, [0.0, 25.0, 0.0], from_s=FROM, to_s=TO))["st"].ds
    ry = ds["reaction"].sel(axis="y")
    assert ry.sel(node="A").item() + ry.sel(node="B").item() == pytest.approx(
        -25.0 * (TO - FROM), rel=1e-10)


def test_partial_distributed_load_follows_its_time_function():
    # a ramp over 2 s, read by static steps at the case's clock: t = 0 (nothing), then after a
    # 1 s transient (half); reactions balance weight + the ramped load
    snow = distributed_load("c", [0.0, 0.0, -Q], name="snow", from_s=FROM, to_s=TO,
                            time={"kind": "ramp", "duration": 2.0})
    text = cable_scene(B=(SAG_SPAN, 0.0, 0.0), L0=SAG_L0, EA=SAG_EA, mass=W / 9.81, weight=W,
                       elements=4, extra=snow,
                       steps=static_step("t0") + step("transient", "wait", duration=1.0,
                                                      output_interval=0.5, rtol=1e-4, atol=1e-4,
                                                      remove=["snow"])
                       + step("static", "t1", add=["snow"]))
    tree = catdae.run(text)
    for name, factor in (("t0", 0.0), ("t1", 0.5)):
        rz = tree[name].ds["reaction"].sel(axis="z", node=["A", "B"]).sum().item()
        assert rz == pytest.approx(W * SAG_L0 + factor * Q * (TO - FROM), rel=1e-10)


# ---------------------------------------------------------------------------------------------
# Validation: located messages, exit code 2
# ---------------------------------------------------------------------------------------------
def check(tmp_path, capsys, extra: str, steps: str) -> str:
    """Run ``catdae check`` on the sagging scene with ``extra`` items; expect exit 2."""
    from catdae.cli import main

    case = tmp_path / "bad.toml"
    case.write_text(cable_scene(B=(SAG_SPAN, 0.0, 0.0), L0=SAG_L0, EA=SAG_EA, mass=1.0,
                                elements=4, extra=extra, steps=steps))
    assert main(["check", str(case)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return err.replace(f"{case}: ", "@ ")


LOADS = (load("P", [0.0, 0.0, -1.0], node="c.2", active=False)
         + point_mass("M", 2.0, node="c.1")
         + distributed_load("c", [0.0, 5.0, 0.0], name="wind", active=False))


def test_add_and_remove_follow_what_is_present(tmp_path, capsys):
    steps = (step("static", "a", add=["P", "wnid"], remove=["P"])
             + step("static", "b", add=["M"], remove=["wind"])
             + step("static", "c", add=["wind"])
             + step("static", "d", add=["wind"], remove=["nobody"]))
    err = check(tmp_path, capsys, LOADS, steps)
    assert "@ steps[0].remove[0]: 'P' is both added and removed by this step" in err
    assert ("@ steps[0].add[1]: unknown point mass, load or distributed load 'wnid'; "
            "did you mean 'wind'?") in err
    assert ("@ steps[1].add[0]: 'M' is already present (active from the start); add names "
            "what is absent") in err
    assert ("@ steps[1].remove[0]: 'wind' is absent: it has active = false and no earlier "
            "step adds it") in err
    assert "@ steps[2]" not in err  # adding the absent 'wind' is fine
    assert "@ steps[3].add[0]: 'wind' is already present (added by step 'c' (steps[2]))" in err
    assert "@ steps[3].remove[0]: unknown point mass, load or distributed load 'nobody'" in err


def test_partial_coverage_is_checked_against_the_cable(tmp_path, capsys):
    side = [0.0, 1.0, 0.0]
    items = (distributed_load("c", side, name="d0", from_s=60.0, to_s=20.0)
             + distributed_load("c", side, name="d1", to_s=150.0)
             + distributed_load("c", side, name="d2", from_s=-1.0)
             + distributed_load("c", side, active=False)
             + distributed_load("c", side, name="d4", from_s=102.0))
    err = check(tmp_path, capsys, items, static_step())
    assert ("@ distributed_loads[0].to_s: expected from_s < to_s (the load covers from_s <= s "
            "<= to_s), found from_s = 60 and to_s = 20") in err
    assert ("@ distributed_loads[1].to_s: expected 0 <= to_s <= 102 (the length of cable 'c'), "
            "found 150") in err
    assert "@ distributed_loads[2].from_s:" in err and ">= 0" in err
    assert ("@ distributed_loads[3].active: a distributed load with active = false needs a "
            "name") in err
    assert "@ distributed_loads[4].to_s: expected from_s < to_s" in err
