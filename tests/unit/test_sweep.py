"""Sweeps (``catdae.case.sweep``): a step repeated over the values of one field, as one group
with a ``sweep`` dimension; bad sweeps get a located message."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

import catdae
import catdae.output.results
from catdae.case import case_from_dict

from scene_toml import damper, load, point_mass, scene, spring, step

SPRING = scene(head={"title": "a weight on a spring", "gravity": 0.0}, materials={},
               nodes={"G": (0.0, 0.0, 0.0), "N": (0.0, 0.0, -1.0)},
               supports=("G", 'N = ["x", "y"]'), cables="",
               extra=(spring("k", ["G", "N"], 1000.0) + damper("d", ["G", "N"], 10.0)
                      + point_mass("m", 4.0, node="N") + load("P", [0.0, 0.0, -100.0], node="N")))


def test_load_factor_and_coefficient_sweeps_against_closed_forms(tmp_path):
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
    path = tmp_path / "sw.nc"  # a coordinate variable has no _FillValue (CF 2.5.1; tester t75)
    catdae.output.results.write_tree(tree, path)
    import netCDF4

    with netCDF4.Dataset(path) as f:
        assert "_FillValue" not in f["loads"]["sweep"].ncattrs()
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
    # a coordinate: sel(sweep=0.5) gave two entries (tester t75; CF wants it monotonic)
    ({"field": "load_factor", "values": [0.5, 2.0, 0.5]}, "steps[0].sweep.values",
     "expected values in strictly increasing or decreasing order"),
])
def test_bad_sweeps_are_located(sweep, field, words, tmp_path, capsys):
    from catdae.cli import main

    f = tmp_path / "bad.toml"
    f.write_text(SPRING + step("static", sweep=sweep))
    assert main(["check", str(f)]) == 2
    err = capsys.readouterr().err
    assert f"{f}: {field}: {words}" in err, err


GUY = scene(head={"title": "a guy line", "reference_temperature": 20.0},
            materials={"guy": {"EA": 5.0e7, "mass": 2.0, "thermal_expansion": 1.2e-5}},
            nodes={"A": (0.0, 0.0, 0.0), "B": (40.0, 0.0, 60.0)}, supports=("A", "B"),
            cables='[[cables]]\nname = "g"\nends = ["A", "B"]\nmaterial = "guy"\n'
                   'length = 72.05\nelements = 4\n')


def test_a_temperature_sweep_is_labelled_and_drawn_per_value(tmp_path, capsys):
    """Each value of a temperature_change sweep carries its own temperature (attributes that
    differ between values are arrays over them, case-format.md): the printed summary, the
    group's attributes, and a value's dataset agree with a step run at that temperature
    alone. The file plots (a figure per value, and the sag-temperature figure across them)
    and exports (a series per value); an ordinary step beside it too."""
    from catdae.cli import main
    from catdae.output.reading import step_values

    values = [-40.0, 0.0, 10.0]
    text = GUY + step("static", "ref") + step(
        "static", "sw", sweep={"field": "temperature_change", "values": values}) + step(
        "static", "hot", temperature_change=10.0)
    case = tmp_path / "guy.toml"
    case.write_text(text)
    out = tmp_path / "guy.nc"
    assert main(["run", str(case), "-o", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    for v in values:
        assert f"[sw temperature_change = {v:g}] static at {20 + v:g} deg" in printed, printed
    tree = catdae.read_results(out)
    sw = tree["sw"].ds
    assert np.array_equal(sw.attrs["temperature_change"], values)
    assert np.array_equal(sw.attrs["temperature"], np.add(values, 20.0))
    # and per cable, one row per value (the guy is the only cable)
    assert sw.temperature.dims == ("sweep", "cable")
    assert np.array_equal(sw.temperature.values[:, 0], np.add(values, 20.0))
    assert np.array_equal(sw.temperature_change.values[:, 0], values)
    (_, last), hot = step_values("sw", sw)[-1], tree["hot"].ds
    assert last.attrs["temperature"] == hot.attrs["temperature"] == 30.0
    assert float(last.cable_end_tension.max()) == pytest.approx(
        float(hot.cable_end_tension.max()), rel=1e-12)
    figs = tmp_path / "figs"
    assert main(["plot", str(out), "-o", str(figs)]) == 0
    names = {p.name for p in figs.iterdir()}
    assert {"sw-sweep0-profile.png", "sw-sweep2-tension.png", "ref-profile.png",
            "spans.png"} <= names, names
    assert main(["plot", str(out), "-o", str(figs), "--step", "hot"]) == 0
    vtk = tmp_path / "vtk"
    assert main(["export", str(out), "--vtk", str(vtk)]) == 0
    assert {"sw-sweep1.pvd", "ref.pvd", "hot.pvd"} <= {p.name for p in vtk.iterdir()}


def test_a_scene_of_connectors_alone_plots_and_exports(tmp_path, capsys):
    """No cable (the spring and damper scene above): the figures and the VTK series are made,
    the connectors drawn between their end nodes (``connector_node``)."""
    import meshio

    from catdae.cli import main

    case = tmp_path / "spring.toml"
    case.write_text(SPRING + step("static", "st"))
    out = tmp_path / "spring.nc"
    assert main(["run", str(case), "-o", str(out), "--no-progress"]) == 0
    ds = catdae.read_results(out)["st"].ds
    assert ds.connector_node.sel(connector="k").values.tolist() == ["G", "N"]
    assert main(["plot", str(out), "-o", str(tmp_path / "figs"), "--what", "profile"]) == 0
    assert main(["export", str(out), "--vtk", str(tmp_path / "vtk")]) == 0
    mesh = meshio.read(tmp_path / "vtk" / "st" / "st_00000.vtu")
    assert sum(len(b.data) for b in mesh.cells) == 2  # the spring and the damper
    force = np.concatenate(mesh.cell_data["tension"])
    assert np.allclose(force, ds.connector_force.values)


def test_a_study_of_a_swept_step_is_refused_before_any_run(tmp_path, capsys):
    from catdae.study.cli import main as study

    case = tmp_path / "swept.toml"
    case.write_text(SPRING + step("static", "st") + step(
        "modal", "modes", modes=1, sweep={"field": "dampers.d.coefficient",
                                          "values": [0.0, 10.0]}))
    assert study([str(case), "--step", "modes", "-o", str(tmp_path / "s.nc")]) == 2
    err = capsys.readouterr().err
    assert f"{case}: steps[1].sweep: the study step 'modes' is swept" in err, err
    assert not (tmp_path / "s.nc").exists()


def test_a_damped_modal_step_whose_every_mode_is_overdamped_is_written():
    """The weight on its spring and damper (k 1000 N/m, m 4 kg) swept over c: below
    c = 2 sqrt(k m) = 126.5 N s/m the mode has ζ = c / (2 sqrt(k m)); at 400 N s/m (ζ 1.58)
    none is underdamped and the mode is NaN with its label (a tester's run crashed there, with
    a traceback and nothing written)."""
    text = SPRING + step("static", "st") + step(
        "modal", "modes", modes=1, sweep={"field": "dampers.d.coefficient",
                                          "values": [10.0, 400.0]})
    md = catdae.run(case_from_dict(tomllib.loads(text)))["modes"].ds
    zeta = md.damping_ratio.sel(mode=1).values
    assert zeta[0] == pytest.approx(10.0 / (2 * np.sqrt(1000.0 * 4.0)), rel=1e-10)
    assert np.isnan(zeta[1]) and np.isnan(md.frequency.sel(mode=1).values[1])
    # and the note of that value says so (tester t68: NaN with no word)
    notes = str(md.attrs.get("note", "")).split(" | ")
    assert "overdamped" not in notes[0] and "1 of the 1 modes asked for are overdamped" in notes[1]


def test_a_modal_step_after_a_load_sweep_is_about_its_own_equilibrium():
    """A static sweep of load_factor leaves the state of its last value (factor 2); the modal
    step after it has the case's loads (factor 1) and was linearised about the factor-2 state,
    out of balance (tester t70: frequencies 0.4-1.0 % off both scenes). It now finds its own
    equilibrium first: the same modes as a modal step after an unswept static step."""
    from scene_toml import cable, modal_step

    def case(sweep: str) -> str:
        return scene(materials={"m": {"EA": 2.0e7, "mass": 1.5}},
                     nodes={"A": (0.0, 0.0, 0.0), "B": (100.0, 0.0, 0.0)},
                     cables=cable("c", ("A", "B"), "m", 100.8, 10),
                     extra=load("lamp", [0.0, 0.0, -500.0], node="c.5"),
                     steps=step("static", "st") + sweep + modal_step(4, name="after"))

    swept = catdae.run(catdae.load_case(case(step(
        "static", "sw", sweep={"field": "load_factor", "values": [0.5, 2.0]}))))
    plain = catdae.run(catdae.load_case(case("")))
    after = swept["after"].ds
    assert "found again" in after.attrs["equilibrium"]
    np.testing.assert_allclose(after.frequency.values, plain["after"].ds.frequency.values,
                               rtol=1e-9)
