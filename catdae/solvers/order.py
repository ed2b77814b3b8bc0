"""The BDF order cap of ``max_order = "auto"`` (docs/theory.md §8.6): a measured race between
orders 2 and 5 (``OrderChoice``), and the frequencies about the start that scale it and the
velocity tolerance."""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from catdae.solvers.residual import TransientProblem


class OrderChoice:
    """The BDF order cap of ``max_order = "auto"``: a race between orders 2 and 5, measured.

    BDF orders 3-5 are not stable along the imaginary axis: undamped modes with h ω of order 1
    (the axial modes of a fine mesh) hold their step down whatever the accuracy needs. BDF2 is
    A-stable and damps them, but is less accurate per step. Which of the two takes fewer steps
    depends on the mesh, the tolerance and the motion, and changes during a run, so it is
    measured (docs/theory.md §8.6), in steps per simulated second over the second half of a
    *window* of steps of one IDA (a new IDA starts at order 1 with short steps). The run starts
    at order 2 where ω_max / ω₁ > ``START_RATIO`` (it leaves the state free of the fast content
    that order 5 carries and order 2 must first damp), at order 5 otherwise. After the first
    window the other order runs one window from the current state (a new IDA) and takes over if
    it measures fewer than ``MARGIN`` times the incumbent's steps per second (where it does not,
    the driver takes the trial back and the incumbent's IDA goes on from the trial's start:
    ``catdae.solvers.transient``). An order-2 window
    is ``LONG2`` times ``WINDOW`` steps: from a state order 5 left it first damps the axial
    content (about 350 steps on issue 11's cable at 48 elements) before its own rate shows, and
    a first window at order 2 lasts ``FIRST_TIME`` times the lowest period 2π/ω₁ (the start of
    a motion excites that content too), or ``FIRST_MAX`` windows if that comes first. The race
    is run again after ``FIRST_INTERVAL`` windows at the chosen order, the interval doubling
    each time the choice is kept and starting again when it changes, so that a change of
    regime is followed at a cost that shrinks with the run. No race is run with fewer than
    ``MIN_REMAINING`` trial windows of steps left (the trial could cost more than it saves), and
    order 5 is not tried where it cannot win: its steady steps have h ω_max < ``STABILITY_HW``
    (measured 0.2-0.8 undamped, 3.3 with example 1's damping), so it takes at least
    ω_max / ``STABILITY_HW`` steps per second. Deterministic: the decisions depend on the step
    counts and the times reached only. ``order_choice`` says what was measured."""

    WINDOW = 160  # steps per window; the second half is measured
    FIRST_INTERVAL = 8  # windows at the chosen order before the next race (doubles when kept)
    MARGIN = 0.9  # the trial order takes over where it takes fewer than MARGIN x the steps/s
    STABILITY_HW = 4.0  # order 5's steady h ω_max stays below this (measured <= 3.3)
    START_RATIO = 100.0  # ω_max / ω₁ above which the run starts at order 2
    MIN_REMAINING = 8  # no race when fewer than this many trial windows of steps are left
    LONG2 = 3  # an order-2 window is this many windows long (it first damps what order 5 left)
    FIRST_TIME = 0.1  # a first window at order 2 lasts at least this share of 2π/ω₁ ...
    FIRST_MAX = 16  # ... or this many windows of steps, whichever comes first

    def __init__(self, omega_max: float | None, omega_1: float, t_end: float = np.inf):
        self.t_end = t_end
        self.omega_max = omega_max
        self.omega_1 = omega_1
        self.order = 2 if (omega_max is not None
                           and omega_max / omega_1 > self.START_RATIO) else 5
        self.first = self.order
        self.mode = "first"  # first window; then "trial" of the other order; then "run"
        self.length = self._window(self.order)
        self.count = 0
        self.t_mark = None
        self.incumbent = self.order
        self.interval = self.FIRST_INTERVAL
        self.rate = {}  # steps per simulated second at each order, as the race uses them
        self.measured = {}  # the latest measurement at each order
        self.races = []  # (t, steps/s at 5, steps/s at 2, chosen)
        self.skipped = 0  # races not run because order 5 cannot win
        self.short = 0  # races not run because too little of the step was left
        self.since = None  # time the current order was chosen
        self.t_first = None  # time of the first step
        self.n_first = 0  # steps of the first window
        self.note = ("no highest frequency: order 5 kept" if omega_max is None else "")

    @property
    def measuring(self) -> bool:
        """False without ω_max: nothing to measure against, order 5 kept."""
        return self.omega_max is not None

    def restart(self) -> None:
        """IDA was started again (a kink or jump of a prescribed motion): the window's measured
        half is taken after a new ramp."""
        self.count = min(self.count, max(self.length - self.WINDOW, 0))
        self.t_mark = None

    def _window(self, order: int) -> int:
        return self.WINDOW * (self.LONG2 if order == 2 else 1)

    def _can_win(self, order: int) -> bool:
        if order == 2:
            return True
        return not (2 in self.rate
                    and self.MARGIN * self.rate[2] <= self.omega_max / self.STABILITY_HW)

    def _measure(self, measured: float) -> None:
        """The rate of the current order: the incumbent's is the lower of its last two
        measurements, so that a burst of short steps within one window (content either order
        must resolve) neither starts a race nor decides one."""
        previous = self.measured.get(self.order)
        self.measured[self.order] = measured
        self.rate[self.order] = (min(measured, previous) if self.mode == "run"
                                 and previous is not None else measured)

    def observe(self, t: float) -> int | None:
        """Called after every step at time t; returns the new order cap when it changes."""
        self.count += 1
        self.n_first += self.mode == "first"
        if self.t_first is None:
            self.t_first = t
        half = self.WINDOW // 2
        if self.count == self.length - half:
            self.t_mark = t
        if self.count < self.length or self.t_mark is None or t <= self.t_mark:
            if self.count >= self.length:  # interrupted by restarts: measure a new half
                self.count = self.length - half - 1
            return None
        if (self.mode == "first" and self.order == 2
                and t - self.t_first < self.FIRST_TIME * 2.0 * np.pi / self.omega_1
                and self.n_first < self.FIRST_MAX * self.WINDOW):
            self.count = self.length - half - 1  # order 2 is still damping what the start
            self.t_mark = None  # excited: measure a later half-window
            return None
        self._measure(half / (t - self.t_mark))
        self.count = 0
        self.t_mark = None
        other = 7 - self.order
        if self.mode in ("first", "run"):
            if self.since is None:
                self.since = t
            left = self.rate[self.order] * (self.t_end - t)  # steps still to go, about
            if left < self.MIN_REMAINING * self._window(other):
                self.short += 1
            elif self._can_win(other):
                self.incumbent = self.order
                self.mode = "trial"
                self.length = self._window(other)
                self.order = other
                return other
            else:
                self.skipped += 1
            self.mode = "run"
            self.length = self.interval * self.WINDOW
            return None
        # end of a trial: the cheaper goes on
        trial, inc = self.order, self.incumbent
        best = trial if self.rate[trial] < self.MARGIN * self.rate[inc] else inc
        self.races.append((t, self.rate[5], self.rate[2], best))
        if best == self.incumbent:
            self.interval *= 2
        else:
            self.interval = self.FIRST_INTERVAL
            self.since = t
        self.mode = "run"
        self.length = self.interval * self.WINDOW
        if best != self.order:
            self.order = best
            return best
        return None

    def summary(self) -> str:
        if self.note:
            return self.note
        text = f"order {self.order}"
        if self.races:
            t, r5, r2, _ = self.races[-1]
            text += (f" (started at {self.first}; since t = {self.since:.4g} s): last race at "
                     f"t = {t:.4g} s, {r2:.4g} steps/s at order 2 vs {r5:.4g} at order 5; "
                     f"{len(self.races)} race(s), chosen "
                     + ", ".join(str(b) for *_, b in self.races))
        elif self.rate:
            text += f" (started at {self.first}): {self.rate.get(self.order, 0):.4g} steps/s"
        else:
            text += f" (started at {self.first}; too few steps to measure)"
        if self.skipped:
            text += (f"; order 5 not tried {self.skipped} time(s): its stability bound "
                     f"ω_max/{self.STABILITY_HW:g} = {self.omega_max / self.STABILITY_HW:.4g} "
                     f"steps/s against {self.rate.get(2, 0):.4g} measured at order 2")
        if self.short:
            text += (f"; {self.short} race(s) left out: fewer than {self.MIN_REMAINING} trial "
                     "windows of steps to go")
        return text


def _extreme_frequency(prob: TransientProblem, t0: float, y0: np.ndarray,
                       highest: bool) -> float | None:
    """ω (rad/s) of the lowest (or the highest) mode of the free dofs about the start, or None
    if it cannot be had. Dense below 400 unknowns; above, ARPACK from a fixed start vector
    (its default is random, which made identical runs differ in their velocity atol and so in
    their step counts): shift-invert about 0 for the lowest, largest algebraic (to 1 %) for the
    highest."""
    conf = prob.configuration(t0, y0[0::2])
    if conf is None:
        return None
    n = prob.n
    try:
        mff = prob.ff(prob.mass_data(conf))
        kff = prob.ff(prob.blocks(conf, 0.0)[0])  # K_t, with connectors if any
        if n <= 400:
            k = n - 1 if highest else 0
            lam = sla.eigh(kff.toarray(), mff.toarray(), eigvals_only=True,
                           subset_by_index=[k, k])[0]
        else:
            v0 = np.linspace(1.0, 2.0, n)
            opts = dict(which="LA", tol=1e-2) if highest else dict(sigma=0.0, which="LM")
            lam = spla.eigsh(kff.tocsc(), 1, mff.tocsc(), v0=v0, return_eigenvectors=False,
                             **opts)[0]
        if np.isfinite(lam) and lam > 0:
            return float(np.sqrt(lam))
    except (ValueError, RuntimeError, np.linalg.LinAlgError, spla.ArpackError):
        pass
    return None


def highest_frequency(prob: TransientProblem, t0: float, y0: np.ndarray) -> float | None:
    """ω_max about the start (rad/s), or None: the stability scale of OrderChoice."""
    return _extreme_frequency(prob, t0, y0, highest=True)


def reference_frequency(prob: TransientProblem, t0: float, y0: np.ndarray) -> float:
    """ω of the lowest mode about the start (rad/s): scales the velocity tolerance (2π if it
    cannot be had)."""
    omega = _extreme_frequency(prob, t0, y0, highest=False)
    return 2.0 * np.pi if omega is None else omega

