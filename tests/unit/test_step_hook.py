"""catdae.solvers.step_hook: IDA's root function as the per-step callback of a transient
(docs/theory.md §8.8). A stand-in run records what the hook does with the calls IDA makes:
step ends, output times it interpolates to, and the evaluations of root location."""

from __future__ import annotations

import types

import numpy as np

from catdae.solvers.step_hook import STALL_COUNT, StepHook


class _Envelope:
    def __init__(self):
        self.times = []

    def update(self, t, y):
        self.times.append(t)


class _Race:
    """Asks for order 5 at the third step it sees."""

    measuring = True

    def __init__(self):
        self.seen = []

    def observe(self, t):
        self.seen.append(t)
        return 5 if len(self.seen) == 3 else None


class _Bar:
    def update(self, t):
        self.t = t


def _hook(race=None):
    run = types.SimpleNamespace(outputs=types.SimpleNamespace(work=None, envelope=_Envelope()),
                                order_choice=race, dt_out=0.1, t0=0.0, n_steps=0)
    return StepHook(run, _Bar()), run


def _call(hook, t):
    events = np.zeros(1)
    y = np.zeros(2)
    hook(t, y, y, events)
    return events[0]


def test_steps_are_counted_and_outputs_are_not():
    hook, run = _hook()
    hook.aim(0.1, 1.0)  # an output at 0.1, the stop at 1.0
    for t in (0.03, 0.07, 0.1, 0.12):  # 0.1 is the interpolated output, not a step
        assert _call(hook, t) == 1.0
    assert run.n_steps == 3
    assert run.outputs.envelope.times == [0.03, 0.07, 0.12]
    assert _call(hook, 0.05) == 1.0 and run.n_steps == 3  # a root-location query: no step
    hook.aim(1.0, 1.0)  # an output at the stop: IDA ends a step exactly there
    _call(hook, 1.0)
    assert run.n_steps == 4 and hook.bar.t == 1.0


def test_a_race_decision_is_a_root_at_that_step_end():
    race = _Race()
    hook, run = _hook(race)
    hook.aim(1.0, 2.0)
    assert [_call(hook, t) for t in (0.1, 0.2)] == [1.0, 1.0]
    assert _call(hook, 0.3) == -1.0  # the race chose: the sign changes at this step's end
    # IDA locates the root between the last two step ends: + before 0.3, - from 0.3 on
    assert _call(hook, 0.25) == 1.0 and _call(hook, 0.2999999) == 1.0
    assert _call(hook, 0.3) == -1.0
    assert run.n_steps == 3 and race.seen == [0.1, 0.2, 0.3]
    assert hook.take_order() == 5
    hook.reset(0.3)  # the driver goes on from the step end with a new IDA
    assert _call(hook, 0.3) == 1.0 and run.n_steps == 3  # IDA's check at its start
    assert _call(hook, 0.4) == 1.0 and run.n_steps == 4


def test_no_race_is_observed_at_a_stop():
    race = _Race()
    hook, _ = _hook(race)
    hook.aim(0.5, 0.5)
    _call(hook, 0.5)  # a step ends at the stop: the driver restarts IDA there anyway
    assert race.seen == []


def test_a_collapsed_step_size_stops_the_run():
    hook, run = _hook()
    hook.reset(0.5)
    hook.aim(1.0, 2.0)
    t, signs = 0.5, []
    for _ in range(STALL_COUNT):
        t += 1e-14
        signs.append(_call(hook, t))
    assert signs[:-1] == [1.0] * (STALL_COUNT - 1) and signs[-1] == -1.0
    assert hook.take_order() is None  # None: no order, the run is stuck
    hook2, _ = _hook()
    hook2.reset(0.5)
    hook2.aim(1.0, 2.0)
    t = 0.5
    for k in range(2 * STALL_COUNT):  # short steps broken by a normal one: not stuck
        t += 1e-3 if k % 100 == 99 else 1e-14
        assert _call(hook2, t) == 1.0


def test_a_due_snapshot_is_a_root_at_a_step_end_only():
    hook, run = _hook()
    hook.aim(0.1, 1.0)
    hook.written(every=0.0)  # due at once
    assert _call(hook, 0.1) == 1.0  # the output at 0.1 is not a step: no return for it
    assert _call(hook, 0.12) == -1.0  # a step end: IDA returns there
    assert hook.take_snapshot() and not hook.take_snapshot()
    assert _call(hook, 0.12) == 1.0  # IDA's check at the return: the sign is back
    hook.written(every=1e9)  # the next far off
    assert _call(hook, 0.15) == 1.0 and not hook.take_snapshot()
    hook.written(every=0.0)
    hook.aim(1.0, 1.0)
    assert _call(hook, 1.0) == 1.0  # the stop: IDA returns there anyway
    assert run.n_steps == 3


def test_the_wrappers_record_of_returns_does_not_grow():
    """scikit-sundae appends every root return to lists on its eventsfn and converts them to
    arrays at each IDA call: the hook empties them when the driver takes a return."""
    hook, _ = _hook()
    for name in ("_i", "_t", "_y", "_yp"):
        setattr(hook, name, [np.zeros(2)] * 3)
    hook.written(every=0.0)
    hook.aim(0.1, 1.0)
    assert _call(hook, 0.05) == -1.0 and hook.take_snapshot()
    assert all(getattr(hook, name) == [] for name in ("_i", "_t", "_y", "_yp"))
    for name in ("_i", "_t", "_y", "_yp"):
        setattr(hook, name, [np.zeros(2)])
    hook.take_order()
    assert all(getattr(hook, name) == [] for name in ("_i", "_t", "_y", "_yp"))
