"""The line engineer's three scenes of issue 23, from ``catdae run`` and ``catdae plot`` alone
(the bundled cases), each against its closed form or hand calculation (docs/theory.md §14):

- the Drake sag-temperature table (cases/drake_sag_temperature.toml): the elastic catenary of a
  level span with a thermal strain (Irvine 1981 §2.2), solved here by brentq;
- the wind swing (cases/conductor_wind_swing.toml): under its weight w and a uniform wind p
  the span hangs in the plane of the resultant, swung by atan(p/w), where it is the elastic
  catenary under sqrt(w² + p²) (Irvine's, tests/reference.py);
- the ice-shedding jump (cases/ice_shedding.toml): a taut span moves as a string whose
  symmetric modes have frequencies k f1, so half a period 1/(2 f1) after the ice drops it is
  the mirror image of its iced shape about the bare one: the jump above the bare position is
  the sag the ice added.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import catdae
from catdae.cli import main
from catdae.output import plot_spans

from reference import irvine_catenary
from repo_paths import CASES
from scene_toml import cable, cable_scene, scene, static_step
from scene_toml import step as step_block

G = 9.81


def level_span(L0, EA, w, eps_t, span):
    """(sag at midspan, H) of an elastic catenary of unstrained length L0 between level
    supports ``span`` apart, weight w per unstrained metre, stretch 1 + eps_t + T/EA
    (Irvine 1981, §2.2 with a thermal strain): span = H L0/EA + (1 + eps_t) (2H/w)
    asinh(w L0/(2H)), sag = (1 + eps_t) (sqrt(H² + (w L0/2)²) - H)/w + w L0²/(8 EA)."""
    def gap(H):
        return H * L0 / EA + (1.0 + eps_t) * 2.0 * H / w * math.asinh(w * L0 / (2.0 * H)) - span
    H = brentq(gap, 1e-6 * w * L0, 1e3 * w * L0, xtol=1e-13, rtol=1e-15)
    return (1.0 + eps_t) * (math.hypot(H, 0.5 * w * L0) - H) / w + w * L0**2 / (8.0 * EA), H


def run_and_plot(case, tmp_path, what):
    out = tmp_path / f"{case.stem}.nc"
    assert main(["run", str(case), "-o", str(out), "--no-progress"]) == 0
    assert main(["plot", str(out), "-o", str(tmp_path / "plots"), "--what", *what]) == 0
    return catdae.read_results(out)


def test_drake_sag_temperature_table(tmp_path):
    case = CASES / "drake_sag_temperature.toml"
    tree = run_and_plot(case, tmp_path, ["spans"])
    assert (tmp_path / "plots" / "spans.png").is_file()
    c = catdae.load_case(case)
    mat = c.materials["drake"]
    w, ref = mat.mass * G, c.reference_temperature
    steps = [s for s in c.steps]
    assert len(steps) == 12 and ref == 15.0
    L0 = float(tree["strung"].ds.unstrained_length.sel(cable="span"))
    # the stringing target holds in the closed form with the length found
    assert level_span(L0, mat.EA, w, 0.0, 300.0)[1] == pytest.approx(28020.0, rel=1e-9)
    fig = plot_spans.spans(tree)
    drawn = {ln.get_gid(): ln for ax in fig.axes for ln in ax.get_lines()}
    temps = sorted(float(tree[s.name].ds.attrs["temperature"]) for s in steps)
    np.testing.assert_array_equal(drawn["span|sag_midspan"].get_xdata(), temps)
    table = []
    for step in steps:
        ds = tree[step.name].ds
        T = float(ds.attrs["temperature"])
        sag, H = level_span(L0, mat.EA, w, mat.thermal_expansion * (T - ref), 300.0)
        got = ds.sel(cable="span")
        assert float(got.sag_midspan) == pytest.approx(sag, rel=1e-9), T
        assert float(got.sag_lowest_point) == pytest.approx(sag, rel=1e-9), T
        assert float(got.horizontal_tension_along_chord) == pytest.approx(H, rel=1e-9), T
        end = math.hypot(H, 0.5 * w * L0)  # the support carries half the weight
        assert float(got.tension_percent_rated) == pytest.approx(100 * end / 140.1e3, rel=1e-9)
        assert float(got.swing_angle) == pytest.approx(0.0, abs=1e-9)
        assert float(got.clearance) == pytest.approx(30.0 - sag, rel=1e-9)  # ground at 0
        table.append((T, sag))
    table.sort()
    y = drawn["span|sag_midspan"].get_ydata()
    np.testing.assert_allclose(y, [s for _, s in table], rtol=1e-12)
    assert np.all(np.diff(y) > 0)  # hotter, longer, lower


def test_wind_swing_angle(tmp_path):
    case = CASES / "conductor_wind_swing.toml"
    tree = run_and_plot(case, tmp_path, ["spans", "profile"])
    c = catdae.load_case(case)
    mat = c.materials["drake"]
    w, p = mat.mass * G, 8.43
    L0 = float(tree["still"].ds.unstrained_length.sel(cable="span"))
    windy = tree["windy"].ds.sel(cable="span")
    phi = math.degrees(math.atan(p / w))  # 27.83 deg
    tilted = irvine_catenary(300.0, 0.0, L0, mat.EA, math.hypot(w, p))
    # the wind acts at Gauss points, the weight exactly: O(h²), 40 elements
    assert float(windy.swing_angle) == pytest.approx(phi, rel=1e-5)
    assert float(windy.horizontal_tension_along_chord) == pytest.approx(tilted["H"], rel=1e-5)
    assert float(windy.sag_midspan) == pytest.approx(
        tilted["sag"] * math.cos(math.radians(phi)), rel=1e-5)
    # the printed horizontal tension holds the wind's share at the support as well
    assert float(windy.horizontal_tension) == pytest.approx(
        math.hypot(float(windy.horizontal_tension_along_chord), p * L0 / 2), rel=1e-9)
    assert float(tree["still"].ds.swing_angle.sel(cable="span")) == pytest.approx(0, abs=1e-9)


def test_ice_shedding_jump(tmp_path):
    case = CASES / "ice_shedding.toml"
    tree = run_and_plot(case, tmp_path, ["history"])
    c = catdae.load_case(case)
    mat = c.materials["steel"]
    w, ice = mat.mass * G, 5.0
    L0 = float(tree["bare"].ds.unstrained_length.sel(cable="wire"))
    bare = level_span(L0, mat.EA, w, 0.0, 60.0)
    iced = level_span(L0, mat.EA, w + ice, 0.0, 60.0)
    sags = [float(tree[k].ds.sag_midspan.sel(cable="wire")) for k in ("bare", "iced")]
    assert sags[0] == pytest.approx(bare[0], rel=1e-9)
    assert sags[1] == pytest.approx(iced[0], rel=1e-4)  # the ice at Gauss points: O(h²)
    ds = tree["shedding"].ds
    assert ds.attrs["jump_reference"] == "bare"
    jump = ds.sel(cable="wire")
    # the mirror of a string: the jump is the sag the ice added, half a period after it drops
    f1 = math.sqrt(bare[1] / mat.mass) / (2 * 60.0)  # taut string, Irvine's λ² = 0.002
    assert float(jump.jump_height) == pytest.approx(iced[0] - bare[0], rel=3e-3)
    assert float(jump.jump_time) == pytest.approx(0.5 / f1, rel=2e-2)
    assert float(jump.jump_s) == pytest.approx(L0 / 2, abs=L0 / 24)
    # the envelope of the midspan's vertical displacement holds the same peak
    dz = float(ds.displacement_max.sel(node="wire.12", axis="z")
               - tree["bare"].ds.displacement.sel(node="wire.12", axis="z"))
    assert dz == pytest.approx(float(jump.jump_height), rel=1e-12)
    assert float(ds.displacement_max_time.sel(node="wire.12", axis="z")) == float(jump.jump_time)
    assert "may still be growing" not in ds.attrs["note"]  # the peaks are inside the step


def test_a_jump_still_rising_at_the_step_end_is_flagged(tmp_path, capsys):
    """The taut wire of ice_shedding.toml rises until half a period 1/(2 f1) = 0.134 s after
    the ice drops (the string's closed form, above): cut at 0.1 s, its largest rise is at the
    step's last output, and the step's note and the printed jump say it may still be rising.
    The midspan's upward displacement peaks there too (its headline, named in the note)."""
    text = (CASES / "ice_shedding.toml").read_text()
    assert "duration = 0.6\n" in text
    case = tmp_path / "short.toml"
    case.write_text(text.replace("duration = 0.6\n", "duration = 0.1\n"))
    out = tmp_path / "short.nc"
    assert main(["run", str(case), "-o", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    c = catdae.load_case(case)
    L0 = float(catdae.read_results(out)["bare"].ds.unstrained_length.sel(cable="wire"))
    H = level_span(L0, c.materials["steel"].EA, c.materials["steel"].mass * G, 0.0, 60.0)[1]
    f1 = math.sqrt(H / c.materials["steel"].mass) / (2 * 60.0)
    ds = catdae.read_results(out)["shedding"].ds
    end = float(ds.time[-1])
    assert end == pytest.approx(0.1) and end < 0.5 / f1
    assert float(ds.jump_time.sel(cable="wire")) == end
    note = ds.attrs["note"]
    assert "t = 0.1 s" in note and "may still be growing" in note, note
    assert "jump_height of cable wire" in note, note
    assert "displacement_max at wire." in note, note
    line = next(s for s in printed.splitlines() if "cable wire: jump " in s)
    assert f"at t = {end:.6g} s (at the step's end: may still be rising)" in line, line
    assert f"note: {note}" in printed


def test_per_cable_temperatures(tmp_path, capsys):
    """Two independent level Drake spans (300 m, L0 300.108303 m, at 15 °C). After both are at
    50 °C, ``temperature = { c1 = 75.0 }`` heats c1 to 75 °C and puts c2, which it does not
    name, back at the reference temperature: each sag is the closed form's at its own
    temperature; the group records each cable's temperature and change, the printed step line
    lists them, and the next step (no temperature) keeps them. A table that gives the one
    cable of a scene a temperature is uniform: the group has the attrs as for a number."""
    EA, mass, alpha, L0 = 3.28e7, 1.628, 18.9e-6, 300.108303
    text = scene(
        head={"reference_temperature": 15.0},
        materials={"drake": {"EA": EA, "mass": mass, "thermal_expansion": alpha}},
        nodes={"A": (0.0, 0.0, 30.0), "B": (300.0, 0.0, 30.0), "C": (0.0, 50.0, 30.0),
               "D": (300.0, 50.0, 30.0)},
        supports=("A", "B", "C", "D"),
        cables=[cable("c1", ("A", "B"), "drake", L0, 10),
                cable("c2", ("C", "D"), "drake", L0, 10)],
        steps=step_block("static", "all50", temperature=50.0)
        + step_block("static", "c1hot", temperature={"c1": 75.0}) + step_block("static", "next")
        + step_block("transient", "moving", duration=0.02, output_interval=0.01))
    case = tmp_path / "two.toml"
    case.write_text(text)
    out = tmp_path / "two.nc"
    assert main(["run", str(case), "-o", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    tree = catdae.read_results(out)
    w = mass * G
    for name in ("c1hot", "next"):
        ds = tree[name].ds
        assert "temperature" not in ds.attrs and "temperature_change" not in ds.attrs
        assert ds.temperature.sel(cable="c1") == 75.0 and ds.temperature.sel(cable="c2") == 15.0
        assert ds.temperature_change.values.tolist() == [60.0, 0.0]
        assert ds.temperature_change.attrs["units"] == "K"
        assert "temperature of the cable" in ds.temperature.attrs["long_name"]
        for cab, T in (("c1", 75.0), ("c2", 15.0)):
            sag = level_span(L0, EA, w, alpha * (T - 15.0), 300.0)[0]
            assert float(ds.sag_midspan.sel(cable=cab)) == pytest.approx(sag, rel=1e-9), cab
        assert f"[{name}] static at c1 75, c2 15 deg:" in printed, printed
    both = tree["all50"].ds
    assert both.attrs["temperature"] == 50.0 and both.temperature.values.tolist() == [50.0] * 2
    assert "[all50] static at 50 deg:" in printed
    moving = tree["moving"].ds  # a transient group too
    assert moving.temperature.values.tolist() == [75.0, 15.0]
    # one cable named by a table: uniform, so the attrs (and the sag-temperature figure)
    one = catdae.run(catdae.load_case(scene(
        head={"reference_temperature": 15.0},
        materials={"drake": {"EA": EA, "mass": mass, "thermal_expansion": alpha}},
        nodes={"A": (0.0, 0.0, 30.0), "B": (300.0, 0.0, 30.0)},
        cables=cable("c1", ("A", "B"), "drake", L0, 10),
        steps=step_block("static", "ref") + step_block("static", "hot", temperature={"c1": 75.0}))))
    assert one["hot"].ds.attrs["temperature"] == 75.0
    assert one["hot"].ds.attrs["temperature_change"] == 60.0
    drawn = {ln.get_gid(): ln for ax in plot_spans.spans(one).axes for ln in ax.get_lines()}
    assert drawn["c1|sag_midspan"].get_xdata().tolist() == [15.0, 75.0]


def test_load_cases_at_one_temperature_are_drawn_apart_in_the_spans_figure():
    """Bare and iced at -5 °C, and hot at 50 °C (an independent tester's line): against the
    temperature the two load cases at -5 °C would be drawn one above the other, unnamed; the
    figure is drawn against the steps instead, each tick naming its step and temperature, and
    the sags in step order."""
    text = cable_scene(B=(300.0, 0.0, 0.0), L0=301.0, EA=3.0e7, mass=1.6, elements=8,
                       head={"reference_temperature": 15.0},
                       properties={"thermal_expansion": 1.9e-5},
                       extra='[[distributed_loads]]\ncable = "c"\nload = [0.0, 0.0, -15.0]\n'
                             'name = "ice"\nactive = false\n',
                       steps=('[[steps]]\nkind = "static"\nname = "bare"\ntemperature = -5.0\n'
                              '[[steps]]\nkind = "static"\nname = "iced"\ntemperature = -5.0\n'
                              'add = ["ice"]\n'
                              '[[steps]]\nkind = "static"\nname = "hot"\ntemperature = 50.0\n'
                              'remove = ["ice"]\n'))
    tree = catdae.run(catdae.load_case(text))
    fig = plot_spans.spans(tree)
    drawn = {ln.get_gid(): ln for ax in fig.axes for ln in ax.get_lines()}
    np.testing.assert_array_equal(drawn["c|sag_midspan"].get_xdata(), [0.0, 1.0, 2.0])
    sags = [float(tree[n].ds.sag_midspan.sel(cable="c")) for n in ("bare", "iced", "hot")]
    np.testing.assert_array_equal(drawn["c|sag_midspan"].get_ydata(), sags)
    assert sags[1] > sags[0]  # the ice's weight
    ticks = [t.get_text() for t in fig.axes[1].get_xticklabels()]
    assert ticks == ["bare (-5°)", "iced (-5°)", "hot (50°)"], ticks
    # one colour for the cable in both panels (the sags told apart by their line style)
    colours = {drawn[g].get_color() for g in ("c|sag_midspan", "c|sag_lowest_point")}
    assert len(colours) == 1 and colours == {d.get_color() for g, d in drawn.items()
                                             if g.startswith("c|tension")
                                             or g.startswith("c|horizontal")}, drawn


@pytest.mark.parametrize("rated, ground", [(1.0e3, -5.0), (1.0e6, -20.0)])
def test_a_cable_past_its_rated_strength_or_below_the_ground_is_noted(rated, ground):
    """A 300 m span of 301 m (15.7 N/m; about 16 kN, its lowest point 11.4 m down): rated at
    1 kN and over a ground 5 m down it breaks and passes through the ground, and the step's
    note says both (a tester's length in mm read as m gave 1711 % and -155 km with no word);
    rated at 1 MN over a ground 20 m down, nothing is said."""
    text = cable_scene(B=(300.0, 0.0, 0.0), L0=301.0, EA=3.0e7, mass=1.6, elements=8,
                       properties={"rated_strength": rated},
                       extra=f"[ground]\nelevation = {ground!r}\n", steps=static_step())
    ds = catdae.run(catdae.load_case(text))["st"].ds
    pct = float(ds.tension_percent_rated.sel(cable="c"))
    gap = float(ds.clearance.sel(cable="c"))
    # the elastic catenary's closed form: the end tension, and the lowest point at midspan
    sag, H = level_span(301.0, 3.0e7, 1.6 * 9.81, 0.0, 300.0)
    assert pct == pytest.approx(100 * math.hypot(H, 0.5 * 1.6 * 9.81 * 301.0) / rated, rel=1e-6)
    assert gap == pytest.approx(-sag - ground, abs=1e-6)
    note = ds.attrs.get("note", "")
    assert (f"at {pct:.4g} % of its rated strength" in note) == (pct > 100.0)
    assert (f"passes {-gap:.4g} m below the ground" in note) == (gap < 0.0)
    assert (pct > 100.0 and gap < 0.0) == (rated < 1e4), (pct, gap)


def test_a_swept_static_step_is_labelled_by_its_values_in_the_spans_figure():
    """A load_factor sweep of the ice load (no temperature): the figure is drawn against the
    steps, and each swept point's tick says its step and value, not its index ("iced-sweep1");
    the sags are Irvine's level span's under the self-weight and that share of the ice."""
    def text(factors):
        sweep = f'sweep = {{ field = "load_factor", values = {factors} }}\n'
        return cable_scene(B=(300.0, 0.0, 0.0), L0=301.0, EA=3.0e7, mass=1.6, elements=8,
                           extra='[[distributed_loads]]\ncable = "c"\nload = [0.0, 0.0, -15.0]\n'
                                 'name = "ice"\n',
                           steps='[[steps]]\nkind = "static"\nname = "iced"\n' + sweep)

    tree = catdae.run(catdae.load_case(text([0.5, 1.0])))
    fig = plot_spans.spans(tree)
    ticks = [t.get_text() for t in fig.axes[1].get_xticklabels()]
    assert ticks == ["iced: load_factor = 0.5", "iced: load_factor = 1"], ticks
    drawn = {ln.get_gid(): ln for ax in fig.axes for ln in ax.get_lines()}
    exact = [level_span(301.0, 3.0e7, 1.6 * G + 15.0 * f, 0.0, 300.0)[0] for f in (0.5, 1.0)]
    # the ice as loads at Gauss points converges as h² to Irvine's (2.3e-4 at 8 elements)
    np.testing.assert_allclose(drawn["c|sag_midspan"].get_ydata(), exact, rtol=5e-4)
