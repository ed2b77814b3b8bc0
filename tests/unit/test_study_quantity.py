"""``catdae study`` on one number (issue 23): a static quantity of a static step (a sag, an end
tension) and one natural frequency of a modal step. A uniform load over part of a cable is
integrated at Gauss points, second order in the element length (case-format.md, docs/theory.md
§5): the study's errors in an end tension and the horizontal tension must fall at that rate."""

from __future__ import annotations

import numpy as np
import pytest

from catdae.study import StudyError, main, run_study

from scene_toml import cable_scene, distributed_load, modal_step, static_step

CASE = cable_scene(B=(100.0, 0.0, 20.0), L0=104.0, EA=2.0e7, mass=2.0, elements=4,
                   extra=distributed_load("c", [0.0, 0.0, -80.0], name="snow", from_s=11.0,
                                          to_s=58.5),
                   steps=static_step("loaded") + modal_step(4))


@pytest.mark.parametrize("response", ["end_tension:c:j", "horizontal_tension:c"])
def test_static_errors_fall_at_second_order(response):
    ds = run_study(CASE, step="loaded", elements=[4, 8, 16, 32], response=response,
                   scheduler="synchronous")
    assert list(ds.error.dims) == ["elements", "gauss_points"]
    err = ds.error.squeeze("gauss_points").values
    assert np.all(err > 0) and np.all(np.diff(err) < 0)
    rate = -np.polyfit(np.log([4, 8, 16, 32]), np.log(err), 1)[0]
    assert 1.7 < rate < 2.6, (response, err, rate)
    assert ds.attrs["error_definition"] == "|q - q_ref| / |q_ref|"
    assert ds.attrs["reference_elements"] == 64 and ds.attrs["step_kind"] == "static"


def test_sag_error():
    # the sag is a largest distance over the cable: it converges, but not monotonically (where
    # the coverage ends fall in the elements changes with the mesh)
    ds = run_study(CASE, step="loaded", elements=[4, 32], response="sag:c",
                   scheduler="synchronous")
    err = ds.error.squeeze("gauss_points").values
    assert 0 < err[1] < err[0] / 10
    assert ds.attrs["response"] == "sag (largest vertical distance from the chord) of cable 'c'"


def test_one_frequency():
    ds = run_study(CASE, step="modes", elements=[4, 8], response="frequency:2",
                   scheduler="synchronous")
    np.testing.assert_array_equal(ds.error.values,
                                  np.abs(ds.frequency_error.sel(mode=2).values))
    assert ds.attrs["response"] == "natural frequency of mode 2"


@pytest.mark.parametrize(("step", "response", "words"), [
    ("loaded", "sag:wire", "no cable 'wire'"),
    ("loaded", "droop:c", "expected <quantity>:<cable>"),
    ("loaded", "end_tension:c", "end_tension:c:i"),
    ("modes", "frequency:9", "k from 1 to 4"),
])
def test_bad_responses(step, response, words, tmp_path, capsys):
    with pytest.raises(StudyError, match=words):
        run_study(CASE, step=step, response=response, scheduler="synchronous")
    case = tmp_path / "c.toml"
    case.write_text(CASE)
    assert main([str(case), "--step", step, "--response", response, "--scheduler",
                 "synchronous", "--store", str(tmp_path / "s")]) == 2
    assert words in capsys.readouterr().err


def test_a_mesh_exact_static_study_says_its_errors_are_rounding():
    """Self-weight alone: the catenary element is exact at any mesh (Irvine), so a mesh study's
    errors are 1e-15 to 4e-12 (the solves' tolerance); the table said the reference is
    "computed, not exact" and the figure fitted "order 0.08" to rounding (tester t74). Both
    now say so."""
    from catdae.study import summary
    from catdae.study.plots import plot_convergence

    text = cable_scene(B=(100.0, 0.0, 20.0), L0=104.0, EA=2.0e7, mass=8.0, elements=4,
                       steps=static_step("hang"))
    ds = run_study(text, elements=[1, 2, 4, 8], response="end_tension:c:j",
                   scheduler="synchronous")
    assert float(np.abs(ds.error).max()) <= 1e-10  # the static solves' tolerance
    printed = summary(ds)
    assert "every error is at the level of the solves' tolerance" in printed
    assert "computed, not exact" not in printed
    fig = plot_convergence(ds)
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()] == [
        "at solver tolerance: no order"]
