"""Sweeps (``catdae.case.sweep``): a step repeated over the values of one field, as one group
with a ``sweep`` dimension; bad sweeps get a located message."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

import catdae
from catdae.case import case_from_dict

from scene_toml import damper, load, point_mass, scene, spring, step

SPRING = scene(head={"title": "a weight on a spring", "gravity": 0.0}, materials={},
               nodes={"G": (0.0, 0.0, 0.0), "N": (0.0, 0.0, -1.0)},
               supports=("G", 'N = ["x", "y"]'), cables="",
               extra=(spring("k", ["G", "N"], 1000.0) + damper("d", ["G", "N"], 10.0)
                      + point_mass("m", 4.0, node="N") + load("P", [0.0, 0.0, -100.0], node="N")))


def test_load_factor_and_coefficient_sweeps_against_closed_forms():
    """A mass m on a spring k (rest length 1 m, along z) under a load f P: the spring stretches
    by f P / k exactly; the damped mode has ζ = c / (2 √(k m)) whatever the stretch (the spring
    and damper act along the same line), for each swept coefficient."""
    text = SPRING + step("static", "loads",
                         sweep={"field": "load_factor", "values": [0.5, 1.0, 2.0]}) + step(
        "modal", "modes", modes=1,
        sweep={"field": "dampers.d.coefficient", "values": [0.0, 10.0, 40.0]})
    tree = catdae.run(case_from_dict(tomllib.loads(text)))
    st = tree["loads"].ds
    assert st.sweep.attrs["units"] == "1" and st.attrs["sweep_field"] == "load_factor"
    f = st.sweep.values
    assert np.allclose(f, [0.5, 1.0, 2.0])
    z = st.position.sel(node="N", axis="z").values
    assert np.allclose(z, -(1.0 + f * 100.0 / 1000.0), rtol=0, atol=1e-12)
    assert np.allclose(st.connector_force.sel(connector="k").values, f * 100.0, rtol=1e-12)
    md = tree["modes"].ds
    c = md.sweep.values
    assert md.sweep.attrs["units"] == "N s/m"
    zeta = md.damping_ratio.sel(mode=1).values
    assert np.allclose(zeta, c / (2 * np.sqrt(1000.0 * 4.0)), rtol=1e-10, atol=1e-14)
    w = np.sqrt(1000.0 / 4.0)
    assert np.allclose(md.frequency.sel(mode=1).values,
                       w * np.sqrt(1 - zeta**2) / (2 * np.pi), rtol=1e-10)


@pytest.mark.parametrize(("sweep", "field", "words"), [
    ({"field": "dampers.nobody.coefficient", "values": [1.0]}, "steps[0].sweep.field",
     "unknown damper 'nobody'"),
    ({"field": "dampers.d.colour", "values": [1.0]}, "steps[0].sweep.field",
     "expected one of ['temperature_change', 'load_factor'"),
    ({"field": "dampers.d.coefficient", "values": [1.0, -2.0]}, "steps[0].sweep.values[1]",
     "expected a value >= 0 for dampers.d.coefficient, found the number -2.0"),
    ({"field": "load_factor", "values": []}, "steps[0].sweep.values",
     "expected a non-empty list of finite numbers"),
])
def test_bad_sweeps_are_located(sweep, field, words, tmp_path, capsys):
    from catdae.cli import main

    f = tmp_path / "bad.toml"
    f.write_text(SPRING + step("static", sweep=sweep))
    assert main(["check", str(f)]) == 2
    err = capsys.readouterr().err
    assert f"{f}: {field}: {words}" in err, err
