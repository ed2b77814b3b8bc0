"""Figures (``catdae.plot``, ``catdae plot``) are drawn from the right data: the plotted lines
hold the dataset's values at the right nodes, times and cables, in order along each cable; axes
carry the variables' units; the spectrum peaks at the frequency the modal step finds."""

from __future__ import annotations

import numpy as np
import pytest

import catdae
from catdae.cli import main
from catdae.output import plot

from repo_paths import CASES  # noqa: E402
from scene_toml import cable_scene, damper, modal_step, static_step  # noqa: E402

EX1 = CASES / "example1_free_vibration.toml"
THREE = CASES / "three_cables_shared_node.toml"
NE = 8
MAIN = ["A", *[f"main.{k}" for k in range(1, NE)], "B"]  # cable main from its first end


@pytest.fixture(scope="module")
def ex1(tmp_path_factory):
    out = tmp_path_factory.mktemp("plot") / "ex1.nc"
    catdae.run(EX1, elements=NE, rtol=1e-6, output=out, progress=False)
    return catdae.read_results(out), out


def _lines(ax, gid_prefix):
    return [ln for ln in ax.get_lines() if str(ln.get_gid()).startswith(gid_prefix)]


def test_profile_draws_each_cable_through_its_nodes_in_order(ex1):
    tree, _ = ex1
    ds = tree["release"].to_dataset()
    fig = plot.profile(ds, times=[0.0, 1.0])
    ax_e, ax_p = fig.axes
    for t in (0.0, 1.0):
        x = ds.position.sel(time=t, node=MAIN)
        (le,) = _lines(ax_e, f"main|{t}")
        (lp,) = _lines(ax_p, f"main|{t}")
        np.testing.assert_array_equal(le.get_xdata(), x.sel(axis="x").values)
        np.testing.assert_array_equal(le.get_ydata(), x.sel(axis="z").values)
        np.testing.assert_array_equal(lp.get_ydata(), x.sel(axis="y").values)
    # along the cable: x grows from support A to support B
    assert np.all(np.diff(_lines(ax_e, "main|0.0")[0].get_xdata()) > 0)
    assert ax_e.get_ylabel().endswith("z [m]") and ax_p.get_xlabel().endswith("x [m]")


def test_times_outside_the_step_are_refused_with_its_span(ex1):
    """A time past the step's last output was drawn silently as the last output."""
    tree, _ = ex1
    ds = tree["release"].to_dataset()
    t_end = float(ds.time[-1])
    step = float(ds.time[1] - ds.time[0])
    with pytest.raises(plot.PlotError, match=f"run from 0 to {t_end:g} s"):
        plot.profile(ds, times=[1.0, t_end + 3.0])
    with pytest.raises(plot.PlotError, match="run from"):
        plot.tension(ds, times=[-step])
    fig = plot.profile(ds, times=[t_end + 0.4 * step])  # the nearest output is within reach
    assert _lines(fig.axes[0], f"main|{t_end}")


def test_profile_of_a_network_draws_the_shared_node_on_every_cable():
    tree = catdae.run(THREE, progress=False)
    ds = tree["equilibrium"].to_dataset()
    fig = plot.profile(ds)
    case = catdae.load_case(THREE)
    for cable in case.cables:
        (ln,) = _lines(fig.axes[0], f"{cable.name}|")
        a, b = (ds.position.sel(node=n) for n in cable.ends)
        assert len(ln.get_xdata()) == cable.elements + 1
        assert (ln.get_xdata()[0], ln.get_ydata()[0]) == (a.sel(axis="x"), a.sel(axis="z"))
        assert (ln.get_xdata()[-1], ln.get_ydata()[-1]) == (b.sel(axis="x"), b.sel(axis="z"))


def test_history_is_the_displacement_of_the_node(ex1):
    tree, _ = ex1
    ds = tree["release"].to_dataset()
    fig = plot.history(ds, "main.4")
    for ax, a in zip(fig.axes, "xyz", strict=True):
        (ln,) = _lines(ax, f"main.4|{a}")[:1]  # then the envelope's peak markers
        np.testing.assert_array_equal(ln.get_xdata(), ds.time.values)
        np.testing.assert_array_equal(ln.get_ydata(), ds.displacement.sel(node="main.4",
                                                                          axis=a).values)
        assert ax.get_ylabel() == f"{a} [m]"
    assert fig.axes[-1].get_xlabel() == "time [s]"
    # x moves by rounding only (1e-14 m) at midspan of this symmetric release, y not at all:
    # said, on the scale of the z motion, not magnified to fill the panel
    dz = float(np.ptp(ds.displacement.sel(node="main.4", axis="z").values))
    for ax, a in zip(fig.axes[:2], "xy", strict=True):
        assert [t.get_text() for t in ax.texts] == [f"no motion along {a} (within rounding)"]
        assert np.diff(ax.get_ylim())[0] == pytest.approx(dz)
    assert not any("no motion" in t.get_text() for t in fig.axes[2].texts)
    # default node: the free node that moves most (midspan, where the mass was released)
    assert str(plot.history(ds).axes[0].get_lines()[0].get_gid()).startswith("main.4|")


def test_the_spectrum_peaks_at_the_first_symmetric_in_plane_mode(ex1):
    tree, _ = ex1
    ds = tree["release"].to_dataset()
    md = tree["modes"].to_dataset()
    fig = plot.spectrum(ds, "main.4")
    (ln,) = _lines(fig.axes[0], "main.4|z")
    f, amp = ln.get_xdata(), ln.get_ydata()
    sym_in = md.frequency.where((md.plane == "in-plane") & (md.symmetry == "symmetric"),
                                drop=True)
    f1 = float(sym_in[0])
    resolution = 1.0 / float(ds.time[-1] - ds.time[0])
    assert abs(f[np.argmax(amp)] - f1) <= resolution, (f[np.argmax(amp)], f1)
    assert fig.axes[0].get_xlabel() == "frequency [Hz]"


def test_amplitude_spectrum_of_a_sine():
    t = np.arange(0, 20.0, 0.01)
    f, amp = plot.amplitude_spectrum(t, 0.3 * np.sin(2 * np.pi * 2.0 * t) + 5.0)
    k = np.argmax(amp)
    assert f[k] == pytest.approx(2.0) and amp[k] == pytest.approx(0.3, rel=1e-2)


def test_tension_along_the_cable_and_at_the_supports(ex1):
    tree, _ = ex1
    ds = tree["release"].to_dataset()
    fig = plot.tension(ds, times=[2.0])
    ax_s, ax_t = fig.axes
    (ln,) = _lines(ax_s, "main|2.0")
    el = [f"main.{k}" for k in range(1, NE + 1)]
    np.testing.assert_array_equal(ln.get_ydata(), ds.tension.sel(time=2.0, element=el)
                                  .values.ravel())
    s = ln.get_xdata()
    assert s[0] == 0.0 and s[-1] == pytest.approx(44.304) and np.all(np.diff(s) >= 0)
    (la,) = _lines(ax_t, "A")
    ra = ds.reaction.sel(node="A")
    np.testing.assert_allclose(la.get_ydata(), np.sqrt((ra**2).sum("axis")).values)
    assert ax_s.get_ylabel().endswith("[N]") and ax_s.get_xlabel().endswith("[m]")
    # the force on the cable at the support is the tension of its end element, less the
    # inertia of the mass the support carries (here below 1e-3 of it)
    np.testing.assert_allclose(la.get_ydata(), ds.tension.sel(element="main.1", end="i"),
                               rtol=1e-3)


def test_modes_are_the_shapes_along_the_cable_with_their_frequencies(ex1):
    tree, _ = ex1
    md = tree["modes"].to_dataset()
    fig = plot.modes(md, n=4)
    for k, ax in enumerate(fig.axes):
        mode = k + 1
        (lz,) = _lines(ax, f"{mode}|main|z")
        np.testing.assert_array_equal(lz.get_ydata(), md["shape"].sel(mode=mode, node=MAIN,
                                                                      axis="z").values)
        x = lz.get_xdata()
        assert x[0] == 0.0 and x[-1] == pytest.approx(44.304)  # arc length from A to B
        assert f"{float(md.frequency.sel(mode=mode)):.4g} Hz" in ax.get_title()


def test_catdae_plot_writes_png_files(ex1, tmp_path, capsys):
    _, out = ex1
    assert main(["plot", str(out), "-o", str(tmp_path / "figs"), "--step", "release",
                 "--what", "history", "spectrum", "--node", "main.2"]) == 0
    files = sorted(p.name for p in (tmp_path / "figs").iterdir())
    assert files == ["release-history.png", "release-spectrum.png"]
    assert (tmp_path / "figs" / "release-history.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["plot", str(out), "-o", str(tmp_path / "x"), "--node", "nowhere"]) == 2
    assert "no node 'nowhere'" in capsys.readouterr().err


def test_damped_modes_are_drawn_as_the_damped_modes_they_are_titled_with():
    """A taut level cable (100 m, 1e5 N) with a damper across the plane (along y) at 6 m from
    A, at about its optimal coefficient: the out-of-plane mode 1 is damped and its frequency
    moves above the in-plane one, so sorted by |s| the damped modes are not in the undamped
    order (an independent tester's figure titled the in-plane frequency over the out-of-plane
    shape). Each panel draws the real part of its damped mode's complex shape, its title gives
    that mode's damped frequency and damping ratio, and the drawn shape moves mostly in the
    plane its title names."""
    text = cable_scene(B=(100.0, 0.0, 0.0), L0=99.02, EA=1.0e7, mass=1.0, elements=50,
                       nodes={"G": (6.0, 2.0, 0.0)}, supports=("G", "A", "B"),
                       extra=damper("d", ["c.3", "G"], 3000.0),
                       steps=static_step() + modal_step(6))
    ds = catdae.run(catdae.load_case(text))["modes"].to_dataset()
    assert "complex_shape" in ds
    assert list(ds.undamped_mode.values[:2]) != [1, 2]  # the case the figure got wrong
    fig = plot.modes(ds, n=4)
    for k, ax in enumerate(fig.axes):
        mode = int(ds.mode.values[k])
        real = ds.complex_shape.sel(mode=mode, part="real")
        (ly,) = _lines(ax, f"{mode}|c|y")
        (lz,) = _lines(ax, f"{mode}|c|z")
        path = plot._paths(ds)["c"]  # the nodes along the cable, A to B
        np.testing.assert_array_equal(ly.get_ydata(), real.sel(node=path, axis="y"))
        title = ax.get_title()
        assert f"{float(ds.frequency.sel(mode=mode)):.4g} Hz" in title
        zeta = float(ds.damping_ratio.sel(mode=mode))
        assert (f"damping ratio {zeta:.3g}" if abs(zeta) > 1e-12 else "damping ratio 0") in title
        across = np.sum(ly.get_ydata() ** 2) > np.sum(lz.get_ydata() ** 2)
        assert ("out-of-plane" in title) == across, (title, mode)


def test_figures_and_series_of_a_run_that_did_not_complete_say_so(ex1, tmp_path, capsys):
    """Only the netCDF status said that a run was interrupted (tester t63): the PNG carries
    the step's status, the ParaView collection a comment, and both commands say it."""
    tree, _ = ex1
    status = "interrupted at t = 1.5 s (histories up to the output at t = 1.5 s)"
    cut = tree.copy()
    cut["release"] = cut["release"].to_dataset().sel(time=slice(0.0, 1.5)).assign_attrs(
        status=status)
    cut.attrs["status"] = f"interrupted in step 'release': {status}"
    path = tmp_path / "cut.nc"
    cut.to_netcdf(path)
    assert main(["plot", str(path), "-o", str(tmp_path / "figs"), "--step", "release",
                 "--what", "history"]) == 0
    err = capsys.readouterr().err
    assert "note: the run did not complete (interrupted in step 'release'" in err
    made = []
    original = plot._figure

    def keep(*args):
        made.append(original(*args))
        return made[-1]

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(plot, "_figure", keep)
        plot.write_all(catdae.read_results(path), tmp_path / "f2", steps="release",
                       what="history")
        plot.write_all(tree, tmp_path / "f3", steps="release", what="history")
    cut_texts, whole_texts = ([t.get_text() for t in f.texts] for f in made)
    assert f"step not completed: {status}" in cut_texts
    assert not any("not completed" in t for t in whole_texts)
    assert main(["export", str(path), "--vtk", str(tmp_path / "vtk"), "--step", "release"]) == 0
    assert "the series hold what it computed" in capsys.readouterr().err
    pvd = (tmp_path / "vtk" / "release.pvd").read_text()
    assert f"<!-- step not completed: {status} -->" in pvd
    done = main(["export", str(ex1[1]), "--vtk", str(tmp_path / "vtk2"), "--step", "release"])
    assert done == 0 and "did not complete" not in capsys.readouterr().err


def test_modes_of_a_network_draw_every_cable_through_its_shared_node():
    """The modal groups held no elements, so the mode figure drew each cable through its own
    mesh nodes only: a node shared by three cables appeared on the first alone, the others'
    lines stopping short of it (tester t72). Each cable's line now runs from s = 0 to its
    length, through the shared node's own shape value."""
    tree = catdae.run(THREE, progress=False)
    modal = next(n for n in tree.children if tree[n].ds.attrs.get("kind") == "modal")
    ds = tree[modal].to_dataset()
    fig = plot.modes(ds, n=2)
    case = catdae.load_case(THREE)
    for cable in case.cables:
        (line,) = _lines(fig.axes[0], f"1|{cable.name}|z")
        x, z = line.get_xdata(), line.get_ydata()
        assert x[0] == 0.0 and x[-1] == pytest.approx(cable.length, rel=1e-12)
        for end, at in ((cable.ends[0], 0), (cable.ends[1], -1)):
            assert z[at] == float(ds.shape.isel(mode=0).sel(node=end, axis="z"))


def test_a_modal_step_named_for_export_is_refused_with_why(tmp_path, capsys):
    """Modal groups now carry the elements' coordinates (for the mode figure); exporting one
    by name must still be a clear refusal (exit 2), not a missing-variable traceback."""
    tree = catdae.run(THREE, progress=False)
    path = tmp_path / "three.nc"
    tree.to_netcdf(path)
    modal = next(n for n in tree.children if tree[n].ds.attrs.get("kind") == "modal")
    assert main(["export", str(path), "--vtk", str(tmp_path / "v"), "--step", modal]) == 2
    assert "no cable positions to export (a modal step" in capsys.readouterr().err
