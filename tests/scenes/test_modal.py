"""Mass, damping and natural frequencies from the catenary interpolation functions (issue 4).

Every assertion compares catdae with something that shares no code with it:

* Irvine & Caughey's linear theory of a shallow level cable (``tests/reference.py``) over
  lambda² = 0.1 ... 1000, the symmetric/antisymmetric crossover at 4π² included, picking the modes
  by catdae's own labels (plane, symmetry), so that the labelling is tested too;
* the convergence rate of the frequencies with the number of elements (np.polyfit of log error
  against log N), and the closed-form dispersion of linearly interpolated string elements;
* exact identities of the mass matrix: a rigid translation r gives rᵀ M r = total mass, M and K
  symmetric, M positive definite on the free dofs;
* invariance of the frequencies under renumbering of nodes, reversal of a cable and mirroring;
* the published numbers of the paper's example 1 (Chang, Park & Lee 2008, Table 2; experiment of
  Koh 2007);
* the Rayleigh damping ratio formula zeta(w) = alpha/(2 w) + beta w/2.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import brentq

import catdae
from catdae.case import Damping, Step
from catdae.element.elements import SLACK
from catdae.model.assembly import Model
from catdae.model.mesh import build_mesh
from catdae.solvers.modal import solve_modal
from catdae.solvers.static import solve_static

from reference import irvine_catenary, irvine_caughey_frequencies
from repo_paths import ROOT  # noqa: E402
from scene_toml import (
    cable,
    cable_scene,
    distributed_load,
    modal_step,
    point_mass,
    scene,
    static_step,
)

EXAMPLE1 = ROOT / "cases" / "example1_free_vibration.toml"
G = 9.81
FOUR_PI2 = 4.0 * math.pi**2


# ----------------------------------------------------------------------------------------------
# scenes
# ----------------------------------------------------------------------------------------------
def design(lambda2: float, sag_ratio: float, span: float = 100.0, m: float = 2.0) -> dict:
    """A level cable with the intended Irvine parameter lambda² and sag/span.

    From d = w l²/(8 H) and lambda² = 64 (d/l)² EA l/(H L_e): H = w l/(8 d/l),
    EA = lambda² H (1 + 8 (d/l)²)/(64 (d/l)²). catdae takes the unstrained length, so L0 is the
    root of H_irvine(L0) = H, with the independent elastic catenary of ``tests/reference.py``.
    """
    w = m * G
    H = w * span / (8.0 * sag_ratio)
    EA = lambda2 * H * (1.0 + 8.0 * sag_ratio**2) / (64.0 * sag_ratio**2)
    lo = span * (1.0 - 2.0 * H / EA)  # taut: H above the target
    hi = span * (1.0 + 3.0 * sag_ratio**2) * 1.05  # slack: H below it
    L0 = brentq(lambda L: irvine_catenary(span, 0.0, L, EA, w)["H"] - H, lo, hi,
                xtol=1e-14 * span, rtol=1e-15)
    return dict(span=span, m=m, w=w, H=H, EA=EA, L0=L0)


def level_toml(d: dict, elements: int, modes: int = 12, mass_model: str = "consistent") -> str:
    return cable_scene(B=(d["span"], 0.0, 0.0), L0=d["L0"], EA=d["EA"], mass=d["m"],
                       elements=elements, gauss_points=3, gravity=G, material="c",
                       steps=static_step() + modal_step(modes, mass_model=mass_model))


def families(ds) -> dict[str, np.ndarray]:
    """Frequencies (Hz) by catdae's labels, in ascending order within each family."""
    out: dict[str, list[float]] = {"out_of_plane": [], "antisymmetric": [], "symmetric": []}
    for f, plane, sym in zip(ds.frequency.values, ds.plane.values, ds.symmetry.values,
                             strict=True):
        if plane == "out-of-plane":
            out["out_of_plane"].append(float(f))
        else:
            out[str(sym)].append(float(f))
    return {k: np.array(v) for k, v in out.items()}


def run_modes(text: str):
    tree = catdae.run(catdae.load_case(text))
    return tree["st"].ds, tree["modes"].ds


# ----------------------------------------------------------------------------------------------
# Irvine & Caughey linear theory
# ----------------------------------------------------------------------------------------------
# (lambda², sag/span): sag/span <= 1/50 keeps the shallow theory valid; the tautest cables use a
# smaller sag ratio so that the strain H/EA stays below 0.3 % (lambda² = 64 (d/l)² EA/H).
IRVINE_CASES = [
    (0.1, 1 / 500),
    (1.0, 1 / 200),
    (0.9 * FOUR_PI2, 1 / 100),
    (FOUR_PI2, 1 / 100),
    (1.1 * FOUR_PI2, 1 / 100),
    (100.0, 1 / 50),
    (1000.0, 1 / 50),
]
IRVINE_ELEMENTS = 100


@pytest.mark.parametrize(("lambda2", "sag_ratio"), IRVINE_CASES,
                         ids=[f"lambda2={a:.4g}" for a, _ in IRVINE_CASES])
def test_irvine_caughey_frequencies(lambda2, sag_ratio):
    """First two out-of-plane, in-plane antisymmetric and in-plane symmetric frequencies within
    0.5 % of the shallow-cable theory at 100 elements (measured: within 0.14 %; the
    discretisation error at 100 elements is ~(kh)²/24 <= 0.1 % for these modes, the theory's
    own error O((d/l)²))."""
    d = design(lambda2, sag_ratio)
    st, ds = run_modes(level_toml(d, IRVINE_ELEMENTS, modes=16))
    H = float(st.horizontal_tension.sel(cable="c"))
    assert H == pytest.approx(d["H"], rel=1e-9)  # catdae's statics find the intended tension
    assert float(st.sag.sel(cable="c")) / d["span"] == pytest.approx(sag_ratio, rel=0.01)
    ref = irvine_caughey_frequencies(d["span"], H, d["m"], d["w"], d["EA"], L0=d["L0"], n=2)
    assert ref["lambda2"] == pytest.approx(lambda2, rel=0.01)
    got = families(ds)
    for key in ("out_of_plane", "antisymmetric", "symmetric"):
        assert got[key].size >= 2, f"{key}: fewer than two modes labelled so among 16"
        np.testing.assert_allclose(got[key][:2], ref[key], rtol=5e-3, err_msg=key)
    # the crossover at lambda² = 4π²: the first symmetric mode is below the first antisymmetric
    # one for lambda² < 4π² and above it for lambda² > 4π² (at 4π² they coincide in theory)
    if abs(ref["lambda2"] / FOUR_PI2 - 1.0) > 0.05:
        below = ref["symmetric"][0] < ref["antisymmetric"][0]
        assert below == (lambda2 < FOUR_PI2)
        assert (got["symmetric"][0] < got["antisymmetric"][0]) == below


def _mac(a: np.ndarray, b: np.ndarray) -> float:
    return float((a @ b) ** 2 / ((a @ a) * (b @ b)))


@pytest.mark.parametrize("lambda2", [1.0, 100.0])
def test_irvine_mode_shapes(lambda2):
    """Mode shapes against the shallow theory (Irvine 1981, ch. 3), x along the span:
    out-of-plane n: sin(nπx/l) across; in-plane antisymmetric: sin(2πx/l) vertical; in-plane
    symmetric: 1 - tan(wb/2) sin(wb x/l) - cos(wb x/l) vertical. MAC > 0.999 at 60 elements."""
    d = design(lambda2, 1 / 50 if lambda2 > 10 else 1 / 200)
    st, ds = run_modes(level_toml(d, 60, modes=10))
    names = ["A"] + [f"c.{k}" for k in range(1, 60)] + ["B"]
    xi = st.position.sel(node=names, axis="x").values / d["span"]
    shape = ds.shape.sel(node=names)
    H = float(st.horizontal_tension.sel(cable="c"))
    wb = irvine_caughey_frequencies(d["span"], H, d["m"], d["w"], d["EA"], L0=d["L0"],
                                    n=1)["wb_symmetric"][0]
    expected = {
        ("out-of-plane", "symmetric"): ("y", np.sin(np.pi * xi)),
        ("out-of-plane", "antisymmetric"): ("y", np.sin(2 * np.pi * xi)),
        ("in-plane", "antisymmetric"): ("z", np.sin(2 * np.pi * xi)),
        ("in-plane", "symmetric"): ("z", 1 - np.tan(wb / 2) * np.sin(wb * xi) - np.cos(wb * xi)),
    }
    seen = set()
    for i in range(ds.sizes["mode"]):
        key = (str(ds.plane.values[i]), str(ds.symmetry.values[i]))
        if key in expected and key not in seen:
            seen.add(key)
            axis, ref = expected[key]
            assert _mac(shape.isel(mode=i).sel(axis=axis).values, ref) > 0.999, key
            # the motion of a labelled mode lies in its plane
            other = "z" if axis == "y" else "y"
            assert np.abs(shape.isel(mode=i).sel(axis=other).values).max() < 1e-6, key
    assert seen == set(expected)


# ----------------------------------------------------------------------------------------------
# convergence with the number of elements
# ----------------------------------------------------------------------------------------------
def _frequencies(d, n, mass_model):
    _, ds = run_modes(level_toml(d, n, modes=8, mass_model=mass_model))
    return ds.frequency.values, families(ds)["symmetric"][0]


@pytest.mark.parametrize(("lambda2", "sag_ratio", "meshes"),
                         [(1.0, 1 / 200, (4, 8, 16, 32)), (100.0, 1 / 50, (8, 16, 32, 64))])
def test_convergence_order(lambda2, sag_ratio, meshes):
    """Frequencies converge at order 2 in the element size, from above with the consistent and
    the linear (straight-line) mass and from below with the lumped mass, to the same limit.

    Why 2: along the cable the interpolation functions N(s) = [I - G(s) K, G(s) K] are, to
    leading order, the linear ones [(1 - s/L0) I, (s/L0) I] (exact for statics, but a motion
    with a wavelength of a few elements is not a static deflection); for linear elements the
    Rayleigh quotient's error is O((kh)²), the consistent mass overestimating and the lumped one
    underestimating the frequency by about (kh)²/24 each (string dispersion relation). Measured
    slopes (first in-plane symmetric mode, modes 3 and 4): 1.99-2.00 at lambda² = 1 over
    N = 4..32 and 1.96-2.01 at lambda² = 100 over N = 8..64 (over N = 4..32 there they are
    1.81-1.84: with 4 elements the symmetric mode, ~3 half-waves, is not yet asymptotic); hence
    the band [1.8, 2.2]. Reference: 512 elements (its own error is (64/512)² = 1.6 % of the
    error at the finest mesh fitted, or less).
    """
    fine_c, sym_c = _frequencies(d := design(lambda2, sag_ratio), 512, "consistent")
    fine_l, sym_l = _frequencies(d, 512, "lumped")
    fine_s, sym_s = _frequencies(d, 512, "linear")
    # same limit: the mass models differ at 512 elements only by their O(h²) errors
    np.testing.assert_allclose(fine_c[:6], fine_l[:6], rtol=1e-4)
    np.testing.assert_allclose(fine_c[:6], fine_s[:6], rtol=1e-4)
    logn = np.log(meshes)
    for mass_model, fine, sym_fine, sign in (("consistent", fine_c, sym_c, 1.0),
                                            ("lumped", fine_l, sym_l, -1.0),
                                            ("linear", fine_s, sym_s, 1.0)):
        err_modes = []
        err_sym = []
        for n in meshes:
            f, sym = _frequencies(d, n, mass_model)
            err_modes.append(f[2:4] / fine[2:4] - 1.0)
            err_sym.append(sym / sym_fine - 1.0)
        errs = np.column_stack([np.array(err_sym), np.array(err_modes)])  # (n_mesh, 3)
        assert np.all(sign * errs > 0), f"{mass_model}: not converging from the expected side"
        # the straight-line mass misses the sag kinematics that the symmetric in-plane mode of
        # a λ² = 100 cable is made of: pre-asymptotic at the coarsest mesh (slopes 0.9, 1.8,
        # 2.0 from 8 to 64 elements), so its order is fitted from the second mesh on
        first = 1 if mass_model == "linear" else 0
        for j in range(errs.shape[1]):
            slope = np.polyfit(logn[first:], np.log(np.abs(errs[first:, j])), 1)[0]
            assert -2.2 < slope < -1.8, (mass_model, j, slope, errs[:, j])


# ----------------------------------------------------------------------------------------------
# the mass matrix: total mass, symmetry, definiteness
# ----------------------------------------------------------------------------------------------
MASS_SCENES = {
    # level, sagging, point masses at a node and inside elements
    "sagging": cable_scene(
        material="s", cable="main", B=(44.335, 0.0, 0.0), L0=46.0, EA=4.696e8, mass=20.3,
        elements=7,
        extra=(point_mass("at_node", 55.0, node="main.3")
               + point_mass("inside", 100.0, cable="main", s=3.1)
               + point_mass("inside2", 7.0, cable="main", s=3.9))),
    # inclined in 3-D, pushed out of its vertical plane by a lateral wind
    "inclined_3d": cable_scene(
        material="r", B=(30.0, 20.0, 15.0), L0=42.0, EA=2.0e7, mass=3.0, elements=9,
        gauss_points=4,
        extra=(distributed_load("c", [10.0, -20.0, 0.0])
               + point_mass("pm", 40.0, cable="c", s=30.7))),
    # taut: unstrained length shorter than the chord
    "taut": cable_scene(material="r", B=(10.0, 0.0, 1.0), L0=9.95, EA=1.0e6, mass=1.5,
                        elements=5, extra=point_mass("pm", 3.0, cable="c", s=4.2)),
    # weightless with a point mass: the mesh sags under it; slack elements are made below
    "weightless": cable_scene(material="r", B=(8.0, 0.0, 0.0), L0=10.0, EA=1.0e5, mass=1.0,
                              weight=0.0, elements=4,
                              extra=point_mass("pm", 20.0, cable="c", s=3.3)),
    "three_cables": (ROOT / "cases" / "three_cables_shared_node.toml").read_text(),
}


def _total_mass(case) -> float:
    """Cable mass m L0 plus every point mass, from the case data."""
    cable = sum(case.materials[c.material].mass * c.length for c in case.cables)
    return cable + sum(pm.mass for pm in case.point_masses)


def _configurations(name, case, model, rng):
    """(X, label) pairs: the static state and a perturbed, non-equilibrium one."""
    X0 = model.mesh.X0
    if name == "weightless":
        # pull the first and last inner nodes halfway to the supports: the two end elements
        # (weightless, unloaded) get chords shorter than L0 and go slack
        X = X0.copy()
        for node, end in (("c.1", "A"), ("c.3", "B")):
            i, e = model.mesh.node_index(node), model.mesh.node_index(end)
            X[i] = X0[e] + 0.5 * (X0[i] - X0[e])
        yield X0, "meshed"
        yield X, "slack elements"
        return
    sol = solve_static(model, X0, load_steps=2)
    yield sol.X, "static"
    X = sol.X + rng.normal(scale=0.02, size=sol.X.shape)
    X.reshape(-1)[model.fixed] = sol.X.reshape(-1)[model.fixed]
    yield X, "perturbed"


@pytest.mark.parametrize("mass_model", ["consistent", "lumped", "linear"])
@pytest.mark.parametrize("name", list(MASS_SCENES))
def test_mass_matrix_identities(name, mass_model):
    """rᵀ M r = total mass for a rigid translation r (Φ_i(s) + Φ_j(s) = I at every s, and the
    Gauss weights sum to one), M and K_t symmetric on the full dof set, M positive definite on the
    free dofs; the compiled mass of the dynamics (``solve_dynamic``) equals the assembled one."""
    case = catdae.load_case(MASS_SCENES[name])
    mesh = build_mesh(case)
    model = Model(case, mesh, set(), mass_model=mass_model)
    total = _total_mass(case)
    assert model.total_mass == pytest.approx(total, rel=1e-14)
    rng = np.random.default_rng(4)
    for X, label in _configurations(name, case, model, rng):
        state = model.element_state(X)
        if label == "slack elements":
            assert (state.status == SLACK).sum() >= 2
        M = model.mass(state).toarray()
        K = model.stiffness(state).toarray()
        scale = np.abs(M).max()
        np.testing.assert_allclose(M, M.T, rtol=0, atol=1e-13 * scale)
        np.testing.assert_allclose(K, K.T, rtol=0, atol=1e-12 * np.abs(K).max())
        for a in np.eye(3):
            r = np.tile(a, mesh.n_nodes)
            assert r @ M @ r == pytest.approx(total, rel=1e-12), (label, a)
        # the rigid translation along a carries no inertia in the other directions
        rx, ry = np.tile([1.0, 0, 0], mesh.n_nodes), np.tile([0, 1.0, 0], mesh.n_nodes)
        assert abs(rx @ M @ ry) < 1e-12 * total
        mf = M[np.ix_(model.free, model.free)]
        assert np.linalg.eigvalsh(mf).min() > 0.0, label
        if mass_model == "consistent":
            # the compiled mass (modal and transient paths) against docs/theory.md §7.1
            # written out here from N(s) (which test_element checks by finite differences)
            _, me, _ = model.elements.solve_dynamic(
                model.chords(X), state.h, model.gauss_s, model.gauss_w, mesh.m, None,
                (model.loading.mass_elem, model.loading.mass_s, model.loading.mass_value))
            nmat = model.elements.interpolation(state, model.gauss_s)  # (n_elem, g, 3, 6)
            wq = (mesh.m * mesh.L0)[:, None] * model.gauss_w
            ref = np.einsum("eg,egki,egkj->eij", wq, nmat, nmat)
            ld = model.loading
            for e, s_p, m_p in zip(ld.mass_elem, ld.mass_s, ld.mass_value, strict=True):
                sq = np.zeros((mesh.n_elements, 1))
                sq[e, 0] = s_p
                nk = model.elements.interpolation(state, sq)[e, 0]
                ref[e] += m_p * nk.T @ nk
            np.testing.assert_allclose(me, ref, rtol=0, atol=1e-12 * scale)
            np.testing.assert_allclose(model.element_mass(state), ref, rtol=0,
                                       atol=1e-12 * scale)


# ----------------------------------------------------------------------------------------------
# invariance: numbering, orientation, mirror
# ----------------------------------------------------------------------------------------------
def _invariance_case(order="AB", reverse=False, mirror=False):
    xs = {"A": 0.0, "B": 40.0}
    zs = {"A": 0.0, "B": 8.0}
    sign = -1.0 if mirror else 1.0
    ends = ("B", "A") if reverse else ("A", "B")
    s = 41.5 - 13.3 if reverse else 13.3  # the same material point
    return scene(materials={"r": {"EA": 2.0e7, "mass": 3.0}},
                 nodes={n: (sign * xs[n], 0.0, zs[n]) for n in order},
                 cables=[cable("c", ends, "r", 41.5, 10)],
                 extra=(point_mass("pm", 25.0, cable="c", s=s)
                        + distributed_load("c", [0.0, 15.0, 0.0])),
                 steps=static_step() + modal_step(10))


def test_frequencies_independent_of_numbering_and_mirror():
    """An inclined cable with a lateral wind and a point mass inside an element: the frequencies
    do not depend on the order of the nodes in the file, on which end the cable starts from, or
    on mirroring x -> -x (the wind along y is unchanged by that mirror)."""
    base = catdae.run(catdae.load_case(_invariance_case()))["modes"].ds
    f0 = base.frequency.values
    assert np.all(np.diff(f0) > 0)
    for kw in ({"order": "BA"}, {"reverse": True}, {"mirror": True},
               {"order": "BA", "reverse": True, "mirror": True}):
        ds = catdae.run(catdae.load_case(_invariance_case(**kw)))["modes"].ds
        np.testing.assert_allclose(ds.frequency.values, f0, rtol=1e-9, err_msg=str(kw))
        assert list(ds.plane.values) == list(base.plane.values), kw


# ----------------------------------------------------------------------------------------------
# the paper's example 1
# ----------------------------------------------------------------------------------------------
PAPER = np.array([1.51, 4.39, 7.37, 10.50])  # Chang, Park & Lee (2008), 14 elements
MEASURED = np.array([1.51, 4.41, 7.43, 10.61])  # Koh (2007)
ABAQUS = np.array([1.56, 4.30, 7.03, 9.96])  # B21H beams, from the paper


def example1_symmetric(elements: int, n: int = 4, mass_model: str = "consistent") -> np.ndarray:
    """In-plane symmetric frequencies of example 1 at rest without the hung mass (Hz)."""
    case = catdae.load_case(EXAMPLE1).with_overrides(elements=elements)
    case = dataclasses.replace(case, steps=(
        Step(kind="static", name="at_rest", remove=("hung",)),
        Step(kind="modal", name="modes", modes=24, mass_model=mass_model)))
    ds = catdae.run(case)["modes"].ds
    return families(ds)["symmetric"][:n]


def _string_dispersion(theta):
    """f_h/f of linear consistent string elements at theta = k h: sqrt(6 (1-cos)/(θ² (2+cos)))."""
    return np.sqrt(6.0 * (1.0 - np.cos(theta)) / (theta**2 * (2.0 + np.cos(theta))))


def _blended_dispersion(theta):
    """f_h/f of the blended (half consistent, half lumped) linear string elements
    (docs/theory.md §7.4): sqrt(2 (1-cos θ) / (θ² (1 - (1-cos θ)/6)))."""
    return np.sqrt(2.0 * (1.0 - np.cos(theta)) / (theta**2 * (1.0 - (1.0 - np.cos(theta)) / 6.0)))


def test_example1_table2_blended():
    """The blended mass at the paper's 14 elements, against its converged mesh (112): below it
    by the blended string dispersion (closed form, θ⁴/480 to leading order), -0.04, -0.35,
    -1.4 % for symmetric modes 2-4 (the consistent mass: +1.9, +5.2, +10.1 %); mode 1 within
    1e-5 (measured -6.6e-6, the closed form -5.3e-6: the sag adds its part there)."""
    f14 = example1_symmetric(14, mass_model="blended")
    f112 = example1_symmetric(112, mass_model="blended")
    assert f14[0] == pytest.approx(MEASURED[0], rel=0.015)
    np.testing.assert_allclose(f112, PAPER, rtol=0.03)
    n = 2 * np.arange(1, 5) - 1
    predicted = _blended_dispersion(n * np.pi / 14) / _blended_dispersion(n * np.pi / 112) - 1.0
    excess = f14 / f112 - 1.0
    np.testing.assert_allclose(excess[1:], predicted[1:], rtol=0.1)
    assert abs(excess[0]) < 1e-5
    # the consistent 112-element mesh is above the blended one by its own dispersion there
    # (order 2): the blended converges from below, the consistent from above
    f112c = example1_symmetric(112)
    assert np.all(f112c > f112)


def test_example1_table2(capsys):
    """The paper's mass (consistent, asked for explicitly: the default "auto" is blended).
    Example 1 (span 44.335 m, as in the case file): the first in-plane symmetric mode within
    1.5 % of the measured 1.51 Hz; the converged mesh (112 elements) within 3 % of the paper's
    14-element column for symmetric modes 1-4; at 14 elements catdae's consistent mass is above
    the converged mesh by the string dispersion of linear consistent elements, (kh)²/24 to
    leading order with k = (2j - 1)π/l for symmetric mode j: +0.2, +1.9, +5.2, +10.1 %
    (docs/theory.md §10 derives about +0.2, +2, +5, +10 %). The paper's 14-element column came
    from the spectrum of a time history and is closer to the converged mesh than that."""
    f14 = example1_symmetric(14)
    f112 = example1_symmetric(112)
    with capsys.disabled():
        print("\nexample 1, in-plane symmetric modes (Hz), span 44.335 m")
        print(" mode  catdae-14  catdae-112  paper-14  experiment  ABAQUS")
        for j in range(4):
            print(f" {j + 1:4d}  {f14[j]:9.3f}  {f112[j]:10.3f}  {PAPER[j]:8.2f}  "
                  f"{MEASURED[j]:10.2f}  {ABAQUS[j]:6.2f}")
    assert f14[0] == pytest.approx(MEASURED[0], rel=0.015)
    np.testing.assert_allclose(f112, PAPER, rtol=0.03)
    np.testing.assert_allclose(f112, MEASURED, rtol=0.04)
    n = 2 * np.arange(1, 5) - 1  # half-waves of symmetric modes 1-4 of a taut cable
    predicted = _string_dispersion(n * np.pi / 14) / _string_dispersion(n * np.pi / 112) - 1.0
    excess = f14 / f112 - 1.0
    np.testing.assert_allclose(excess, predicted, rtol=0.1)
    # and so within a few % of the paper's 14-element column (mode 4: +7.6 %)
    assert np.all(np.abs(f14 / PAPER - 1.0) < predicted + 0.03), f14 / PAPER - 1.0


# ----------------------------------------------------------------------------------------------
# damping
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("ratio", "f1", "f2"), [(0.00155, 1.5, 14.0), (0.05, 0.2, 3.0),
                                                 (0.02, 10.0, 10.5)])
def test_rayleigh_ratio_at_both_frequencies(ratio, f1, f2):
    """zeta(w) = alpha/(2 w) + beta w/2 equals the requested ratio at both frequencies and is
    below it between them (the Rayleigh curve is convex with its minimum inside)."""
    alpha, beta = Damping("rayleigh", ratio=ratio, frequencies=(f1, f2)).coefficients()
    w1, w2 = 2 * math.pi * f1, 2 * math.pi * f2

    def zeta(w):
        return alpha / (2 * w) + beta * w / 2

    assert zeta(w1) == pytest.approx(ratio, rel=1e-13)
    assert zeta(w2) == pytest.approx(ratio, rel=1e-13)
    wm = math.sqrt(w1 * w2)
    assert zeta(wm) < ratio
    assert Damping("rayleigh", alpha=0.3, beta=1e-4).coefficients() == (0.3, 1e-4)


def test_modal_damping_ratio_of_a_model():
    """With C = alpha M + beta K_t on example 1, the modal ratio of the modes at the two chosen
    frequencies is the requested one (phi_i^T C phi_i / (2 w_i phi_i^T M phi_i))."""
    case = catdae.load_case(EXAMPLE1)
    mesh = build_mesh(case)
    model = Model(case, mesh, {"hung"})
    sol = solve_static(model, mesh.X0)
    state = model.element_state(sol.X, sol.state.h)
    modes = solve_modal(model, sol.X, state, 6)
    f = modes.frequency
    damp = Damping("rayleigh", ratio=0.00155, frequencies=(float(f[0]), float(f[4])))
    alpha, beta = damp.coefficients()
    free = model.free
    M = model.mass(state)[free][:, free].toarray()
    K = model.stiffness(state)[free][:, free].toarray()
    C = alpha * M + beta * K
    for i in (0, 4):
        phi = modes.shape[i].reshape(-1)[free]
        w = 2 * math.pi * f[i]
        assert phi @ C @ phi / (2 * w * (phi @ M @ phi)) == pytest.approx(0.00155, rel=1e-8)


# ----------------------------------------------------------------------------------------------
# the eigensolvers
# ----------------------------------------------------------------------------------------------
def test_massless_cable_with_a_point_mass():
    """A cable of zero mass carrying a 3 kg mass at a node: M is singular on the free dofs and
    the model has exactly three finite frequencies, those of the mass on the statically condensed
    stiffness of the cable, ω² = eig(K_mm - K_ms K_ss⁻¹ K_sm)/m."""
    text = MASS_SCENES["taut"].replace("mass = 1.5", "mass = 0.0\nweight = 10.0")
    text = text.replace('cable = "c"\ns = 4.2', 'node = "c.2"')
    case = catdae.load_case(text)
    mesh = build_mesh(case)
    model = Model(case, mesh, set())
    sol = solve_static(model, mesh.X0)
    modes = solve_modal(model, sol.X, sol.state, 6)
    assert modes.frequency.size == 3
    K = model.stiffness(sol.state).toarray()[np.ix_(model.free, model.free)]
    at = np.isin(model.free, 3 * mesh.node_index("c.2") + np.arange(3))
    kc = K[np.ix_(at, at)] - K[np.ix_(at, ~at)] @ np.linalg.solve(K[np.ix_(~at, ~at)],
                                                                  K[np.ix_(~at, at)])
    expected = np.sqrt(np.linalg.eigvalsh(kc) / 3.0) / (2 * math.pi)
    np.testing.assert_allclose(modes.frequency, expected, rtol=1e-9)


def test_dense_and_sparse_solvers_agree():
    """603 free dofs: the first modes from sparse shift-invert Lanczos equal those of the dense
    solver, which is also used when every mode is asked for (ARPACK needs k < n - 1)."""
    case = catdae.load_case(EXAMPLE1).with_overrides(elements=202)
    mesh = build_mesh(case)
    model = Model(case, mesh, {"hung"})
    sol = solve_static(model, mesh.X0)
    sparse = solve_modal(model, sol.X, sol.state, 6)
    full = solve_modal(model, sol.X, sol.state, 10_000)
    assert sparse.solver == "sparse shift-invert" and full.solver == "dense"
    assert full.frequency.size == model.free.size == 603
    assert np.all(np.diff(full.frequency) >= 0)
    np.testing.assert_allclose(sparse.frequency, full.frequency[:6], rtol=1e-9)


WARM_STRING = """
title = "a weightless string, cooled or loaded at its modal step"
reference_temperature = 20.0
[materials.w]
EA = 1.0e6
mass = 1.0
weight = 0.0
thermal_expansion = 1.2e-5
[nodes]
A = [0.0, 0.0, 0.0]
B = [20.0, 0.0, 0.0]
[supports]
A = "pinned"
B = "pinned"
[[cables]]
name = "c"
ends = ["A", "B"]
material = "w"
length = 19.99
elements = 8
[[loads]]
name = "P"
node = "c.4"
force = [0.0, 0.0, -500.0]
active = false
[[steps]]
kind = "static"
name = "s0"
"""


def test_a_modal_step_that_changes_the_scene_finds_its_equilibrium_first():
    """A modal step's own temperature_change, add and load_factor sweep change the static
    state; its modes are about the new equilibrium (an independent tester found them about
    the old state, 10 % off, and the added load ignored). Cooled by 50 K the string's tension
    is EA (span - L) / L with L = L0 (1 + α ΔT): f1 = sqrt(T / μ) / (2 span), μ = m L0 / span;
    the loaded string is checked against the same load added in a static step before."""
    text = WARM_STRING + (
        '[[steps]]\nkind = "modal"\nname = "cold"\nmodes = 2\ntemperature_change = -50.0\n'
        '[[steps]]\nkind = "static"\nname = "back"\ntemperature_change = 0.0\n'
        '[[steps]]\nkind = "modal"\nname = "loaded"\nmodes = 2\nadd = ["P"]\n'
        '[[steps]]\nkind = "modal"\nname = "factor"\nmodes = 2\n'
        'sweep = { field = "load_factor", values = [0.0, 1.0] }\n'
        '[[steps]]\nkind = "static"\nname = "held"\n'
        '[[steps]]\nkind = "modal"\nname = "after"\nmodes = 2\n')
    tree = catdae.run(catdae.load_case(text))
    L = 19.99 * (1 - 1.2e-5 * 50.0)
    T = 1.0e6 * (20.0 - L) / L
    f1 = math.sqrt(T / (1.0 * 19.99 / 20.0)) / 40.0
    cold = tree["cold"].ds
    assert float(cold.frequency[0]) == pytest.approx(f1, rel=1e-3)
    assert "found again" in cold.attrs["equilibrium"]
    after = float(tree["after"].ds.frequency[0])  # the load added, then a static step
    assert float(tree["loaded"].ds.frequency[0]) == pytest.approx(after, rel=1e-9)
    factor = tree["factor"].ds.frequency.sel(mode=1).values
    assert factor[1] == pytest.approx(after, rel=1e-9)
    T0 = 1.0e6 * (20.0 - 19.99) / 19.99  # no load: the warm string
    assert factor[0] == pytest.approx(math.sqrt(T0 / (19.99 / 20.0)) / 40.0, rel=1e-3)
    assert factor[1] > 1.5 * factor[0]


def test_a_modal_step_after_a_transient_says_its_state_is_not_an_equilibrium():
    """Straight after a transient the modal step linearises the moving state the transient
    ended in (a tester found modes 4 % off the equilibrium's with no word of it): its note
    names the largest node speed, which is the transient's last velocity; after a static step
    there is no such note, and the string's first mode is its closed form sqrt(T/μ)/(2 span)."""
    text = WARM_STRING.replace("active = false", "active = true") + (
        '[[steps]]\nkind = "transient"\nname = "swing"\nremove = ["P"]\nduration = 0.3\n'
        'output_interval = 0.1\n'
        '[[steps]]\nkind = "modal"\nname = "moving"\nmodes = 1\n'
        '[[steps]]\nkind = "static"\nname = "rest"\n'
        '[[steps]]\nkind = "modal"\nname = "still"\nmodes = 1\n')
    tree = catdae.run(catdae.load_case(text))
    swing, moving, still = (tree[k].ds for k in ("swing", "moving", "still"))
    v_end = float(np.sqrt((swing.velocity.isel(time=-1) ** 2).sum("axis")).max())
    assert v_end > 1e-2  # the string is still vibrating
    note = moving.attrs["note"]
    assert "not an equilibrium" in note and f"{v_end:.3g} m/s" in note
    assert moving.attrs["equilibrium"] == note
    assert "note" not in still.attrs and "equilibrium" not in still.attrs
    T0 = 1.0e6 * (20.0 - 19.99) / 19.99
    assert float(still.frequency[0]) == pytest.approx(math.sqrt(T0 / (19.99 / 20.0)) / 40.0,
                                                      rel=1e-3)


def mass_off_midspan(a: float) -> str:
    """A taut 20 m string (40 elements) with a 5 kg mass at arc length ``a``: its modes."""
    return cable_scene(B=(20.0, 0.0, 0.0), L0=19.99, EA=1.0e7, mass=1.0, weight=0.5,
                       elements=40, material="w", extra=point_mass("m", 5.0, cable="c", s=a),
                       steps=static_step("s0") + modal_step(8, mass_model="consistent"))


@pytest.mark.parametrize("a", [6.0, 10.0])
def test_symmetry_labels_of_a_string_with_a_mass_off_midspan_follow_the_closed_form(a):
    """Out-of-plane modes of a taut string (tension H, μ per metre) with a mass M at x = a:
    k H (cot ka + cot k(L - a)) = M ω², shape sin kx / sin ka, then sin k(L - x) / sin k(L - a).
    A tester found a mass at 30 % of the span labelled "symmetric" at 82 % symmetry. The share
    of each mode's squares in its mirror-symmetric part, from the closed form, says "symmetric"
    or "antisymmetric" at 90 % or more, else "mixed"; with the mass at midspan no mode mixes."""
    tree = catdae.run(catdae.load_case(mass_off_midspan(a)))
    ds = tree["modes"].ds
    H = float(tree["s0"].ds.horizontal_tension[0])
    L, M = 20.0, 5.0
    mu = 19.99 / L  # kg per metre of span
    c = math.sqrt(H / mu)

    def g(k):
        return k * H * (1 / math.tan(k * a) + 1 / math.tan(k * (L - a))) - M * (c * k) ** 2

    ks = np.linspace(1e-3, 3 * math.pi / L * 1.4, 4000)
    vals = [g(k) for k in ks]
    roots = [brentq(g, ks[i], ks[i + 1]) for i in range(len(ks) - 1)
             if np.isfinite(vals[i]) and np.isfinite(vals[i + 1]) and vals[i] * vals[i + 1] < 0
             and abs(vals[i] - vals[i + 1]) < 1e3 * H / L]
    out = ds.plane.values == "out-of-plane"
    f_cat, labels = ds.frequency.values[out], ds.symmetry.values[out]
    x = np.linspace(0.0, L, 2001)
    checked = 0
    for k in roots[:3]:
        u = np.where(x <= a, np.sin(k * x) / np.sin(k * a),
                     np.sin(k * (L - x)) / np.sin(k * (L - a)))
        sym, anti = np.sum((u + u[::-1]) ** 2), np.sum((u - u[::-1]) ** 2)
        share = max(sym, anti) / (sym + anti)
        expected = ("mixed" if share < 0.9 else "symmetric" if sym > anti else "antisymmetric")
        if abs(share - 0.9) < 0.02:
            continue  # too close to the line to ask the discrete shape for the same side
        j = int(np.argmin(abs(f_cat - c * k / (2 * math.pi))))
        assert f_cat[j] == pytest.approx(c * k / (2 * math.pi), rel=5e-3)
        assert labels[j] == expected
        checked += 1
    assert checked >= 2
    if a == 10.0:
        assert "mixed" not in set(ds.symmetry.values)
    else:
        assert "mixed" in set(labels)


def test_an_inclined_stays_in_plane_modes_are_labelled_by_its_chord():
    """A taut stay at 30° (200 m of chord, 4 MN, 80 kg/m, EA 80 MN: λ² about 0.02, a string whose
    tension varies by 2 % along it): in the plane
    its mode n has n half-waves across the chord, symmetric about the chord's middle for odd n
    and antisymmetric for even n, at n times the first frequency (the string's sqrt(T/m) n/(2l),
    m per stretched metre).
    Mirrored in the chord's frame the shapes are clean; mirrored in the level frame (the along-
    span component's sign flipped, the vertical kept) they read "mixed" (an independent
    tester's stays)."""
    l, theta, T, m = 200.0, math.radians(30.0), 4.0e6, 80.0
    B = (l * math.cos(theta), 0.0, l * math.sin(theta))
    text = cable_scene(B=B, L0=l / (1 + T / 8.0e7), EA=8.0e7, mass=m, elements=40,
                       steps=static_step() + modal_step(8, mass_model="consistent"))
    ds = catdae.run(catdae.load_case(text))["modes"].ds
    labels = zip(ds.frequency.values, ds.plane.values, ds.symmetry.values, strict=True)
    inplane = [(float(f), str(s)) for f, p, s in labels if p == "in-plane"]
    assert len(inplane) >= 3, inplane
    f1 = math.sqrt(T * (1 + T / 8.0e7) / m) / (2 * l)
    for n, (f, sym) in enumerate(inplane, start=1):
        assert abs(f / (n * f1) - 1) < 0.005, (n, f, n * f1)
        assert sym == ("symmetric" if n % 2 else "antisymmetric"), (n, inplane)


def test_more_modes_than_the_model_has_are_all_given_and_said():
    """A cable of 3 elements between two supports has 2 free nodes, 6 degrees of freedom and so
    6 modes: asked for 40 it gives those 6, and its note says so (it said nothing: an
    independent tester took 10 of 40 for a truncation)."""
    text = cable_scene(B=(10.0, 0.0, 0.0), L0=10.05, EA=1.0e6, mass=1.0, elements=3,
                       steps=static_step() + modal_step(40))
    ds = catdae.run(catdae.load_case(text))["modes"].ds
    assert ds.mode.size == 6
    assert "40 modes were asked for and the model has 6" in ds.attrs["note"]


def test_labels_follow_the_plane_of_a_cable_swung_by_wind():
    """A conductor blown 50° aside hangs in a plane tilted by atan(p / w) from the vertical:
    its pendulum swing (the lowest mode) moves normal to that plane and was labelled
    "in-plane" (the labels took the vertical plane through the chord). Each mode's share of
    motion normal to the closed-form plane decides its label here."""
    w, p = 9.81 * 1.6, 9.81 * 1.6 * math.tan(math.radians(50.0))  # N/m weight, wind across
    text = cable_scene(B=(300.0, 0.0, 0.0), L0=303.0, EA=2e7, mass=1.6, elements=20,
                       gravity=9.81, extra=distributed_load("c", [0.0, p, 0.0]),
                       steps=static_step("st") + modal_step(6))
    tree = catdae.run(catdae.load_case(text))
    swing = float(tree["st"].ds.swing_angle.values[0])
    assert swing == pytest.approx(50.0, abs=1e-3)  # the plane the closed form tilts (O(h²))
    theta = math.atan2(p, w)
    normal = np.array([0.0, math.cos(theta), math.sin(theta)])  # normal to the swung plane
    modes = tree["modes"].ds
    for k in range(modes.sizes["mode"]):
        u = modes.shape.values[k]
        share = float(np.sum((u @ normal) ** 2) / np.sum(u * u))
        label = str(modes.plane.values[k])
        assert label == ("out-of-plane" if share > 0.5 else "in-plane"), (k, share, label)
        assert min(share, 1 - share) < 0.01  # each mode is clearly one or the other
    assert str(modes.plane.values[0]) == "out-of-plane"  # the swing


def test_a_cable_whose_ends_met_has_no_plane_and_its_modes_are_unclassified():
    """A support motion drove B onto A (tester t75): the modal step after divided by the zero
    chord and failed as an "internal error". A loop has no chord, so no plane of its own: its
    modes are unclassified, as a straight vertical cable's are; a sagging span keeps its
    vertical plane."""
    from catdae.solvers.modal import _cable_plane

    s = np.linspace(0.0, 2.0 * np.pi, 9)
    loop = np.stack([np.sin(s), np.zeros_like(s), np.cos(s) - 1.0], axis=1)
    loop[-1] = loop[0]
    assert _cable_plane(loop) is None
    span = np.stack([10.0 * s, np.zeros_like(s), 0.1 * s * (s - s[-1])], axis=1)
    along, in_plane, normal = _cable_plane(span)
    np.testing.assert_allclose(np.abs(normal), [0.0, 1.0, 0.0], atol=1e-12)
