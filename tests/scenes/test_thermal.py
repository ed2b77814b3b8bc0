"""Temperature: ``thermal_expansion`` on a material, ``temperature_change`` on a step.

The strain is ε = T/EA + α ΔT per unit of unstrained length; mass and weight per unit of
unstrained length are unchanged. References, each derived here without catdae's element:
- code_aster SSNL114 (heavy cable heated by 39.26 K): Irvine's closed form for a level span,
  written with the thermal strain, solved by brentq;
- a plumb line with a point load inside an element: z(s) = -∫ (1 + α ΔT + T(σ)/EA) dσ;
- a weightless taut bar: T = EA (chord/L0 - 1 - α ΔT);
- a taut string's frequencies k/(2l) sqrt(T l/(m L0)) in a modal step after heating;
- the published result of OpenSees' two-cable CatenaryCable example with a thermal load.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import catdae
from catdae.errors import CaseError

from reference import level_catenary_midspan
from scene_toml import cable, cable_scene, distributed_load, load, point_mass, scene, step

# code_aster V6.02.114 (SSNL114): 2 l0 = 2 L = 325 m, A = 2.2783e-4 m², E = 5.7e10 Pa,
# α = 2.3e-5 /K, ρ = 2844.23 kg/m³, g = 9.81; heated from 0 to 39.26 °C
SSNL = dict(L=325.0, A=2.2783e-4, E=5.7e10, alpha=2.3e-5, rho=2844.23, g=9.81, dT=39.26)
SSNL114_MIDSPAN = -8.195  # m, published, to 1e-3 (weight per heated length)


def ssnl114_text(elements=10):
    p = SSNL
    EA, m = p["E"] * p["A"], p["rho"] * p["A"]
    return cable_scene(
        B=(p["L"], 0.0, 0.0), L0=p["L"], EA=EA, mass=m, elements=elements,
        properties={"thermal_expansion": p["alpha"]},
        steps=step("static", "cold") + step("static", "hot", temperature_change=p["dT"]))


def test_ssnl114_heavy_cable_heated():
    p = SSNL
    EA, w = p["E"] * p["A"], p["rho"] * p["A"] * p["g"]
    tree = catdae.run(catdae.load_case(ssnl114_text()))
    cold, H_cold = level_catenary_midspan(p["L"], EA, w, 0.0)
    hot, H_hot = level_catenary_midspan(p["L"], EA, w, p["alpha"] * p["dT"])
    z_cold = float(tree["cold"].ds.position.sel(node="c.5", axis="z"))
    z_hot = float(tree["hot"].ds.position.sel(node="c.5", axis="z"))
    assert z_cold == pytest.approx(cold, rel=1e-9)
    assert z_hot == pytest.approx(hot, rel=1e-9)  # -8.19265 m
    assert float(tree["hot"].ds.horizontal_tension[0]) == pytest.approx(H_hot, rel=1e-9)
    assert float(tree["hot"].ds.unstrained_length[0]) == pytest.approx(p["L"], rel=1e-14)
    # code_aster keeps the weight per heated length (w (1 + α ΔT) per unstrained length):
    # that convention reproduces its published midspan, ours differs by the extra weight
    aster, _ = level_catenary_midspan(p["L"], EA, w * (1 + p["alpha"] * p["dT"]),
                                      p["alpha"] * p["dT"])
    assert abs(aster - SSNL114_MIDSPAN) <= 1e-3


def plumb_text(dT, alpha, s_load, gravity=None, M=50.0, P=30.0):
    """A line from A (pinned) to B (free, started 2 m to the side so that no element starts
    vertical and slack) with a point mass M at B and a downward load P on the cable at arc
    length s_load: it hangs vertically below A."""
    return cable_scene(B=(2.0, 0.0, -20.0), L0=20.0, EA=2e5, mass=1.2, elements=4,
                       supports=("A",), gravity=gravity, properties={"thermal_expansion": alpha},
                       extra=(point_mass("end", M, node="B")
                              + load("p", [0.0, 0.0, -P], cable="c", s=s_load)),
                       steps=step("static", "st", temperature_change=dT))


def plumb_z(s, L0, EA, w, M, g, P, s_load, eps_t):
    """z(s) of the plumb line: -∫_0^s (1 + eps_t + T(σ)/EA) dσ with
    T(σ) = M g + w (L0 - σ) + P [σ < s_p]."""
    def int_T(a, b):  # ∫_a^b T dσ
        val = (M * g + w * L0) * (b - a) - 0.5 * w * (b * b - a * a)
        return val + P * max(0.0, min(b, s_load) - a)
    return -((1.0 + eps_t) * s + int_T(0.0, s) / EA)


@pytest.mark.parametrize("dT", [0.0, 80.0, -40.0])
def test_plumb_line_heated_with_a_load_inside_an_element(dT):
    alpha, s_load, g = 1.5e-4, 7.3, 9.81  # s_load inside element 2 of 4 (5 m each)
    tree = catdae.run(catdae.load_case(plumb_text(dT, alpha, s_load)))
    ds = tree["st"].ds
    args = (20.0, 2e5, 1.2 * g, 50.0, g, 30.0, s_load, alpha * dT)
    for node, s in (("B", 20.0), ("c.1", 5.0), ("c.2", 10.0), ("c.3", 15.0)):
        z = float(ds.position.sel(node=node, axis="z"))
        assert z == pytest.approx(plumb_z(s, *args), rel=1e-12, abs=1e-12)
        assert float(ds.position.sel(node=node, axis="x")) == pytest.approx(0.0, abs=1e-9)


def test_weightless_taut_bar_and_per_cable_temperature():
    EA, L0, chord, alpha = 1e6, 9.9, 10.0, 1e-4
    text = scene(
        materials={"m": {"EA": EA, "mass": 0.5, "weight": 0.0, "thermal_expansion": alpha}},
        nodes={"A": (0.0, 0.0, 0.0), "B": (chord, 0.0, 0.0), "C": (0.0, 5.0, 0.0),
               "D": (chord, 5.0, 0.0)},
        supports=("A", "B", "C", "D"),
        cables=[cable("hot", ("A", "B"), "m", L0), cable("cold", ("C", "D"), "m", L0)],
        steps=step("static", "st", temperature_change={"hot": 50.0}))
    ds = catdae.run(catdae.load_case(text))["st"].ds
    T = ds.cable_end_tension.sel(end="i").values
    assert T[0] == pytest.approx(EA * (chord / L0 - 1.0 - alpha * 50.0), rel=1e-10)
    assert T[1] == pytest.approx(EA * (chord / L0 - 1.0), rel=1e-10)


def test_temperature_holds_in_the_modal_and_transient_steps_that_follow():
    # a taut string: f_k = k/(2 l) sqrt(T l / (m L0)) with T = EA (l/L0 - 1 - α ΔT)
    l, L0, EA, m, alpha, dT = 10.0, 9.99, 1e6, 0.2, 2e-5, 25.0
    steps = (step("static", "hot", temperature_change=dT) + step("modal", "modes", modes=2)
             + step("transient", "rest", duration=0.05, output_interval=0.01, rtol=1e-8,
                    atol=1e-10))
    text = cable_scene(B=(l, 0.0, 0.0), L0=L0, EA=EA, mass=m, weight=0.0, elements=40,
                       properties={"thermal_expansion": alpha}, steps=steps)
    tree = catdae.run(catdae.load_case(text))
    T = EA * (l / L0 - 1.0 - alpha * dT)
    f1 = 1.0 / (2.0 * l) * math.sqrt(T * l / (m * L0))
    f1_cold = 1.0 / (2.0 * l) * math.sqrt(EA * (l / L0 - 1.0) * l / (m * L0))
    assert abs(f1 / f1_cold - 1.0) > 0.2  # the test can tell
    assert float(tree["modes"].ds.frequency[0]) == pytest.approx(f1, rel=2e-3)
    # the heated equilibrium stays at rest in the transient step (it would move if the
    # transient step saw the cold cable)
    assert float(np.abs(tree["rest"].ds.displacement.values
                        - tree["hot"].ds.displacement.values[None]).max()) < 1e-9
    assert float(tree["rest"].ds.tension.max()) == pytest.approx(T, rel=1e-8)


@pytest.mark.parametrize(("value", "path", "fragment"), [
    ("hot", "steps[0].temperature_change", "expected a temperature change in K"),
    ({"nope": 3.0}, "steps[0].temperature_change.nope", "unknown cable 'nope'"),
    ({"c": "warm"}, "steps[0].temperature_change.c", "finite number"),
])
def test_bad_temperature_names_the_field(value, path, fragment):
    text = cable_scene(B=(10.0, 0.0, 0.0), L0=10.1, EA=1e6, mass=1.0,
                       steps=step("static", temperature_change=value))
    with pytest.raises(CaseError) as err:
        catdae.load_case(text)
    found = dict(err.value.problems)
    assert fragment in found[path]


def test_bad_thermal_expansion_names_the_field():
    text = cable_scene(B=(10.0, 0.0, 0.0), L0=10.1, EA=1e6, mass=1.0,
                       properties={"thermal_expansion": "steel"})
    with pytest.raises(CaseError) as err:
        catdae.load_case(text)
    assert "expected a number" in dict(err.value.problems)["materials.m.thermal_expansion"]


def test_opensees_two_cable_example_with_a_thermal_load():
    # OpenSees CatenaryCable verification example (after Salehi Ahmad Abad et al. 2013): two
    # 50 m cables from (0, 0, 90) to node 2 at (15, 0, 40) (free in x and z) to (30, 60, 30),
    # E A = 3e7 N, a uniform load of 1 N per unstrained metre along -z, α = 6.5e-6 /K,
    # ΔT = 100 K. Published: node 2 moves by (8.58693, 0, 2.82578) m.
    text = scene(
        materials={"s": {"EA": 3.0e7, "mass": 0.1, "weight": 1.0, "thermal_expansion": 6.5e-6}},
        nodes={"N1": (0.0, 0.0, 90.0), "N2": (15.0, 0.0, 40.0), "N3": (30.0, 60.0, 30.0)},
        supports=("N1", 'N2 = ["y"]', "N3"),
        cables=[cable("a", ("N1", "N2"), "s", 50.0, 4), cable("b", ("N2", "N3"), "s", 50.0, 4)],
        steps=step("static", "hot", temperature_change=100.0))
    ds = catdae.run(catdae.load_case(text))["hot"].ds
    assert ds.displacement.sel(node="N2").values == pytest.approx([8.58693, 0.0, 2.82578],
                                                                  abs=5e-6)


def test_distributed_load_is_per_unstrained_metre_at_the_reference_temperature():
    # heating lengthens the cable by 1 + α ΔT = 1.05; the loads it carries do not change:
    # the supports take w L0 + q L0 along z and p L0 along y
    L0, w, q, p, alpha, dT = 10.5, 1.2 * 9.81, 3.0, 2.0, 1e-3, 50.0
    text = cable_scene(B=(10.0, 0.0, 0.0), L0=L0, EA=1e5, mass=1.2, elements=5,
                       properties={"thermal_expansion": alpha},
                       extra=distributed_load("c", [0.0, p, -q]),
                       steps=step("static", "st", temperature_change=dT))
    ds = catdae.run(catdae.load_case(text))["st"].ds
    R = ds.reaction.sel(node=["A", "B"]).values.sum(axis=0)
    assert R == pytest.approx([0.0, -p * L0, (w + q) * L0], abs=1e-9 * (w + q) * L0)
    assert float(ds.unstrained_length[0]) == pytest.approx(L0, rel=1e-14)
