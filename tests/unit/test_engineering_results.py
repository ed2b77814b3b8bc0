"""Engineering results and the case fields behind them (issue 23): transient envelopes over
the output times, ``rated_strength``, ``reference_temperature`` with a step's ``temperature``,
``jump_reference``; bad input gets the field path and what was expected."""

from __future__ import annotations

import numpy as np
import pytest

import catdae
from catdae.cli import main
from catdae.errors import CaseError

BASE = """
{top}
[materials.m]
EA = 1.0e6
mass = 1.0
{material}
[nodes]
A = [0.0, 0.0, 0.0]
B = [10.0, 0.0, 0.0]
[supports]
A = "pinned"
B = "pinned"
[[cables]]
name = "c"
ends = ["A", "B"]
material = "m"
length = 10.5
elements = 6
[[loads]]
name = "kick"
node = "c.3"
force = [0.0, 40.0, -30.0]
time = {{ kind = "ramp", duration = 0.05 }}
{steps}
"""

TRANSIENT = """
[[steps]]
kind = "static"
name = "rest"
[[steps]]
kind = "transient"
name = "kicked"
duration = 0.6
output_interval = 0.01
"""


def case(top="", material="", steps=TRANSIENT):
    return BASE.format(top=top, material=material, steps=steps)


@pytest.fixture(scope="module")
def kicked():
    return catdae.run(catdae.load_case(case(material="rated_strength = 2000.0",
                                            steps=TRANSIENT + 'jump_reference = "rest"\n')),
                      progress=False)


def test_envelopes_are_the_extremes_of_the_stored_histories(kicked):
    ds = kicked["kicked"].ds
    t = ds.time.values
    for var in ("reaction", "displacement"):
        v = ds[var].values
        for how, pick in (("max", np.nanargmax), ("min", np.nanargmin)):
            env, when = ds[f"{var}_{how}"].values, ds[f"{var}_{how}_time"].values
            for n in range(ds.node.size):
                for a in range(3):
                    col = v[:, n, a]
                    if np.isnan(col).all():  # reactions at free nodes
                        assert np.isnan(env[n, a]) and np.isnan(when[n, a])
                        continue
                    k = pick(col)
                    assert env[n, a] == col[k] and when[n, a] == t[k]
    assert ds.reaction_max.attrs["units"] == "N" and ds.reaction_max_time.attrs["units"] == "s"
    # supports: the sideways kick pulls both supports towards +y at some time
    assert float(ds.reaction_min.sel(node="A", axis="y")) < 0.0


def test_tension_against_the_rated_strength_and_the_jump(kicked):
    ds = kicked["kicked"].ds
    t_max = float(ds.tension.max())
    assert float(ds.tension_percent_rated.sel(cable="c")) == pytest.approx(
        100 * t_max / 2000.0, rel=1e-14)
    rest = kicked["rest"].ds
    rise = (ds.position.sel(axis="z") - rest.position.sel(axis="z")).max().item()
    assert float(ds.jump_height.sel(cable="c")) == pytest.approx(rise, rel=1e-14)
    assert rest.tension_max_along_cable.sel(cable="c").item() == pytest.approx(
        float(rest.tension.max()), rel=1e-14)


def test_without_rated_strength_no_percentage():
    tree = catdae.run(catdae.load_case(case(steps='[[steps]]\nkind = "static"\nname = "s"\n')))
    assert "tension_percent_rated" not in tree["s"].ds


def test_temperature_is_measured_from_the_reference_temperature():
    c = catdae.load_case(case(top="reference_temperature = 15.0", steps=(
        '[[steps]]\nkind = "static"\nname = "hot"\ntemperature = 55.0\n'
        '[[steps]]\nkind = "static"\nname = "per_cable"\ntemperature = { c = -5.0 }\n')))
    assert c.steps[0].temperature_change == 40.0
    assert dict(c.steps[1].temperature_change) == {"c": -20.0}
    assert c.reference_temperature == 15.0


@pytest.mark.parametrize(("top", "steps", "where", "words"), [
    ("", '[[steps]]\nkind = "static"\ntemperature = 30.0\n', "steps[0].temperature",
     "needs the case's reference_temperature"),
    ("reference_temperature = 15.0",
     '[[steps]]\nkind = "static"\ntemperature = 30.0\ntemperature_change = 3.0\n',
     "steps[0].temperature", "not both"),
    ("reference_temperature = 15.0", '[[steps]]\nkind = "static"\ntemperature = "hot"\n',
     "steps[0].temperature", "expected a temperature (the units"),
    ("", TRANSIENT + 'jump_reference = "rst"\n', "steps[1].jump_reference",
     "did you mean 'rest'"),
    ("", '[[steps]]\nkind = "modal"\nname = "m"\n' + TRANSIENT.replace("rest", "r") +
     'jump_reference = "m"\n', "steps[2].jump_reference", "static step"),
])
def test_bad_fields_are_named(top, steps, where, words, tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(case(top=top, steps=steps))
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert where in err and words in err, err
    with pytest.raises(CaseError):
        catdae.load_case(path)


def test_rated_strength_must_be_positive(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(case(material="rated_strength = -3.0",
                         steps='[[steps]]\nkind = "static"\n'))
    assert main(["check", str(path)]) == 2
    assert "materials.m.rated_strength" in capsys.readouterr().err


def test_figures_show_the_envelopes(kicked, tmp_path):
    from catdae.output import plot
    from catdae.output.plot_envelopes import reactions

    ds = kicked["kicked"].ds
    fig = plot.history(ds, "c@1/2")
    marks = {ln.get_gid(): ln for ax in fig.axes for ln in ax.get_lines()}
    for a in ("x", "y", "z"):
        for how in ("max", "min"):
            ln = marks[f"c.3|{a}|{how}"]
            assert ln.get_xdata()[0] == float(ds[f"displacement_{how}_time"].sel(node="c.3",
                                                                                 axis=a))
            assert ln.get_ydata()[0] == float(ds[f"displacement_{how}"].sel(node="c.3", axis=a))
    fig = reactions(ds)
    gids = {ln.get_gid() for ax in fig.axes for ln in ax.get_lines()}
    assert {"A|y", "B|y", "A|y|max", "B|z|min"} <= gids
    assert not any(g.startswith("c.") for g in gids)  # free nodes have no reaction
    path = tmp_path / "r.nc"
    from catdae.output.results import write_tree

    write_tree(kicked, path)
    assert main(["plot", str(path), "-o", str(tmp_path / "p"), "--what", "reactions"]) == 0
    assert (tmp_path / "p" / "kicked-reactions.png").is_file()
