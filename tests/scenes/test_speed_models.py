"""The blended mass, the analytic ∂M/∂c and the automatic BDF order (issue 11), against
independent references: the taut string's closed-form frequencies, the complex-step derivative,
the other mass models' common limit, the work-energy balance, and fixed-order runs.
"""

from __future__ import annotations

import numpy as np
import pytest

import catdae
from catdae.element.elements import Elements, PointLoads

from scene_toml import (
    cable_scene,
    modal_step,
    point_mass,
    static_step,
    step,
    support_motion,
)

# ----------------------------------------------------------------------------------------------
# blended mass: order 4 on the taut string
# ----------------------------------------------------------------------------------------------
SPAN, L0, EA, MASS = 10.0, 9.99, 1.0e6, 2.0
TENSION = EA * (SPAN / L0 - 1.0)


def _string_modes(n: int, mass_model: str) -> np.ndarray:
    """Out-of-plane frequencies (Hz) of a weightless taut string on n elements."""
    text = cable_scene(B=(SPAN, 0.0, 0.0), L0=L0, EA=EA, mass=MASS, elements=n, gravity=0.0,
                       steps=static_step() + modal_step(12, mass_model=mass_model))
    ds = catdae.run(catdae.load_case(text), progress=False)["modes"].ds
    return np.sort(ds.frequency.values[ds.plane.values == "out-of-plane"])


@pytest.mark.parametrize(("mass_model", "order", "sign"),
                         [("blended", 4.0, -1.0), ("consistent", 2.0, 1.0), ("lumped", 2.0, -1.0)])
def test_taut_string_frequency_convergence_order(mass_model, order, sign):
    """f_k = k/(2 L) sqrt(T/μ), μ = m L0/L the mass per stretched length (closed form). The
    consistent and lumped masses err by about ±(kh)²/24; their average cancels that term and
    leaves -(kh)⁴/480 (dispersion of the two-node string element), so the blend converges at
    order 4 from below."""
    c = np.sqrt(TENSION / (MASS * L0 / SPAN))
    meshes = (6, 12, 24)
    errs = []
    for n in meshes:
        f = _string_modes(n, mass_model)[:3]
        exact = np.arange(1, 4) * c / (2.0 * SPAN)
        errs.append(f / exact - 1.0)
    errs = np.array(errs)  # (mesh, mode)
    assert np.all(sign * errs > 0)
    for j in range(3):
        slope = np.polyfit(np.log(meshes), np.log(np.abs(errs[:, j])), 1)[0]
        assert abs(slope + order) < 0.15, (mass_model, j, slope, errs[:, j])
    if mass_model == "blended":  # leading term -(kh)⁴/480 of the dispersion relation
        kh = np.pi * np.arange(1, 4) / meshes[-1]
        np.testing.assert_allclose(errs[-1], -kh**4 / 480.0, rtol=0.05)


def test_blended_is_the_average_of_consistent_and_lumped():
    """M_blended = ½ M_consistent + ½ M_lumped, assembled on a sagging cable with a point mass
    inside an element; the total mass is kept."""
    text = cable_scene(B=(30.0, 0.0, 5.0), L0=33.0, EA=1e7, mass=3.0, elements=5, gravity=9.81,
                       extra=point_mass("p", 40.0, cable="c", s=7.3),
                       steps=static_step())
    case = catdae.load_case(text)
    from catdae.model.assembly import Model
    from catdae.model.mesh import build_mesh

    mesh = build_mesh(case)
    mats = {}
    for mm in ("blended", "consistent", "lumped"):
        model = Model(case, mesh, set(), mass_model=mm)
        state = model.element_state(mesh.X0)
        mats[mm] = model.mass(state).toarray()
    np.testing.assert_allclose(mats["blended"], 0.5 * (mats["consistent"] + mats["lumped"]),
                               rtol=0, atol=1e-12 * np.abs(mats["consistent"]).max())
    r = np.tile([0.0, 0.0, 1.0], mesh.n_nodes)
    assert r @ mats["blended"] @ r == pytest.approx(3.0 * 33.0 + 40.0, rel=1e-12)


# ----------------------------------------------------------------------------------------------
# analytic ∂M/∂c against complex steps
# ----------------------------------------------------------------------------------------------
def test_analytic_mass_gradient_matches_complex_step():
    """The forward-mode ∂M_e/∂c (fused into the element pass) equals the complex-step one
    (exact to round-off by construction: no difference is taken) on taut, sagging, near-vertical,
    inclined and loaded elements, with point masses inside."""
    el, chord, gs, gw, m, pm = _six_elements()
    state, me, _, dm = el.solve_dynamic(chord, None, gs, gw, m, None, pm, gradient=True)
    assert np.all(state.status == 0)
    ref = el.mass_gradient(state)
    for e in range(el.n):
        scale = np.abs(ref[e]).max()
        assert scale > 0
        np.testing.assert_allclose(dm[e], ref[e], rtol=0, atol=1e-9 * scale)
    # and the same mass as the pass without the gradient
    _, me2, _ = el.solve_dynamic(chord, None, gs, gw, m, None, pm)
    np.testing.assert_allclose(me, me2, rtol=1e-13, atol=0)


def _six_elements():
    """Six elements (taut, sagging, near-vertical, inclined, loaded, with point masses inside):
    (elements, chords, Gauss points and weights, mass per length, point masses)."""
    L0 = np.array([10.0, 10.0, 3.0, 20.0, 2.0, 12.0])
    EA = np.array([1e8, 1e6, 1e5, 1e8, 1e4, 5e7])
    w = np.array([100.0, 10.0, 50.0, 300.0, 5.0, 80.0])
    chord = np.array([[10.0004, 0.0, 0.0], [6.0, 2.0, -5.0], [0.1, 0.2, -2.9],
                      [15.0, 3.0, 8.0], [1.5, 1.0, 0.5], [8.0, -4.0, 6.0]])
    loads = PointLoads.from_lists([[], [(3.0, [0.0, 0.0, 50.0])],
                                   [(1.0, [5.0, 0.0, 20.0]), (2.0, [0.0, 3.0, 10.0])], [], [],
                                   [(6.0, [0.0, 0.0, 900.0])]])
    xi = np.array([0.5 - np.sqrt(0.15), 0.5, 0.5 + np.sqrt(0.15)])
    gs = xi[None, :] * L0[:, None]
    gw = np.tile(np.array([5.0, 8.0, 5.0]) / 18.0, (L0.size, 1))
    m = np.array([10.0, 2.0, 1.0, 30.0, 3.0, 8.0])
    pm = (np.array([0, 3, 5]), np.array([4.0, 11.0, 6.0]), np.array([7.0, 20.0, 15.0]))
    return Elements(L0, EA, w, loads), chord, gs, gw, m, pm


def _lagrange(el, state, e, gs, gw, m, pm, fade, share, ve, ae):
    """``lagrange_one`` of element e: share (M_e ae + fade g_e) without the matrices."""
    from catdae.element.lagrange import kinetic_one, lagrange_one

    pmptr, pms, pmm = el._point_mass_csr(pm)
    fe = np.full(6, np.nan)
    ok, kinetic = lagrange_one(state.h[e], state.K[e], el.L0[e], el.EA[e], el.w[e], el._ls,
                               el._lf, el._ptr[e], el._ptr[e + 1], gs[e], gw[e], m[e], pmptr[e],
                               pmptr[e + 1], pms, pmm, fade, share, ve, ae, fe, np.empty(6),
                               np.empty((6, 3)))
    assert ok
    # an output's kinetic energy, where the element's forces are not read
    alone = kinetic_one(state.h[e], state.K[e], el.L0[e], el.EA[e], el.w[e], el._ls, el._lf,
                        el._ptr[e], el._ptr[e + 1], gs[e], gw[e], m[e], pmptr[e], pmptr[e + 1],
                        pms, pmm, share, ve, np.empty(3), np.empty(6))
    assert alone == pytest.approx(kinetic, rel=1e-13)
    return fe, kinetic


def test_element_forces_without_the_matrices_equal_those_with_them():
    """The residual's matrix-free element force share (M_e a + fade g_e) (docs/theory.md §7.6)
    equals the one from the matrices M_e and ∂M_e/∂c (checked against complex steps above),
    g_e = Σ_k ċ_k ∂M_e/∂c_k v - ½ vᵀ ∂M_e/∂c_k v [e_k; -e_k], with random velocities and
    accelerations, to round-off, and so does its kinetic energy ½ share vᵀ M_e v (with the pass
    that computes that alone, for outputs); the matrices' ∂M_e/∂c carries the element's fade
    near zero tension (§7.6), which is given to the matrix-free pass too."""
    from catdae.element.mass_gradient import gradient_fade

    el, chord, gs, gw, m, pm = _six_elements()
    state, me, _, dm = el.solve_dynamic(chord, None, gs, gw, m, None, pm, gradient=True)
    rng = np.random.default_rng(5)
    for e in range(el.n):
        ve, ae = rng.normal(size=6), rng.normal(size=6)
        fade = gradient_fade(state.h[e], el.w[e], el.L0[e], el._ls, el._lf, el._ptr[e],
                             el._ptr[e + 1])
        share = 0.6
        g = np.zeros(6)
        for k in range(3):
            qv = dm[e, k] @ ve
            g += (ve[3 + k] - ve[k]) * qv
            g[k] += 0.5 * ve @ qv
            g[3 + k] -= 0.5 * ve @ qv
        ref = share * (me[e] @ ae + g)  # dm carries the fade
        fe, kinetic = _lagrange(el, state, e, gs, gw, m, pm, fade, share, ve, ae)
        np.testing.assert_allclose(fe, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
        assert kinetic == pytest.approx(0.5 * share * ve @ me[e] @ ve, rel=1e-12)


def test_velocity_terms_without_the_matrices_balance_the_kinetic_power():
    """vᵀ g_e = ½ vᵀ Ṁ_e v = d/dt (½ vᵀ M_e(c) v) at fixed v (docs/theory.md §7.6: the terms
    that make the energy balance): the matrix-free g_e against a central difference of the
    kinetic energy along ċ = v_j - v_i, the element re-solved by Newton at c ± δ ċ
    (Richardson-extrapolated): an independent path through the solve and the mass."""
    el, chord, gs, gw, m, pm = _six_elements()
    state, _, _ = el.solve_dynamic(chord, None, gs, gw, m, None, pm)
    rng = np.random.default_rng(9)
    ve = rng.normal(size=(el.n, 6))
    cdot = ve[:, 3:] - ve[:, :3]

    def kinetic(step):
        me = el.solve_dynamic(chord + step * cdot, state.h, gs, gw, m, None, pm)[1]
        return 0.5 * np.einsum("ei,eij,ej->e", ve, me, ve)

    def central(d):
        return (kinetic(d) - kinetic(-d)) / (2 * d)

    ref = (4 * central(1e-6) - central(2e-6)) / 3  # a chord change of about 1 µm
    for e in range(el.n):
        g = _lagrange(el, state, e, gs, gw, m, pm, 1.0, 1.0, ve[e], np.zeros(6))[0]
        assert ve[e] @ g == pytest.approx(ref[e], rel=1e-7)  # measured: < 1e-8


# ----------------------------------------------------------------------------------------------
# transients: the blend balances work and energy; the order choice converges
# ----------------------------------------------------------------------------------------------
def _moving_cable(n: int, duration: float, rtol: float, max_order: int | None = None) -> str:
    """The 100 m cable whose end B moves 0.05 (1 - cos πt) m along the span, in the blended
    transient "motion" (``max_order``: its BDF order limit, when given)."""
    motion = support_motion("B", x={"kind": "cosine", "amplitude": -0.05, "frequency": 0.5,
                                    "offset": 0.05})
    return cable_scene(B=(100.0, 0.0, 0.0), L0=102.0, EA=1e8, mass=100.0 / 9.81, weight=100.0,
                       elements=n, gauss_points=3, gravity=9.81, extra=motion,
                       steps=static_step("initial")
                       + step("transient", "motion", duration=float(duration),
                              output_interval=0.01, rtol=float(rtol), atol=rtol * 1e-2,
                              mass_model="blended", max_order=max_order))


def test_blended_work_energy_balance():
    """Undamped, with a support moving: the change of kinetic + strain + gravity energy equals
    the work of the support reactions on the cable, ∫ R·v_support dt (trapezoid on the
    outputs; ``reaction`` is the force the support exerts on the cable)."""
    from scipy.integrate import trapezoid

    ds = catdae.run(catdae.load_case(_moving_cable(12, 2.0, 1e-8)), progress=False)["motion"].ds
    b = ds.velocity.sel(node="B").values  # (time, 3)
    r = ds.reaction.sel(node="B").values
    power = np.sum(np.nan_to_num(r) * b, axis=1)
    work = trapezoid(power, ds.time.values)
    de = float(ds.energy_total.values[-1] - ds.energy_total.values[0])
    assert abs(work) > 1.0  # the support does work
    assert de == pytest.approx(work, rel=5e-3)


def test_automatic_order_switches_on_a_fine_mesh_and_agrees():
    """On a fine mesh of a sagging cable (axial modes far above the motion) the automatic cap
    runs at order 2; its midspan history agrees with a tight order-5 run to the accuracy its
    tolerance gives (the order-2 error at rtol 1e-4 on this cable is about 1e-3 m:
    benchmarks/speed_accuracy.md). A coarse mesh keeps order 5."""
    fine = catdae.run(catdae.load_case(_moving_cable(160, 1.0, 1e-4)), progress=False)
    ds = fine["motion"].ds
    assert ds.attrs["max_order_setting"] == "auto"
    assert ds.attrs["max_order"] == 2, ds.attrs["order_choice"]
    ref = catdae.run(catdae.load_case(_moving_cable(160, 1.0, 1e-6, max_order=5)),
                     progress=False)["motion"].ds
    z = ds.position.sel(node="c.80", axis="z").values
    zr = ref.position.sel(node="c.80", axis="z").values
    assert np.abs(z - zr).max() < 3e-3
    assert np.abs(zr - zr[0]).max() > 0.02  # the motion is much larger than that
    coarse = catdae.run(catdae.load_case(_moving_cable(16, 4.0, 1e-4)), progress=False)
    assert coarse["motion"].ds.attrs["max_order"] == 5, coarse["motion"].ds.attrs["order_choice"]


def _steps(n: int, duration: float, rtol: float, max_order: int | None = None) -> tuple[int, str]:
    ds = catdae.run(catdae.load_case(_moving_cable(n, duration, rtol, max_order)),
                    progress=False)["motion"].ds
    return int(ds.attrs["n_steps"]), str(ds.attrs["order_choice"])


def test_automatic_order_keeps_order_5_where_it_is_cheaper():
    """32 elements at rtol 1e-5 over 10 s: fixed order 5 takes well under half the steps of
    fixed order 2 (accuracy, not stability, sets its step). The race measures that and does
    not cost more than a quarter over fixed order 5 (benchmarks/speed_accuracy.md §8)."""
    n5, _ = _steps(32, 10.0, 1e-5, max_order=5)
    n2, _ = _steps(32, 10.0, 1e-5, max_order=2)
    auto, choice = _steps(32, 10.0, 1e-5)
    assert n5 < 0.6 * n2  # the premise: order 5 is the cheaper here
    assert choice.startswith("order 5"), choice
    assert "race" in choice  # the other order was measured, not assumed
    assert auto <= 1.25 * n5, (auto, n5, choice)


def test_automatic_order_goes_to_order_2_where_it_is_cheaper():
    """40 elements at rtol 1e-3 over 10 s: order 5 is held down by the axial modes' stability
    (it takes more steps than at rtol 1e-4), order 2 takes a fifth of its steps. The race must
    find order 2 and take far fewer steps than fixed order 5."""
    n5, _ = _steps(40, 10.0, 1e-3, max_order=5)
    n2, _ = _steps(40, 10.0, 1e-3, max_order=2)
    auto, choice = _steps(40, 10.0, 1e-3)
    assert n2 < 0.4 * n5  # the premise: order 2 is much the cheaper here
    assert choice.startswith("order 2"), choice
    assert auto < 0.5 * n5, (auto, n5, n2, choice)


def test_a_lost_race_costs_its_trial_window_only():
    """48 elements at rtol 3e-4 over 6 s: the run starts at order 2, races order 5 once (at
    about 1.6 s) and order 2 wins (over 5 s the race is left out: too few steps to go). The
    incumbent's IDA goes on from the trial's start with its history intact, so the run is
    fixed order 2's run, recorded again over the trial's span: the midspan history equals
    fixed order 2's to round-off (measured identical: the residual's buffers, its carried
    Newton start, are taken back with the incumbent; asserted below 1e-9 m, against the
    1.1 mm error both have against a tight run), and the race
    costs at most the trial's window of steps (a new IDA from the trial's end took about 400
    more on this cable: it starts at order 1 and first damps what order 5 left)."""
    from catdae.solvers.order import OrderChoice

    runs = {}
    for key, rtol, order in (("auto", 3e-4, None), ("two", 3e-4, 2), ("tight", 1e-6, 2)):
        ds = catdae.run(catdae.load_case(_moving_cable(48, 6.0, rtol, order)),
                        progress=False)["motion"].ds
        runs[key] = (ds.position.sel(node="c.24", axis="z").values, int(ds.attrs["n_steps"]),
                     str(ds.attrs["order_choice"]))
    (za, na, choice), (z2, n2, _), (zt, _, _) = runs["auto"], runs["two"], runs["tight"]
    assert "1 lost race(s) taken back" in choice, choice
    err = np.abs(z2 - zt).max()
    assert err > 1e-4  # the tolerance's own error, for scale
    assert np.abs(za - z2).max() < 1e-9, np.abs(za - z2).max()
    assert n2 < na <= n2 + OrderChoice.WINDOW, (na, n2, choice)


def test_a_lost_race_takes_the_fluids_work_back():
    """The same cable 50 m under still water (d 5 cm, Cd 1.2, Ca 1), 8 s: the race is lost at
    about 1.9 s and the incumbent goes on from the trial's start (1.4 s); the work the water
    did, accumulated step by step, is taken back to that time with it, so it equals fixed
    order 2's to round-off (without that it counted the trial's span twice: 0.58 J of 207 J;
    measured identical, the residual's carried Newton start being taken back too)."""
    runs = {}
    for order in (None, 2):
        text = _moving_cable(48, 8.0, 3e-4, order).replace(
            "weight = 100.0\n",
            "weight = 100.0\ndiameter = 0.05\ndrag_normal = 1.2\nadded_mass_normal = 1.0\n", 1)
        text += "\n[water]\ndensity = 1000.0\nsurface = 50.0\ndepth = 200.0\n"
        runs[order] = catdae.run(catdae.load_case(text), progress=False)["motion"].ds
    auto, two = runs[None], runs[2]
    assert "lost race(s) taken back" in auto.attrs["order_choice"], auto.attrs["order_choice"]
    w_auto, w_two = auto.energy_fluid_work.values, two.energy_fluid_work.values
    assert abs(w_two[-1]) > 100.0  # the water does work
    assert np.abs(w_auto - w_two).max() < 1e-6 * abs(w_two[-1])
    assert np.abs(auto.position.values - two.position.values).max() < 1e-6


@pytest.mark.parametrize("mass_model", ["consistent", "blended", "lumped", "linear"])
@pytest.mark.parametrize("damping", ["material", "rayleigh"])
def test_compiled_residual_equals_the_assembled_one(mass_model, damping):
    """The one-pass compiled residual (residual_kernel) against the residual assembled from
    its parts (element solve, element masses, ∂M/∂c, dynamic forces, nodal terms), at a random
    state away from equilibrium, with a point mass inside the cable, for every mass model and
    both kinds of damping; and the iteration matrix built from its buffers against the one
    built from a fresh element solve."""
    import dataclasses
    from pathlib import Path

    from catdae.case import load_case
    from catdae.model.assembly import Model
    from catdae.model.mesh import build_mesh
    from catdae.solvers.residual import TransientProblem

    text = (Path(catdae.__path__[0]) / "data" / "example1_free_vibration.toml").read_text()
    text = text.replace("mass = 20.3 ", "damping = 5.0\nmass = 20.3 ")
    text = text.replace("s = 22.152 ", "s = 20.0 ")  # inside an element, not on a node
    if damping == "material":
        text = text.replace('damping = { kind = "rayleigh", ratio = 0.00155, '
                            'frequencies = [1.5, 14.0] }', 'damping = { kind = "material" }')
    case = load_case(text)
    mesh = build_mesh(case)
    step = dataclasses.replace(case.steps[1], mass_model=mass_model)
    model = Model(case, mesh, set(), mass_model=mass_model)  # the point mass kept
    prob = TransientProblem(model, step, mesh.X0, None)
    assert prob.material == (damping == "material") and model.loading.mass_value.size == 1
    y0, yp0 = prob.initial(0.0, mesh.X0, np.zeros_like(mesh.X0))
    rng = np.random.default_rng(7)
    y = y0 + 1e-3 * rng.standard_normal(y0.size)
    yp = yp0 + rng.standard_normal(y0.size)
    t = 0.013
    fast = np.empty_like(y)
    assert prob.evaluate(t, y, yp, fast)
    jac_fast = [a.copy() for a in prob._jac_parts(t, y, yp, 30.0)]
    prob._buffers_at = None
    prob._cache_t = None  # the parts again, from a fresh element solve
    conf = prob.configuration(t, y[0::2])
    V, A = prob.full_vectors(t, y[1::2], yp[1::2])
    f = prob.dynamic_force(t, conf, V, A)
    ref = np.empty_like(y)
    ref[0::2] = yp[0::2] - y[1::2]
    ref[1::2] = f[prob.fidx]
    assert np.abs(fast - ref).max() <= 1e-12 * np.abs(ref).max()
    for a, b in zip(jac_fast, prob._jac_parts(t, y, yp, 30.0), strict=True):
        assert np.abs(a - b).max() <= 1e-12 * np.abs(b).max()
