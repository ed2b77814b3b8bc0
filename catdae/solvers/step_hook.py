"""What a transient does after each of IDA's steps, run from inside IDA (docs/theory.md §8.8).

IDA is called once per output time (its "normal" mode: it steps past the output and
interpolates back). What must see every accepted step (the tension envelope, the fluid's work,
the step count, the order race, a stalled step size, the progress report) is done by
``StepHook``, which IDA calls as its root function: with root finding on, IDA evaluates the
root function at the end of every step it takes, in time order, and at each output time it
interpolates to. The function never has a root unless the hook asks IDA to stop (the order
race chose a new order cap, or the step size collapsed): it then changes sign at that step's
end, IDA locates the root there and returns at it, and the driver acts. Calling IDA once per
step instead (its "one-step" mode) costs a round trip through scikit-sundae's Python wrapper
per step (a result object, copies of the state, statistics), about as much as IDA's own work
on a small mesh.
"""

from __future__ import annotations

import math
import time

STALL_STEP = 1e-12  # a step shorter than this (relative to t or the output interval) ...
STALL_COUNT = 200  # ... this many times in a row stops the step as stuck


class StepHook:
    """IDA's root function (one component): the per-step work of a transient ``run``
    (catdae.solvers.transient), and a sign change at a step's end where the driver must act.

    ``aim(tout, tstop)`` before each IDA call says which time is an output (evaluated by IDA
    without a step ending there, unless it is also the stop time, where IDA ends a step
    exactly). Evaluations at or before the latest time seen are IDA locating a root (or the
    check at a restart): they only answer the sign."""

    def __init__(self, run, bar):
        self.run = run
        self.bar = bar
        self.shift = getattr(run, "shift", None)  # IDA's y are displacements (§18.7)
        self.work = run.outputs.work
        self.envelope = run.outputs.envelope
        self.race = run.order_choice if (run.order_choice is not None
                                         and run.order_choice.measuring) else None
        self.dt_out = run.dt_out
        # a callable of the envelope that returns why the step must stop ("" to go on), or None
        self.watch = getattr(run, "watch", None)
        self.stop_reason = ""
        self.tout = self.tstop = math.nan
        # a snapshot of the run so far is due every write_every s of wall time (None: no
        # writer), at the wall time ``due``; between two outputs the hook asks IDA to return
        self.write_every: float | None = None
        self.due = math.inf
        self.reset(run.t0)

    def reset(self, t: float) -> None:
        """IDA starts (again) from time t: nothing asked of it, nothing seen after t."""
        self.t_seen = self.t_prev = t
        self.t_flag = None  # the step end at which IDA is asked to return
        self.new_order = None  # the order cap the race chose there
        self.snapshot = False  # IDA returns there for a snapshot
        self.stalled = 0
        self.stuck = False

    def aim(self, tout: float, tstop: float) -> None:
        self.tout, self.tstop = tout, tstop

    def take_order(self) -> int | None:
        """The order cap asked for at the flagged step (None: a stall), and the flag cleared."""
        new, self.new_order, self.t_flag = self.new_order, None, None
        self._forget_returns()
        return new

    def _forget_returns(self) -> None:
        """Empty the lists in which scikit-sundae keeps every root return (on this object, its
        ``eventsfn``): it turns them into arrays at each call of IDA, a cost that would grow
        with every return of a long run (a snapshot every 20 s); catdae does not read them."""
        for name in ("_i", "_t", "_y", "_yp"):
            kept = getattr(self, name, None)
            if isinstance(kept, list):
                kept.clear()

    def written(self, every: float | None = None) -> None:
        """A snapshot was written (or snapshots begin, every ``every`` s): the next is due
        write_every s of wall time from now."""
        if every is not None:
            self.write_every = every
        if self.write_every is not None:
            self.due = time.perf_counter() + self.write_every

    def snapshot_due(self) -> bool:  # (inlined in _step, which runs at every step)
        return time.perf_counter() > self.due

    def take_snapshot(self) -> bool:
        """Whether IDA returned for a snapshot (the flag then cleared: IDA goes on as it was)."""
        if not self.snapshot:
            return False
        self.snapshot, self.t_flag = False, None
        self._forget_returns()
        return True

    def __call__(self, t, y, yp, events):
        if t > self.t_seen and self.t_flag is None:
            self.t_seen = t
            if t != self.tout or t == self.tstop:  # the end of an accepted step
                self._step(t, y if self.shift is None else self.shift.view(y, "hook"), yp)
        events[0] = -1.0 if self.t_flag is not None and t >= self.t_flag else 1.0

    def _step(self, t: float, y, yp) -> None:
        run = self.run
        run.n_steps += 1
        self.envelope.update(t, y)
        if self.watch is not None and self.t_flag is None:
            self.stop_reason = self.watch(self.envelope, t)
            if self.stop_reason:
                self.t_flag = t  # IDA returns here, and the driver stops the step
        if self.work is not None:
            self.work.advance(t, y, yp)
        small = t - self.t_prev <= STALL_STEP * max(abs(t), self.dt_out)
        self.stalled = self.stalled + 1 if small else 0
        self.t_prev = t
        if self.stalled >= STALL_COUNT:
            self.stuck = True
            self.t_flag = t
        elif self.race is not None and t != self.tstop:  # a stop restarts IDA anyway
            new = self.race.observe(t)
            if new is not None:
                self.new_order, self.t_flag = new, t
        if self.t_flag is None and t != self.tstop and time.perf_counter() > self.due:
            self.snapshot, self.t_flag = True, t  # a long stretch between outputs
        self.bar.update(t)
