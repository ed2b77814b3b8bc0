"""Form-finding (``catdae.model.formfind``): lengths from the tension or sag an engineer knows.

Each length found is put into Irvine's elastic catenary (``tests/reference.py``, its own root
solve), which must show the target: for a cable pinned at both ends with nothing on it the
single-cable scan (``initial_lengths``) is the answer; the Newton loop (``solve``) is driven here
by an evaluation written from Irvine's closed form, from deliberately wrong starting lengths.
Whole scenes (point masses, nets, later steps) are in tests/scenes/test_forms.py.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.optimize import brentq

import catdae
from catdae.errors import CaseError
from catdae.model import formfind

from reference import irvine_catenary
from scene_toml import cable, scene, static_step

EA, MASS, G = 2.0e7, 2.0, 9.81
W = MASS * G
SPAN, DZ = 100.0, 20.0


def form_case(*forms, B=(SPAN, 0.0, DZ)):
    """One cable c per form (c0, c1, ...) from A to B, all alike."""
    nodes = {"A": (0.0, 0.0, 0.0), "B": B}
    return catdae.load_case(scene(
        materials={"s": {"EA": EA, "mass": MASS}}, nodes=nodes,
        cables=[cable(f"c{k}", "AB", "s", None, 4, form=f) for k, f in enumerate(forms)],
        steps=static_step()))


TARGETS = [
    ({"horizontal_tension": 5000.0}, "H", 5000.0),
    ({"tension": 6000.0, "at": "B"}, "T_j", 6000.0),
    ({"tension": 5700.0, "at": "A"}, "T_i", 5700.0),
    ({"sag": 3.0}, "sag", 3.0),
    ({"sag": 30.0}, "sag", 30.0),  # deep: L0 well above the chord
]


@pytest.mark.parametrize(("form", "key", "target"), TARGETS, ids=[t[1] + str(t[2])
                                                                   for t in TARGETS])
def test_single_cable_scan_reaches_each_target(form, key, target):
    case = form_case(form)
    assert formfind.pending(case) == [0] and case.cables[0].length is None
    found = formfind.initial_lengths(case)
    L0 = found.cables[0].length
    # the scan measures a sag as the largest of 257 samples along the cable (the static step's
    # Newton then refines it on the exact curve): to 1e-7; the tensions to round-off
    rel = 1e-7 if key == "sag" else 1e-9
    assert irvine_catenary(SPAN, DZ, L0, EA, W)[key] == pytest.approx(target, rel=rel)


def test_pretension_is_applied_when_the_case_is_read():
    T, B = 3.0e4, (10.0, 0.0, 4.0)
    case = form_case({"pretension": T}, B=B)
    assert formfind.pending(case) == []  # nothing left for the static step
    assert case.cables[0].length == pytest.approx(np.linalg.norm(B) / (1 + T / EA), rel=1e-14)


def test_the_tension_first_falls_then_rises_and_the_taut_length_is_taken():
    # an end tension is met twice along L0 (taut, and deep): the scan takes the shorter length
    found = formfind.initial_lengths(form_case({"tension": 6000.0, "at": "B"}))
    L0 = found.cables[0].length

    def excess(length):
        return irvine_catenary(SPAN, DZ, length, EA, W)["T_j"] - 6000.0

    lengths = L0 * np.geomspace(1.01, 50.0, 60)
    d = np.array([excess(x) for x in lengths])
    assert d.min() < 0.0 < d[-1]  # it falls below the target, then rises above it again
    deep = brentq(excess, lengths[np.argmin(d)], lengths[-1])
    assert L0 < deep
    assert excess(L0) == pytest.approx(0.0, abs=1e-9 * 6000.0)


@pytest.mark.parametrize(("form", "field", "words"), [
    ({"tension": 100.0, "at": "B"}, "cables[0].form.tension", "cannot be reached"),
    ({"horizontal_tension": 1.0e9}, "cables[0].form.horizontal_tension", "strain above"),
    ({"sag": 1.0e4}, "cables[0].form.sag", "beyond what the cable can hang"),
])
def test_unreachable_targets_of_an_isolated_cable_name_the_field(form, field, words):
    with pytest.raises(CaseError) as info:
        formfind.initial_lengths(form_case(form))
    problems = dict(info.value.problems)
    assert field in problems and words in problems[field], problems


def irvine_evaluate(calls):
    """``evaluate`` for ``formfind.solve`` from Irvine's closed form (each cable alone)."""
    def evaluate(trial, warm):
        calls.append(warm)
        sols = [irvine_catenary(SPAN, DZ, c.length, EA, W) for c in trial.cables]
        summary = {"horizontal_tension": np.array([s["H"] for s in sols]),
                   "end_tension": np.array([[s["T_i"], s["T_j"]] for s in sols]),
                   "sag": np.array([s["sag"] for s in sols])}
        return "result", summary
    return evaluate


def test_newton_reaches_every_target_together_from_wrong_lengths():
    forms = [t[0] for t in TARGETS]
    case = form_case(*forms)
    chord = np.hypot(SPAN, DZ)
    start = dataclasses.replace(case, cables=tuple(
        dataclasses.replace(c, length=chord * f) for c, f in
        zip(case.cables, (1.02, 1.001, 1.2, 1.01, 1.05), strict=True)))
    calls = []
    found, result = formfind.solve(start, irvine_evaluate(calls))
    assert result == "result"
    assert calls[0] is None and all(w == "result" for w in calls[1:])  # warm starts after
    for c, (_, key, target) in zip(found.cables, TARGETS, strict=True):
        got = irvine_catenary(SPAN, DZ, c.length, EA, W)[key]
        assert abs(got - target) <= formfind.TOL * target * 1.0001, (c.name, got, target)
    # a handful of Newton iterations of (n + 1) solves each, a few line-search trials
    assert len(calls) <= 12 * (len(forms) + 1)


def test_newton_reports_targets_it_cannot_reach():
    case = form_case({"horizontal_tension": 5000.0})
    start = dataclasses.replace(case, cables=(dataclasses.replace(case.cables[0], length=101.0),))

    def flat(trial, warm):  # a quantity that does not depend on the length
        return None, {"horizontal_tension": np.array([4000.0]),
                      "end_tension": np.zeros((1, 2)), "sag": np.zeros(1)}

    with pytest.raises(CaseError) as info:
        formfind.solve(start, flat)
    message = dict(info.value.problems)["cables[0].form.horizontal_tension"]
    assert "cannot be reached" in message and "4000" in message


def _steep(target: float) -> str:
    """A 100 m span rising 80 m (1.5 kg/m, EA 1e7), its length form-found from the tension at
    its lower end A."""
    return scene(materials={"m": {"EA": 1.0e7, "mass": 1.5}},
                 nodes={"A": [0.0, 0.0, 0.0], "B": [100.0, 0.0, 80.0]},
                 cables=[cable("c", ("A", "B"), "m", None, 8,
                               form={"tension": target, "at": "A"})],
                 steps=static_step("eq"))


def test_a_tension_target_just_above_the_least_one_is_reached():
    """A 100 m span rising 80 m (1.5 kg/m): the tension at the lower end A has a least value
    over the cable's length, 719.171 N at L0 = 153.93 m by an independent tester's own elastic
    catenary. A target of 719.18 N, between two scanned lengths whose tensions are both above
    it, was refused ("at least 719.202 N"); it is reached (at L0 = 153.746 m, the tester's),
    and 719.16 N is refused quoting the least tension to 1e-6."""
    tree = catdae.run(catdae.load_case(_steep(719.18)))
    ds = tree["eq"].ds
    assert float(ds.cable_end_tension.sel(cable="c", end="i")) == pytest.approx(719.18, rel=1e-9)
    assert float(ds.unstrained_length.sel(cable="c")) == pytest.approx(153.746, abs=1e-3)
    with pytest.raises(CaseError) as err:
        catdae.run(catdae.load_case(_steep(719.16)))
    least = float(str(err.value).split("at least ")[1].split(" N")[0])
    assert least == pytest.approx(719.171, abs=2e-3)


def _net(n: int = 3, span: float = 12.0, rise: float = 1.5, target: float = 5000.0) -> str:
    """A hypar-like net: n - 1 lines each way across a square of ``span`` (edge nodes pinned,
    corners left out, the edges' heights ``rise`` (x y) / span² apart), every segment
    between crossings a cable of 2 elements form-found to ``target`` N at its first end."""
    h = span / n
    nodes, cables, pinned = {}, [], []
    for i in range(n + 1):
        for j in range(n + 1):
            if i in (0, n) and j in (0, n):
                continue
            x, y = i * h - span / 2, j * h - span / 2
            nodes[f"N{i}_{j}"] = [i * h, j * h, 4.0 * rise * x * y / span**2]
            if i in (0, n) or j in (0, n):
                pinned.append(f"N{i}_{j}")
    for a in range(1, n):  # lines along x at j = a, along y at i = a
        for b in range(n):
            for name, e0, e1 in ((f"x{a}_{b}", f"N{b}_{a}", f"N{b + 1}_{a}"),
                                 (f"y{a}_{b}", f"N{a}_{b}", f"N{a}_{b + 1}")):
                cables.append(cable(name, (e0, e1), "m", None, 2,
                                    form={"tension": target, "at": e0}))
    return scene(materials={"m": {"EA": 2.0e7, "mass": 2.0}}, nodes=nodes, supports=pinned,
                 cables=cables, steps=static_step("eq"))


def test_a_net_of_tension_targets_is_found_with_few_static_solves(monkeypatch):
    """Every segment of a 3 x 3 net form-found to 5 kN (12 cables solved together). The
    lengths found, given back as plain lengths, reproduce the targets in a fresh static solve;
    the search took a Jacobian by differences (n static solves) once or twice, then Broyden's
    updates: a 6 x 6 net (60 cables) took 14 Jacobians, 881 static solves and a minute."""
    text = _net()
    evaluations = []
    original = formfind.solve

    def counted(case, evaluate):
        def ev(trial, warm):
            evaluations.append(warm is None)
            return evaluate(trial, warm)
        return original(case, ev)

    monkeypatch.setattr(formfind, "solve", counted)
    tree = catdae.run(catdae.load_case(text))
    ds = tree["eq"].ds
    n = ds.sizes["cable"]
    assert n == 12
    first = ds.cable_end_tension.sel(end="i").values
    np.testing.assert_allclose(first, 5000.0, rtol=10 * formfind.TOL)
    assert len(evaluations) <= 3 * (n + 1), len(evaluations)
    assert ds.attrs["form_static_solves"] == len(evaluations)
    # the found lengths as given lengths, without form-finding: the same tensions
    plain = catdae.load_case(text)
    plain = dataclasses.replace(plain, cables=tuple(
        dataclasses.replace(c, length=float(ds.unstrained_length.sel(cable=c.name)), form=None)
        for c in plain.cables))
    again = catdae.run(plain)["eq"].ds
    np.testing.assert_allclose(again.cable_end_tension.sel(end="i").values, 5000.0,
                               rtol=1e-7)
