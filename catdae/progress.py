"""Progress of a long step, on a terminal and in logs.

On a terminal a tqdm bar; elsewhere (logs, CI, batch jobs, where a bar is either hidden or a
mess of carriage returns) one plain line on stderr every ``interval`` seconds of wall time
(``CATDAE_LOG_INTERVAL`` in the environment, default 15 s):

    catdae: release: t = 1.25 / 4 s (31 %), 42.0 s wall

Both have the same interface: ``update(t)`` with the step's current time, ``close()`` at the end.
In a log the lines come from a ticker thread, so they keep coming while the step is inside one
long call (numba compiling the kernels, which the line then says, or one long integrator
step); the step starts its reporter before its set-up. :func:`announce_compiling` prints one
line when numba first compiles during a run (``catdae run``).
"""

from __future__ import annotations

import os
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import IO

from numba.core import event

LOG_INTERVAL = 15.0  # s of wall time between two log lines (CATDAE_LOG_INTERVAL overrides)


class _Compilations(event.Listener):
    """numba's "numba:compile" events (fired for real compilations, not for loads from the
    on-disk cache): how many are under way, and callbacks at the start of the first."""

    def __init__(self):
        self.active = 0
        self.on_first: list = []

    def on_start(self, ev) -> None:
        self.active += 1
        if self.active == 1:
            for callback in list(self.on_first):
                callback()

    def on_end(self, ev) -> None:
        self.active = max(self.active - 1, 0)


_COMPILATIONS = _Compilations()
_ANNOUNCED: list[bool] = []  # the compiling line was printed in this process
event.register("numba:compile", _COMPILATIONS)


def compiling() -> bool:
    """Whether numba is compiling a kernel right now (in any thread)."""
    return _COMPILATIONS.active > 0


@contextmanager
def announce_compiling(stream: IO[str] | None = None) -> Iterator[None]:
    """Within the block, the first time numba compiles a line on ``stream`` (default stderr)
    says so, once per process (a run compiles some kernels in its static step and others in
    its transient): after an install or an upgrade the kernels take about a minute."""
    said = _ANNOUNCED

    def say():
        if not said:
            said.append(True)
            print("catdae: compiling the element kernels for this machine (once after install "
                  "or upgrade, about a minute)...", file=stream if stream is not None
                  else sys.stderr, flush=True)

    _COMPILATIONS.on_first.append(say)
    try:
        yield
    finally:
        _COMPILATIONS.on_first.remove(say)


def log_interval() -> float:
    """The wall time between two log lines, s: ``CATDAE_LOG_INTERVAL`` if set to a number > 0,
    else LOG_INTERVAL."""
    try:
        value = float(os.environ.get("CATDAE_LOG_INTERVAL", ""))
    except ValueError:
        return LOG_INTERVAL
    return value if 0.0 < value < float("inf") else LOG_INTERVAL


class LogProgress:
    """A line on ``stream`` at most every ``interval`` s of wall time, and one at the end if
    the step took longer than ``interval``: the step's name, t / t_end and the wall time.

    ``ticker``: a daemon thread also prints a line whenever ``interval`` s passed without one,
    so that lines keep coming while the caller is blocked in one long call; such a line says
    ", compiling the kernels" while numba compiles. ``close()`` stops it."""

    def __init__(self, name: str, t0: float, t_end: float, interval: float = LOG_INTERVAL,
                 stream: IO[str] | None = None, clock=time.perf_counter, ticker: bool = False):
        self.name = name
        self.t0 = float(t0)
        self.t_end = float(t_end)
        self.interval = float(interval)
        self.stream = stream
        self.clock = clock
        self.start = clock()
        self.last = self.start
        self.t = self.t0
        self.lines = 0
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = None
        if ticker and self.interval > 0.0:
            self._thread = threading.Thread(target=self._tick, name=f"catdae-progress-{name}",
                                            daemon=True)
            self._thread.start()

    def _tick(self) -> None:
        while not self._stop.wait(min(0.25 * self.interval, 1.0)):
            with self._lock:
                now = self.clock()
                if not self._stop.is_set() and now - self.last >= self.interval:
                    self._line(now, note=", compiling the kernels" if compiling() else "")

    def update(self, t: float) -> None:
        self.t = float(t)
        now = self.clock()
        if now - self.last >= self.interval:
            with self._lock:
                self._line(now)

    def close(self) -> None:
        if self._stop.is_set():
            return
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        now = self.clock()
        if self.lines and self.last < now:
            self._line(now, done=True)

    def _line(self, now: float, done: bool = False, note: str = "") -> None:
        span = self.t_end - self.t0
        pct = 100.0 * (self.t - self.t0) / span if span > 0 else 100.0
        # the last line: "done" where the step got to its end, "stopped" where it did not
        finished = self.t >= self.t_end - 1e-9 * max(abs(self.t_end), span, 1e-300)
        end = (", done" if finished else ", stopped") if done else ""
        stream = self.stream if self.stream is not None else sys.stderr
        print(f"catdae: {self.name}: t = {self.t:.6g} / {self.t_end:.6g} s ({pct:.0f} %), "
              f"{now - self.start:.1f} s wall{note}{end}", file=stream, flush=True)
        self.last = now
        self.lines += 1


class BarProgress:
    """A tqdm bar over the step's time span (for a terminal)."""

    def __init__(self, name: str, t0: float, t_end: float):
        from tqdm import tqdm

        self.t0 = float(t0)
        self.bar = tqdm(total=float(t_end) - self.t0, desc=name, unit="s", leave=False,
                        bar_format="{desc}: {percentage:3.0f}%|{bar}| t={n:.3f}/{total:.3f} s "
                                   "[{elapsed}<{remaining}]")

    def update(self, t: float) -> None:
        self.bar.update(float(t) - self.t0 - self.bar.n)

    def close(self) -> None:
        self.bar.close()


class NoProgress:
    def update(self, t: float) -> None:
        pass

    def close(self) -> None:
        pass


def reporter(progress: bool | None, name: str, t0: float, t_end: float):
    """``progress`` True: a bar; False: nothing; None (the default): a bar when stderr is a
    terminal, log lines otherwise."""
    if progress is None:
        if sys.stderr.isatty():
            return BarProgress(name, t0, t_end)
        return LogProgress(name, t0, t_end, interval=log_interval(),
                           ticker=True)
    return BarProgress(name, t0, t_end) if progress else NoProgress()


def say(text: str = "") -> None:
    """A line on standard output. A reader that has gone (``catdae run | head -1``: a broken
    pipe) stops the printing, not the work: the rest of the output is discarded."""
    try:
        print(text, flush=True)
    except BrokenPipeError:
        try:  # further prints and the flush at exit go nowhere instead of failing again
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            os.close(devnull)
        except (OSError, ValueError):
            pass
