"""Progress of a long step, on a terminal and in logs.

On a terminal a tqdm bar; elsewhere (logs, CI, batch jobs, where a bar is either hidden or a
mess of carriage returns) one plain line on stderr every ``interval`` seconds of wall time:

    catdae: release: t = 1.25 / 4 s (31 %), 42.0 s wall

Both have the same interface: ``update(t)`` with the step's current time, ``close()`` at the end.
"""

from __future__ import annotations

import os
import sys
import time
from typing import IO

LOG_INTERVAL = 15.0  # s of wall time between two log lines


class LogProgress:
    """A line on ``stream`` at most every ``interval`` s of wall time, and one at the end if
    the step took longer than ``interval``: the step's name, t / t_end and the wall time."""

    def __init__(self, name: str, t0: float, t_end: float, interval: float = LOG_INTERVAL,
                 stream: IO[str] | None = None, clock=time.perf_counter):
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

    def update(self, t: float) -> None:
        self.t = float(t)
        now = self.clock()
        if now - self.last >= self.interval:
            self._line(now)

    def close(self) -> None:
        now = self.clock()
        if self.lines and self.last < now:
            self._line(now, done=True)

    def _line(self, now: float, done: bool = False) -> None:
        span = self.t_end - self.t0
        pct = 100.0 * (self.t - self.t0) / span if span > 0 else 100.0
        end = ", done" if done else ""
        stream = self.stream if self.stream is not None else sys.stderr
        print(f"catdae: {self.name}: t = {self.t:.6g} / {self.t_end:.6g} s ({pct:.0f} %), "
              f"{now - self.start:.1f} s wall{end}", file=stream, flush=True)
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
        return LogProgress(name, t0, t_end, interval=LOG_INTERVAL)
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
