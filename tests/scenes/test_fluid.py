"""Cables in water and air (issue 21, docs/theory.md §13): buoyancy, added mass, drag damping,
the iteration matrix with the fluid, and what a scene without a fluid costs.

Each check is against something independent: the elastic catenary of the submerged weight
(Irvine, tests/reference.py), the taut string with the added mass and the discrete dispersion
of its mesh, the linearised quasi-steady drag damping, and finite differences.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import catdae
from catdae.case import load_case
from catdae.model.assembly import Model
from catdae.model.mesh import build_mesh
from catdae.solvers.residual import TransientProblem
from catdae.solvers.static import solve_static

from reference import irvine_catenary_inclined_3d
from scene_toml import cable_scene, modal_step, static_step, transient_step

RHO = 1025.0
G = 9.81


def _water(extra: str = "") -> str:
    return f"[water]\ndensity = {RHO}\nsurface = 0.0\ndepth = 200.0\n{extra}"


# ------------------------------------------------------------------------------------------------
# buoyancy: exact in statics
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("ne", [1, 4, 10, 40])
def test_submerged_line_is_the_catenary_of_the_submerged_weight(ne):
    """A line wholly under water: its static nodes and end forces are those of the elastic
    catenary of w - ρ g π d²/4, to 1e-9 relative (issue 21, acceptance)."""
    A, B = (0.0, 0.0, -120.0), (80.0, 30.0, -15.0)
    L0, EA, mass, d = 140.0, 3.0e8, 60.0, 0.12
    text = cable_scene(A=A, B=B, L0=L0, EA=EA, mass=mass, elements=ne,
                       extra=_water(), steps=static_step())
    text = text.replace("mass = 60.0\n", f"mass = 60.0\ndiameter = {d}\n")
    ds = catdae.run(load_case(text))["st"].to_dataset()
    w_sub = mass * G - RHO * G * math.pi * d * d / 4.0
    ref = irvine_catenary_inclined_3d(A, B, L0, EA, w_sub)
    scale = float(np.abs(ref["h"]).max())
    np.testing.assert_allclose(ds.reaction.sel(node="A").values, -ref["h"], rtol=0,
                               atol=1e-9 * scale)
    np.testing.assert_allclose(ds.reaction.sel(node="B").values, ref["t_B"], rtol=0,
                               atol=1e-9 * scale)
    if ne > 1:
        s = np.arange(1, ne) * L0 / ne
        X = ds.position.sel(node=[f"c.{k}" for k in range(1, ne)]).values
        np.testing.assert_allclose(X, ref["x"](s), rtol=0, atol=1e-9 * L0)
    # and not the catenary in air: buoyancy is there
    air = irvine_catenary_inclined_3d(A, B, L0, EA, mass * G)
    assert abs(air["h"][0] - ref["h"][0]) > 1e3 * 1e-9 * scale


# ------------------------------------------------------------------------------------------------
# added mass: transverse modes of a neutrally buoyant taut line
# ------------------------------------------------------------------------------------------------
SPAN, TENSION, MASS, DIAM, CA = 50.0, 2.0e4, 8.0, 0.1, 1.0


def _taut_scene(ne: int, mass_model: str, ca: float = CA) -> str:
    """A straight line along x at 30 m depth, neutrally buoyant (weight = ρ g π d²/4)."""
    EA = 1.0e7
    area = math.pi * DIAM**2 / 4.0
    L0 = SPAN / (1.0 + TENSION / EA)
    text = cable_scene(A=(0.0, 0.0, -30.0), B=(SPAN, 0.0, -30.0), L0=L0, EA=EA, mass=MASS,
                       weight=RHO * G * area, elements=ne, extra=_water(),
                       steps=modal_step(6, mass_model=mass_model))
    return text.replace("weight = ", f"diameter = {DIAM}\nadded_mass_normal = {ca}\n"
                        "added_mass_axial = 0.0\nweight = ")


def _out_of_plane(ds) -> np.ndarray:
    return np.sort(ds.frequency.values[np.asarray(ds.plane.values) == "out-of-plane"])


@pytest.mark.parametrize("mass_model, order", [("consistent", 2), ("blended", 4)])
def test_added_mass_gives_the_taut_string_frequencies(mass_model, order):
    """Transverse frequencies of a straight, neutrally buoyant taut line in water: the taut
    string's with m + ρ Ca π d²/4 per unstrained metre, to the mesh's own dispersion (the
    linear consistent mass: θ²/24; the blend: -θ⁴/480, docs/theory.md §7) and converging at its
    order."""
    area = math.pi * DIAM**2 / 4.0
    L0 = SPAN / (1.0 + TENSION / 1.0e7)
    mu = (MASS + RHO * CA * area) * L0 / SPAN  # kg per metre of the stretched line
    errs, hs = [], []
    for ne in (8, 16, 32):
        ds = catdae.run(load_case(_taut_scene(ne, mass_model)))["modes"].to_dataset()
        f = _out_of_plane(ds)[:3]
        n = np.arange(1, 4)
        exact = n / (2.0 * SPAN) * math.sqrt(TENSION / mu)
        theta = n * math.pi / ne
        if mass_model == "consistent":
            disp = np.sqrt(6 * (1 - np.cos(theta)) / (theta**2 * (2 + np.cos(theta))))
        else:
            disp = np.sqrt(2 * (1 - np.cos(theta)) / (theta**2 * (1 - (1 - np.cos(theta)) / 6)))
        # the discrete string of this mesh, to the tension's stretch (T/EA = 2e-3 on L0)
        np.testing.assert_allclose(f, exact * disp, rtol=1e-6)
        errs.append(abs(f[0] / exact[0] - 1.0))
        hs.append(SPAN / ne)
    rate = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert abs(rate - order) < 0.1, rate
    # without the added mass the frequencies are those of m alone: the added mass is there
    ds0 = catdae.run(load_case(_taut_scene(32, mass_model, ca=0.0)))["modes"].to_dataset()
    ratio = _out_of_plane(ds0)[0] / _out_of_plane(
        catdae.run(load_case(_taut_scene(32, mass_model)))["modes"].to_dataset())[0]
    assert ratio == pytest.approx(math.sqrt((MASS + RHO * CA * area) / MASS), rel=1e-9)


# ------------------------------------------------------------------------------------------------
# the iteration matrix with drag, added mass and Froude-Krylov, against finite differences
# ------------------------------------------------------------------------------------------------
_WAVY = _water(
    'current = { z = [-200.0, -60.0, 0.0], velocity = [[0.1, 0.0, 0.0], [0.6, 0.2, 0.0], '
    '[1.2, 0.4, 0.05]], time = { kind = "sine", amplitude = 0.3, frequency = 0.1, '
    'offset = 1.0 } }\n'
    'waves = { kind = "airy", height = 6.0, period = 9.0, heading = 20.0, ramp = 4.0 }\n')
_WINDY = ('[air]\ndensity = 1.3\nwind = { speed = 25.0, direction = 60.0, profile = "power", '
          'exponent = 0.16, reference_height = 10.0, ground = -5.0 }\n')


def _problem(extra: str, A, B, mass_model: str):
    text = cable_scene(A=A, B=B, L0=130.0, EA=5.0e8, mass=40.0, elements=6, extra=extra,
                       steps=static_step() + transient_step("tr", 1.0, 0.1, rtol=1e-6,
                                                            atol=1e-6,
                                                            extra=f'mass_model = "{mass_model}"'))
    text = text.replace("mass = 40.0\n", "mass = 40.0\ndiameter = 0.15\ndrag_normal = 1.1\n"
                        "drag_axial = 0.3\nadded_mass_normal = 0.9\nadded_mass_axial = 0.4\n")
    case = load_case(text)
    mesh = build_mesh(case)
    model = Model(case, mesh, set(), mass_model=mass_model, kind="transient")
    sol = solve_static(model, mesh.X0)
    return model, TransientProblem(model, case.steps[1], sol.X, sol.state.h), sol


@pytest.mark.parametrize("extra, ends, mass_model", [
    (_WAVY, ((0.0, 0.0, -150.0), (100.0, 20.0, -40.0)), "blended"),
    (_WAVY, ((0.0, 0.0, -150.0), (100.0, 20.0, -40.0)), "lumped"),
    (_WINDY, ((0.0, 0.0, 60.0), (100.0, 20.0, 90.0)), "consistent"),
])
def test_fluid_iteration_matrix_against_finite_differences(extra, ends, mass_model):
    """The fluid's part of IDA's iteration matrix, ∂r/∂y + c_j ∂r/∂y', equals central
    differences of the fluid's part of the residual (the residual with the fluid less the
    residual without it), on a moving line in current and waves, and in a power-law wind."""
    model, prob, sol = _problem(extra, *ends, mass_model)
    rng = np.random.default_rng(3)
    n = prob.n
    y = np.empty(2 * n)
    y[0::2] = sol.X.reshape(-1)[prob.fidx] + 0.05 * rng.standard_normal(n)
    y[1::2] = 0.8 * rng.standard_normal(n)
    yp = rng.standard_normal(2 * n)
    t, cj = 2.3, 37.0
    fluid = model.fluid

    def r_fluid(yy, yyp):
        with_f = np.empty(2 * n)
        without = np.empty(2 * n)
        assert prob.evaluate(t, yy, yyp, with_f)
        model.fluid = None
        try:
            assert prob.evaluate(t, yy, yyp, without)
        finally:
            model.fluid = fluid
        return with_f - without

    def jac():
        JJ = np.empty((2 * n, 2 * n))
        prob._cache_t = None  # a fresh configuration
        prob.jac_dense(t, y, yp, None, cj, JJ)
        return JJ

    J_with = jac()
    model.fluid = None
    try:
        J_without = jac()
    finally:
        model.fluid = fluid
    J = J_with - J_without
    fd = np.zeros_like(J)
    for k in range(2 * n):
        e = np.zeros(2 * n)
        h = 1e-6 * max(1.0, abs(y[k]))
        e[k] = h
        fd[:, k] = (r_fluid(y + e, yp) - r_fluid(y - e, yp)) / (2 * h)
        fd[:, k] += cj * (r_fluid(y, yp + e) - r_fluid(y, yp - e)) / (2 * h)
    scale = np.abs(fd).max()
    assert scale > 0
    np.testing.assert_allclose(J, fd, rtol=0, atol=2e-6 * scale)
