"""Progress in a batch log while the step is inside one long call (issue 23, defect 4).

``catdae run CASE > log 2>&1``: a 91 s first run wrote no line while it ran. The lines were
printed only between integrator steps, and the reporter started after the step's set-up: a
minute of kernel compilation (in the set-up, or inside one integrator call) printed nothing.
Now a ticker prints every interval of wall time whatever the step is doing, from the step's
start, and says when numba is compiling; ``catdae run`` announces the first compilation of the
run, whenever it happens. ``CATDAE_LOG_INTERVAL`` (s) sets the interval (default 15 s).
"""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys
import time

from numba.core import event

from catdae.progress import LogProgress, announce_compiling, reporter

from scene_toml import cable_scene, step

LINE = re.compile(r"catdae: (\w+): t = ([0-9.e+-]+) / ([0-9.e+-]+) s \((\d+) %\), "
                  r"([0-9.]+) s wall(, compiling the kernels)?(, done|, stopped)?$")


def test_lines_come_while_the_step_is_blocked_in_one_call():
    out = io.StringIO()
    rep = LogProgress("blocked", 0.0, 2.0, interval=0.05, stream=out, ticker=True)
    rep.update(0.5)
    time.sleep(0.5)  # one long call: an integrator step, a compilation
    rep.close()
    lines = [LINE.match(s) for s in out.getvalue().splitlines()]
    assert len(lines) >= 4 and all(lines), out.getvalue()
    assert all(float(m[2]) == 0.5 for m in lines)
    assert lines[-1][7] == ", stopped"  # closed at t = 0.5 of 2: not done
    n = len(lines)
    time.sleep(0.2)  # closed: the ticker has stopped
    assert len(out.getvalue().splitlines()) == n


def test_lines_say_when_numba_compiles():
    out = io.StringIO()
    rep = LogProgress("setup", 0.0, 1.0, interval=0.05, stream=out, ticker=True)
    with event.trigger_event("numba:compile", data={}):
        time.sleep(0.4)
    time.sleep(0.2)
    rep.close()
    lines = [LINE.match(s) for s in out.getvalue().splitlines()]
    assert all(lines), out.getvalue()
    flags = [m[6] for m in lines]
    assert ", compiling the kernels" in flags and flags[-1] is None


def test_the_first_compilation_is_announced_once():
    out = io.StringIO()
    with announce_compiling(out):
        for _ in range(3):
            with event.trigger_event("numba:compile", data={}):
                pass
    with event.trigger_event("numba:compile", data={}):  # after the run: not announced
        pass
    assert out.getvalue().count("compiling") == 1, out.getvalue()


def test_a_reporter_for_a_log_ticks_and_stops(monkeypatch):
    monkeypatch.setenv("CATDAE_LOG_INTERVAL", "0.05")
    monkeypatch.setattr(sys, "stderr", io.StringIO())
    rep = reporter(None, "quick", 0.0, 1.0)
    time.sleep(0.3)
    rep.close()
    text = sys.stderr.getvalue()
    assert len(text.splitlines()) >= 3 and text.rstrip().endswith(", stopped"), text


def test_catdae_run_into_a_log_file(tmp_path):
    case = tmp_path / "c.toml"
    case.write_text(cable_scene(B=(10.0, 0.0, 0.0), L0=10.5, EA=1.0e6, mass=1.0, elements=6,
                                steps=step("transient", "swing", duration=2.0,
                                           output_interval=0.01)))
    log = tmp_path / "log"
    env = dict(os.environ, CATDAE_LOG_INTERVAL="0.02")
    with open(log, "w") as f:
        proc = subprocess.run([sys.executable, "-m", "catdae", "run", str(case), "-o",
                               str(tmp_path / "r.nc")], stdout=f, stderr=subprocess.STDOUT,
                              env=env, cwd=tmp_path, timeout=600)
    text = log.read_text()
    assert proc.returncode == 0, text
    lines = [LINE.match(s) for s in text.splitlines() if s.startswith("catdae: swing:")]
    assert len(lines) >= 2 and all(lines), text
    assert float(lines[0][2]) == 0.0  # the first line comes before the integrator moves
    assert lines[-1][7] == ", done" and float(lines[-1][2]) == 2.0
