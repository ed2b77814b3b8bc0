"""Gravity as a vector: ``gravity = [gx, gy, gz]``.

The element carries its weight along its own -z (catdae.case.frame rotates the scene so that
gravity points there). Checked by symmetry (a scene turned by an arbitrary rotation, with its
gravity turned alike, gives the turned positions and reactions and the same tensions, sags and
frequencies) and by a plumb line hanging along +x, against its closed form.
"""

from __future__ import annotations

import numpy as np
import pytest

import catdae
from catdae.errors import CaseError

from scene_toml import (
    cable_scene,
    load,
    modal_step,
    point_mass,
    static_step,
    support_motion,
    transient_step,
)


def scene(R, gravity, supports=("A", "B"), motion=True) -> str:
    """A 30 m span (32 m of cable, 6 elements) with a load at c.2, B shaken sideways
    (``motion``), turned by the rotation R; ``gravity``: the case's value as it stands (a
    number, a vector or anything a bad case gives)."""
    A, B = R @ np.zeros(3), R @ np.array([30.0, 0.0, -5.0])
    P = R @ np.array([0.0, 300.0, -100.0])
    extra = load("p", P, node="c.2")
    if motion:
        u = R @ np.array([0.0, 0.05, 0.02])
        extra += support_motion("B", **{
            a: {"kind": "sine", "amplitude": float(u[k]), "frequency": 1.0}
            for k, a in enumerate("xyz") if u[k] != 0.0})
    return cable_scene(A=A, B=B, L0=32.0, EA=1.0e6, mass=1.5, elements=6, material="s",
                       head={"gravity": gravity}, supports=supports, extra=extra,
                       steps=(static_step("s") + modal_step(4, "m")
                              + transient_step("t", 0.2, 0.05, rtol=1e-8, atol=1e-10)))


def rotation(axis, angle):
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


@pytest.fixture(scope="module")
def upright():
    return catdae.run(catdae.load_case(scene(np.eye(3), 9.81)))


@pytest.mark.parametrize("R", [
    rotation([1.0, 2.0, 0.5], 0.7),  # gravity along no axis
    rotation([1.0, 0.0, 0.0], np.pi / 2),  # y up
], ids=["oblique", "y-up"])
def test_rotated_scene_is_the_rotated_answer(upright, R):
    g = R @ np.array([0.0, 0.0, -9.81])
    turned = catdae.run(catdae.load_case(scene(R, g)))
    # statics to round-off; the transient step to its integration accuracy (IDA's error norm
    # weighs the components of each vector, so its steps differ in a turned frame)
    for step, rel in (("s", 1e-11), ("t", 1e-6)):
        a, b = upright[step].ds, turned[step].ds
        for var in ("position", "displacement", "reaction") + (("velocity",) if step == "t"
                                                                else ()):
            want = a[var].values @ R.T
            scale = np.nanmax(np.abs(want))
            assert np.allclose(b[var].values, want, rtol=0, atol=rel * scale,
                               equal_nan=True), var
        assert b.tension.values == pytest.approx(a.tension.values, rel=max(rel, 1e-9))
    s0, s1 = upright["s"].ds, turned["s"].ds
    for var in ("sag", "horizontal_tension"):
        assert s1[var].values == pytest.approx(s0[var].values, rel=1e-9)
    assert turned["m"].ds.frequency.values == pytest.approx(
        upright["m"].ds.frequency.values, rel=1e-9)
    assert list(turned["m"].ds.plane.values) == list(upright["m"].ds.plane.values)


def test_plumb_line_hangs_along_gravity():
    # gravity along +x: a line from A with 40 kg at its free end B hangs along +x, stretched
    # by T(s)/EA with T(s) = M g + w (L0 - s)
    L0, EA, m, M, g = 12.0, 5e4, 0.8, 40.0, 9.81
    text = cable_scene(gravity=[g, 0.0, 0.0], B=(11.0, 0.0, 3.0), L0=L0, EA=EA, mass=m,
                       elements=3, material="s", supports=("A",),
                       extra=point_mass("end", M, node="B"), steps=static_step("s"))
    ds = catdae.run(catdae.load_case(text))["s"].ds
    w = m * g
    for node, s in (("c.1", 4.0), ("c.2", 8.0), ("B", 12.0)):
        x = s + ((M * g + w * L0) * s - 0.5 * w * s * s) / EA
        assert ds.position.sel(node=node).values == pytest.approx([x, 0.0, 0.0], abs=1e-10)
    assert ds.reaction.sel(node="A").values == pytest.approx([-(M * g + w * L0), 0, 0],
                                                             abs=1e-8)


def test_partial_supports_must_stay_coordinate_constraints():
    R = rotation([1.0, 2.0, 0.5], 0.7)
    g = R @ np.array([0.0, 0.0, -9.81])
    with pytest.raises(CaseError) as err:
        catdae.load_case(scene(R, g, supports=("A", 'B = ["y"]'), motion=False))
    assert "pin the node" in dict(err.value.problems)["supports.B"]
    # gravity along -y: a support fixing z (perpendicular to gravity) is fine
    text = scene(np.eye(3), [0.0, -9.81, 0.0], supports=("A", 'B = ["x", "z"]'), motion=False)
    assert catdae.load_case(text).gravity_direction == (0.0, -1.0, 0.0)


@pytest.mark.parametrize(("value", "fragment"), [
    ([0.0, 9.81], "vector [gx, gy, gz] of 3 finite numbers"),
    ("down", "expected a number >= 0"),
    (-9.81, "expected a value >= 0"),
])
def test_bad_gravity_names_the_field(value, fragment):
    with pytest.raises(CaseError) as err:
        catdae.load_case(scene(np.eye(3), value, motion=False))
    assert fragment in dict(err.value.problems)["gravity"]


def test_a_partial_support_reacts_on_its_fixed_axes_under_a_gravity_vector():
    """B held in x and z only (upright), the same scene turned so that up is y and B is held in
    x and y: its reaction is the upright one turned, NaN only on the axis it leaves free (the
    NaN of the free local axis spread to all three global ones), in the static and the
    transient step."""
    R = rotation([1.0, 0.0, 0.0], np.pi / 2)
    held = np.abs(R @ np.array([1.0, 0.0, 1.0])) > 0.5
    turned_axes = [a for a, h in zip("xyz", held, strict=True) if h]
    a = catdae.run(catdae.load_case(scene(np.eye(3), 9.81, supports=("A", 'B = ["x", "z"]'),
                                          motion=False)))
    b = catdae.run(catdae.load_case(scene(R, R @ np.array([0.0, 0.0, -9.81]), supports=(
        "A", f"B = {turned_axes!r}".replace("'", '"')), motion=False)))
    for step in ("s", "t"):
        up = a[step].ds.reaction.sel(node="B").values  # NaN on y, the free axis
        want = np.where(np.isnan(up), 0.0, up) @ R.T
        want[..., ~held] = np.nan
        got = b[step].ds.reaction.sel(node="B").values
        assert np.array_equal(np.isnan(got), np.isnan(want))
        assert np.isfinite(got).sum() == 2 * got.size // 3  # two axes held
        assert np.allclose(got, want, rtol=1e-6, atol=1e-6 * np.nanmax(np.abs(want)),
                           equal_nan=True)


def test_mode_shapes_have_a_largest_component_of_one_in_the_case_axes(upright):
    R = rotation([1.0, 2.0, 0.5], 0.7)
    turned = catdae.run(catdae.load_case(scene(R, R @ np.array([0.0, 0.0, -9.81]))))
    shape = turned["m"].ds["shape"].values.reshape(4, -1)
    top = shape[np.arange(4), np.abs(shape).argmax(axis=1)]
    assert np.allclose(top, 1.0, rtol=0, atol=1e-12)
    want = (upright["m"].ds["shape"].values @ R.T).reshape(4, -1)
    want /= want[np.arange(4), np.abs(want).argmax(axis=1)][:, None]
    f = upright["m"].ds.frequency.values
    single = [k for k in range(4) if np.min(np.abs(np.delete(f, k) / f[k] - 1)) > 1e-6]
    assert single  # compare the shapes of the modes that are not one of a degenerate pair
    assert np.allclose(shape[single], want[single], atol=1e-8)
    assert "case" in turned["m"].ds.axis.attrs["long_name"]
