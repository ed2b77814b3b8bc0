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


def test_damped_modes_are_paired_with_undamped_ones_one_to_one():
    """Two stays of different tension joined by a strong damper mix their undamped modes;
    pairing each damped mode with its largest modal assurance criterion mapped two of them to
    one undamped mode (tester t68: damped modes 6 and 8 both 'like undamped mode 8'). The
    pairing is one to one, and where a damped mode is an undamped one untouched (the
    damper's point at rest in it: ζ = 0, same frequency) it is paired with that one."""
    text = ('title = "two stays and a damper tie"\n[materials.strand]\nEA = 2.0e9\n'
            'mass = 60.0\n[nodes]\nA1 = [0.0, 0.0, 0.0]\nB1 = [150.0, 0.0, 0.0]\n'
            'A2 = [0.0, 2.0, 0.21875332]\nB2 = [150.0, 2.0, 0.21875332]\n[supports]\n'
            'A1 = "pinned"\nB1 = "pinned"\nA2 = "pinned"\nB2 = "pinned"\n'
            '[[cables]]\nname = "s1"\nends = ["A1", "B1"]\nmaterial = "strand"\n'
            'form = { pretension = 4.0e6 }\nelements = 40\n'
            '[[cables]]\nname = "s2"\nends = ["A2", "B2"]\nmaterial = "strand"\n'
            'form = { pretension = 2.5e6 }\nelements = 40\n'
            '[[dampers]]\nname = "tie"\nends = ["s1.16", "s2.16"]\ncoefficient = 5.0e4\n'
            '[[steps]]\nkind = "static"\nname = "st"\n'
            '[[steps]]\nkind = "modal"\nname = "modes"\nmodes = 12\n')
    ds = catdae.run(catdae.load_case(text))["modes"].ds
    like = ds.undamped_mode.values
    found = like[like > 0]
    assert len(set(found.tolist())) == found.size, like
    untouched = np.flatnonzero(np.abs(ds.damping_ratio.values) < 1e-9)
    assert untouched.size >= 2
    for k in untouched:
        f_u = float(ds.undamped_frequency.sel(mode=int(like[k])))
        assert float(ds.frequency.values[k]) == pytest.approx(f_u, rel=1e-6), k
