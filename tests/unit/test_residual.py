"""The transient residual and its iteration matrix (``catdae.solvers.residual``).

IDA's iteration matrix is J = ∂r/∂y + c_j ∂r/∂y'. It is compared here with central differences
of the residual itself, for a small scene (an inclined cable of 4 elements, a point mass inside
an element) with every mass model and both kinds of damping:

- at rest (v = 0) with any acceleration, J is exact (docs/theory.md §8): the terms it leaves out,
  the q-derivatives of C(q) v and of the Lagrangian velocity terms, vanish with v;
- while moving (v ≠ 0), the v-columns of J (∂r/∂v + c_j ∂r/∂v') are still exact: only the
  q-derivatives are approximated.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import catdae
from catdae.model.assembly import Model
from catdae.model.mesh import build_mesh
from catdae.solvers.residual import TransientProblem

from scene_toml import cable_scene, point_mass, static_step, transient_step

DAMPING = {
    "rayleigh": 'damping = { kind = "rayleigh", ratio = 0.05, frequencies = [1.0, 10.0] }',
    "material": 'damping = { kind = "material" }',
}


def problem(mass_model: str, damping: str, step_extra: str = "") -> TransientProblem:
    text = cable_scene(
        B=(12.0, 2.0, 3.0), L0=13.0, EA=1.0e5, mass=2.0, elements=4, gauss_points=3,
        extra=point_mass("pm", 6.0, cable="c", s=4.1),
        steps=static_step() + transient_step("dyn", 1.0, 0.1, rtol=1e-8, atol=1e-10,
                                             extra=DAMPING[damping] + step_extra))
    text = text.replace("mass = 2.0\n", "mass = 2.0\ndamping = 3.0\n", 1)  # c per metre
    case = catdae.load_case(text)
    mesh = build_mesh(case)
    step = dataclasses.replace(case.steps[1], mass_model=mass_model)
    model = Model(case, mesh, set(), mass_model=mass_model)
    prob = TransientProblem(model, step, mesh.X0, None)
    assert prob.material == (damping == "material")
    assert prob.lagrangian == model.mass_model.catenary  # the default inertia
    return prob


def residual(prob, t, y, yp):
    r = np.empty_like(y)
    prob.resfn(t, y, yp, r)
    assert np.isfinite(r).all()
    return r


def fd_iteration_matrix(prob, t, y, yp, cj, h=1e-6):
    """∂r/∂y + cj ∂r/∂y' by central differences, column by column."""
    n2 = y.size
    out = np.empty((n2, n2))
    for k in range(n2):
        e = np.zeros(n2)
        e[k] = h
        dy = (residual(prob, t, y + e, yp) - residual(prob, t, y - e, yp)) / (2 * h)
        dyp = (residual(prob, t, y, yp + e) - residual(prob, t, y, yp - e)) / (2 * h)
        out[:, k] = dy + cj * dyp
    return out


def analytic(prob, t, y, yp, cj):
    J = np.empty((y.size, y.size))
    residual(prob, t, y, yp)  # IDA evaluates the residual at the state first
    prob.jac_dense(t, y, yp, None, cj, J)
    return J


def state(prob, moving: bool):
    """(y, yp) near the static shape, q perturbed, a random acceleration; v = 0 unless moving."""
    X0 = prob.model.mesh.X0
    y0, _ = prob.initial(0.0, X0, np.zeros_like(X0))
    rng = np.random.default_rng(17)
    y = y0.copy()
    y[0::2] += 1e-2 * rng.standard_normal(prob.n)
    y[1::2] = 0.3 * rng.standard_normal(prob.n) if moving else 0.0
    yp = np.zeros_like(y)
    yp[0::2] = y[1::2]
    yp[1::2] = rng.standard_normal(prob.n)
    return y, yp


def assert_blocks_close(J, fd, cols, rtol):
    """Rows of q and of v separately, each to rtol of its own largest entry."""
    for rows in (slice(0, None, 2), slice(1, None, 2)):
        a, b = J[rows][:, cols], fd[rows][:, cols]
        scale = np.abs(b).max()
        assert np.abs(a - b).max() <= rtol * scale, (np.abs(a - b).max(), scale)


MASS_MODELS = ["consistent", "blended", "lumped", "linear"]
T, CJ = 0.05, 40.0


def matrices(mass_model, damping, moving):
    """(problem, J, its finite differences, J with the acceleration (at rest) or the velocity
    (moving) set to zero at the same positions)."""
    prob = problem(mass_model, damping)
    y, yp = state(prob, moving)
    J = analytic(prob, T, y, yp, CJ)
    fd = fd_iteration_matrix(prob, T, y, yp, CJ)
    y0, yp0 = y.copy(), yp.copy()
    if moving:
        y0[1::2] = 0.0
        yp0[0::2] = 0.0
    else:
        yp0[1::2] = 0.0
    return prob, J, fd, analytic(prob, T, y0, yp0, CJ)


@pytest.mark.parametrize("damping", ["rayleigh", "material"])
@pytest.mark.parametrize("mass_model", MASS_MODELS)
def test_iteration_matrix_at_rest_is_the_derivative_of_the_residual(mass_model, damping):
    prob, J, fd, J0 = matrices(mass_model, damping, moving=False)
    assert_blocks_close(J, fd, slice(None), 1e-7)  # measured: < 1e-9
    if prob.lagrangian:  # the acceleration matters: ∂(M(q) a)/∂q is in J
        assert np.abs(J - J0).max() > 1e-3 * np.abs(J).max()


@pytest.mark.parametrize("damping", ["rayleigh", "material"])
@pytest.mark.parametrize("mass_model", MASS_MODELS)
def test_velocity_columns_of_the_iteration_matrix_while_moving(mass_model, damping):
    prob, J, fd, J0 = matrices(mass_model, damping, moving=True)
    assert_blocks_close(J, fd, slice(1, None, 2), 1e-7)  # measured: < 3e-9
    if prob.lagrangian:  # the velocity terms are there, and large against that tolerance
        assert np.abs(J - J0)[1::2, 1::2].max() > 1e-2 * np.abs(fd[1::2, 1::2]).max()
    # the kinematic rows r_q = q' - v: exactly c_j I and -I
    n = prob.n
    np.testing.assert_array_equal(J[0::2, 0::2], CJ * np.eye(n))
    np.testing.assert_array_equal(J[0::2, 1::2], -np.eye(n))


@pytest.mark.parametrize("axial", [False, True], ids=["plain", "axial_damping"])
def test_an_output_leaves_the_residual_as_it_was(axial):
    """An output between two residual evaluations (IDA's normal mode interpolates one inside a
    step, docs/theory.md §8.8) puts the residual's buffers back: the state the next residual
    starts from (its carried Newton start, and with axial damping the chord rates the tension
    envelope carries with) is bit for bit what it was, and so is the next residual, against
    the same sequence without the output."""
    runs = []
    for with_output in (False, True):
        prob = problem("blended", "material",
                       "\naxial_damping = { ratio = 0.05 }" if axial else "")
        assert (prob.axial is not None) == axial
        y, yp = state(prob, moving=True)
        residual(prob, T, y, yp)
        before = prob.start_state()
        if with_output:
            prob.observe(T + 0.01, y + 1e-3, yp)
            after = prob.start_state()
            assert after[1] is before[1]  # the same (t, q) the buffers hold
            assert (before[3] is None) == (not axial)  # the axial damping's chord rates
            for a, b in zip([*before[2], *(before[3] or ())], [*after[2], *(after[3] or ())],
                            strict=True):
                np.testing.assert_array_equal(a, b)
            np.testing.assert_array_equal(before[0], after[0])
        runs.append(residual(prob, T + 0.002, y + 1e-4, yp))
    np.testing.assert_array_equal(runs[0], runs[1])
