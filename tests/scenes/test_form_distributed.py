"""A distributed load on a cable whose length comes from ``form = {...}`` (issue 23, defect 1).

An iced or wind-loaded conductor strung to a tension is the most natural line case: the load
covers the whole cable, whose length is not known until the first static step finds it. The
reference is Irvine's elastic catenary (``tests/reference.py``, its own brentq solve) with the
weight plus the ice per unstrained metre: run with the found length it must show the target.
"""

from __future__ import annotations

import pytest

import catdae
from catdae.cli import main
from catdae.errors import CaseError

from reference import irvine_catenary
from scene_toml import cable, distributed_load, scene, static_step, step

EA, MASS, G, ICE = 2.0e7, 1.6, 9.81, 12.0  # N, kg/m, m/s², N/m


def iced(form: dict, coverage: dict | None = None) -> str:
    """A 200 m span strung to ``form`` under ice over the whole cable (or over ``coverage``:
    from_s, to_s): the static step "iced", then "bare" with the ice removed."""
    return scene(materials={"s": {"EA": EA, "mass": MASS}},
                 nodes={"A": (0.0, 0.0, 0.0), "B": (200.0, 0.0, 10.0)},
                 cables=cable("c", ("A", "B"), "s", form=form, elements=16),
                 extra=distributed_load("c", [0.0, 0.0, -ICE], name="ice", **(coverage or {})),
                 steps=static_step("iced") + step("static", "bare", remove=["ice"]))


@pytest.mark.parametrize(("form", "key", "target"), [
    ({"horizontal_tension": 2.0e4}, "H", 2.0e4),
    ({"tension": 2.2e4, "at": "B"}, "T_j", 2.2e4),
    ({"sag": 6.0}, "sag", 6.0),
])
def test_iced_cable_strung_to_a_target(form, key, target, tmp_path):
    case = tmp_path / "iced.toml"
    case.write_text(iced(form))
    assert main(["check", str(case)]) == 0  # was: TypeError in the coverage check
    tree = catdae.run(case)
    L0 = float(tree["iced"].ds.unstrained_length[0])
    ref = irvine_catenary(200.0, 10.0, L0, EA, MASS * G + ICE)
    # the ice becomes point loads at Gauss points: O(h²), 4e-5 at 16 elements (case-format.md)
    assert ref[key] == pytest.approx(target, rel=2e-4)
    assert float(tree["iced"].ds.horizontal_tension[0]) == pytest.approx(ref["H"], rel=2e-4)
    bare = irvine_catenary(200.0, 10.0, L0, EA, MASS * G)
    assert float(tree["bare"].ds.sag[0]) == pytest.approx(bare["sag"], rel=1e-7)


def test_part_coverage_on_a_found_length_is_refused_clearly():
    text = iced({"horizontal_tension": 2.0e4}, {"from_s": 10.0, "to_s": 50.0})
    with pytest.raises(CaseError) as err:
        catdae.load_case(text)
    msg = str(err.value)
    assert "distributed_loads[0].from_s" in msg and "form-finding" in msg
    assert "distributed_loads[0].to_s" in msg
