"""The grounded element (catdae.element.grounded) and the penalty contact
(catdae.model.seabed.SeabedContact): derivatives against central finite differences, and one
grounded element spanning a line against the closed-form grounded catenary."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from catdae.element import grounded as g
from catdae.model.seabed import SeabedContact

from reference import grounded_catenary

W, EA, L0 = 3324.4, 1.674e9, 76.0


def _chord(h, mode):
    d, f = np.zeros(3), np.zeros(6)
    assert g.chord_grounded(h[0], h[1], h[2], W, EA, L0, mode, d, f, True)
    F = np.array([[f[0], f[1], f[2]], [f[1], f[3], f[4]], [f[2], f[4], f[5]]])
    return d, F


@pytest.mark.parametrize("mode, v", [(g.AT_I, -W * 30.0), (g.AT_I, -W * 75.0),
                                     (g.AT_I, W * 5.0), (g.AT_J, -W * 45.0),
                                     (g.AT_J, -W * 1.0), (g.AT_J, -W * 90.0)])
def test_grounded_flexibility_is_the_chord_derivative(mode, v):
    """F = ∂ℓ/∂h of an element lying over part of its length (and the limits where it does
    not touch), against central differences; F is symmetric."""
    h = np.array([1.4e6, 2.0e5, v])
    _, F = _chord(h, mode)
    fd = np.empty((3, 3))
    for k in range(3):
        e = np.zeros(3)
        e[k] = 1e-6 * np.abs(h).max()
        fd[:, k] = (_chord(h + e, mode)[0] - _chord(h - e, mode)[0]) / (2 * e[k])
    assert np.abs(F - fd).max() <= 1e-7 * np.abs(F).max()
    assert np.allclose(F, F.T, rtol=0, atol=1e-14 * np.abs(F).max())


@pytest.mark.parametrize("mode", [g.AT_I, g.AT_J])
def test_one_grounded_element_is_the_closed_form(mode):
    """One element spanning a 760 m chain from its anchor (200 m rise, 700 m span): h is the
    closed form's (horizontal tension, and V = -w × lying length at the anchor's side)."""
    ref = grounded_catenary(700.0, 200.0, 760.0, EA, W)
    c = np.array([700.0, 0.0, 200.0]) * (1 if mode == g.AT_I else -1)
    h, f, k = np.zeros(3), np.zeros(6), np.zeros((3, 3))
    _, status = g.solve_grounded(c, 760.0, EA, W, mode, h, False, 1e-14, 100, f, k)
    assert status == g.CONVERGED
    if mode == g.AT_I:
        assert h == pytest.approx([ref["H"], 0.0, -W * ref["lying_length"]], rel=1e-12,
                                  abs=1e-9)
    else:  # from the fairlead: pulled down towards the anchor, V = -w l_s
        assert h == pytest.approx([-ref["H"], 0.0, -ref["V"]], rel=1e-12, abs=1e-9)


def _contact(mu_a=0.5, mu_l=0.8):
    seabed = SimpleNamespace(z=-1.0, stiffness=2e5, damping=3e3, friction_axial=mu_a,
                             friction_lateral=mu_l, friction_velocity=0.05)
    mesh = SimpleNamespace(conn=np.array([[0, 1], [1, 2], [2, 3]]), n_nodes=4)
    area = np.array([0.5, 1.0, 1.2, 0.6])
    return SeabedContact(seabed, mesh, np.array([False, True, True, True]), area)


def test_contact_derivatives_are_finite_differences():
    """-∂F/∂q and -∂F/∂v of the penalty contact with damping and anisotropic smoothed
    friction, at nodes in contact, against central differences (the line direction held)."""
    c = _contact()
    rng = np.random.default_rng(3)
    X = np.array([[0.0, 0.0, -1.0], [1.0, 0.2, -1.01], [2.0, 0.5, -1.003], [3.0, 0.4, -1.02]])
    V = rng.normal(scale=0.04, size=(4, 3))
    kq, kv = c.derivatives(X, V)
    # hold ê, as the iteration matrix does: the direction is taken from copies of the
    # neighbours (rows appended to X) that the perturbations below do not move
    n = X.shape[0]
    ghosts = np.concatenate([c.nb_a, c.nb_b])
    c.nb_a, c.nb_b = n + np.arange(c.nodes.size), n + c.nodes.size + np.arange(c.nodes.size)
    X = np.vstack([X, X[ghosts]])
    V = np.vstack([V, V[ghosts]])
    for p, node in enumerate(c.nodes):
        for a in range(3):
            for which, blk in (("q", kq), ("v", kv)):
                step = 1e-7
                Xp, Xm, Vp, Vm = X.copy(), X.copy(), V.copy(), V.copy()
                if which == "q":
                    Xp[node, a] += step
                    Xm[node, a] -= step
                else:
                    Vp[node, a] += step
                    Vm[node, a] -= step
                d = -(c.forces(Xp, Vp)[node] - c.forces(Xm, Vm)[node]) / (2 * step)
                assert blk[p, :, a] == pytest.approx(d, rel=1e-6, abs=1e-6 * np.abs(blk).max())


def test_contact_friction_limits_and_dissipation():
    """Well above the velocity scale friction is Coulomb's μ N against the motion (axial and
    lateral coefficients along and across the line); the seabed only takes energy out."""
    c = _contact()
    X = np.array([[0.0, 0.0, -1.0], [1.0, 0.0, -1.01], [2.0, 0.0, -1.01], [3.0, 0.0, -1.01]])
    V = np.zeros((4, 3))
    V[2, 0] = 50.0  # along the line (x)
    V[3, 1] = -50.0  # across it
    f = c.forces(X, V)
    n2 = 1.2 * 2e5 * 0.01
    n3 = 0.6 * 2e5 * 0.01
    assert f[2, 0] == pytest.approx(-0.5 * n2, rel=1e-5)
    assert f[3, 1] == pytest.approx(0.8 * n3, rel=1e-5)
    assert c.dissipation(X, V) > 0.0
