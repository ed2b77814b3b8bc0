"""Interrupted runs and unwritable outputs (issue 12), through the command line.

The promises (README, exit codes): Ctrl-C (SIGINT) exits 130 and SIGTERM 143, with everything
computed so far written and marked; a snapshot of a running step never says "completed"; a
process killed outright leaves only files whose names say what they are; an output that cannot
be written is refused before any work (exit 2), and a disk that fails during the run gives one
line saying what was lost and where the last snapshot is (exit 1).

Signals are sent to a real ``python -m catdae`` process once it shows that the transient step
runs (its progress bar, or its first snapshot file): no fixed sleeps, generous timeouts.
"""

from __future__ import annotations

import errno
import os
import signal
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr

import catdae
import catdae.analysis
import catdae.output.results
from catdae.cli import main

from processes import catdae_process, interrupted_run, long_case, signal_when
from repo_paths import CASES  # noqa: E402
from scene_toml import cable_scene, load, point_mass, step

THREE = CASES / "three_cables_shared_node.toml"


def test_sigterm_in_a_transient_step_keeps_and_marks_the_partial_results(tmp_path):
    code, err, out = interrupted_run(tmp_path, signal.SIGTERM)
    assert code == 143, err
    assert "Traceback" not in err
    assert "catdae: interrupted by SIGTERM" in err
    assert f"results computed before the interrupt were written to {out}" in err
    tree = catdae.read_results(out)
    assert tree.attrs["status"].startswith("interrupted in step 'dyn': interrupted at t = ")
    ds = tree["dyn"].to_dataset()
    assert ds.attrs["status"].startswith("interrupted at t = ")
    t_last = float(ds.time[-1])
    assert 0.0 < t_last < 1000.0 and ds.attrs["n_outputs"] == ds.time.size
    assert f"t = {t_last:.6g} s" in ds.attrs["status"]
    for name in ("position", "velocity", "acceleration", "tension"):
        assert np.isfinite(ds[name].values).all(), name
    # the engineering results of the outputs so far (a tester's interrupted ice shedding had
    # none): the envelopes over them, which bound every output
    for name, var, sign in (("displacement_max", "displacement", 1),
                            ("reaction_max", "reaction", 1), ("reaction_min", "reaction", -1)):
        assert name in ds, name
        bound = ds[var].max("time") if sign > 0 else ds[var].min("time")
        gap = (sign * (ds[name] - bound)).values  # NaN where a reaction's axis is free
        assert np.isfinite(gap).any() and (gap[np.isfinite(gap)] >= -1e-9).all(), name
    assert tree["static"].to_dataset().attrs["status"] == "completed"
    # only the marked result is left: no snapshot, no temporary file
    assert sorted(p.name for p in tmp_path.iterdir()) == ["long.nc", "long.toml"]


def test_a_snapshot_never_marks_the_running_step_completed(tmp_path):
    """SIGKILL (nothing can be saved) once the first snapshot is there: the snapshot says the
    step is running; any temporary file is named ``*.incomplete``, never ``*.nc``."""
    case = long_case(tmp_path / "long.toml")
    out = tmp_path / "long.nc"
    snapshot = tmp_path / "long.partial.nc"
    proc = catdae_process(["run", str(case), "-o", str(out), "--no-progress"], tmp_path,
                          snapshot_seconds=0.5)
    code, err = signal_when(proc, signal.SIGKILL, lambda _: snapshot.exists())
    assert code == -signal.SIGKILL, err
    tree = catdae.read_results(snapshot)
    assert tree.attrs["status"] == "running step 'dyn' (snapshot, not a result)"
    ds = tree["dyn"].to_dataset()
    assert ds.attrs["status"].startswith("running (snapshot at t = ")
    assert "completed" not in ds.attrs["status"]
    assert tree["static"].to_dataset().attrs["status"] == "completed"
    assert [p.name for p in tmp_path.glob("*.nc")] == ["long.partial.nc"]
    left = {p.name for p in tmp_path.iterdir()} - {"long.toml", "long.partial.nc"}
    assert all(n.startswith("long.partial.nc.") and n.endswith(".incomplete") for n in left), left


def test_sigterm_while_the_results_are_written_waits_for_the_file(tmp_path, monkeypatch,
                                                                   capsys):
    """A signal that arrives while the complete results are being written does not cut the
    file short: it is finished, then the run stops with 143."""
    real = catdae.output.results.write_tree

    def signalled(tree, path):
        os.kill(os.getpid(), signal.SIGTERM)
        return real(tree, path)

    monkeypatch.setattr(catdae.output.results, "write_tree", signalled)
    out = tmp_path / "three.nc"
    assert main(["run", str(THREE), "-o", str(out)]) == 143
    err = capsys.readouterr().err
    assert "catdae: interrupted by SIGTERM" in err and f"written to {out}" in err
    tree = catdae.read_results(out)
    assert tree.attrs["status"] == "completed"
    assert list(tree.children) == ["equilibrium", "modes"]
    assert signal.getsignal(signal.SIGTERM) == signal.SIG_DFL  # handlers restored


def test_sigterm_in_a_modal_step_says_where_the_results_went(tmp_path, monkeypatch, capsys):
    def terminated(*args, **kwargs):
        raise catdae.Interrupted(signal.SIGTERM)

    monkeypatch.setattr(catdae.analysis, "solve_modal", terminated)
    out = tmp_path / "three.nc"
    assert main(["run", str(THREE), "-o", str(out)]) == 143
    err = capsys.readouterr().err
    assert err.splitlines() == ["catdae: interrupted by SIGTERM",
                                f"catdae: results computed before the interrupt were written "
                                f"to {out}"]
    tree = catdae.read_results(out)
    assert tree.attrs["status"] == "interrupted in step 'modes'"
    assert list(tree.children) == ["equilibrium"]


# ------------------------------------------------------------------------------------------------
# outputs
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("output, why", [
    (".", "it is a directory"),
    ("", "it is a directory"),
    ("/dev/null", "it exists and is not a regular file"),
    ("{tmp}/missing/x.nc", "no directory {tmp}/missing"),
    ("{case}", "it is the case file"),
])
def test_an_output_that_cannot_be_written_is_refused_before_any_work(tmp_path, monkeypatch,
                                                                     capsys, output, why):
    case = tmp_path / "three.toml"
    case.write_text(THREE.read_text())

    def never(*args, **kwargs):
        raise AssertionError("a step ran")

    monkeypatch.setattr(catdae.analysis, "solve_static", never)
    monkeypatch.chdir(tmp_path)
    output = output.format(tmp=tmp_path, case=case)
    assert main(["run", str(case), "-o", output]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(f"catdae: cannot write the results to {Path(output)}: "
                          f"{why.format(tmp=tmp_path)}")
    assert case.read_text() == THREE.read_text()


def test_an_unwritable_directory_is_refused_before_any_work(tmp_path, monkeypatch, capsys):
    """As root every directory is writable, so the refusal of the system is simulated: on a
    read-only mount os.access says no, to root too."""
    real = os.access
    monkeypatch.setattr(catdae.analysis.os, "access",
                        lambda p, mode: False if Path(p) == tmp_path else real(p, mode))
    out = tmp_path / "three.nc"
    assert main(["run", str(THREE), "-o", str(out)]) == 2
    assert capsys.readouterr().err == (f"catdae: cannot write the results to {out}: no "
                                       f"permission to create files in {tmp_path}\n")


def _fail_writes(monkeypatch, exc, *, unless=""):
    """Every netCDF write raises ``exc``, except to a file whose name contains ``unless``."""
    real = xr.DataTree.to_netcdf

    def failing(self, path, *args, **kwargs):
        if not unless or unless not in Path(path).name:
            raise exc
        return real(self, path, *args, **kwargs)

    monkeypatch.setattr(xr.DataTree, "to_netcdf", failing)


def test_a_full_disk_at_the_end_is_one_line_that_states_the_loss(tmp_path, monkeypatch,
                                                                  capsys):
    _fail_writes(monkeypatch, OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)))
    out = tmp_path / "three.nc"
    assert main(["run", str(THREE), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err == (f"catdae: {THREE}: cannot write the results to {out}: No space left on "
                   "device; they are lost\n")
    assert list(tmp_path.iterdir()) == []


def test_the_netcdf_libraries_hdf_error_on_a_full_disk_is_named(tmp_path, monkeypatch, capsys):
    """netCDF4 reports a full disk as RuntimeError('NetCDF: HDF error')."""
    _fail_writes(monkeypatch, RuntimeError("NetCDF: HDF error"))
    monkeypatch.setattr(catdae.output.results.shutil, "disk_usage",
                        lambda p: SimpleNamespace(total=10**9, used=10**9 - 4096, free=4096))
    out = tmp_path / "three.nc"
    assert main(["run", str(THREE), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert f"cannot write the results to {out}: No space left on device (4096 bytes free" in err


def test_a_full_disk_after_snapshots_points_to_the_last_snapshot(tmp_path, monkeypatch, capsys):
    from catdae.solvers import transient

    monkeypatch.setattr(transient, "INCREMENT_SECONDS", 0.0)  # a snapshot after every step
    _fail_writes(monkeypatch, OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)),
                 unless="partial")
    case = long_case(tmp_path / "short.toml", duration=0.05)
    out = tmp_path / "short.nc"
    assert main(["run", str(case), "-o", str(out), "--no-progress"]) == 1
    err = capsys.readouterr().err
    snapshot = tmp_path / "short.partial.nc"
    assert err == (f"catdae: {case}: cannot write the results to {out}: No space left on "
                   f"device; the last snapshot of the run is kept in {snapshot}\n")
    tree = catdae.read_results(snapshot)
    assert tree["dyn"].to_dataset().attrs["status"].startswith("running (snapshot at t = ")
    assert not out.exists()


def test_a_full_disk_after_a_failed_step_states_the_loss(tmp_path, monkeypatch, capsys):
    def broken(*args, **kwargs):
        raise catdae.ConvergenceError("no modes (test)")

    monkeypatch.setattr(catdae.analysis, "solve_modal", broken)
    _fail_writes(monkeypatch, OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)))
    out = tmp_path / "three.nc"
    assert main(["run", str(THREE), "-o", str(out)]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err == [f"catdae: {THREE}: no modes (test)",
                   f"catdae: cannot write the results computed so far to {out}: No space left "
                   "on device; they are lost"]


def test_failed_runs_never_overwrite_an_earlier_failed_file(tmp_path, monkeypatch, capsys):
    def broken(*args, **kwargs):
        raise catdae.ConvergenceError("no modes (test)")

    monkeypatch.setattr(catdae.analysis, "solve_modal", broken)
    out = tmp_path / "three.nc"
    out.write_bytes(b"earlier")
    (tmp_path / "three.failed.nc").write_bytes(b"earlier failure")
    assert main(["run", str(THREE), "-o", str(out)]) == 1
    assert f"written to {tmp_path / 'three.failed-2.nc'}" in capsys.readouterr().err
    assert out.read_bytes() == b"earlier"
    assert (tmp_path / "three.failed.nc").read_bytes() == b"earlier failure"
    tree = catdae.read_results(tmp_path / "three.failed-2.nc")
    assert tree.attrs["status"].startswith("failed in step 'modes'")


# a weight on a short line, held aside, then let go: one output at the end of the swing
_SPARSE = cable_scene(
    B=(0.0, 0.0, -10.0), L0=10.0, EA=1.0e7, mass=1.0, elements=2, supports=("A",),
    title="a weight on a short line, one output at the end",
    extra=point_mass("bob", 100.0, node="B") + load("hold", [500.0, 0.0, 0.0], node="B"),
    steps=step("static", "held") + step("transient", "swing", remove=["hold"], duration=2.0,
                                        output_interval=2.0))


def test_an_interrupt_between_outputs_says_how_far_the_integration_got(tmp_path, monkeypatch):
    """IDA returns only at output times: an interrupt after the last output but well into the
    integration says the time the integration had reached and the last output kept (the
    steps after it are in the tension envelope), not only the output's time."""
    from catdae.solvers.step_hook import StepHook

    real_step = StepHook._step

    def interrupt_after_half_a_second(self, t, y, yp):
        real_step(self, t, y, yp)
        if t > 0.5:
            raise KeyboardInterrupt

    monkeypatch.setattr(StepHook, "_step", interrupt_after_half_a_second)
    case = tmp_path / "sparse.toml"
    case.write_text(_SPARSE)
    with pytest.raises(KeyboardInterrupt) as info:
        catdae.analysis.run(case)
    ds = info.value.partial["swing"].to_dataset()
    status = ds.attrs["status"]
    assert status.startswith("interrupted at t = ")
    reached = float(status.split("t = ")[1].split(" s")[0])
    assert 0.5 < reached < 2.0, status
    assert status.endswith("(histories up to the output at t = 0 s)")
    assert ds.time.values.tolist() == [0.0]
    # the envelope saw the steps after the output, up to the time reached
    assert 0.0 < float(ds.time_tension_max.max()) <= reached


def test_snapshots_come_between_outputs_and_leave_the_run_as_it_was(tmp_path, monkeypatch):
    """A long stretch without outputs still gets its snapshots (every INCREMENT_SECONDS of
    wall time; 0.02 s here): the hook asks IDA to return at a step's end, the snapshot is
    written and IDA goes on as it was, so the run is the one without snapshots (no output
    file, none asked for), step for step."""
    from catdae.output.writer import ResultWriter
    from catdae.solvers import transient

    case = tmp_path / "sparse.toml"
    case.write_text(_SPARSE)
    plain = catdae.analysis.run(case)["swing"].to_dataset()
    monkeypatch.setattr(transient, "INCREMENT_SECONDS", 0.02)
    outputs_then, statuses = [], []
    real = ResultWriter.write_increment

    def record(self, name, rec, reached=None):
        outputs_then.append(rec.n_valid)
        real(self, name, rec, reached)
        statuses.append(catdae.read_results(self.partial_path)["swing"].attrs["status"])

    monkeypatch.setattr(ResultWriter, "write_increment", record)
    snapped = catdae.analysis.run(case, output=tmp_path / "s.nc")["swing"].to_dataset()
    assert plain.time.values.tolist() == [0.0, 2.0]
    assert outputs_then.count(1) >= 3, outputs_then  # between the two outputs
    # each says how far the step had got, and that its histories end at the first output
    head, tail = "running (snapshot at t = ", " s (histories up to the output at t = 0 s); "
    between = [float(x[len(head):x.index(tail)]) for x in statuses if tail in x]
    assert len(between) >= 3 and all(x.startswith(head) for x in statuses), statuses
    assert 0.0 < between[0] < between[-1] < 2.0
    assert snapped.attrs["n_steps"] == plain.attrs["n_steps"]
    for name in ("position", "velocity", "tension", "tension_max", "time_tension_max"):
        np.testing.assert_array_equal(snapped[name].values, plain[name].values, err_msg=name)
    assert not (tmp_path / "s.partial.nc").exists()  # removed at the end


def test_a_signal_inside_llvmlite_is_sent_again_not_lost():
    """llvmlite's execution engine calls back into Python through ctypes, which drops an
    exception raised there: a Ctrl-C while numba loaded a kernel was lost, and every later
    signal ignored as if the run were stopping (tester t75: exit 0, "completed", after SIGINT,
    SIGINT and SIGTERM). Inside llvmlite the handler sends the signal again shortly; it is
    raised once the main thread is back in catdae's code."""
    import time

    from catdae import interrupts

    code = compile("import sys\ndef here():\n    return sys._getframe()\n",
                   "/site-packages/llvmlite/binding/executionengine.py", "exec")
    scope: dict = {}
    exec(code, scope)
    inside = scope["here"]()
    # SIGTERM: a SIGINT the parent ignores (a background job) stays ignored, by design
    with interrupts.signals_as_interrupts():
        assert interrupts._handler(signal.SIGTERM, inside) is None  # not raised there
        assert not interrupts._State.stopping
        with pytest.raises(catdae.Interrupted):
            for _ in range(500):  # the signal comes back after RESEND s
                time.sleep(0.01)
        assert interrupts._State.stopping


def test_a_summary_out_of_memory_keeps_the_finished_run(tmp_path, monkeypatch, capsys):
    """The printed summary of a finished transient ran out of memory (a 40 MB temporary over
    50 001 outputs under a memory limit): the error escaped the run, and no file was written
    (tester t75). A summary never costs the results: the file holds every step, completed."""
    def no_memory(name, ds):
        raise MemoryError

    monkeypatch.setattr(catdae.cli, "step_summary", no_memory)
    out = tmp_path / "r.nc"
    assert main(["run", str(THREE), "-o", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert "no summary printed: MemoryError while summarising" in printed
    tree = catdae.read_results(out)
    case = catdae.load_case(THREE)
    assert list(tree.children) == [s.name for s in case.steps]
    assert all(tree[s.name].ds.attrs["status"] == "completed" for s in case.steps
               if "status" in tree[s.name].ds.attrs)
