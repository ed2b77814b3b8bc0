"""Progress of long steps in logs: a plain line every so many seconds when stderr is not a
terminal (CI, batch jobs), with the step's name, its time against its end time, and wall time."""

from __future__ import annotations

import io
import re

import catdae
import catdae.progress
from catdae.progress import LogProgress

from repo_paths import CASES  # noqa: E402

LINE = re.compile(r"catdae: (\w+): t = ([0-9.e+-]+) / ([0-9.e+-]+) s \((\d+) %\), "
                  r"([0-9.]+) s wall(, done|, stopped)?$")


class Clock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def test_a_line_every_interval_of_wall_time_and_one_at_the_end():
    clock, out = Clock(), io.StringIO()
    rep = LogProgress("release", 0.0, 4.0, interval=10.0, stream=out, clock=clock)
    for wall, t in [(3, 0.5), (9.9, 0.9), (10.0, 1.0), (15, 1.5), (21, 2.0), (25, 3.0)]:
        clock.now = 100.0 + wall
        rep.update(t)
    clock.now = 127.0
    rep.update(4.0)
    rep.close()
    lines = [LINE.match(s) for s in out.getvalue().splitlines()]
    assert all(lines), out.getvalue()
    # at wall 10 (t = 1), 21 (t = 2) and the closing line at 27 s (t = 4)
    assert [float(m[2]) for m in lines] == [1.0, 2.0, 4.0]
    assert [int(m[4]) for m in lines] == [25, 50, 100]
    assert [float(m[5]) for m in lines] == [10.0, 21.0, 27.0]
    assert [m[1] for m in lines] == ["release"] * 3 and float(lines[0][3]) == 4.0
    assert lines[-1][6] == ", done" and lines[0][6] is None


def test_a_short_step_prints_nothing():
    clock, out = Clock(), io.StringIO()
    rep = LogProgress("quick", 0.0, 1.0, interval=10.0, stream=out, clock=clock)
    clock.now += 2.0
    rep.update(1.0)
    rep.close()
    assert out.getvalue() == ""


def test_a_transient_run_logs_its_progress_when_stderr_is_not_a_terminal(monkeypatch, capsys):
    # under pytest stderr is captured, not a terminal: the default (progress=None) logs lines
    monkeypatch.setattr(catdae.progress, "LOG_INTERVAL", 0.0)
    catdae.run(CASES / "example2_support_motion_gentle.toml", elements=4, rtol=1e-4)
    lines = [LINE.match(s) for s in capsys.readouterr().err.splitlines() if s.startswith("catdae:")]
    assert lines and all(lines)
    t_end = float(lines[0][3])
    assert t_end > 0 and lines[-1][6] == ", done" and float(lines[-1][2]) == t_end
    ts = [float(m[2]) for m in lines]
    assert ts == sorted(ts) and ts[0] < t_end


def test_the_last_line_of_a_step_that_did_not_reach_its_end_says_stopped():
    """An interrupted or failed step closes its reporter before its end: its last line says
    so ("stopped"), not "done"."""
    clock, out = Clock(), io.StringIO()
    rep = LogProgress("release", 0.0, 4.0, interval=10.0, stream=out, clock=clock)
    clock.now = 111.0
    rep.update(1.3)
    clock.now = 112.0
    rep.close()
    lines = [LINE.match(s) for s in out.getvalue().splitlines()]
    assert all(lines) and [m[6] for m in lines] == [None, ", stopped"], out.getvalue()
    assert float(lines[-1][2]) == 1.3
