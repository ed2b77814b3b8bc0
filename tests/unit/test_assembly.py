"""DOF pattern and assembly (``catdae.model.assembly``): Pattern, and the Model of a step.

The sparse scatter is compared with a dense assembly written out here (a loop over elements and
their 6 x 6 blocks), the assembled tangent stiffness with finite differences of the assembled
internal forces, and the reactions with the equilibrium of the whole cable (forces, and moments
where every force acts at a node).
"""

from __future__ import annotations

import numpy as np
import pytest

import catdae
from catdae.model.assembly import Model, Pattern
from catdae.model.mesh import build_mesh
from catdae.solvers.static import solve_static

from scene_toml import cable_scene, load, point_mass, static_step

G = 9.81


def dense_assembly(edofs, n, blocks=None, diag=None):
    """Σ over elements of blocks[e] at (edofs[e], edofs[e]), entries with -1 dropped, + diag."""
    out = np.zeros((n, n))
    if blocks is not None:
        for e, dofs in enumerate(edofs):
            for a, r in enumerate(dofs):
                for b, c in enumerate(dofs):
                    if r >= 0 and c >= 0:
                        out[r, c] += blocks[e, a, b]
    if diag is not None:
        out += np.diag(diag)
    return out


def test_pattern_scatter_equals_a_dense_assembly():
    rng = np.random.default_rng(5)
    n = 14
    edofs = rng.integers(-1, n, size=(9, 6))  # random dofs, some dropped (-1), some repeated
    blocks = rng.normal(size=(9, 6, 6))
    diag = rng.normal(size=n)
    pat = Pattern(edofs, n)
    for b, d, scale in ((blocks, None, 1.0), (None, diag, 1.0), (blocks, diag, -2.5)):
        got = pat.matrix(pat.assemble(b, d, scale=scale)).toarray()
        np.testing.assert_allclose(got, scale * dense_assembly(edofs, n, b, d), rtol=0,
                                   atol=1e-13)
    # the pattern: every entry an element touches and the whole diagonal, nothing else
    want = dense_assembly(edofs, n, np.ones_like(blocks), np.ones(n)) != 0
    have = pat.matrix(np.ones(pat.nnz)).toarray() != 0
    np.testing.assert_array_equal(have, want)
    assert pat.nnz == want.sum()


def scene_text(weight=None, supports=("A", 'B = ["y", "z"]')):
    """An inclined cable of 5 elements with a point mass on a node and one inside an element,
    a load on a node and one inside an element."""
    return cable_scene(
        B=(20.0, 3.0, 4.0), L0=21.5, EA=1.0e6, mass=2.0, weight=weight, elements=5,
        supports=supports,
        extra=(point_mass("pn", 30.0, node="c.2") + point_mass("pe", 12.0, cable="c", s=14.0)
               + load("fn", [40.0, -25.0, -60.0], node="c.3")
               + load("fe", [-15.0, 30.0, -20.0], cable="c", s=5.5)),
        steps=static_step())


def model_of(text):
    case = catdae.load_case(text)
    mesh = build_mesh(case)
    return case, mesh, Model(case, mesh, set(), kind="static")


def test_dof_pattern_of_the_supports():
    case, mesh, model = model_of(scene_text())
    assert model.n_dof == 3 * mesh.n_nodes
    iB = mesh.node_index("B")
    iA = mesh.node_index("A")
    want_fixed = sorted([3 * iA, 3 * iA + 1, 3 * iA + 2, 3 * iB + 1, 3 * iB + 2])
    np.testing.assert_array_equal(model.fixed, want_fixed)
    np.testing.assert_array_equal(np.sort(np.concatenate([model.fixed, model.free])),
                                  np.arange(model.n_dof))
    assert model.fixed_mask.sum() == 5 and model.fixed_mask[iB].tolist() == [False, True, True]
    # dofs node-major: element e joins nodes conn[e] and holds their x, y, z
    for e, (i, j) in enumerate(mesh.conn):
        assert model.edofs[e].tolist() == [3 * i, 3 * i + 1, 3 * i + 2, 3 * j, 3 * j + 1,
                                           3 * j + 2]
    # total mass: cable plus both point masses
    assert model.total_mass == pytest.approx(2.0 * 21.5 + 30.0 + 12.0, rel=1e-14)


def test_assembled_stiffness_and_forces_equal_dense_sums_and_finite_differences():
    case, mesh, model = model_of(scene_text())
    rng = np.random.default_rng(2)
    X = mesh.X0 + 0.05 * rng.normal(size=mesh.X0.shape)
    state = model.element_state(X)
    K = model.stiffness(state).toarray()
    np.testing.assert_allclose(K, dense_assembly(model.edofs, model.n_dof, state.stiffness6),
                               rtol=0, atol=1e-12 * np.abs(K).max())
    # internal force: the end forces of every element summed on their nodes
    r = model.elements.end_forces(state.h)
    f = np.zeros(model.n_dof)
    for e, dofs in enumerate(model.edofs):
        f[dofs] += r[e].ravel()
    np.testing.assert_allclose(model.internal_force(state), f, rtol=0,
                               atol=1e-12 * np.abs(f).max())
    # K_t = ∂(internal force)/∂X, by central differences, every column
    h = 1e-6
    fd = np.zeros_like(K)
    for k in range(model.n_dof):
        Xp, Xm = X.copy(), X.copy()
        Xp.reshape(-1)[k] += h
        Xm.reshape(-1)[k] -= h
        fp = model.internal_force(model.element_state(Xp, state.h))
        fm = model.internal_force(model.element_state(Xm, state.h))
        fd[:, k] = (fp - fm) / (2 * h)
    np.testing.assert_allclose(K, fd, rtol=0, atol=1e-6 * np.abs(K).max())
    np.testing.assert_allclose(K, K.T, rtol=0, atol=1e-12 * np.abs(K).max())


def test_reactions_balance_the_weight_and_the_loads():
    case, mesh, model = model_of(scene_text(supports=("A", "B")))
    sol = solve_static(model, mesh.X0)
    R = model.reactions(sol.state, 0.0)
    sup = [mesh.node_index(n) for n in ("A", "B")]
    assert np.isnan(np.delete(R, sup, axis=0)).all()  # NaN on free axes
    weight = G * (2.0 * 21.5 + 30.0 + 12.0)
    loads = np.array([40.0, -25.0, -60.0]) + np.array([-15.0, 30.0, -20.0])
    np.testing.assert_allclose(R[sup].sum(axis=0) + loads - [0.0, 0.0, weight], 0.0, rtol=0,
                               atol=1e-9 * weight)


def test_reactions_balance_moments_of_forces_at_nodes():
    # weightless, every force at a node: Σ x × f = 0 over the reactions and the loads
    text = cable_scene(B=(12.0, 2.0, 3.0), L0=14.0, EA=1.0e6, mass=1.0, weight=0.0, elements=4,
                       # at s = 3.5 and 10.5: on nodes c.1 and c.3
                       extra=(point_mass("pn", 20.0, cable="c", s=3.5)
                              + load("fn", [30.0, 50.0, -80.0], cable="c", s=10.5)),
                       steps=static_step())
    case, mesh, model = model_of(text)
    sol = solve_static(model, mesh.X0)
    R = model.reactions(sol.state, 0.0)
    X = sol.X
    forces = {mesh.node_index("A"): R[mesh.node_index("A")],
              mesh.node_index("B"): R[mesh.node_index("B")]}
    forces[mesh.node_index("c.1")] = np.array([0.0, 0.0, -20.0 * G])
    forces[mesh.node_index("c.3")] = np.array([30.0, 50.0, -80.0])
    total = sum(forces.values())
    moment = sum(np.cross(X[i], f) for i, f in forces.items())
    scale = 100.0 * np.abs(X).max()
    assert np.abs(total).max() < 1e-9 * 100.0
    assert np.abs(moment).max() < 1e-9 * scale
