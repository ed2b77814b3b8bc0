"""Nonlinear transient dynamics with SUNDIALS IDA (docs/theory.md §8): the driver.

The only module that imports sksundae. ``run_transient`` integrates one transient step: it
builds the residual and iteration matrix (``residual.TransientProblem``), picks the linear
solver, the tolerances and the BDF order cap, steps IDA one internal step at a time (stopping
and restarting at the kinks and jumps of prescribed motions and loads), records the output times
(``transient_results.Outputs``) and keeps what was computed when a run fails or is interrupted.

BDF order (``max_order = "auto"``, the default): OrderChoice races orders 5 and 2, a window of
steps each from the same state, and goes on with the one that takes fewer steps per simulated
second, racing again now and then (docs/theory.md §8.6).
"""

from __future__ import annotations

import time as _time
import warnings

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla
from sksundae.ida import IDA

from catdae._xr import xr
from catdae.errors import SolverError
from catdae.model.assembly import Model
from catdae.output.transient import Outputs, note
from catdae.progress import reporter
from catdae.solvers.residual import TransientProblem

__all__ = ["IDA", "OrderChoice", "TransientProblem", "choose_solver", "run_transient"]

INCREMENT_SECONDS = 20.0  # wall time between incremental writes of a long run
STALL_STEP = 1e-12  # a step shorter than this (relative to t or the output interval) ...
STALL_COUNT = 200  # ... this many times in a row stops the step as stuck


def choose_solver(problem: TransientProblem, requested: str) -> str:
    """'band' when the band is narrow, 'sparse' for networks with a wide band, 'dense' tiny."""
    if requested != "auto":
        return requested
    n2 = 2 * problem.n
    band = 4 * problem.bandwidth + 3
    if n2 <= 24:
        return "dense"
    # measured (benchmarks/transient_speed.md): band is fastest up to ~50 elements; from ~200
    # elements sparse is as fast or faster, and sksundae's band matrix is stored as n x n
    if band <= max(32, n2 // 4) and n2 <= 800:
        return "band"
    return "sparse"


def run_transient(step, model: Model, state, writer, progress) -> xr.Dataset:
    """Integrate one transient step from ``state`` (positions, velocities, tensions)."""
    wall0 = _time.perf_counter()
    prob = TransientProblem(model, step, state.X, state.h)
    t0 = float(state.t)  # one clock for the whole case: a transient continues the time
    t_end = t0 + float(step.duration)
    dt_out = float(step.output_interval)
    n_out = int(np.floor((t_end - t0) / dt_out + 1e-9)) + 1
    times = t0 + dt_out * np.arange(n_out)
    if times[-1] < t_end - 1e-9 * dt_out:
        times = np.append(times, t_end)
    times[-1] = t_end  # exactly: the next step starts there
    y0, yp0 = prob.initial(t0, state.X, state.V)
    linsolver = choose_solver(prob, step.linear_solver)
    omega = _reference_frequency(prob, t0, y0)
    atol = np.empty(2 * prob.n)
    atol[0::2] = step.atol
    atol[1::2] = step.atol * omega
    auto = step.max_order == "auto"
    order_choice = (OrderChoice(_highest_frequency(prob, t0, y0), omega, t_end)
                    if auto else None)
    options = dict(rtol=step.rtol, atol=atol,
                   max_order=order_choice.order if auto else int(step.max_order),
                   max_num_steps=100000, linsolver=linsolver)
    if linsolver == "band":
        bw = prob.bandwidth
        options.update(lband=2 * bw + 1, uband=max(2 * bw, 1), jacfn=prob.jac_dense)
    elif linsolver == "sparse":
        options.update(sparsity=prob.j_pattern, jacfn=prob.jac_sparse)
    else:
        options.update(jacfn=prob.jac_dense)
    def make_solver(max_order):
        with warnings.catch_warnings():
            # sksundae warns that its own sparse approximation is unused when jacfn is given:
            # that is the intent (the analytic iteration matrix)
            warnings.filterwarnings("ignore", "Custom sparse Jacobian approximation",
                                    UserWarning)
            return IDA(prob.resfn, **dict(options, max_order=max_order))

    solver = make_solver(options["max_order"])
    solver.init_step(t0, y0, yp0)

    outputs = Outputs(prob, times)
    record = outputs.record

    n_steps = 0
    n_restarts = 0
    status = "completed"
    interrupt = None
    k_done = 0
    bar = reporter(progress, step.name, t0, t_end)
    last_write = _time.perf_counter()

    def dataset(n_valid):
        attrs = {
            "n_steps": n_steps, "n_residual_evaluations": prob.n_res,
            "n_jacobian_evaluations": prob.n_jac,
            "n_rejected_states": prob.n_rejected,
            "wall_time": _time.perf_counter() - wall0, "rtol": step.rtol, "atol": step.atol,
            "atol_velocity": step.atol * omega, "status": status, "linear_solver": linsolver,
            "bandwidth": prob.bandwidth,
            "max_order": (order_choice.order if auto else int(step.max_order)),
            "max_order_setting": str(step.max_order),
            "order_choice": order_choice.summary() if auto else "fixed by the step",
            "mass_model": model.mass_model, "mass_model_setting": model.mass_model_setting,
            "mass_model_choice": model.mass_model_choice,
            "inertia": step.inertia if prob.lagrangian else
            "paper" if model.mass_model in ("consistent", "blended") else "constant mass",
            "damping": "none" if step.damping is None else step.damping.kind,
            "rayleigh_alpha": prob.alpha, "rayleigh_beta": prob.beta,
            "n_outputs": n_valid, "n_restarts": n_restarts, "note": note(model, prob),
        }
        return outputs.dataset(n_valid, attrs)

    try:
        record(0, t0, y0, yp0)
        k_done = 1
        t_int = t0
        stalled = 0
        # kinks and jumps of the prescribed motions and loads: the integrator stops at each
        # and restarts from a consistent state (momentum balance across a velocity jump)
        groups = model.breakpoints(t0, t_end)
        end_jump = bool(groups) and groups[-1][1] == t_end
        stops = [at for _, at in groups]
        befores = [before for before, _ in groups]
        if not end_jump:
            stops.append(t_end)
            befores.append(t_end)
        i_stop = 0
        while k_done < times.size:
            t_stop = stops[i_stop]
            res = solver.step(t_stop, method="onestep", tstop=t_stop)
            if not res.success:
                status = f"IDA stopped at t = {t_int:.6g} s: {res.message}"
                break
            t_new = float(np.atleast_1d(res.t)[-1])
            if t_new > t_int:
                n_steps += 1
            # IDA's max_num_steps counts per call; in one-step mode guard the step size
            # ourselves: steps that no longer advance time mean the integration is stuck
            stalled = stalled + 1 if t_new - t_int <= STALL_STEP * max(abs(t_new), dt_out) else 0
            t_int = t_new
            if stalled >= STALL_COUNT:
                status = (f"step size collapsed at t = {t_int:.6g} s (IDA could not advance; "
                          f"{prob.n_rejected} trial states rejected)")
                break
            y_last, yp_last = np.atleast_2d(res.y)[-1], np.atleast_2d(res.yp)[-1]
            at_stop = ((t_stop < t_end or end_jump)
                       and t_int >= t_stop - 1e-13 * max(abs(t_stop), 1.0))
            while k_done < times.size and times[k_done] <= t_int * (1 + 1e-13) + 1e-300:
                tk = times[k_done]
                if abs(tk - t_int) <= 1e-13 * max(abs(t_int), 1.0):
                    if at_stop:
                        break  # recorded after the restart, with the velocities after it
                    yk, ypk = y_last, yp_last
                else:
                    ri = solver.step(tk, method="normal")
                    yk, ypk = np.atleast_2d(ri.y)[-1], np.atleast_2d(ri.yp)[-1]
                record(k_done, tk, yk, ypk)
                k_done += 1
            if at_stop:
                t_int = t_stop
                y_last, yp_last = prob.restart(t_stop, y_last, befores[i_stop])
                n_restarts += 1
                i_stop += 1
                if i_stop < len(stops):
                    solver.init_step(t_stop, y_last, yp_last)
                    if order_choice is not None:
                        order_choice.restart()
                while (k_done < times.size
                       and abs(times[k_done] - t_int) <= 1e-13 * max(abs(t_int), 1.0)):
                    record(k_done, times[k_done], y_last, yp_last)
                    k_done += 1
            elif order_choice is not None and order_choice.measuring:
                new_order = order_choice.observe(t_int)
                if new_order is not None:
                    solver = make_solver(new_order)
                    solver.init_step(t_int, y_last, yp_last)
            bar.update(t_int)
            if writer is not None and _time.perf_counter() - last_write > INCREMENT_SECONDS:
                writer.write_increment(step.name, dataset(k_done))
                last_write = _time.perf_counter()
    except KeyboardInterrupt as exc:  # goes on after the partial dataset is attached below
        status = f"interrupted at t = {times[max(k_done - 1, 0)]:.6g} s"
        interrupt = exc
    except SolverError as exc:
        status = str(exc)
    except Exception as exc:  # nothing lost: keep what was computed, say what went wrong
        status = (f"stopped after t = {times[max(k_done - 1, 0)]:.6g} s by an unexpected "
                  f"error: {type(exc).__name__}: {exc}")
    finally:
        bar.close()
    ds = dataset(k_done)
    if interrupt is not None:
        interrupt.partial = ds
        raise interrupt
    if status != "completed":
        raise SolverError(f"transient step '{step.name}': {status}", termination=status,
                          partial=ds)
    # hand the final state to the next step
    state.X = outputs.X[-1].copy()
    state.V = outputs.V[-1].copy()
    state.h = prob.h
    state.t = t_end
    return ds


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
    it measures fewer than ``MARGIN`` times the incumbent's steps per second. An order-2 window
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
        self.rate = {}  # latest steps per simulated second measured at each order
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
        self.rate[self.order] = half / (t - self.t_mark)
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


def _highest_frequency(prob: TransientProblem, t0: float, y0: np.ndarray) -> float | None:
    """ω_max about the start (rad/s), or None: the stability scale of OrderChoice."""
    return _extreme_frequency(prob, t0, y0, highest=True)


def _reference_frequency(prob: TransientProblem, t0: float, y0: np.ndarray) -> float:
    """ω of the lowest mode about the start (rad/s): scales the velocity tolerance (2π if it
    cannot be had)."""
    omega = _extreme_frequency(prob, t0, y0, highest=False)
    return 2.0 * np.pi if omega is None else omega

