"""Connectors (``catdae.model.connectors``, issue 22): their forces against finite differences
of themselves and of their energy, the transient iteration matrix of a scene with springs,
dampers and bars against finite differences of its residual, and bad input refused with a
located message and exit 2."""

from __future__ import annotations

import numpy as np
import pytest

from catdae.case import case_from_dict
from catdae.model.connectors import Connectors

from scene_toml import bar, cable, cable_scene, damper, point_mass, scene, spring, static_step, step


def _toml(text):
    import tomllib

    return case_from_dict(tomllib.loads(text))


def some_connectors() -> Connectors:
    """A spring, a damper and a bar with mass among 4 nodes (ρ: the consistent correction)."""
    return Connectors(("s", "d", "b"), ("spring", "damper", "bar"),
                      np.array([[0, 1], [2, 1], [3, 0]]), np.array([3e3, 0.0, 2e5]),
                      np.array([1.3, 0.0, 2.0]), np.array([0.0, 50.0, 0.0]),
                      np.array([0.0, 0.0, 4.0]))


def assembled(cn: Connectors, blocks: np.ndarray, n_dof: int) -> np.ndarray:
    out = np.zeros((n_dof, n_dof))
    for e in range(cn.n):
        out[np.ix_(cn.edofs[e], cn.edofs[e])] += blocks[e]
    return out


def test_connector_blocks_are_the_derivatives_of_their_forces():
    """∂f/∂x (with the damper's geometric term at a nonzero velocity), ∂f/∂v and ∂f/∂a against
    central differences; the elastic forces are the gradient of the strain energy."""
    rng = np.random.default_rng(1)
    cn = some_connectors()
    X, V, A = (rng.normal(size=(4, 3)) for _ in range(3))
    h = 1e-6

    def fd(which, h=h):
        out = np.zeros((12, 12))
        for j in range(12):
            d = np.zeros(12)
            d[j] = h
            args = [X.ravel(), V.ravel(), A.ravel()]
            plus = list(args)
            minus = list(args)
            plus[which] = args[which] + d
            minus[which] = args[which] - d
            out[:, j] = (cn.force(*(a.reshape(-1, 3) for a in plus))
                         - cn.force(*(a.reshape(-1, 3) for a in minus))) / (2 * h)
        return out

    K = assembled(cn, cn.stiffness_blocks(X, V), 12)
    C = assembled(cn, cn.damping_blocks(X), 12)
    M = assembled(cn, cn.mass_blocks(), 12)
    assert np.abs(K - fd(0)).max() <= 1e-8 * np.abs(K).max()
    assert np.abs(C - fd(1)).max() <= 1e-8 * np.abs(C).max()
    # linear in the accelerations: a unit step is exact (forces ~1e5 N would drown a small one)
    assert np.abs(M - fd(2, 1.0)).max() <= 1e-9 * np.abs(M).max()
    grad = np.array([(cn.strain_energy(X + h * e.reshape(4, 3))
                      - cn.strain_energy(X - h * e.reshape(4, 3))) / (2 * h)
                     for e in np.eye(12)])
    assert np.abs(grad - cn.force(X)).max() <= 1e-8 * np.abs(grad).max()
    # a rigid rotation leaves the axial forces unchanged (large rotations exact)
    c, s = np.cos(0.7), np.sin(0.7)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    assert np.allclose(cn.axial_force(X @ R.T, V @ R.T), cn.axial_force(X, V), rtol=1e-13)


NETWORK = (spring("k1", ["c.1", "G"], 3.0e3, length=2.5) + damper("d1", ["c.2", "G"], 400.0)
           + bar("hanger", ["c.3", "H"], 1.0e6, mass=3.0) + point_mass("pm", 5.0, node="H"))


def network(mass_model: str) -> str:
    """A cable with a spring and a damper to the ground G and a bar hanging a mass H."""
    return cable_scene(B=(10.0, 0.0, 0.0), L0=10.3, EA=1e5, mass=1.0, elements=4,
                       nodes={"G": (5.0, 2.0, -1.0), "H": (7.5, 0.5, -4.0)},
                       supports=("G", "A", "B"), extra=NETWORK,
                       steps=step("transient", "dyn", duration=0.1, output_interval=0.05,
                                  rtol=1e-6, atol=1e-8, mass_model=mass_model))


@pytest.mark.parametrize("mass_model", ["lumped", "linear"])
def test_transient_iteration_matrix_is_the_derivative_of_the_residual(mass_model):
    """With a constant element mass (lumped, linear) the analytic iteration matrix
    J = ∂r/∂y + c_j ∂r/∂y' is exact, connectors included (the linear model gives the bar its
    consistent mass): it equals central differences of the residual at a moving state."""
    from catdae.model.assembly import Model
    from catdae.model.mesh import build_mesh
    from catdae.solvers.residual import TransientProblem

    case = _toml(network(mass_model))
    mesh = build_mesh(case)
    model = Model(case, mesh, set(), mass_model=mass_model, kind="transient")
    assert model.connectors is not None and model.connectors.n == 3
    prob = TransientProblem(model, case.steps[0], mesh.X0, None)
    rng = np.random.default_rng(3)
    n = prob.n
    y = np.empty(2 * n)
    yp = np.empty(2 * n)
    y[0::2] = mesh.X0.reshape(-1)[prob.fidx] + 0.05 * rng.normal(size=n)
    y[1::2] = rng.normal(size=n)
    yp[:] = rng.normal(size=2 * n)
    cj = 37.0
    J = np.zeros((2 * n, 2 * n))

    def residual(yy, yyp):
        r = np.empty(2 * n)
        assert prob.evaluate(0.0, yy, yyp, r)
        return r

    residual(y, yp)
    prob.jac_dense(0.0, y, yp, None, cj, J)
    h = 1e-6
    fd = np.zeros_like(J)
    for j in range(2 * n):
        d = np.zeros(2 * n)
        d[j] = h
        fd[:, j] = (residual(y + d, yp + cj * d) - residual(y - d, yp - cj * d)) / (2 * h)
    # the spring alone (3e3 N/m) is 7 % of the largest entry: a missing block would show
    assert np.abs(J - fd).max() <= 1e-7 * np.abs(J).max()


def test_connectors_off_leave_the_model_as_it_was():
    """A scene without connectors: no connector object, the pattern of the elements alone."""
    from catdae.model.assembly import Model
    from catdae.model.mesh import build_mesh

    case = _toml(cable_scene(B=(10.0, 0.0, 0.0), L0=10.3, EA=1e5, mass=1.0, elements=4,
                             steps=static_step("st")))
    model = Model(case, build_mesh(case), set())
    assert model.connectors is None
    assert model.pattern.nnz == 3 * 3 * (3 * 5 - 2) + 0  # 5 nodes in a chain: 13 3x3 blocks


# ------------------------------------------------------------------------------------------------
# bad input: a located message and exit 2
# ------------------------------------------------------------------------------------------------
def bad(extra: str) -> str:
    """The network's cable with a ground node G, a second ground G2 at the same place."""
    return cable_scene(B=(10.0, 0.0, 0.0), L0=10.3, EA=1e5, mass=1.0, elements=4,
                       nodes={"G": (5.0, 2.0, -1.0), "G2": (5.0, 2.0, -1.0)},
                       supports=("G", "G2", "A", "B"), extra=extra, steps=static_step("st"))


@pytest.mark.parametrize(("extra", "field", "words"), [
    (spring("k", ["c.2", "nowhere"], 1.0), "springs[0].ends[1]", "unknown node 'nowhere'"),
    (spring("k", ["c.2", "c.9"], 1.0), "springs[0].ends[1]", "mesh node 'c.9' does not exist"),
    (damper("d", ["c.2", "G"], -5.0),
     "dampers[0].coefficient", "expected a value >= 0.0, found the number -5.0"),
    (bar("b", ["c.2", "G"], 1.0e6, length=0.0),
     "bars[0].length", "expected a value > 0.0, found the number 0.0"),
    (bar("b", ["G", "G2"], 1.0e6),
     "bars[0].ends", "a bar of zero length: nodes 'G' and 'G2' coincide"),
    (damper("d", ["c.1", "c.1"], 5.0),
     "dampers[0].ends", "the two ends are the same node 'c.1'"),
])
def test_bad_connectors_get_a_located_message_and_exit_2(extra, field, words, tmp_path, capsys):
    from catdae.cli import main

    f = tmp_path / "bad.toml"
    f.write_text(bad(extra))
    for args in (["check", str(f)], ["run", str(f), "-o", str(tmp_path / "o.nc")]):
        assert main(args) == 2
        err = capsys.readouterr().err
        assert f"{f}: {field}: {words}" in err, err
    assert not (tmp_path / "o.nc").exists()


def test_a_node_held_by_a_damper_alone_is_refused_before_any_work(tmp_path, capsys):
    """A tester's free node F joined to the cable by a damper only: the static step
    "converged" and the modal step failed with "not stable", naming nothing. It has no
    stiffness, so no equilibrium: refused at check (exit 2) naming the damper and the node;
    a spring beside the damper makes the scene valid."""
    from catdae.cli import main

    def scene(extra):
        return cable_scene(B=(10.0, 0.0, 0.0), L0=10.3, EA=1e5, mass=1.0, elements=4,
                           nodes={"F": (5.0, 2.0, -1.0)}, extra=extra,
                           steps=static_step("st"))

    f = tmp_path / "loose.toml"
    f.write_text(scene(damper("d", ["c.2", "F"], 5.0)))
    assert main(["check", str(f)]) == 2
    err = capsys.readouterr().err
    assert f"{f}: dampers[0].ends: node 'F' is held by the damper alone" in err
    f.write_text(scene(damper("d", ["c.2", "F"], 5.0) + spring("k", ["c.2", "F"], 100.0)))
    assert main(["check", str(f)]) == 0


def test_a_massless_node_on_one_spring_is_named_by_the_modal_step(tmp_path, capsys):
    """A massless free node F hung from the cable by one spring at zero force has stiffness
    along the spring only; the modal step said "the static state is not stable", naming
    nothing (tester t68). It names F; three springs along x, y and z hold it in every
    direction, and it is condensed out (massless, infinitely stiff in frequency)."""
    from catdae.cli import main

    def scene(extra):
        return cable_scene(B=(10.0, 0.0, 0.0), L0=10.3, EA=1e5, mass=1.0, elements=4,
                           nodes={"F": (5.0, 2.0, -1.0), "G1": (6.0, 2.0, -1.0),
                                  "G2": (5.0, 3.0, -1.0), "G3": (5.0, 2.0, -2.0)},
                           supports=("A", "B", "G1", "G2", "G3"), extra=extra,
                           steps=static_step("st") + step("modal", "m", modes=3))

    f = tmp_path / "one_way.toml"
    f.write_text(scene(spring("k", ["c.2", "F"], 100.0)))
    assert main(["run", str(f), "-o", str(tmp_path / "o.nc")]) == 1
    err = capsys.readouterr().err
    assert "free node(s) F have no mass and no stiffness in some direction" in err, err
    f.write_text(scene("".join(spring(f"k{i}", [g, "F"], 100.0)
                               for i, g in enumerate(("G1", "G2", "G3")))))
    assert main(["run", str(f), "-o", str(tmp_path / "o2.nc")]) == 0


def test_a_part_no_support_holds_is_refused_before_any_work(tmp_path, capsys):
    """A tester's second cable C-D touching nothing: check said valid, the static step ran
    200 Newton iterations ("ramped up to 0 %") and the modal step said "not stable", naming
    nothing. A part of the scene with no support has no equilibrium (a rigid drift at least):
    refused at check (exit 2) naming its cables; held through a spring, or only in a
    transient (a part let fall on purpose), it is valid."""
    from catdae.cli import main

    def floating(extra="", steps=None):
        return scene(materials={"m": {"EA": 1e6, "mass": 1.0}},
                     nodes={"A": (0, 0, 0), "B": (10, 0, 0), "C": (0, 5, 0), "D": (10, 5, 0)},
                     cables=cable("c", ("A", "B"), length=10.2, elements=2)
                     + cable("f", ("C", "D"), length=10.2, elements=2)
                     + cable("g", ("D", "C"), length=10.4, elements=2),
                     extra=extra, steps=steps or static_step("st"))

    f = tmp_path / "floating.toml"
    f.write_text(floating())
    for args in (["check", str(f)], ["run", str(f), "-o", str(tmp_path / "o.nc")]):
        assert main(args) == 2
        err = capsys.readouterr().err
        assert f"{f}: cables[1]: cables 'f', 'g': no support holds them" in err, err
    f.write_text(floating(spring("k", ["c.1", "f.1"], 1e3)))
    assert main(["check", str(f)]) == 0
    f.write_text(floating(steps=step("transient", "fall", duration=0.1, output_interval=0.1)))
    assert main(["check", str(f)]) == 0


def test_more_elements_keep_a_connector_on_its_mesh_node(tmp_path):
    """``elements`` overrides move an end on mesh node c.k to the same place of the new mesh,
    and refuse a count that puts it between mesh nodes."""
    from catdae.errors import CaseError

    case = _toml(network("lumped"))
    finer = case.with_overrides(elements=8)
    assert [d.ends for d in finer.dampers] == [("c.4", "G")]
    assert [b.ends for b in finer.bars] == [("c.6", "H")]
    with pytest.raises(CaseError, match="use a multiple of 4 elements"):
        case.with_overrides(elements=6)  # c.3 of 4
    midspan = _toml(bad(spring("k", ["c.2", "G"], 1.0)))  # c.2 of 4: any even count
    assert [k.ends for k in midspan.with_overrides(elements=6).springs] == [("c.3", "G")]
    with pytest.raises(CaseError, match="use a multiple of 2 elements"):
        midspan.with_overrides(elements=3)


def test_catdae_check_takes_elements_as_run_does(tmp_path, capsys):
    """``catdae check --elements N`` judges the case meshed as ``catdae run --elements N``
    would (a tester found no way to check a mesh before running it): a spring on c.2 of 4
    elements needs an even count."""
    from catdae.cli import main

    f = tmp_path / "midspan.toml"
    f.write_text(bad(spring("k", ["c.2", "G"], 1.0)))
    assert main(["check", str(f), "--elements", "6"]) == 0
    assert "6 elements" in capsys.readouterr().out
    assert main(["check", str(f), "--elements", "3"]) == 2
    assert "use a multiple of 2 elements" in capsys.readouterr().err


def test_a_misspelt_connector_end_is_the_only_message(tmp_path, capsys):
    """The node the spring was meant to hold (with a point mass on it) is not reported as held
    by nothing: those would follow from the misspelling, which is reported with its fix."""
    from catdae.cli import main

    f = tmp_path / "bad.toml"
    f.write_text(cable_scene(B=(10.0, 0.0, 0.0), L0=10.3, EA=1e5, mass=1.0, elements=4,
                             nodes={"m": (5.0, 0.0, -2.0)}, supports=("A", "B"),
                             extra=spring("k", ["c.2", "mm"], 1.0e3)
                             + point_mass("bob", 10.0, node="m"), steps=static_step("st")))
    assert main(["check", str(f)]) == 2
    err = capsys.readouterr().err
    assert f"{f}: springs[0].ends[1]: unknown node 'mm'; did you mean 'm'?" in err, err
    assert "nothing" not in err, err


def test_a_cable_ending_at_another_cables_mesh_node_is_told_how_to_join_them(tmp_path, capsys):
    """A hanger ending at 'c.2' was told "unknown node 'c.2'; expected one of: 'A', 'B', 'C'"
    (tester t64), though 'c.2' is a real node of the mesh: it is told that cables end at
    [nodes] and that springs and bars may join mesh nodes."""
    from catdae.cli import main

    f = tmp_path / "hanger.toml"
    f.write_text(scene(materials={"m": {"EA": 1e6, "mass": 1.0}},
                       nodes={"A": (0, 0, 0), "B": (10, 0, 0), "C": (5, 0, -5)},
                       supports=("A", "B", "C"),
                       cables=cable("c", ("A", "B"), length=10.2, elements=4)
                       + cable("h", ("c.2", "C"), length=4.0, elements=2),
                       steps=static_step("st")))
    assert main(["check", str(f)]) == 2
    err = capsys.readouterr().err
    assert (f"{f}: cables[1].ends[0]: 'c.2' is a mesh node of cable 'c': a cable ends at a "
            "node of [nodes]") in err, err
