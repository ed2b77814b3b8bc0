"""Water, air and a seabed under a gravity vector: "up" is -g (docs/case-format.md, "Water and
air"; catdae.case.frame).

Checked by symmetry: a scene in water, current, waves, wind and on a seabed, turned rigidly by
a rotation Q together with its gravity, its current and wind vectors (its heights along up, the
still-water level, the depth, the seabed's height and the current profile's heights, are those
of the upright scene; headings and the wind's direction turn with the frame's first axis, see
:func:`heading_offset`), must give the turned answer: positions, reactions, touchdown points and
fluid velocities turned by Q, tensions, lengths on the seabed, frequencies (with added mass)
and the surface elevation unchanged. Statics and modes to round-off (1e-9), the transient
with waves to its integration tolerance.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import catdae
from catdae.case.frame import gravity_rotation

from scene_toml import scene, step


def rotation(axis, angle):
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def heading_offset(Q) -> float:
    """Degrees to add to a heading (or a wind direction) of the upright scene in the scene
    turned by Q: headings are measured from the gravity frame's first axis e1 (the first row of
    gravity_rotation), which need not be Q's image of +x."""
    e1 = gravity_rotation(Q @ np.array([0.0, 0.0, -1.0]))[0]
    local = Q.T @ e1  # e1 seen in the upright scene: a horizontal unit vector
    assert abs(local[2]) < 1e-12
    return -math.degrees(math.atan2(local[1], local[0]))


def vec(v):
    return [float(x) for x in v]


def water_scene(Q, rigid: bool = False) -> str:
    """A chain from an anchor on the seabed (50 m of water) to a fairlead 3 m above the
    surface, in a current profile, Airy waves and a power-law wind; turned by Q. On a rigid
    seabed (statics only) the current is zero at the bed (the resting part then straight)."""
    off = heading_offset(Q)
    bottom = [0.0, 0.0, 0.0] if rigid else [0.2, 0.1, 0.0]
    cur = [vec(Q @ np.array(u)) for u in (bottom, [0.6, 0.3, 0.0])]
    bed = "" if rigid else "stiffness = 1.0e6\ndamping = 1.0e3\nfriction = 0.3\n"
    extra = (
        "[water]\nsurface = 0.0\ndepth = 50.0\n"
        f"current = {{ z = [-50.0, 0.0], velocity = {cur} }}\n"
        f'waves = {{ kind = "airy", height = 2.0, period = 8.0, heading = {30.0 + off!r}, '
        "ramp = 1.0 }\n"
        f'[air]\nwind = {{ speed = 20.0, direction = {60.0 + off!r}, profile = "power", '
        "exponent = 0.12 }\n"
        f"[seabed]\n{bed}")
    steps = step("static", "s") + ("" if rigid else step("modal", "m", modes=4) + step(
        "transient", "t", duration=1.0, output_interval=0.25, rtol=1e-10, atol=1e-12))
    return scene(nodes={"A": Q @ np.array([0.0, 0.0, -50.0]),
                        "B": Q @ np.array([80.0, 20.0, 3.0])},
                 cables='[[cables]]\nname = "c"\nends = ["A", "B"]\nmaterial = "chain"\n'
                        "length = 110.0\nelements = 10\n",
                 materials={"chain": {"EA": 5.0e8, "mass": 50.0, "diameter": 0.1}},
                 head={"gravity": vec(Q @ np.array([0.0, 0.0, -9.81]))},
                 extra=extra, steps=steps)


TURNS = {"g+x": rotation([0.0, 1.0, 0.0], -np.pi / 2),  # gravity along +x
         "oblique": rotation([1.0, 2.0, 0.5], 0.7)}


@pytest.fixture(scope="module")
def upright():
    return catdae.run(catdae.load_case(water_scene(np.eye(3))))


def _close(b, a, Q, rel):
    """b == a turned by Q (variables with an axis) or equal, to rel of a's largest value."""
    want = a.values @ Q.T if a.dims and a.dims[-1] == "axis" else a.values
    scale = np.nanmax(np.abs(want))
    assert np.allclose(b.transpose(*a.dims).values, want, rtol=0, atol=rel * scale,
                       equal_nan=True), a.name


@pytest.mark.parametrize("turn", TURNS)
def test_turned_scene_in_water_air_and_on_a_seabed_is_the_turned_answer(upright, turn):
    Q = TURNS[turn]
    turned = catdae.run(catdae.load_case(water_scene(Q)))
    s0, s1 = upright["s"].ds, turned["s"].ds
    assert float(s0.seabed_length.values[0]) > 10.0  # the chain does rest on the seabed
    for var in ("position", "reaction", "tension", "seabed_length", "touchdown",
                "fluid_velocity"):
        _close(s1[var], s0[var], Q, 1e-9)
    f0, f1 = upright["m"].ds.frequency.values, turned["m"].ds.frequency.values
    assert f1 == pytest.approx(f0, rel=1e-9)
    t0, t1 = upright["t"].ds, turned["t"].ds
    assert np.ptp(t0.surface_elevation.values) > 0.5  # the waves are there
    for var in ("position", "velocity", "tension", "fluid_velocity", "surface_elevation"):
        _close(t1[var], t0[var], Q, 1e-6)
    # the fluid's work is a trapezoidal sum over IDA's own steps, which differ when turned
    # (the element crossing the surface, its drag and added mass on the wet part of its chord:
    # 2.4e-5 measured on the oblique turn)
    _close(t1.energy_fluid_work, t0.energy_fluid_work, Q, 5e-5)


@pytest.mark.parametrize("turn", TURNS)
def test_turned_chain_on_a_rigid_seabed_in_current_is_the_turned_answer(turn):
    # the rigid seabed's exact grounded elements in the turned frame (statics only)
    Q = TURNS[turn]
    a = catdae.run(catdae.load_case(water_scene(np.eye(3), rigid=True)))["s"].ds
    b = catdae.run(catdae.load_case(water_scene(Q, rigid=True)))["s"].ds
    assert float(a.seabed_length.values[0]) > 10.0
    for var in ("position", "reaction", "tension", "seabed_length", "touchdown"):
        _close(b[var], a[var], Q, 1e-9)


def test_static_fluid_velocity_is_the_current_profile_and_the_wind_law(upright):
    # below the surface the profile, linear in z between (-50, [0.2, 0.1, 0]) and (0, [0.6,
    # 0.3, 0]), constant below -50 (nodes sunk into the contact springs); above the surface
    # 20 (h / 10)^0.12 m/s towards 60 deg
    ds = upright["s"].ds
    x = ds.position.values
    want = np.zeros_like(x)
    wet = x[:, 2] <= 0.0
    f = np.clip((x[wet, 2] + 50.0) / 50.0, 0.0, 1.0)
    want[wet] = np.outer(1 - f, [0.2, 0.1, 0.0]) + np.outer(f, [0.6, 0.3, 0.0])
    b = math.radians(60.0)
    want[~wet] = np.outer(20.0 * (x[~wet, 2] / 10.0) ** 0.12, [math.cos(b), math.sin(b), 0.0])
    assert (~wet).sum() == 1 and wet.sum() == 10
    np.testing.assert_allclose(ds.fluid_velocity.values, want, rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("turn", TURNS)
def test_turned_chain_on_a_rigid_seabed_with_current_at_the_bed_is_the_turned_answer(turn):
    # a current at the seabed's height (0.3 m/s across the chain at the bed) moves the resting
    # part in plan (tests/scenes/test_seabed_current.py); turned with its gravity and current
    Q = TURNS[turn]
    a = catdae.run(catdae.load_case(_with_bottom(water_scene(np.eye(3), rigid=True),
                                                 [-0.1, 0.3, 0.0])))["s"].ds
    b = catdae.run(catdae.load_case(_with_bottom(water_scene(Q, rigid=True),
                                                 vec(Q @ np.array([-0.1, 0.3, 0.0])))))["s"].ds
    assert float(a.seabed_length.values[0]) > 10.0
    assert abs(float(a.touchdown.sel(cable="c", axis="y")) - float(a.touchdown.sel(
        cable="c", axis="x")) * 20.0 / 80.0) > 0.2  # off the chord in plan (0.47 m; 0.03 m
    # without the current at the bed)
    for var in ("position", "reaction", "tension", "seabed_length", "touchdown"):
        _close(b[var], a[var], Q, 1e-9)


def _with_bottom(text: str, bottom: list[float]) -> str:
    """The scene with the current profile's bottom velocity replaced by ``bottom``."""
    head, _, rest = text.partition("velocity = [[")
    _, _, tail = rest.partition("], [")
    return f"{head}velocity = [{bottom}, [{tail}"
