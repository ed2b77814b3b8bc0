"""A real ``python -m catdae`` process and signals sent to it once it shows that it runs (shared
by tests/unit/test_interrupts.py, tests/unit/test_hostile_use.py and
tests/scenes/test_extremes.py): no fixed sleeps, generous timeouts. ``long_case`` writes the
scene such a run is interrupted in, ``interrupted_run`` runs it and sends the signal."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from scene_toml import long_transient


def default_signals() -> None:
    """In a child before it runs: the signals the tests send at their default disposition. A
    runner started under ``nohup`` ignores SIGHUP, its children inherit that, and catdae keeps
    an ignored signal ignored (catdae.interrupts): the run would not stop."""
    for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(s, signal.SIG_DFL)


def catdae_process(args, cwd, *, snapshot_seconds=None):
    """``python -m catdae ARGS``; with ``snapshot_seconds`` the same command line with the
    transient snapshot interval lowered (catdae.solvers.transient.INCREMENT_SECONDS, 20 s)."""
    if snapshot_seconds is None:
        cmd = [sys.executable, "-m", "catdae", *args]
    else:
        code = ("import sys, catdae.solvers.transient as t, catdae.cli as c; "
                f"t.INCREMENT_SECONDS = {snapshot_seconds!r}; sys.exit(c.main(sys.argv[1:]))")
        cmd = [sys.executable, "-c", code, *args]
    return subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, cwd=cwd,
                            env=dict(os.environ, PYTHONUNBUFFERED="1"),
                            preexec_fn=default_signals)


def long_case(path: Path, duration: float = 1000.0) -> Path:
    """``scene_toml.long_transient`` written to ``path``: a run of it is interrupted long before
    its end."""
    path.write_text(long_transient(duration))
    return path


def interrupted_run(folder: Path, sig, out: Path | None = None) -> tuple[int, str, Path]:
    """``catdae run`` of ``long_case(folder / "long.toml")`` into ``out`` (by default
    ``folder / "long.nc"``) with the progress bar, sent ``sig`` once the transient runs past
    t = 1 s. Returns (exit code, stderr, out)."""
    case = long_case(folder / "long.toml")
    out = folder / "long.nc" if out is None else out
    proc = catdae_process(["run", str(case), "-o", str(out), "--progress"], folder)
    code, err = signal_when(proc, sig, transient_runs)
    return code, err, out


def signal_when(proc, sig, ready, timeout=180.0) -> tuple[int, str]:
    """Send ``sig`` once ``ready(stderr so far)`` holds; return (exit code, stderr)."""
    chunks: list[bytes] = []

    def read_err():
        while b := proc.stderr.read1(4096):
            chunks.append(b)

    reader = threading.Thread(target=read_err, daemon=True)
    reader.start()
    try:
        deadline = time.monotonic() + timeout
        while not ready(b"".join(chunks).decode(errors="replace")):
            assert proc.poll() is None, b"".join(chunks).decode(errors="replace")
            assert time.monotonic() < deadline, b"".join(chunks).decode(errors="replace")
            time.sleep(0.05)
        proc.send_signal(sig)
        code = proc.wait(120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    reader.join(10)
    proc.stderr.close()
    return code, b"".join(chunks).decode(errors="replace")


def transient_runs(err: str) -> bool:
    """The progress bar of the transient step shows that it has passed t = 1 s."""
    shown = re.findall(r"dyn:.*?t=([0-9.]+)/", err)
    return bool(shown) and float(shown[-1]) > 1.0
