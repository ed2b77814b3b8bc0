"""Static equilibrium of scenes (``catdae.solvers.static`` through ``catdae.run``) against physics.

References, none of which share code with catdae:
- Irvine's elastic catenary (``tests/reference.py``) for a single cable under self-weight;
- an elastic cable with point loads solved here by adaptive quadrature of the tangent,
  dx/ds = t/T + t/EA with t(s) = h + w s e_z - sum of the loads before s, and a scipy root
  solve for the tension vector h at the first end (:func:`solve_cable`). The flexibility of an
  elastic cable is positive definite, so the h that meets a chord is unique and any root found
  is the root;
- node equilibrium of every free node, and global force and moment balance, evaluated from the
  reported positions with element tensions re-solved by that quadrature;
- symmetry: mirrored scenes and cables with swapped ends.

The scene of ``cases/three_cables_shared_node.toml`` gets the same equilibrium check in
``tests/scenes/test_cases.py``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

import catdae
from catdae.case import case_from_dict

from cable_quadrature import (
    cable_end_pull,
    cable_position,
    check_equilibrium,
    node_names,
    solve_cable,
)
from reference import irvine_catenary_inclined_3d
from scene_toml import cable_scene, point_mass, static_step

G = 9.81


# ------------------------------------------------------------------------------------------------
# Scenes
# ------------------------------------------------------------------------------------------------
def make_case(nodes, cables, *, supports=None, point_masses=(), loads=(), load_steps=1,
              EA=1.0e7, mass=5.0):
    """A Case with one material and one static step named 'st'."""
    data = {
        "gravity": G,
        "materials": {"m": {"EA": EA, "mass": mass}},
        "nodes": {k: [float(c) for c in v] for k, v in nodes.items()},
        "supports": supports if supports is not None else {},
        "cables": [dict(name=n, ends=list(e), material="m", length=float(L), elements=int(ne))
                   for n, e, L, ne in cables],
        "point_masses": list(point_masses),
        "loads": list(loads),
        "steps": [{"kind": "static", "name": "st", "load_steps": load_steps}],
    }
    return case_from_dict(data)


def static(case) -> xr.Dataset:
    return catdae.run(case)["st"].to_dataset()


# ------------------------------------------------------------------------------------------------
# 1. A single cable under self-weight is the closed-form elastic catenary at any mesh
# ------------------------------------------------------------------------------------------------
GEOMETRIES = {
    "level": ((0.0, 0.0, 0.0), (100.0, 0.0, 0.0), 110.0, 1.0e7),
    "inclined": ((0.0, 0.0, 0.0), (100.0, 0.0, 30.0), 110.0, 1.0e7),
    "inclined-3d": ((1.0, 2.0, 3.0), (60.0, -40.0, -25.0), 110.0, 1.0e7),
    "taut-3d": ((0.0, 0.0, 0.0), (30.0, 20.0, 25.0), 44.1, 4.696e8),
}


def _sag_bound(ne):
    """Relative error of a maximum sampled at 17 points per element (cable_summary): the sag
    curve is nearly a parabola of the cable's length, so a sample spacing of L0/(16 ne) misses
    its top by at most sag * (1/(16 ne))²; doubled for the non-parabolic part."""
    return 2.0 / (16.0 * ne) ** 2


@pytest.mark.parametrize("ne", [1, 2, 7, 40])
@pytest.mark.parametrize("geom", list(GEOMETRIES))
def test_single_cable_is_the_closed_form_catenary(geom, ne):
    A, B, L0, EA = GEOMETRIES[geom]
    w = 5.0 * G
    ds = static(make_case({"A": A, "B": B}, [("c", ("A", "B"), L0, ne)],
                          supports={"A": "pinned", "B": "pinned"}, EA=EA))
    ref = irvine_catenary_inclined_3d(A, B, L0, EA, w)
    p = ref["planar"]
    rel = 1e-9
    # horizontal tension and the tension vectors at both ends, from the reactions
    assert float(ds.horizontal_tension[0]) == pytest.approx(p["H"], rel=rel)
    RA = ds.reaction.sel(node="A").values  # the support pushes the cable with -h
    RB = ds.reaction.sel(node="B").values  # and with +t(L0) at the last end
    tmax = max(p["T_i"], p["T_j"])
    np.testing.assert_allclose(-RA, ref["h"], rtol=0, atol=rel * tmax)
    np.testing.assert_allclose(RB, ref["t_B"], rtol=0, atol=rel * tmax)
    assert -RA[2] == pytest.approx(p["V_i"], rel=rel)
    assert RB[2] == pytest.approx(p["V_j"], rel=rel)
    # ... and from the tensions: V = ±sqrt(T² - H²) at the two ends, and T(s) at every element end
    T_i, T_j = (float(v) for v in ds.cable_end_tension.values[0])
    assert T_i == pytest.approx(p["T_i"], rel=rel)
    assert T_j == pytest.approx(p["T_j"], rel=rel)
    assert math.copysign(math.sqrt(T_j**2 - p["H"] ** 2), p["V_j"]) == pytest.approx(
        p["V_j"], rel=1e-8, abs=1e-8 * tmax)
    le = L0 / ne
    s_ends = np.stack([le * np.arange(ne), le * np.arange(1, ne + 1)], axis=1)  # (ne, 2)
    T_ref = np.hypot(p["H"], p["V_i"] + w * s_ends)
    np.testing.assert_allclose(ds.tension.values, T_ref, rtol=rel)
    # node positions on the exact curve
    names = node_names("c", ("A", "B"), ne)
    X = ds.position.sel(node=names).values
    np.testing.assert_allclose(X, ref["x"](le * np.arange(ne + 1)), rtol=0, atol=1e-10 * L0)
    # sag: sampled on the exact curve, so never above the true sag and close to it
    sag = float(ds.sag[0])
    assert p["sag"] * (1.0 - _sag_bound(ne)) <= sag <= p["sag"] * (1.0 + 1e-12)
    # the node nearest to where the tangent is parallel to the chord sees at most the true sag
    assert ds.attrs["residual_norm"] <= 1e-9 * tmax


def test_sag_of_a_level_cable_is_exact_at_midspan():
    """Level span, even mesh: the deepest point is a node, and the sampled sag is exact."""
    A, B, L0, EA = GEOMETRIES["level"]
    ds = static(make_case({"A": A, "B": B}, [("c", ("A", "B"), L0, 4)],
                          supports={"A": "pinned", "B": "pinned"}, EA=EA))
    ref = irvine_catenary_inclined_3d(A, B, L0, EA, 5.0 * G)
    assert float(ds.sag[0]) == pytest.approx(ref["planar"]["sag"], rel=1e-10)
    assert -float(ds.position.sel(node="c.2", axis="z")) == pytest.approx(
        ref["planar"]["sag"], rel=1e-10)


# ------------------------------------------------------------------------------------------------
# 2. A point load (or point mass) inside an element is exact: same as a node placed there
# ------------------------------------------------------------------------------------------------
SPAN_A = (0.0, 0.0, 0.0)
SPAN_B = (80.0, -60.0, 20.0)
L0_PL = 110.0
S_LOAD = 50.0  # in element 2 of 3 (36.67 .. 73.33); node c.15 of 33 elements


@pytest.mark.parametrize("kind", ["load", "mass"])
def test_point_load_inside_an_element_equals_a_node_there(kind):
    if kind == "load":
        force = np.array([300.0, -400.0, -2000.0])
        items = {"loads": [{"name": "p", "cable": "c", "s": S_LOAD, "force": list(force)}]}
    else:
        force = np.array([0.0, 0.0, -150.0 * G])
        items = {"point_masses": [{"name": "p", "cable": "c", "s": S_LOAD, "mass": 150.0}]}
    w = 5.0 * G
    EA = 1.0e7
    out = {}
    for ne in (3, 33):
        out[ne] = static(make_case({"A": SPAN_A, "B": SPAN_B}, [("c", ("A", "B"), L0_PL, ne)],
                                   supports={"A": "pinned", "B": "pinned"}, **items))
    h = solve_cable(np.subtract(SPAN_B, SPAN_A), L0_PL, EA, w, [(S_LOAD, force)])
    x_load = np.add(SPAN_A, cable_position(h, S_LOAD, EA, w, [(S_LOAD, force)]))
    t_end = cable_end_pull(h, L0_PL, w, [(S_LOAD, force)])
    tmax = max(np.linalg.norm(h), np.linalg.norm(t_end))
    for ds in out.values():
        np.testing.assert_allclose(-ds.reaction.sel(node="A").values, h, atol=1e-9 * tmax)
        np.testing.assert_allclose(ds.reaction.sel(node="B").values, t_end, atol=1e-9 * tmax)
    # the loaded point: a node of the fine mesh; inside element 2 of the coarse one, where it is
    # found by integrating the coarse mesh's own end tension from node A
    fine, coarse = out[33], out[3]
    np.testing.assert_allclose(fine.position.sel(node="c.15").values, x_load, atol=1e-9 * L0_PL)
    h_coarse = -coarse.reaction.sel(node="A").values
    x_coarse = np.add(SPAN_A, cable_position(h_coarse, S_LOAD, EA, w, [(S_LOAD, force)]))
    np.testing.assert_allclose(x_coarse, x_load, atol=1e-9 * L0_PL)
    # nodes at the same arc length agree between the meshes
    for kc, kf in ((1, 11), (2, 22)):
        np.testing.assert_allclose(coarse.position.sel(node=f"c.{kc}").values,
                                   fine.position.sel(node=f"c.{kf}").values, atol=1e-9 * L0_PL)
    np.testing.assert_allclose(coarse.cable_end_tension.values, fine.cable_end_tension.values,
                               rtol=1e-9)


# ------------------------------------------------------------------------------------------------
# 3. Multi-cable scenes: equilibrium checked independently from the reported state
# ------------------------------------------------------------------------------------------------
def net_case(mirror=(1.0, 1.0), swap_c3=False, load_steps=1):
    """Five cables meeting at two free nodes N1, N2, with a point mass at N1, a load at N2, a
    horizontal load inside the middle cable and a point mass inside c1."""
    mx, my = mirror

    def p(x, y, z):
        return (mx * x, my * y, z)

    nodes = {"S1": p(-25.0, -12.0, 10.0), "S2": p(-22.0, 14.0, 12.0), "N1": p(-6.0, 1.0, 2.0),
             "N2": p(7.0, -1.0, 1.0), "S3": p(24.0, -13.0, 9.0), "S4": p(26.0, 11.0, 14.0)}
    L3, n3 = 14.5, 6
    c3 = ("c3", ("N2", "N1") if swap_c3 else ("N1", "N2"), L3, n3)
    cables = [("c1", ("S1", "N1"), 24.0, 5), ("c2", ("N1", "S2"), 22.0, 4), c3,
              ("c4", ("N2", "S3"), 23.0, 5), ("c5", ("S4", "N2"), 24.0, 7)]
    s3 = 5.0
    loads = [{"name": "push", "node": "N2", "force": [mx * 500.0, my * 300.0, -1000.0]},
             {"name": "wind", "cable": "c3", "s": L3 - s3 if swap_c3 else s3,
              "force": [mx * -200.0, my * 400.0, 100.0]}]
    masses = [{"name": "m1", "node": "N1", "mass": 120.0},
              {"name": "m2", "cable": "c1", "s": 9.0, "mass": 40.0}]
    return make_case(nodes, cables, supports={k: "pinned" for k in ("S1", "S2", "S3", "S4")},
                     point_masses=masses, loads=loads, load_steps=load_steps, EA=2.0e7,
                     mass=3.0)


def test_cable_net_is_in_equilibrium():
    case = net_case()
    ds = static(case)
    check_equilibrium(case, ds)
    # the free nodes moved away from where the case put them
    assert np.abs(ds.displacement.sel(node=["N1", "N2"])).max() > 0.1


# ------------------------------------------------------------------------------------------------
# 4. Symmetry: mirrored scenes, swapped cable ends
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("axis", ["x", "y"])
def test_mirrored_scene_gives_the_mirrored_answer(axis):
    base = static(net_case())
    mirror = (-1.0, 1.0) if axis == "x" else (1.0, -1.0)
    mir = static(net_case(mirror=mirror))
    flip = np.array([mirror[0], mirror[1], 1.0])
    tmax = float(base.tension.max())
    np.testing.assert_allclose(mir.position.values, base.position.values * flip,
                               atol=1e-9 * 30.0)
    np.testing.assert_allclose(mir.tension.values, base.tension.values, rtol=1e-9)
    np.testing.assert_allclose(mir.reaction.values, base.reaction.values * flip,
                               atol=1e-9 * tmax)


def test_swapping_the_ends_of_a_cable_reverses_it():
    base = static(net_case())
    sw = static(net_case(swap_c3=True))
    n3 = 6
    for k in range(1, n3 + 1):
        np.testing.assert_allclose(sw.tension.sel(element=f"c3.{n3 + 1 - k}").values[::-1],
                                   base.tension.sel(element=f"c3.{k}").values, rtol=1e-9)
    for k in range(1, n3):
        np.testing.assert_allclose(sw.position.sel(node=f"c3.{n3 - k}").values,
                                   base.position.sel(node=f"c3.{k}").values, atol=1e-9 * 30.0)
    other = [n for n in base.node.values if not str(n).startswith("c3.")]
    np.testing.assert_allclose(sw.position.sel(node=other).values,
                               base.position.sel(node=other).values, atol=1e-9 * 30.0)
    tmax = float(base.tension.max())
    np.testing.assert_allclose(sw.reaction.sel(node=other).values,
                               base.reaction.sel(node=other).values, atol=1e-9 * tmax)
    np.testing.assert_allclose(sw.cable_end_tension.sel(cable="c3").values[::-1],
                               base.cable_end_tension.sel(cable="c3").values, rtol=1e-9)


# ------------------------------------------------------------------------------------------------
# 5. Load stepping and line search: a slack cable under 100 times its weight
# ------------------------------------------------------------------------------------------------
V_A, V_B, V_L0, V_EA, V_MASS = (0.0, 0.0, 0.0), (10.0, 0.0, 0.0), 15.0, 3.4e7, 5.0
V_S = 6.0  # inside the single element; node c.4 of 10 elements


@pytest.mark.parametrize("load_steps", [1, 5])
def test_large_point_load_on_a_slack_cable(load_steps):
    w = V_MASS * G
    P = np.array([0.0, 0.0, -100.0 * w * V_L0])
    loads = [{"name": "p", "cable": "c", "s": V_S, "force": list(P)}]
    out = {}
    for ne in (1, 10):
        out[ne] = static(make_case({"A": V_A, "B": V_B}, [("c", ("A", "B"), V_L0, ne)],
                                   supports={"A": "pinned", "B": "pinned"}, loads=loads,
                                   load_steps=load_steps, EA=V_EA, mass=V_MASS))
    # V shape: two nearly straight legs of 6 and 9 m from the supports 10 m apart (inextensible
    # triangle), stretched by about T/EA ~ 1e-3; the legs sag by w L/(8 T) ~ 1e-3 of their length
    cos_a = (V_S**2 + 10.0**2 - (V_L0 - V_S) ** 2) / (2 * V_S * 10.0)
    tri = np.array([V_S * cos_a, 0.0, -V_S * math.sqrt(1 - cos_a**2)])
    h0 = np.array([-P[2] * 0.4, 0.0, P[2] * 0.6])
    h = solve_cable(np.subtract(V_B, V_A), V_L0, V_EA, w, [(V_S, P)], h0=h0)
    x_load = cable_position(h, V_S, V_EA, w, [(V_S, P)])
    t_end = cable_end_pull(h, V_L0, w, [(V_S, P)])
    assert np.linalg.norm(x_load - tri) < 0.01 * V_S
    tmax = max(np.linalg.norm(h), np.linalg.norm(t_end))
    for ds in out.values():
        np.testing.assert_allclose(-ds.reaction.sel(node="A").values, h, atol=1e-9 * tmax)
        np.testing.assert_allclose(ds.reaction.sel(node="B").values, t_end, atol=1e-9 * tmax)
        assert ds.attrs["residual_norm"] <= 1e-9 * tmax
    np.testing.assert_allclose(out[10].position.sel(node="c.4").values, x_load,
                               atol=1e-9 * V_L0)
    np.testing.assert_allclose(out[1].cable_end_tension.values, out[10].cable_end_tension.values,
                               rtol=1e-9)


def test_load_steps_do_not_change_the_answer():
    one = static(net_case(load_steps=1))
    five = static(net_case(load_steps=5))
    assert five.attrs["load_increments"] >= 2
    np.testing.assert_allclose(five.position.values, one.position.values, atol=1e-9 * 30.0)
    np.testing.assert_allclose(five.tension.values, one.tension.values, rtol=1e-9)


# ------------------------------------------------------------------------------------------------
# 6. Gravity alone: the supports carry the weight
# ------------------------------------------------------------------------------------------------
def test_gravity_only_reactions_carry_the_weight():
    nodes = {"A": (0.0, 0.0, 0.0), "B": (40.0, 5.0, 8.0), "C": (-30.0, 20.0, 3.0),
             "N": (5.0, 10.0, -6.0)}
    cables = [("a", ("A", "N"), 14.0, 3), ("b", ("N", "B"), 38.0, 6), ("c", ("C", "N"), 42.0, 4)]
    masses = [{"name": "atN", "node": "N", "mass": 80.0},
              {"name": "in_b", "cable": "b", "s": 11.0, "mass": 25.0},
              {"name": "at_a1", "cable": "a", "s": 14.0 / 3.0, "mass": 10.0}]
    case = make_case(nodes, cables, supports={"A": "pinned", "B": "pinned", "C": "pinned"},
                     point_masses=masses, EA=5.0e6, mass=2.0)
    ds = static(case)
    weight = 2.0 * G * (14.0 + 38.0 + 42.0) + (80.0 + 25.0 + 10.0) * G
    R = ds.reaction.sel(node=["A", "B", "C"]).values.sum(axis=0)
    assert R[2] == pytest.approx(weight, rel=1e-10)
    np.testing.assert_allclose(R[:2], 0.0, atol=1e-10 * weight)
    check_equilibrium(case, ds)


LIGHT_LINE = """
title = "a nearly weightless line pulled aside by its bob"
[materials.rope]
EA = 1.0e9
mass = 40.0
weight = {w}
[nodes]
A = [0.0, 0.0, -5.0]
B = [0.0, 0.0, -25.0]
[supports]
A = "pinned"
[[cables]]
name = "line"
ends = ["A", "B"]
material = "rope"
length = 20.0
elements = {n}
[[point_masses]]
name = "bob"
node = "B"
mass = 200.0
[[loads]]
name = "pull"
node = "B"
force = [1500.0, 0.0, 0.0]
[[steps]]
kind = "static"
name = "eq"
load_steps = {steps}
"""


@pytest.mark.parametrize(("w", "n", "steps"), [(0.1, 1, 4), (0.1, 1, 1), (6.6e-4, 1, 2),
                                               (6.6e-4, 4, 4), (6.6e-4, 10, 1)])
def test_a_line_that_carries_no_tension_yet_is_pulled_aside(w, n, steps):
    """A line hanging straight down (tension only from its own 0.1 N/m, or nearly neutral in
    water) gets its bob's weight and a side pull: the first Newton step, across a line with
    almost no lateral stiffness, was 7.5e13 m long and the solve stalled at load factor 0 for
    any load_steps > 1 (an independent tester's case); in several elements the capped Newton
    direction was the tensionless chain's mechanism, and a Levenberg-Marquardt step takes
    over. The answer is the weightless link to within the line's own weight: B at
    L0 (1 + T/EA) along (P, 0, -Mg) / T from A."""
    text = LIGHT_LINE.format(w=w, n=n, steps=steps)
    ds = catdae.run(case_from_dict(__import__("tomllib").loads(text)))["eq"].ds
    P, W = 1500.0, 200.0 * 9.81
    T = math.hypot(P, W)
    x = np.array([0.0, 0.0, -5.0]) + 20.0 * (1 + T / 1.0e9) * np.array([P, 0.0, -W]) / T
    weight = w * 20.0  # N: it tilts the line by about weight / T
    assert np.abs(ds.position.sel(node="B").values - x).max() < 20.0 * weight / T + 1e-9
    assert float(ds.tension.max()) == pytest.approx(T, abs=weight + 1e-6)


def test_a_weightless_line_pulled_aside_is_straight_with_no_sag_or_swing():
    """A weightless line (3 m, EA 1e7) holding a 10 kg bob pulled 40° aside: a straight line
    along the chord (nothing loads it between its ends), so its sag, its sag at midspan and its
    swing angle are 0 (round-off read as a sag of 4.4e-16 m and a swing of 180°, "upside
    down", an independent tester's pendulum)."""
    g, M, L, theta = 9.81, 10.0, 3.0, math.radians(40.0)
    chord = L * (1 + M * g / math.cos(theta) / 1.0e7)
    B = (chord * math.sin(theta), 0.0, -chord * math.cos(theta))
    text = cable_scene(B=B, L0=L, EA=1.0e7, mass=0.001, weight=0.0, elements=10,
                       supports=("A",), gravity=g, extra=point_mass("bob", M, node="B") + (
                           f'[[loads]]\nname = "hold"\nnode = "B"\n'
                           f"force = [{M * g * math.tan(theta)!r}, 0.0, 0.0]\n"),
                       steps=static_step("held"))
    ds = catdae.run(catdae.load_case(text))["held"].ds
    assert float(ds.sag.sel(cable="c")) == 0.0
    assert float(ds.sag_midspan.sel(cable="c")) == 0.0
    assert float(ds.swing_angle.sel(cable="c")) == 0.0
    np.testing.assert_allclose(float(ds.tension.max()), M * g / math.cos(theta), rtol=1e-9)
