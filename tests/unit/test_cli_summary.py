"""What ``catdae run`` prints (issue 23, defect 5): every frequency of a modal step with its
labels, and a horizontal tension that says what it includes.

A level span under its weight w and a wind p across it hangs in the plane of the resultant
load, tilted by atan(p/w): there it is a catenary under sqrt(w² + p²) (Irvine's, from
tests/reference.py), whose horizontal tension is the component along the chord; the horizontal
part of the end tension adds the wind's share p L0/2 across the span.
"""

from __future__ import annotations

import math
import re

import pytest

import catdae
from catdae.cli import main

from reference import irvine_catenary
from scene_toml import cable_scene, distributed_load, modal_step, static_step, step

EA, MASS, G, WIND, L0 = 2.0e7, 1.6, 9.81, 9.0, 101.0

CASE = cable_scene(title="wind", B=(100.0, 0.0, 0.0), L0=L0, EA=EA, mass=MASS, elements=12,
                   cable="span", extra=distributed_load("span", [0.0, WIND, 0.0]),
                   steps=static_step("windy") + modal_step(12))


@pytest.fixture(scope="module")
def printed(tmp_path_factory):
    folder = tmp_path_factory.mktemp("summary")
    case = folder / "wind.toml"
    case.write_text(CASE)
    out = folder / "wind.nc"
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(["run", str(case), "-o", str(out), "--no-progress"]) == 0
    return buf.getvalue(), catdae.read_results(out)


def test_every_frequency_is_printed_with_its_labels(printed):
    text, tree = printed
    md = tree["modes"].to_dataset()
    rows = re.findall(r"^ +mode (\d+): ([0-9.e+-]+) Hz, (.*)$", text, re.M)
    assert len(rows) == 12 == md.mode.size, text
    for (k, f, labels), mode in zip(rows, md.mode.values, strict=True):
        assert int(k) == int(mode)
        assert float(f) == pytest.approx(float(md.frequency.sel(mode=mode)), rel=1e-5)
        assert labels == (f"{md.plane.sel(mode=mode).item()}, "
                          f"{md.symmetry.sel(mode=mode).item()}")


def test_the_horizontal_tension_says_what_it_includes(printed):
    text, tree = printed
    ds = tree["windy"].to_dataset()
    tilted = irvine_catenary(100.0, 0.0, L0, EA, math.hypot(MASS * G, WIND))
    along = float(ds.horizontal_tension_along_chord.sel(cable="span"))
    whole = float(ds.horizontal_tension.sel(cable="span"))
    assert along == pytest.approx(tilted["H"], rel=2e-4)  # wind at Gauss points: O(h²)
    assert whole == pytest.approx(math.hypot(along, WIND * L0 / 2), rel=1e-9)
    line = next(s for s in text.splitlines() if s.strip().startswith("cable span"))
    assert f"horizontal tension {whole:.6g} N at A (includes the part across the chord)" in line
    assert f"along the chord {along:.6g} N" in line


def test_still_air_reads_plainly(tmp_path, capsys):
    """An inclined span in still air, after a wind has come and gone: it hangs in the vertical
    plane through its chord again, so its horizontal tension is all along the chord (no part
    across it to mention) and its swing angle is 0 (the stored one is a rounding residue of
    the wind's state, about 1e-15 deg, printed as 0); under the wind the line says that the
    horizontal tension includes the part across the chord."""
    case = tmp_path / "gone.toml"
    case.write_text(cable_scene(
        B=(100.0, 0.0, 10.0), L0=101.5, EA=EA, mass=MASS, elements=12, cable="span",
        extra=distributed_load("span", [0.0, WIND, 0.0], name="wind", active=False),
        steps=static_step("still") + step("static", "windy", add=["wind"])
        + step("static", "calm", remove=["wind"])))
    assert main(["run", str(case), "-o", str(tmp_path / "gone.nc"), "--no-progress"]) == 0
    text = capsys.readouterr().out
    tree = catdae.read_results(tmp_path / "gone.nc")
    lines = dict(re.findall(r"^\[(\w+)\] static.*\n +(cable span: .*)\n +(?:.*)$", text, re.M))
    spans = dict(re.findall(r"^\[(\w+)\] static.*\n +cable span: .*\n +(.*)$", text, re.M))
    assert set(lines) == {"still", "windy", "calm"}, text
    for name in ("still", "calm"):
        ds = tree[name].to_dataset()
        assert float(ds.horizontal_tension_along_chord.sel(cable="span")) == pytest.approx(
            float(ds.horizontal_tension.sel(cable="span")), rel=1e-12)
        assert abs(float(ds.swing_angle.sel(cable="span"))) < 1e-9
        assert "across the chord" not in lines[name], lines[name]
        assert "swing angle 0 deg" in spans[name], spans[name]
    assert "(includes the part across the chord)" in lines["windy"]
    windy = tree["windy"].to_dataset()
    assert f"swing angle {float(windy.swing_angle.sel(cable='span')):.6g} deg" in spans["windy"]


def test_a_vertical_chord_and_an_upward_bulge_are_said(tmp_path, capsys):
    """A vertical line has no vertical plane through its chord, so no midspan sag or swing
    angle: the summary printed 'sag at midspan nan m; swing angle nan deg' with no word of why.
    A weightless line pushed up across its chord hangs above it: sag < 0, swing 180 degrees,
    said as a bulge (the tester read 180 degrees as a fault)."""
    vertical = tmp_path / "vertical.toml"
    vertical.write_text(cable_scene(B=(0.0, 0.0, -50.0), L0=50.0, EA="1e9", mass=10.0,
                                    elements=4, title="hanging vertical", steps=static_step()))
    assert main(["run", str(vertical), "-o", str(tmp_path / "v.nc"), "--no-progress"]) == 0
    text = capsys.readouterr().out
    ds = catdae.read_results(tmp_path / "v.nc")["st"].to_dataset()
    assert math.isnan(float(ds.sag_midspan.values[0]))
    assert "vertical chord: no sag at midspan or swing angle" in text and " nan " not in text
    up = tmp_path / "up.toml"
    up.write_text(cable_scene(B=(50.0, 0.0, 0.0), L0=49.95, EA="1e8", mass=1.0, gravity=0.0,
                              elements=4, title="pushed up",
                              extra=distributed_load("c", [0.0, 0.0, 20.0], name="lift"),
                              steps=static_step()))
    assert main(["run", str(up), "-o", str(tmp_path / "u.nc"), "--no-progress"]) == 0
    text = capsys.readouterr().out
    ds = catdae.read_results(tmp_path / "u.nc")["st"].to_dataset()
    mid = float(ds.sag_midspan.values[0])
    assert mid < 0 and float(ds.swing_angle.values[0]) == pytest.approx(180.0)
    assert f"sag at midspan {mid:.6g} m (above the chord: the cable bulges up)" in text
