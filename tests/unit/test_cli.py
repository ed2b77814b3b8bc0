"""The command line (``catdae.cli``): exit codes, files written, one clear message on errors.

Most commands run in-process through ``catdae.cli.main(argv)``; ``python -m catdae`` is run once
as a subprocess to check the module entry point.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import catdae
import catdae.analysis
from catdae import ConvergenceError
from catdae.cli import default_case_path, main

from repo_paths import CASES  # noqa: E402
from scene_toml import cable_scene

THREE = CASES / "three_cables_shared_node.toml"

# bad on purpose: a negative EA, and "mas" for "mass"
BAD = cable_scene(title="bad", B=(10.0, 0.0, 0.0), L0=11.0, EA=-1.0, mass=3.0).replace(
    "mass = 3.0", "mas = 3.0")


def test_run_writes_the_results(tmp_path, capsys):
    out = tmp_path / "three.nc"
    assert main(["run", str(THREE), "-o", str(out)]) == 0
    stdout = capsys.readouterr().out
    assert f"results written to {out}" in stdout
    assert "[equilibrium] static" in stdout and "[modes] modal" in stdout
    tree = catdae.read_results(out)
    assert list(tree.children) == ["equilibrium", "modes"]
    assert tree.attrs["status"] == "completed"
    assert tree.attrs["case_toml"] == THREE.read_text()


def test_run_default_output_and_overrides(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(THREE), "--elements", "3"]) == 0
    tree = catdae.read_results(tmp_path / "three_cables_shared_node.nc")
    assert tree["equilibrium"].to_dataset().element.size == 9


def test_mass_model_override(tmp_path, capsys):
    """--mass-model sets the mass of modal (and transient) steps: the lumped mass bounds the
    frequencies from below, the consistent mass from above."""
    f = {}
    for mm in ("consistent", "lumped"):
        out = tmp_path / f"{mm}.nc"
        assert main(["run", str(THREE), "--mass-model", mm, "-o", str(out)]) == 0
        ds = catdae.read_results(out)["modes"].to_dataset()
        assert ds.attrs["mass_model"] == mm
        f[mm] = ds.frequency.values
    assert np.all(f["lumped"] < f["consistent"])
    with pytest.raises(SystemExit) as info:
        main(["run", str(THREE), "--mass-model", "heavy"])
    assert info.value.code == 2
    assert "--mass-model" in capsys.readouterr().err


def test_max_order_override(tmp_path, capsys):
    """--max-order caps IDA's BDF order of every transient step: backward Euler (order 1) is
    dissipative (its amplification factor falls below 1 as h ω grows, at first order in h ω),
    so the bundled example's total energy falls by more at order 1 than at order 2, whose
    dissipation is of higher order in h ω (the Rayleigh damping is the same in both runs); a
    value out of range is refused by the option itself (exit 2), not blamed on a case field."""
    lost = {}
    for order in ("1", "2"):
        out = tmp_path / f"o{order}.nc"
        assert main(["run", "--max-order", order, "--rtol", "1e-3", "-o", str(out)]) == 0
        ds = catdae.read_results(out)["release"].to_dataset()
        assert ds.attrs["max_order"] == int(order)
        e = ds.energy_total.values
        lost[order] = e[0] - e[-1]
    assert lost["1"] > 2.0 * lost["2"] > 0.0
    capsys.readouterr()
    for bad in ("7", "0", "two"):  # the option's own error, not a case field's (tester t66)
        with pytest.raises(SystemExit) as info:
            main(["run", "--max-order", bad, "-o", str(tmp_path / "x.nc")])
        assert info.value.code == 2
        err = capsys.readouterr().err
        assert f"argument --max-order: expected auto or 1-5, found '{bad}'" in err, err
        assert "max_order:" not in err
    assert not (tmp_path / "x.nc").exists()


def test_check_valid_case(capsys):
    assert main(["check", str(THREE)]) == 0
    out = capsys.readouterr().out
    assert "valid" in out and "3 cable(s)" in out and "24 elements" in out


def test_check_invalid_case_lists_every_problem(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(BAD)
    assert main(["check", str(bad)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    err = captured.err
    assert "Traceback" not in err
    assert f"{bad}: materials.m.EA:" in err
    assert f"{bad}: materials.m.mas: unknown key 'mas'; did you mean 'mass'?" in err
    assert f"{bad}: materials.m.mass: missing" in err
    # run refuses it the same way, before computing anything
    assert main(["run", str(bad), "-o", str(tmp_path / "bad.nc")]) == 2
    assert "materials.m.EA" in capsys.readouterr().err
    assert not (tmp_path / "bad.nc").exists()


@pytest.mark.parametrize("command", ["run", "check"])
def test_missing_case_file_is_one_clear_line(tmp_path, capsys, command):
    missing = tmp_path / "missing.toml"
    assert main([command, str(missing)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert str(missing) in err and "cannot read the case file" in err


def test_invalid_override_is_an_invalid_case(tmp_path, capsys):
    assert main(["run", str(THREE), "--elements", "0", "-o", str(tmp_path / "x.nc")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "elements: expected a value >= 1, found the integer 0" in err


def test_output_in_a_missing_directory(tmp_path, capsys):
    out = tmp_path / "nowhere" / "x.nc"
    assert main(["run", str(THREE), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nowhere" in err


def test_failed_analysis_exits_1_and_says_where_the_results_are(tmp_path, monkeypatch, capsys):
    def broken(*args, **kwargs):
        raise ConvergenceError("static equilibrium not found (test)")

    monkeypatch.setattr(catdae.analysis, "solve_static", broken)
    out = tmp_path / "x.nc"
    assert main(["run", str(THREE), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "static equilibrium not found (test)" in err and str(out) in err
    assert "failed in step 'equilibrium'" in catdae.read_results(out).attrs["status"]


def test_an_internal_error_keeps_the_steps_before_it(tmp_path, monkeypatch, capsys):
    """A bug inside a step (here a ValueError put into the modal solver; a tester's was a
    swept modal step under a gravity vector) lost every result with a raw traceback: the step
    now fails as any other, exit 1, the static step kept and the status saying why."""
    def broken(*args, **kwargs):
        raise ValueError("operands could not be broadcast (test)")

    monkeypatch.setattr(catdae.analysis, "solve_modal", broken)
    out = tmp_path / "x.nc"
    assert main(["run", str(THREE), "-o", str(out)]) == 1
    printed = capsys.readouterr()
    err = printed.err
    # the finished step's summary was printed as it ended (a tester's interrupted runs had none)
    assert "[equilibrium] static" in printed.out and "results written" not in printed.out
    assert "internal error in step 'modes' (ValueError: operands could not" in err
    assert "bug in catdae" in err and str(out) in err
    tree = catdae.read_results(out)
    assert list(tree.children) == ["equilibrium"]
    assert "failed in step 'modes': internal error" in tree.attrs["status"]


def test_python_m_catdae_version():
    proc = subprocess.run([sys.executable, "-m", "catdae", "--version"], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0
    assert proc.stdout.strip() == f"catdae {catdae.__version__}"


def test_no_command_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as info:
        main([])
    assert info.value.code == 2
    assert "usage" in capsys.readouterr().err


def test_bundled_default_case_is_example_1():
    assert default_case_path().read_text() == (CASES / "example1_free_vibration.toml").read_text()


@pytest.mark.slow
def test_run_without_a_case_runs_the_bundled_default(tmp_path, capsys):
    out = tmp_path / "default.nc"
    assert main(["run", "-o", str(out), "--no-progress"]) == 0
    tree = catdae.read_results(out)
    assert tree.attrs["case_name"] == "example1_free_vibration"
    assert list(tree.children) == ["hanging", "release", "at_rest", "modes"]
    rel = tree["release"].to_dataset()
    assert rel.attrs["status"] == "completed"
    assert float(rel.time[-1]) == pytest.approx(4.0)
    # the cable is at rest under self-weight at the end: the released mass's weight of 981 N
    # has left the reactions
    w = 20.3 * 9.81 * 44.304
    hang = tree["hanging"].to_dataset().reaction.sel(node=["A", "B"], axis="z").values.sum()
    rest = tree["at_rest"].to_dataset().reaction.sel(node=["A", "B"], axis="z").values.sum()
    assert hang == pytest.approx(w + 100.0 * 9.81, rel=1e-10)
    assert rest == pytest.approx(w, rel=1e-10)
    assert np.all(np.diff(tree["modes"].to_dataset().frequency.values) >= 0)


def test_the_plain_install_brings_what_every_command_needs():
    # `pip install -e .` (the README's install) installs the core requirements only: those
    # without an `extra == ...` marker. catdae study needs distributed, catdae plot matplotlib,
    # catdae export meshio.
    from importlib.metadata import requires

    from packaging.requirements import Requirement

    core = {Requirement(r).name for r in requires("catdae")
            if "extra" not in str(Requirement(r).marker or "")}
    assert {"dask", "matplotlib", "meshio"} <= core
    dask = next(Requirement(r) for r in requires("catdae") if Requirement(r).name == "dask"
                and "extra" not in str(Requirement(r).marker or ""))
    assert "distributed" in dask.extras


def test_the_summary_names_the_free_node_that_moves_most(tmp_path, capsys):
    # example 2's motion of support A on a taut cable: A moves most of all, and the summary
    # must name the free node that moves most, not the prescribed support
    text = (CASES / "example2_support_motion_gentle.toml").read_text()
    text = (text.replace("length = 15.0", "length = 10.02").replace("0.03", "0.3")
            .replace("duration = 4.0", "duration = 1.0"))
    case = tmp_path / "taut.toml"
    case.write_text(text)
    out = tmp_path / "taut.nc"
    assert main(["run", str(case), "--elements", "4", "--rtol", "1e-4", "-o", str(out),
                 "--no-progress"]) == 0
    printed = capsys.readouterr().out
    ds = catdae.read_results(out)["excitation"].to_dataset()
    moved = ds.position - ds.position.isel(time=0)  # the motion during the step
    mag = np.sqrt((moved**2).sum("axis")).max("time")
    free = [n for n in ds.node.values if n not in ("A", "B")]
    expected = str(mag.sel(node=free).idxmax("node").values)
    assert float(mag.sel(node="A")) > float(mag.sel(node=expected))  # A moves most of all
    line = "largest distance of a free node from its place at the step's start: "
    assert line in printed and f" m, at {expected}; max tension" in printed
    shown = float(printed.split(line)[1].split(" m")[0])
    assert shown == pytest.approx(float(mag.sel(node=expected)), rel=1e-3)  # 4 digits printed
    peak = float(printed.split("max tension ")[1].split(" N")[0])
    assert peak == pytest.approx(float(ds.tension_max.max()), rel=1e-5)  # the envelope's


def test_a_run_under_a_profiler_ends_the_ordinary_way_and_keeps_its_profile(tmp_path):
    """A finished ``catdae run`` skips the interpreter's teardown (catdae/__main__.py), except
    under a profiler or tracer, which writes what it measured at the teardown: the profile of
    ``python -m cProfile -o F -m catdae run`` exists and reads back, and the results are whole."""
    import pstats

    case = tmp_path / "c.toml"
    case.write_text(cable_scene(B=(10.0, 0.0, 0.0), L0=10.5, EA=1e6, mass=1.0, elements=4,
                                steps='[[steps]]\nkind = "static"\nname = "st"\n'))
    prof, out = tmp_path / "run.prof", tmp_path / "c.nc"
    proc = subprocess.run([sys.executable, "-m", "cProfile", "-o", str(prof), "-m", "catdae",
                           "run", str(case), "-o", str(out), "--no-progress"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert pstats.Stats(str(prof)).total_calls > 0
    assert catdae.read_results(out)["st"].position.notnull().all()


def test_the_readme_first_case_runs_and_prints_the_closed_form(tmp_path, capsys):
    """The README's first case, taken from the README itself: it runs, and the end tensions
    and sag it prints are the elastic catenary's (Irvine's closed form, tests/reference.py),
    as the README quotes them."""
    import re

    from reference import irvine_catenary
    from repo_paths import ROOT

    text = (ROOT / "README.md").read_text()
    toml = re.search(r"```toml\n(.*?)```", text, re.S).group(1)
    case = tmp_path / "span.toml"
    case.write_text(toml)
    assert main(["run", str(case), "-o", str(tmp_path / "span.nc"), "--no-progress"]) == 0
    out = capsys.readouterr().out
    ref = irvine_catenary(100.0, 5.0, 100.8, 2.0e7, 1.5 * 9.81)
    assert f"end tensions {ref['T_i']:.6g} N, {ref['T_j']:.6g} N" in out, out
    assert f"largest sag {ref['sag']:.6g} m" in out
    assert (f"end tensions ({ref['T_i']:.0f} and {ref['T_j']:.0f} N), the sag "
            f"({ref['sag']:.2f} m)") in " ".join(text.split())


def test_the_catdae_command_is_the_entry_that_ends_fast_and_stops_quietly(tmp_path):
    """The console script ``catdae`` and ``python -m catdae`` share catdae._entry: the script
    pointed at catdae.cli:main and so paid the interpreter's teardown (about 0.3 s of CPU)
    after every run. A Ctrl-C while the modules load printed a traceback from inside an
    import (tester t75): it says so in one line and exits 130."""
    import tomllib

    from repo_paths import ROOT

    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]
    assert scripts["catdae"] == "catdae._entry:main"
    case = tmp_path / "c.toml"
    case.write_text(cable_scene(B=(10.0, 0.0, 0.0), L0=10.5, EA=1e6, mass=1.0, elements=4,
                                steps='[[steps]]\nkind = "static"\nname = "st"\n'))
    out = tmp_path / "c.nc"
    run = ("import sys; sys.argv = ['catdae', 'run', sys.argv[1], '-o', sys.argv[2], "
           "'--no-progress']; from catdae._entry import main; sys.exit(main())")
    proc = subprocess.run([sys.executable, "-c", run, str(case), str(out)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert catdae.read_results(out)["st"].position.notnull().all()
    interrupted = ("import sys\n"
                   "class Stop:\n"
                   "    def find_spec(self, name, path=None, target=None):\n"
                   "        if name == 'catdae.cli':\n"
                   "            raise KeyboardInterrupt\n"
                   "sys.meta_path.insert(0, Stop())\n"
                   "from catdae._entry import main\n"
                   "sys.exit(main())\n")
    proc = subprocess.run([sys.executable, "-c", interrupted], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 130
    assert proc.stderr.strip() == "catdae: interrupted while starting (nothing was computed)"


def test_the_summary_of_a_net_names_its_extremes_not_every_cable():
    """A net of 60 cables (a 7x7 grid's inner lines, 5 m segments, edges held) printed a
    line pair per cable (a 25x25 net: 5 206 lines; tester t77). Above 20 cables the summary
    gives the cable of the largest end tension and of the largest sag, each as computed from
    the results here, and says how many more there are."""
    from catdae.output.summary import step_summary

    n = 7
    nodes = {f"N{i}_{j}": (5.0 * i, 5.0 * j, 0.0) for i in range(n) for j in range(n)}
    edge = [k for k in nodes if {"0", str(n - 1)} & set(k[1:].split("_"))]
    cables = "".join(
        f'[[cables]]\nname = "{a}-{b}"\nends = ["{a}", "{b}"]\nmaterial = "m"\n'
        f"length = 5.01\nelements = 2\n"
        for i in range(1, n - 1) for j in range(n - 1)
        for a, b in ((f"N{i}_{j}", f"N{i}_{j + 1}"), (f"N{j}_{i}", f"N{j + 1}_{i}")))
    from scene_toml import scene, static_step

    text = scene(materials={"m": {"EA": 1.0e6, "mass": 1.0}}, nodes=nodes,
                 supports=tuple(edge), cables=cables, steps=static_step("st"))
    ds = catdae.run(catdae.load_case(text))["st"].ds
    assert ds.cable.size == 60 > 20
    printed = step_summary("st", ds)
    big_t = str(ds.cable.values[int(np.argmax(ds.cable_end_tension.values.max(axis=1)))])
    big_sag = str(ds.cable.values[int(np.argmax(ds.sag.values))])
    named = [line.split(":")[0].split()[-1] for line in printed.splitlines()
             if line.startswith("    cable ")]
    assert set(named) == {big_t, big_sag}, named
    assert f"... {60 - len(named)} more cables" in printed
