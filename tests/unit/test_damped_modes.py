"""Damped modes (``catdae.solvers.damped_modes``): the quadratic eigenproblem against closed
forms (one degree of freedom; Rayleigh damping, whose modes are the undamped ones with
ζ = α/2ω + βω/2), and the modal step's results and summary."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

import catdae
from catdae.case import case_from_dict
from catdae.solvers.damped_modes import solve_quadratic

from scene_toml import cable_scene, modal_step, static_step


@pytest.mark.parametrize("c", [0.3, 5.0, 19.0])
def test_one_degree_of_freedom(c):
    """m s² + c s + k = 0: s = (-c + i √(4mk - c²)) / 2m."""
    m, k = 2.0, 50.0
    modes = solve_quadratic(np.array([[k]]), np.array([[c]]), np.array([[m]]), 1)
    s = complex(-c, np.sqrt(4 * m * k - c * c)) / (2 * m)
    assert abs(modes.s[0] - s) <= 1e-12 * abs(s)
    assert abs(modes.damping_ratio[0] - c / (2 * np.sqrt(k * m))) <= 1e-12
    assert modes.solver == "dense"


def test_overdamped_roots_are_left_out():
    modes = solve_quadratic(np.array([[50.0]]), np.array([[30.0]]), np.array([[2.0]]), 1)
    assert modes.s.size == 0


def test_rayleigh_damping_gives_the_closed_form_ratios(capsys):
    """C = α M + β K has the undamped shapes: ζ_n = α/(2ω_n) + β ω_n/2 and the damped
    frequency ω_n √(1 - ζ_n²), mode by mode (the undamped ω_n from the same step)."""
    alpha, beta = 0.2, 1e-3
    text = cable_scene(B=(50.0, 0.0, 10.0), L0=52.0, EA=1e7, mass=2.0, elements=12,
                       steps=static_step("st") + modal_step(6, "modes")
                       + f'damping = {{ kind = "rayleigh", alpha = {alpha}, beta = {beta} }}\n')
    ds = catdae.run(case_from_dict(tomllib.loads(text)))["modes"].ds
    w = 2 * np.pi * ds.undamped_frequency.values
    zeta = alpha / (2 * w) + beta * w / 2
    assert np.allclose(ds.damping_ratio.values, zeta, rtol=1e-8)
    assert np.allclose(ds.frequency.values, w * np.sqrt(1 - zeta**2) / (2 * np.pi), rtol=1e-8)
    assert list(ds.damped_plane.values) == list(ds.plane.values)
    shape = ds.complex_shape.sel(part="real") + 1j * ds.complex_shape.sel(part="imag")
    # the complex shape of proportional damping is real, and equals the undamped one
    assert np.abs(shape.imag).max() < 1e-8
    assert np.allclose(shape.real, ds.shape, atol=1e-8)
    from catdae.cli import summary

    lines = summary(catdae.run(case_from_dict(tomllib.loads(text)))).splitlines()
    first = next(x for x in lines if "mode 1:" in x)
    assert "Hz" in first and "damping ratio" in first and "plane" in first, lines
