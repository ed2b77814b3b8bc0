"""The seabed's penalty contact in modal and transient steps (docs/theory.md §17): its part of
IDA's iteration matrix against finite differences, energy conservation of an undamped,
frictionless contact and loss with damping and friction, the penetration of a lying chain,
and the bundled mooring case at a cheap setting."""

from __future__ import annotations

import math

import numpy as np
import pytest

import catdae
from catdae.case import load_case
from catdae.model.assembly import Model
from catdae.model.mesh import build_mesh
from catdae.model.seabed import ContactModel
from catdae.solvers.residual import TransientProblem
from catdae.solvers.static import solve_static

from reference import grounded_catenary
from repo_paths import CASES
from scene_toml import cable_scene, distributed_load, section, static_step, step

G = 9.81


def _line(seabed: dict, steps: str, *, B=(40.0, 5.0, -10.0), elements=8, mass=80.0,
          diameter=0.1, extra: str = "") -> str:
    """A 60 m chain from an anchor on the seabed (z = -20, ``seabed``: the further fields of
    ``[seabed]``) to B (by default 40 m away, 10 m up)."""
    return cable_scene(A=(0.0, 0.0, -20.0), B=B, L0=60.0, EA=5.0e8, mass=mass, elements=elements,
                       gravity=G, material="chain", properties={"diameter": diameter},
                       extra=section("seabed", z=-20.0, **seabed) + extra, steps=steps)


def _problem(seabed: dict):
    text = _line(seabed, step("static") + step("transient", duration=1.0, output_interval=0.1,
                                               mass_model="lumped"))
    case = load_case(text)
    mesh = build_mesh(case)
    model = Model(case, mesh, set(), mass_model="lumped", kind="transient")
    sol = solve_static(ContactModel.of(model), mesh.X0)
    return model, TransientProblem(model, case.steps[1], sol.X, sol.state.h), sol


def test_seabed_iteration_matrix_against_finite_differences():
    """The contact's part of ∂r/∂y + c_j ∂r/∂y' equals central differences of its part of
    the residual (with isotropic friction, whose direction along the line does not enter),
    on a moving line with nodes below and above the seabed."""
    model, prob, sol = _problem({"stiffness": 2.0e5, "damping": 3.0e3, "friction": 0.6,
                                 "friction_velocity": 0.05})
    rng = np.random.default_rng(5)
    n = prob.n
    y = np.empty(2 * n)
    y[0::2] = sol.X.reshape(-1)[prob.fidx] + 0.004 * rng.standard_normal(n)
    y[1::2] = 0.05 * rng.standard_normal(n)
    yp = rng.standard_normal(2 * n)
    t, cj = 0.3, 41.0
    seabed = prob.seabed
    assert np.any(seabed.zb - y[0::2][np.isin(prob.fidx % 3, [2])] > 0)

    def r_seabed(yy, yyp):
        with_s = np.empty(2 * n)
        without = np.empty(2 * n)
        assert prob.evaluate(t, yy, yyp, with_s)
        prob.seabed = None
        try:
            assert prob.evaluate(t, yy, yyp, without)
        finally:
            prob.seabed = seabed
        return with_s - without

    def jac():
        JJ = np.empty((2 * n, 2 * n))
        prob._cache_t = None
        prob.jac_dense(t, y, yp, None, cj, JJ)
        return JJ

    J_with = jac()
    prob.seabed = None
    try:
        J_without = jac()
    finally:
        prob.seabed = seabed
    J = J_with - J_without
    fd = np.zeros_like(J)
    for k in range(2 * n):
        e = np.zeros(2 * n)
        h = 1e-7
        e[k] = h
        fd[:, k] = (r_seabed(y + e, yp) - r_seabed(y - e, yp)) / (2 * h)
        fd[:, k] += cj * (r_seabed(y, yp + e) - r_seabed(y, yp - e)) / (2 * h)
    scale = np.abs(fd).max()
    assert scale > 0
    np.testing.assert_allclose(J, fd, rtol=0, atol=1e-6 * scale)


def _drop(seabed: dict, rtol=1e-7):
    """The line held 0.2 m higher by an upward load in the static step, then released onto
    the seabed (the load removed): energies at the outputs."""
    fall = step("transient", "fall", duration=4.0, output_interval=0.05, rtol=rtol, atol=rtol,
                mass_model="lumped", remove=["lift"])
    text = _line(seabed, static_step("st") + fall,
                 extra=distributed_load("c", [0.0, 0.0, 400.0], name="lift"))
    tree = catdae.run(load_case(text), progress=False)
    return tree["fall"].to_dataset()


def test_undamped_frictionless_contact_conserves_energy():
    """Without damping and friction the seabed is a conservative spring: the total energy
    (kinetic + strain + gravity + contact springs) of a line falling onto it and bouncing
    stays within 1e-3 of the largest kinetic energy; with damping and friction it falls."""
    ds = _drop({"stiffness": 2.0e5})
    z = ds.position.sel(axis="z").values
    assert z.min() < -20.0  # the line reaches into the seabed
    e = ds.energy_total.values
    ek = ds.energy_kinetic.values.max()
    assert ek > 0
    assert np.abs(e - e[0]).max() <= 1e-3 * ek
    lossy = _drop({"stiffness": 2.0e5, "damping": 5.0e3, "friction": 0.5}, rtol=1e-6)
    el = lossy.energy_total.values
    assert el[-1] < el[0] - 0.1 * ek
    assert np.all(np.diff(el) <= 1e-3 * ek)
    # the balance: what the total lost is the seabed's work (its power integrated by the
    # trapezoidal rule at the 0.05 s outputs: a few per cent)
    lost = el[0] - el
    work = lossy.seabed_work.values
    assert np.abs(lost - work).max() <= 0.05 * lost[-1]


def test_modal_on_contact_springs_stiffens_the_vertical_modes():
    """A modal step on the contact springs: a chain lying wholly on a seabed of stiffness k
    (per contact area) has its lowest vertical frequency at the spring-mass value
    sqrt(k d / m) / 2π (uniform vertical motion of the lying part, lumped mass)."""
    k, d, m = 2.0e5, 0.1, 80.0
    text = _line({"stiffness": k}, step("static") + step("modal", modes=40, mass_model="lumped"),
                 B=(59.0, 0.0, -20.0), elements=30, mass=m, diameter=d)
    tree = catdae.run(load_case(text), progress=False)
    f = tree[list(tree.children)[1]].to_dataset().frequency.values
    f0 = math.sqrt(k * d / m) / (2 * math.pi)
    # the vertical modes of a slack line on springs: every one at or just above f0
    assert np.min(np.abs(f - f0)) <= 0.02 * f0


def test_bundled_mooring_case_statics_and_a_cheap_run():
    """cases/mooring_chain_200m.toml: on the contact springs the lying chain sinks by its
    submerged weight over k d (0.132 m), the fairlead force is within 1 % of the rigid
    closed form, and 5 s of the heave-and-surge record run at rtol 1e-3."""
    case = catdae.load_case(CASES / "mooring_chain_200m.toml")
    import dataclasses

    steps = (case.steps[0], dataclasses.replace(case.steps[1], duration=5.0,
                                                output_interval=0.5, rtol=1e-3, atol=1e-3))
    tree = catdae.run(dataclasses.replace(case, steps=steps), progress=False)
    st = tree["moored"].to_dataset()
    w = (390.0 - 1025.0 * math.pi * 0.252**2 / 4) * G
    sink = w / (1e5 * 0.252)
    z = st.position.sel(axis="z").values
    lying = z < -200.0
    assert np.median(z[lying]) == pytest.approx(-200.0 - sink, rel=2e-4)
    ref = grounded_catenary(700.0, 200.0, 760.0, 1.674e9, w)
    fair = st.reaction.sel(node="fairlead").values
    assert np.linalg.norm(fair) == pytest.approx(ref["fairlead_tension"], rel=1e-2)
    tr = tree["heave_surge"].to_dataset()
    assert tr.attrs["status"] == "completed"
    assert np.all(np.isfinite(tr.position.values))
    # the lying length over time at node resolution, near the static one
    lying_static = float(st.seabed_length.item())
    assert np.all(np.abs(tr.seabed_length.values - lying_static) <= 3 * 38.0)
    assert np.all(np.isfinite(tr.touchdown.values))


@pytest.mark.parametrize("B, lies", [((40.0, 5.0, -10.0), True), ((59.0, 5.0, -10.0), False)])
def test_an_anchor_on_the_seabed_lays_nothing_where_the_line_lifts_off_there(B, lies):
    """On the contact springs an anchor sitting at the seabed counted as lying: a line lifted
    off all along read half an element on the seabed and its touchdown at the anchor, never 0
    and NaN (tester t76, against MoorDyn and the rigid seabed). Where the line leaves the
    anchor rising (chord 60.05 m of a 60 m line: every free node above the seabed), nothing lies, in
    the static group and over a transient; where it lies (40 m away), the anchor's element
    counts whole and the touchdown is a free node below the seabed."""
    text = _line({"stiffness": 1.0e5},
                 step("static", "st") + step("transient", "tr", duration=0.5,
                                              output_interval=0.1, mass_model="lumped"), B=B)
    tree = catdae.run(load_case(text), progress=False)
    st, tr = tree["st"].to_dataset(), tree["tr"].to_dataset()
    free_z = st.position.sel(axis="z", node=[f"c.{k}" for k in range(1, 8)]).values
    if not lies:
        assert free_z.min() > -20.0  # lifted all along (independent of the rule)
        assert float(st.seabed_length.item()) == 0.0
        assert np.isnan(st.touchdown.values).all()
        assert np.all(tr.seabed_length.values == 0.0) and np.isnan(tr.touchdown.values).all()
        return
    below = free_z < -20.0
    assert below[0] and not below.all()  # lying from the anchor, then rising
    k = int(np.argmin(below))  # the first free node above: the touchdown is the one before
    assert float(st.seabed_length.item()) == pytest.approx(7.5 * (k + 0.5), rel=1e-12)
    np.testing.assert_allclose(st.touchdown.values.ravel(),
                               st.position.sel(node=f"c.{k}").values)
