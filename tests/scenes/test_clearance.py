"""Clearance of a span above ``[ground]`` (issue 23): a level ground at an elevation, or a
profile of heights z at x. The reference is Irvine's elastic catenary (tests/reference.py), its
curve x(s), z(s) searched here for the least height above the ground."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

import catdae
from catdae.cli import main
from catdae.errors import CaseError

from reference import irvine_catenary
from scene_toml import cable_scene, section, static_step, step

EA, MASS, G, L0 = 2.0e7, 2.0, 9.81, 104.0

def case(ground: dict, gravity=None) -> str:
    """The span from A (z = 30 m) to B (100 m along, 20 m up) over a ``[ground]`` of the given
    fields: a static step "st" and a short transient "sway"."""
    return cable_scene(A=(0.0, 0.0, 30.0), B=(100.0, 0.0, 50.0), L0=L0, EA=EA, mass=MASS,
                       elements=8, gravity=gravity, extra=section("ground", **ground),
                       steps=static_step("st") + step("transient", "sway", duration=0.3,
                                                      output_interval=0.01))


def least_gap(ground):
    ref = irvine_catenary(100.0, 20.0, L0, EA, MASS * G)

    def gap(s):
        x, z = ref["x"](np.atleast_1d(s))
        return float(30.0 + z[0] - ground(x[0]))

    s = np.linspace(0.0, L0, 2001)
    x, z = ref["x"](s)
    k = int(np.argmin(30.0 + z - np.array([ground(v) for v in x])))
    best = minimize_scalar(gap, bounds=(s[max(k - 1, 0)], s[min(k + 1, s.size - 1)]),
                           method="bounded", options={"xatol": 1e-12})
    return best.fun, best.x


@pytest.mark.parametrize(("table", "ground"), [
    ({"elevation": 12.5}, lambda x: 12.5),
    ({"x": [-10.0, 40.0, 120.0], "z": [5.0, 20.0, 33.0]},
     lambda x: float(np.interp(x, [-10.0, 40.0, 120.0], [5.0, 20.0, 33.0]))),
])
def test_clearance_against_the_catenary(table, ground):
    tree = catdae.run(catdae.load_case(case(table)), progress=False)
    st = tree["st"].ds.sel(cable="c")
    gap, s = least_gap(ground)
    assert float(st.clearance) == pytest.approx(gap, rel=1e-9)
    assert float(st.clearance_s) == pytest.approx(s, abs=1e-4)
    tr = tree["sway"].ds
    # transient: the least over the output times at the nodes
    height = tr.position.sel(axis="z").values - np.vectorize(ground)(
        tr.position.sel(axis="x").values)
    assert float(tr.clearance.sel(cable="c")) == pytest.approx(height.min(), rel=1e-14)
    k_t = np.unravel_index(np.argmin(height), height.shape)[0]
    assert float(tr.clearance_time.sel(cable="c")) == tr.time.values[k_t]


@pytest.mark.parametrize(("table", "where", "words"), [
    ({"elevation": 1.0, "x": [0.0, 1.0], "z": [0.0, 0.0]}, "ground", "not both"),
    ({}, "ground", "not neither"),
    ({"x": [0.0, 1.0]}, "ground.z", "missing"),
    ({"x": [0.0, 0.0], "z": [1.0, 2.0]}, "ground.x", "strictly increasing"),
    ({"x": [0.0, 1.0, 2.0], "z": [1.0, 2.0]}, "ground", "same length"),
])
def test_bad_grounds(table, where, words, tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(case(table))
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"{where}:" in err and words in err, err
    with pytest.raises(CaseError):
        catdae.load_case(path)


def documented_frame(up) -> np.ndarray:
    """Q = (e1, e2, up) as columns, from docs/case-format.md ("Water and air"): e1 the first of
    +x, +y, +z perpendicular to g, else the axis most nearly perpendicular to g projected onto
    the plane normal to it; e2 = up × e1. Q turns the upright scene (x, y, z) onto (e1, e2, up)."""
    up = np.asarray(up, float) / np.linalg.norm(up)
    axes = np.eye(3)
    perp = [e for e in axes if abs(e @ up) <= 1e-12]
    if perp:
        e1 = perp[0]
    else:
        e = axes[int(np.argmin(np.abs(up)))]
        e1 = (e - (e @ up) * up) / np.linalg.norm(e - (e @ up) * up)
    return np.column_stack([e1, np.cross(up, e1), up])


PROFILE = {"x": [-10.0, 40.0, 120.0], "z": [5.0, 20.0, 33.0]}


@pytest.mark.parametrize("up", [(-1.0, 0.0, 0.0), (0.3, -0.5, 0.8)], ids=["g+x", "oblique"])
def test_a_profile_under_a_gravity_vector_is_the_upright_answer(up):
    # the span turned by Q with its gravity, the profile's stations along e1 and heights along
    # up: statics (least height on the exact curve, where) to 1e-9 of the upright scene, the
    # transient's least node height equal to the closed form from its own positions
    Q = documented_frame(up)
    a = catdae.run(catdae.load_case(case(PROFILE)), progress=False)
    turned = cable_scene(A=Q @ np.array([0.0, 0.0, 30.0]), B=Q @ np.array([100.0, 0.0, 50.0]),
                         L0=L0, EA=EA, mass=MASS, elements=8,
                         gravity=list(Q @ np.array([0.0, 0.0, -G])),
                         extra=section("ground", **PROFILE),
                         steps=static_step("st") + step("transient", "sway", duration=0.3,
                                                        output_interval=0.01))
    b = catdae.run(catdae.load_case(turned), progress=False)
    sa, sb = a["st"].ds.sel(cable="c"), b["st"].ds.sel(cable="c")
    gap, _ = least_gap(lambda x: float(np.interp(x, PROFILE["x"], PROFILE["z"])))
    assert float(sa.clearance) == pytest.approx(gap, rel=1e-9)
    assert abs(gap - least_gap(lambda x: 5.0)[0]) > 1.0  # the stations matter in this scene
    assert float(sb.clearance) == pytest.approx(float(sa.clearance), rel=1e-9)
    # where: the argument of a minimum, known to the square root of the round-off (1.3e-7 m
    # on the oblique turn)
    assert float(sb.clearance_s) == pytest.approx(float(sa.clearance_s), abs=1e-7 * L0)
    np.testing.assert_allclose(b["st"].ds.position.values, a["st"].ds.position.values @ Q.T,
                               rtol=0, atol=1e-9 * 100.0)
    tb = b["sway"].ds
    x = tb.position.transpose("time", "node", "axis").values
    height = x @ Q[:, 2] - np.interp(x @ Q[:, 0], PROFILE["x"], PROFILE["z"])
    assert float(tb.clearance.sel(cable="c")) == pytest.approx(height.min(), rel=1e-12)
    assert float(tb.clearance.sel(cable="c")) == pytest.approx(
        float(a["sway"].ds.clearance.sel(cable="c")), rel=1e-9)
