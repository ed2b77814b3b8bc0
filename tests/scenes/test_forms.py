"""Form-finding: a cable gives ``form = { ... }`` instead of ``length``.

Each found unstrained length is checked against an independent reference: Irvine's elastic
catenary (``tests/reference.py``, its own brentq solve) run with that length must show the
target; a weightless pretensioned bar must carry exactly its pretension; a net's free node must
balance the pulls Irvine's catenary gives for each cable at the reported positions.
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

import catdae
from catdae.errors import CaseError

from reference import irvine_catenary, irvine_catenary_inclined_3d
from scene_toml import cable, load, point_mass, scene, static_step, step

EA, MASS, G = 2.0e7, 2.0, 9.81
W = MASS * G


def one_cable(fields: dict, B=(100.0, 0.0, 20.0), elements=8, extra="", steps=None,
              weight=None):
    """Cable c from A to B, both pinned, with the cable ``fields`` (its ``form``, or whatever a
    bad case gives) in place of a length; by default two static steps, "found" and "again"."""
    steps = steps if steps is not None else static_step("found") + static_step("again")
    return scene(materials={"s": {"EA": EA, "mass": MASS, "weight": weight}},
                 nodes={"A": (0.0, 0.0, 0.0), "B": B},
                 cables=cable("c", ("A", "B"), "s", **fields, elements=elements),
                 extra=extra, steps=steps)


@pytest.mark.parametrize(("form", "key", "target"), [
    ({"form": {"horizontal_tension": 5000.0}}, "H", 5000.0),
    ({"form": {"tension": 6000.0, "at": "B"}}, "T_j", 6000.0),
    ({"form": {"tension": 5700.0, "at": "A"}}, "T_i", 5700.0),
    ({"form": {"sag": 3.0}}, "sag", 3.0),
])
def test_single_cable_target_against_irvine(form, key, target):
    tree = catdae.run(catdae.load_case(one_cable(form)))
    ds = tree["found"].ds
    L0 = float(ds.unstrained_length[0])
    ref = irvine_catenary(100.0, 20.0, L0, EA, W)
    assert ref[key] == pytest.approx(target, rel=1e-8)
    # the static results say the same, and later steps keep the length
    assert float(tree["again"].ds.unstrained_length[0]) == L0
    assert float(tree["again"].ds.horizontal_tension[0]) == pytest.approx(ref["H"], rel=1e-9)
    assert float(tree["again"].ds.sag[0]) == pytest.approx(ref["sag"], rel=1e-8)


def test_pretension_is_the_straight_member_convention():
    # weightless and taut: the tension is exactly the pretension, L0 = chord / (1 + T/EA)
    T, chord = 3.0e4, math.hypot(10.0, 4.0)
    text = one_cable({"form": {"pretension": 3.0e4}}, B=(10.0, 0.0, 4.0), elements=3,
                     steps=static_step("found"), weight=0.0)
    ds = catdae.run(catdae.load_case(text))["found"].ds
    assert float(ds.unstrained_length[0]) == pytest.approx(chord / (1 + T / EA), rel=1e-14)
    assert ds.tension.values == pytest.approx(T, rel=1e-10)


def test_a_net_is_found_together():
    # two cables meet at a free node N carrying 200 kg; cable a sets its horizontal tension,
    # cable b its sag: both lengths depend on both targets through N
    text = scene(materials={"s": {"EA": EA, "mass": MASS}},
                 nodes={"A": (0.0, 0.0, 10.0), "N": (20.0, 5.0, 0.0), "B": (45.0, 0.0, 12.0)},
                 cables=[cable("a", ("A", "N"), "s", form={"horizontal_tension": 4000.0},
                               elements=6),
                         cable("b", ("N", "B"), "s", form={"sag": 0.4}, elements=6)],
                 extra=point_mass("m", 200.0, node="N"), steps=static_step("found"))
    ds = catdae.run(catdae.load_case(text))["found"].ds
    L_a, L_b = (float(v) for v in ds.unstrained_length.values)
    X = {n: ds.position.sel(node=n).values for n in ("A", "N", "B")}
    a = irvine_catenary_inclined_3d(X["A"], X["N"], L_a, EA, W)
    b = irvine_catenary_inclined_3d(X["N"], X["B"], L_b, EA, W)
    assert a["planar"]["H"] == pytest.approx(4000.0, rel=1e-8)
    assert b["planar"]["sag"] == pytest.approx(0.4, rel=1e-7)
    # N is in equilibrium: a pulls it with -t_B(a), b with +h(b), gravity with -200 g
    force = -a["t_B"] + b["h"] + np.array([0.0, 0.0, -200.0 * G])
    assert np.abs(force).max() <= 1e-8 * 200.0 * G


def check_cli(text, tmp_path, *args):
    path = tmp_path / "case.toml"
    path.write_text(text)
    out = subprocess.run([sys.executable, "-m", "catdae", *args, str(path)],
                         capture_output=True, text=True, cwd=tmp_path)
    return out.returncode, out.stderr


@pytest.mark.parametrize(("form", "field", "fragments"), [
    ({"form": {"tension": 100.0, "at": "B"}}, "cables[0].form.tension",
     ["cable 'c'", "cannot be reached", "at least"]),
    ({"form": {"sag": 1.0e4}}, "cables[0].form.sag", ["cable 'c'", "beyond what the cable"]),
    ({"form": {"horizontal_tension": 2.0e7}}, "cables[0].form.horizontal_tension",
     ["cable 'c'", "strain above 50%"]),
])
def test_unreachable_targets_are_invalid_input(form, field, fragments, tmp_path):
    code, err = check_cli(one_cable(form), tmp_path, "check")
    assert code == 2, err
    assert f"case.toml: {field}: " in err
    for f in fragments:
        assert f in err
    with pytest.raises(CaseError):
        catdae.run(catdae.load_case(one_cable(form)))


def test_targets_a_net_cannot_reach_together():
    # two cables in series through a free node N with no horizontal load on it: horizontal
    # equilibrium of N makes their horizontal tensions equal, so only equal targets are
    # reachable; each target alone is (the single-cable scan finds a start for both)
    def text(h_b):
        return scene(materials={"s": {"EA": EA, "mass": MASS}},
                     nodes={"A": (0.0, 0.0, 0.0), "N": (20.0, 0.0, -1.0), "B": (40.0, 0.0, 0.0)},
                     supports=("A", "B", 'N = ["y"]'),
                     cables=[cable("a", ("A", "N"), "s", form={"horizontal_tension": 1000.0},
                                   elements=2),
                             cable("b", ("N", "B"), "s", form={"horizontal_tension": h_b},
                                   elements=2)],
                     steps=static_step("found"))

    ds = catdae.run(catdae.load_case(text(1000.0)))["found"].ds
    assert ds.horizontal_tension.values == pytest.approx(1000.0, rel=1e-8)
    with pytest.raises(CaseError) as err:
        catdae.run(catdae.load_case(text(1500.0)))
    msg = str(err.value)
    assert "cannot be reached" in msg and "together" in msg
    assert "cables[" in msg and "form.horizontal_tension" in msg


@pytest.mark.parametrize(("form", "extra", "path", "fragment"), [
    ({"length": 100.0, "form": {"sag": 2.0}}, "", "cables[0]", "either length or form"),
    ({"form": {"sag": 2.0, "tension": 10.0}}, "", "cables[0].form", "exactly one of"),
    ({"form": {"tension": 10.0}}, "", "cables[0].form.at", "missing"),
    ({"form": {"tension": 10.0, "at": "Q"}}, "", "cables[0].form.at", "expected an end"),
    ({"form": {"sag": 2.0, "at": "A"}}, "", "cables[0].form.at", "tension"),
    ({"form": {"sagg": 2.0}}, "", "cables[0].form.sagg", "did you mean 'sag'"),
    ({"form": {"sag": -2.0}}, "", "cables[0].form.sag", "> 0"),
    ({"form": 3.0}, "", "cables[0].form", "expected a table"),
    ({"form": {"sag": 2.0}}, load("p", [0.0, 0.0, -1.0], cable="c", s=3.0), "loads[0].s",
     "mesh node"),
])
def test_bad_form_names_the_field(form, extra, path, fragment):
    with pytest.raises(CaseError) as err:
        catdae.load_case(one_cable(form, extra=extra))
    found = dict(err.value.problems)
    assert path in found, found
    assert fragment in found[path]


def test_form_finding_needs_a_static_first_step():
    text = one_cable({"form": {"sag": 2.0}}, steps=step("modal", modes=2))
    with pytest.raises(CaseError) as err:
        catdae.load_case(text)
    assert "expected a static step first" in dict(err.value.problems)["steps[0].kind"]


def test_sap2000_prestressed_cable_net_7_003():
    # SAP2000 verification example 7-003 (Tibert 1999, comparison example 3): a net of four
    # intersection points on a 100 ft grid, held by eight inclined members to supports
    # f = 30 ft above them and joined by four horizontal members; E A = 0.227 in² x 12000 ksi,
    # self-weight 1e-4 kip/ft, prestress 5.459 kip (horizontal) and 5.325 kip (inclined) in
    # the straight-member convention, 8 kip down at each intersection point. Consistent
    # units: ft, kip. Published, SAP2000: (-0.1328, -0.1328, -1.4745) ft at node 1 (Tibert's
    # own elastic catenary gives -1.4764 ft in z, a 0.13 % different reading of the prestress)
    nodes = {"n1": (100, 100, 0), "n2": (200, 100, 0), "n3": (100, 200, 0),
             "n4": (200, 200, 0), "a1": (0, 100, 30), "a2": (300, 100, 30),
             "a3": (0, 200, 30), "a4": (300, 200, 30), "b1": (100, 0, 30),
             "b2": (200, 0, 30), "b3": (100, 300, 30), "b4": (200, 300, 30)}
    members = [("a1", "n1"), ("n2", "a2"), ("a3", "n3"), ("n4", "a4"), ("b1", "n1"),
               ("n3", "b3"), ("b2", "n2"), ("n4", "b4")]
    horizontal = [("n1", "n2"), ("n3", "n4"), ("n1", "n3"), ("n2", "n4")]
    pretensions = [(m, 5.325) for m in members] + [(m, 5.459) for m in horizontal]
    text = scene(materials={"s": {"EA": 2724.0, "mass": 1.0, "weight": 1e-4}},
                 nodes={k: [float(v) for v in x] for k, x in nodes.items()},
                 supports=[k for k in nodes if k[0] in "ab"],
                 cables=[cable(f"m{k}", ends, "s", form={"pretension": T}, elements=2)
                         for k, (ends, T) in enumerate(pretensions)],
                 extra="".join(load(f"p{k}", [0.0, 0.0, -8.0], node=f"n{k}")
                               for k in range(1, 5)),
                 steps=static_step("loaded"))
    ds = catdae.run(catdae.load_case(text))["loaded"].ds
    u = ds.displacement.sel(node=["n1", "n2", "n3", "n4"]).values
    sign = np.array([[1, 1, 1], [-1, 1, 1], [1, -1, 1], [-1, -1, 1]])  # the net's symmetry
    assert u * sign == pytest.approx(np.tile([-0.1328, -0.1328, -1.4745], (4, 1)), abs=5e-5)
