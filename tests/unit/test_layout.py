"""Where the unknowns of a transient sit (``catdae.solvers.layout``).

The ordering is checked to be a permutation of the free dofs, its free-free entries and bandwidth
against the stiffness pattern permuted here densely, and the pattern of the iteration matrix
against the blocks it must hold (c_j I and -I in the q rows, the stiffness and mass pattern in
the v rows); the sparse iteration matrix written through the maps equals the dense one.
"""

from __future__ import annotations

import numpy as np
import pytest

import catdae
from catdae.model.assembly import Model
from catdae.model.mesh import build_mesh
from catdae.solvers.layout import UnknownLayout
from catdae.solvers.residual import TransientProblem

from repo_paths import CASES
from scene_toml import cable_scene, static_step, transient_step


def one_cable():
    return cable_scene(B=(20.0, 0.0, 2.0), L0=21.0, EA=1.0e6, mass=1.0, elements=12,
                       supports=("A", 'B = ["y", "z"]'),
                       steps=static_step() + transient_step("dyn", 0.1, 0.05, rtol=1e-6,
                                                            atol=1e-8))


SCENES = {"one cable, B on a slider": one_cable,
          "three cables": lambda: ((CASES / "three_cables_shared_node.toml").read_text()
                                   + transient_step("dyn", 0.1, 0.05, rtol=1e-6, atol=1e-8))}


def build(name):
    case = catdae.load_case(SCENES[name]())
    mesh = build_mesh(case)
    model = Model(case, mesh, set())
    return case, mesh, model, UnknownLayout(model.pattern, model.free, model.n_dof)


@pytest.mark.parametrize("name", list(SCENES))
def test_ordering_is_a_permutation_of_the_free_dofs(name):
    case, mesh, model, lay = build(name)
    assert lay.n == model.free.size
    np.testing.assert_array_equal(np.sort(lay.fidx), model.free)
    # the free-free block of the stiffness pattern, in the unknowns' order, is symmetric and has
    # exactly the entries ff_a, ff_b
    full = model.pattern.matrix(np.ones(model.pattern.nnz)).toarray() != 0
    ff = full[np.ix_(lay.fidx, lay.fidx)]
    have = np.zeros_like(ff)
    have[lay.ff_a, lay.ff_b] = True
    np.testing.assert_array_equal(have, ff)
    assert len(set(zip(lay.ff_a.tolist(), lay.ff_b.tolist(), strict=True))) == lay.ff_a.size
    rows, cols = np.nonzero(ff)
    assert lay.bandwidth == np.abs(rows - cols).max()
    # ff_sel picks those entries out of the full CSR data: a matrix with distinct values
    data = np.arange(model.pattern.nnz, dtype=float)
    dense = model.pattern.matrix(data).toarray()
    np.testing.assert_array_equal(data[lay.ff_sel], dense[lay.fidx[lay.ff_a], lay.fidx[lay.ff_b]])
    if name.startswith("one cable"):
        # a chain of 12 elements: reverse Cuthill-McKee keeps it banded, at most two nodes' dofs
        assert lay.bandwidth <= 5


@pytest.mark.parametrize("name", list(SCENES))
def test_iteration_matrix_pattern_holds_every_block_entry(name):
    case, mesh, model, lay = build(name)
    n = lay.n
    want = np.zeros((2 * n, 2 * n), bool)
    k = np.arange(n)
    want[2 * k, 2 * k] = True  # ∂r_q/∂q: c_j I
    want[2 * k, 2 * k + 1] = True  # ∂r_q/∂v: -I
    want[2 * lay.ff_a + 1, 2 * lay.ff_b] = True  # ∂r_v/∂q: K_t
    want[2 * lay.ff_a + 1, 2 * lay.ff_b + 1] = True  # ∂r_v/∂v: c_j M + C
    np.testing.assert_array_equal(lay.j_pattern.toarray() != 0, want)
    assert lay.j_nnz == want.sum()
    # the maps put each block where it belongs: write 1, 2, 3, 4 through them
    jr, jc = lay.j_pattern.nonzero()
    order = np.lexsort((jr, jc))  # CSC data order: by column, then row
    jr, jc = jr[order], jc[order]
    for jmap, rr, cc in ((lay.jmap_qq, 2 * k, 2 * k), (lay.jmap_qv, 2 * k, 2 * k + 1),
                         (lay.jmap_vq, 2 * lay.ff_a + 1, 2 * lay.ff_b),
                         (lay.jmap_vv, 2 * lay.ff_a + 1, 2 * lay.ff_b + 1)):
        np.testing.assert_array_equal(jr[jmap], rr)
        np.testing.assert_array_equal(jc[jmap], cc)


def test_sparse_iteration_matrix_equals_the_dense_one():
    case, mesh, model, _ = build("three cables")
    step = case.steps[-1]
    assert step.kind == "transient"
    prob = TransientProblem(model, step, mesh.X0, None)
    y, yp = prob.initial(0.0, mesh.X0, np.zeros_like(mesh.X0))
    yp = yp + np.random.default_rng(1).standard_normal(yp.size)
    res = np.empty_like(y)
    prob.resfn(0.0, y, yp, res)
    dense = np.zeros((y.size, y.size))
    prob.jac_dense(0.0, y, yp, res, 25.0, dense)
    data = np.zeros(prob.j_nnz)
    prob.jac_sparse(0.0, y, yp, res, 25.0, data)
    sparse = prob.j_pattern.copy()
    sparse.data = data
    np.testing.assert_array_equal(sparse.toarray(), dense)
