"""The fluid's case fields and kinematics (catdae/case/build_fluid.py, catdae/model/fluid.py,
catdae/element/fluid_kernel.py; docs/case-format.md "Water and air", docs/theory.md §13)."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from catdae.case.fluid import Waves
from catdae.element.fluid_kinematics import wave_kinematics
from catdae.model.fluid import dispersion, wave_components

from scene_toml import cable_scene, static_step

BASE = cable_scene(A=(0.0, 0.0, -50.0), B=(60.0, 0.0, -10.0), L0=80.0, EA=1e8, mass=50.0,
                   elements=4, steps=static_step())
WATER = "[water]\ndepth = 100.0\n"


@pytest.mark.parametrize("text, field, expected", [
    (BASE.replace("mass = 50.0\n", "mass = 50.0\ndiameter = -0.1\n") + WATER,
     "materials.m.diameter", "expected a value > 0"),
    (BASE + WATER + "current = { z = [-100.0, 0.0, -20.0], velocity = [[0.1, 0, 0], "
     "[0.5, 0, 0], [0.3, 0, 0]] }\n", "water.current.z", "expected heights increasing strictly"),
    (BASE + '[air]\nwaves = { kind = "airy", height = 1.0, period = 5.0 }\n', "air.waves",
     "waves belong to [water]"),
    (BASE.replace("mass = 50.0\n", "mass = 50.0\ndrag_normal = 1.2\n") + WATER,
     "materials.m.drag_normal", "needs the line's diameter"),
    (BASE + WATER + 'waves = { kind = "jonswap", hs = 2.0 }\n', "water.waves.tp", "missing"),
    (BASE + '[air]\nwind = { speed = 10.0, profile = "power" }\n', "air.wind.exponent",
     "missing"),
    (cable_scene(A=(0.0, 0.0, -50.0), B=(60.0, 0.0, -10.0), L0=70.0, EA=1e8, mass=50.0,
                 elements=4, gravity=0.0, steps=static_step()) + WATER
     + 'waves = { kind = "airy", height = 1.0, period = 5.0 }\n', "water.waves",
     "waves need gravity > 0"),
    (BASE + "[water]\nsurface = -60.0\n[seabed]\nz = -55.0\n", "seabed.z",
     "lies above the still-water level"),
    (BASE + '[water]\ndepth = 40.0\nwaves = { kind = "airy", height = 1.0, period = 5.0 }\n',
     "water.depth", "support 'A' (z = -50 m) lies below the water's floor"),
    (BASE + WATER + 'waves = { kind = "airy", height = 1.0, period = 5.0 }\n[seabed]\n'
     "z = -120.0\n", "seabed.z", "lies below the water's floor surface - depth = -100 m"),
])
def test_bad_fluid_input_is_located_with_exit_2(text, field, expected, tmp_path):
    f = tmp_path / "case.toml"
    f.write_text(text)
    proc = subprocess.run([sys.executable, "-m", "catdae", "check", str(f)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    assert proc.stderr.startswith(f"catdae: invalid case: {f}: {field}: "), proc.stderr
    assert expected in proc.stderr, proc.stderr


def test_dispersion_solves_the_finite_depth_relation():
    g = 9.81
    for omega, depth in ((0.3, 20.0), (0.628, 100.0), (2.0, 5.0), (1.0, math.inf)):
        k = dispersion(omega, g, depth)
        assert omega**2 == pytest.approx(g * k * math.tanh(k * depth), rel=1e-13)


@pytest.mark.parametrize("depth", [30.0, math.inf])
def test_airy_kinematics_are_a_potential_flow_with_the_free_surface_condition(depth):
    """Linear wave velocities are divergence-free and irrotational (the gradient the kernel
    returns is traceless and symmetric, and equals finite differences of the velocity); the
    acceleration is ∂u/∂t; the vertical velocity at the still level is ∂η/∂t."""
    w = Waves("airy", height=2.0, period=7.0, heading=35.0, phase=20.0)
    comps = wave_components(w, 9.81, depth)
    u, a, gu, ga = np.zeros(3), np.zeros(3), np.zeros((3, 3)), np.zeros((3, 3))

    def kin(x, t, z=None):
        uu, aa, g1, g2 = np.zeros(3), np.zeros(3), np.zeros((3, 3)), np.zeros((3, 3))
        eta = wave_kinematics(x[0], x[1], x[2], t, 0.0, depth, *comps, 1.0, 0.0, uu, aa, g1, g2)
        return eta, uu, aa

    x, t = np.array([3.0, -2.0, -6.0]), 1.3
    wave_kinematics(x[0], x[1], x[2], t, 0.0, depth, *comps, 1.0, 0.0, u, a, gu, ga)
    assert abs(np.trace(gu)) < 1e-12 * np.abs(gu).max()
    np.testing.assert_allclose(gu, gu.T, atol=1e-12 * np.abs(gu).max())
    h = 1e-5
    fd = np.column_stack([(kin(x + h * e, t)[1] - kin(x - h * e, t)[1]) / (2 * h)
                          for e in np.eye(3)])
    np.testing.assert_allclose(gu, fd, atol=1e-8 * np.abs(gu).max())
    np.testing.assert_allclose(a, (kin(x, t + h)[1] - kin(x, t - h)[1]) / (2 * h),
                               atol=1e-8 * np.abs(a).max())
    x0 = np.array([3.0, -2.0, 0.0])
    deta = (kin(x0, t + h)[0] - kin(x0, t - h)[0]) / (2 * h)
    assert kin(x0, t)[1][2] == pytest.approx(deta, rel=1e-8)


def test_jonswap_components_carry_the_significant_height():
    w = Waves("jonswap", hs=3.0, tp=9.0, gamma=3.3, seed=7, components=200)
    amp, om, k, *_ = wave_components(w, 9.81, 80.0)
    assert 4.0 * math.sqrt(0.5 * float(amp @ amp)) == pytest.approx(3.0, rel=1e-12)
    wp = 2 * math.pi / 9.0
    assert om.min() >= 0.5 * wp and om.max() <= 3.0 * wp
    # the spectrum peaks at the peak frequency: the largest amplitudes sit near ω_p
    assert abs(om[np.argmax(amp)] / wp - 1.0) < 0.05
    again = wave_components(w, 9.81, 80.0)
    np.testing.assert_array_equal(amp, again[0])  # the seed fixes the sea
