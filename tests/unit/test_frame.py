"""The gravity frame (``catdae.case.frame``): the rotation that takes gravity to -z.

Checked against the definition of a proper rotation (orthonormal rows, determinant +1), its one
requirement (R ĝ = -z), the promise on supports (gravity along an axis: R permutes the axes up to
sign), and by round trips: a case taken to the frame and its vectors rotated back, a rotated
support motion evaluated against R applied to the global one.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import catdae
from catdae.case.frame import gravity_rotation, local_axes, rotate_back, to_gravity_frame

from scene_toml import cable_scene, damper, load, static_step, step, support_motion

EZ = np.array([0.0, 0.0, 1.0])


def directions():
    """Gravity directions: along each axis either way, in a coordinate plane, along none,
    nearly along an axis, and random ones."""
    out = [s * e for e in np.eye(3) for s in (1.0, -1.0)]
    out += [np.array([1.0, 0.0, -1.0]), np.array([0.0, 3.0, 4.0]), np.array([1.0, 2.0, 0.5]),
            np.array([1e-7, 0.0, -1.0]), np.array([-2.0, -1e-9, 1e-3])]
    rng = np.random.default_rng(11)
    out += list(rng.normal(size=(12, 3)))
    return out


@pytest.mark.parametrize("d", directions(), ids=lambda d: np.array2string(d, precision=3))
def test_rotation_is_proper_and_takes_gravity_to_minus_z(d):
    R = gravity_rotation(d)
    # entries below 1e-12 are set to exactly 0 (so that axis-aligned gravity gives exact zeros):
    # orthonormal to that, not to round-off, when gravity is within 1e-9 of a coordinate plane
    np.testing.assert_allclose(R @ R.T, np.eye(3), rtol=0, atol=2e-12)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=2e-12)
    np.testing.assert_allclose(R @ (d / np.linalg.norm(d)), -EZ, rtol=0, atol=1e-14)
    # the length of the vector does not matter
    np.testing.assert_allclose(gravity_rotation(7.5 * np.asarray(d)), R, rtol=0, atol=1e-15)


def test_default_gravity_is_the_identity_and_axis_gravity_permutes_axes():
    np.testing.assert_array_equal(gravity_rotation([0.0, 0.0, -1.0]), np.eye(3))
    for d in [s * e for e in np.eye(3) for s in (1.0, -1.0)]:
        R = gravity_rotation(d)
        # a signed permutation: every row and column one entry of +-1, the rest exactly 0
        assert set(np.unique(np.abs(R))) == {0.0, 1.0}
        assert (np.abs(R).sum(axis=0) == 1).all() and (np.abs(R).sum(axis=1) == 1).all()
        # so a support fixing any set of axes fixes local coordinate axes
        for axes in (("x",), ("y",), ("z",), ("x", "z"), ("y", "z"), ("x", "y", "z")):
            la = local_axes(R, axes)
            assert la is not None and len(la) == len(axes)
            cols = [int(np.flatnonzero(np.abs(R[:, "xyz".index(a)]))[0]) for a in axes]
            assert sorted("xyz"[c] for c in cols) == list(la)


def test_local_axes_of_an_oblique_rotation():
    R = gravity_rotation([1.0, 2.0, 0.5])  # gravity along no axis: y and z mix with x
    assert local_axes(R, ("x", "y", "z")) == ("x", "y", "z")  # a pinned node stays pinned
    assert local_axes(R, ("y",)) is None
    R = gravity_rotation([0.0, -1.0, 0.0])  # gravity along -y: x and z stay coordinate axes
    assert local_axes(R, ("x", "z")) is not None


def test_rotate_back_inverts_the_rotation_into_the_frame():
    R = gravity_rotation([1.0, -2.0, 0.7])
    rng = np.random.default_rng(3)
    glob = rng.normal(size=(4, 5, 3))
    local = glob @ R.T  # v_local = R v for every vector
    ds = xr.Dataset({"position": (("time", "node", "axis"), local),
                     "tension": (("time", "node"), rng.normal(size=(4, 5)))})
    back = rotate_back(ds, R)
    np.testing.assert_allclose(back.position.values, glob, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(back.tension.values, ds.tension.values)  # scalars untouched
    assert rotate_back(ds, None) is ds


def test_case_in_the_gravity_frame_is_the_rigidly_rotated_case():
    g = np.array([3.0, -1.0, -9.0])
    text = cable_scene(
        gravity="[3.0, -1.0, -9.0]", B=(30.0, 4.0, -5.0), L0=32.0,
        EA=1.0e6, mass=1.5, elements=4, supports=("A", "B"),
        extra=(load("p", [10.0, 300.0, -100.0], node="c.2")
               + support_motion("B", x={"kind": "sine", "amplitude": 0.05, "frequency": 1.0},
                                z={"kind": "ramp", "duration": 0.5, "amplitude": 0.02})),
        steps=static_step())
    case = catdae.load_case(text)
    local, R = to_gravity_frame(case)
    np.testing.assert_allclose(R @ (g / np.linalg.norm(g)), -EZ, atol=1e-14)
    assert local.gravity_direction == (0.0, 0.0, -1.0)
    for n, x in case.nodes.items():
        np.testing.assert_allclose(local.nodes[n], R @ np.array(x), rtol=0, atol=1e-13)
    # distances, hence the cable's chord, are kept
    d0 = np.subtract(case.nodes["B"], case.nodes["A"])
    d1 = np.subtract(local.nodes["B"], local.nodes["A"])
    assert np.linalg.norm(d1) == pytest.approx(np.linalg.norm(d0), rel=1e-15)
    np.testing.assert_allclose(local.loads[0].force, R @ np.array(case.loads[0].force),
                               atol=1e-12)
    assert local.supports["B"] == ("x", "y", "z")
    # the rotated support motion: u_local(t) = R u(t), its rate and acceleration alike
    (gm,), (lm,) = case.support_motions, local.support_motions
    for t in (0.0, 0.13, 0.37, 0.8):
        u = np.zeros((3, 3))
        for a, f in gm.moved():
            u[:, "xyz".index(a)] = f.evaluate(t)
        ul = np.zeros((3, 3))
        for a, f in lm.moved():
            ul[:, "xyz".index(a)] = f.evaluate(t)
        np.testing.assert_allclose(ul, u @ R.T, rtol=0, atol=1e-14)
    # breakpoints of the motion survive the rotation (the ramp ends at 0.5 s)
    assert 0.5 in {b for _, f in lm.moved() for b in f.breakpoints()}


def test_a_case_already_in_the_frame_is_returned_as_it_is():
    case = catdae.load_case(cable_scene(B=(10.0, 0.0, 0.0), L0=10.5, EA=1.0e6, mass=1.0,
                                        elements=2, steps=static_step()))
    local, R = to_gravity_frame(case)
    assert R is None and local is case


def stay_damper(gravity, base) -> str:
    """A 200 m stay with a damper from its first mesh node to the ground node ``base``, and a
    modal step swept over the damper's coefficient."""
    return cable_scene(B=(200.0, 0.0, 0.0), L0=199.62, EA=2.55e9, mass=100.0, elements=20,
                       gravity=gravity, material="strand", cable="stay", nodes={"base": base},
                       supports=("A", "B", "base"),
                       extra=damper("d", ["stay.1", "base"], 1.0e5),
                       steps=static_step() + step("modal", "modes", modes=4, sweep={
                           "field": "dampers.d.coefficient", "values": [1.0e5, 3.0e5]}))


def test_a_swept_modal_step_under_a_gravity_vector_is_the_upright_one_rotated():
    """A tester's stay with a damper and a sweep of its coefficient under gravity = -y crashed
    in rotate_back (swept shapes have one more dimension) and kept nothing. The same scene
    turned upright by the rotation (x, y, z) -> (x, -z, y), which takes -y to -z, must give
    the same frequencies and damping ratios, and the same shapes with the axes relabelled,
    each scaled to a largest component of 1."""
    tilted = catdae.run(stay_damper((0.0, -9.81, 0.0), (10.0, 0.0, 1.0)))["modes"].ds
    upright = catdae.run(stay_damper(None, (10.0, -1.0, 0.0)))["modes"].ds
    for name in ("frequency", "undamped_frequency", "damping_ratio", "undamped_mode"):
        np.testing.assert_allclose(tilted[name].values, upright[name].values, rtol=1e-8)
    perm = [0, 2, 1]  # the tilted frame's (x, y, z) are the upright (x, z, -y)
    sign = np.array([1.0, 1.0, -1.0])

    def scaled(v):  # each shape over its component of largest modulus
        flat = v.reshape(-1, v.shape[-2] * v.shape[-1])
        big = flat[np.arange(flat.shape[0]), np.argmax(np.abs(flat), axis=1)]
        return (flat / big[:, None]).reshape(v.shape)

    a = tilted.shape.values
    np.testing.assert_allclose(a, scaled(upright.shape.values[..., perm] * sign), atol=1e-7)
    zt = tilted.complex_shape.sel(part="real") + 1j * tilted.complex_shape.sel(part="imag")
    zu = upright.complex_shape.sel(part="real") + 1j * upright.complex_shape.sel(part="imag")
    np.testing.assert_allclose(zt.values, scaled(zu.values[..., perm] * sign), atol=1e-7)
    largest = np.abs(zt).max(("node", "axis"))
    np.testing.assert_allclose(largest.values, 1.0, rtol=1e-12)
    assert (np.abs(tilted.shape).max(("node", "axis")).values == pytest.approx(1.0))
    # damped modes are sorted by |s|: at 3e5 N s/m the in-plane mode comes first, and
    # undamped_mode points each at the undamped mode of its own family (plane, symmetry)
    for k in range(tilted.sizes["sweep"]):
        one = tilted.isel(sweep=k)
        like = one.undamped_mode.values - 1
        assert (one.plane.values[like] == one.damped_plane.values).all()
        assert (one.symmetry.values[like] == one.damped_symmetry.values).all()
    assert list(tilted.undamped_mode.isel(sweep=1).values[:2]) == [2, 1]
