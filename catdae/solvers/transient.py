"""Nonlinear transient dynamics with SUNDIALS IDA (docs/theory.md §8): the driver.

The only module that imports sksundae. ``run_transient`` integrates one transient step: it
builds the residual and iteration matrix (``residual.TransientProblem``), picks the linear
solver, the tolerances and the BDF order cap, calls IDA once per output time with the per-step
work in its root function (``step_hook.StepHook``), stops and restarts at the kinks and jumps
of prescribed motions and loads, records the output times (``record.OutputRecord``) and keeps
what was computed when a run fails or is interrupted. Its phases: output times, IDA options
(linear solver, tolerances, order), the consistent start, the integration loop, attributes.

BDF order (``max_order = "auto"``, the default): OrderChoice races orders 5 and 2, a window of
steps each from the same state, and goes on with the one that takes fewer steps per simulated
second, racing again now and then (docs/theory.md §8.6).
"""

from __future__ import annotations

import math
import sys
import time as _time
import types
import warnings

from catdae.errors import SolverError
from catdae.model.assembly import Model
from catdae.model.snap import jump_floor, velocity_jumps
from catdae.progress import reporter
from catdae.solvers.order import OrderChoice, highest_frequency, reference_frequency
from catdae.solvers.record import OutputRecord, note, output_times
from catdae.solvers.residual import TransientProblem
from catdae.solvers.shift import Shift
from catdae.solvers.step_hook import StepHook
from catdae.solvers.tolerance import error_weights, resolve_mode


def _import_ida():
    """sksundae's IDA, without importing all of scipy.optimize (0.19 s of CPU per process,
    benchmarks/startup.md) for ``group_columns``, which scikit-sundae 1.2 imports for finite-
    difference Jacobians catdae never asks for. While sksundae is imported a stand-in holds
    ``scipy.optimize._numdiff`` (its ``group_columns`` and any other name go to the real module
    at first use) and leaves ``sys.modules`` right after; otherwise the ordinary import."""
    name = "scipy.optimize._numdiff"
    if name in sys.modules or "sksundae.ida" in sys.modules:
        from sksundae.ida import IDA
        return IDA

    def group_columns(*args, **kwargs):
        from scipy.optimize._numdiff import group_columns as real
        return real(*args, **kwargs)

    def real_attribute(attr):  # another name asked of it: the real module from here on
        import importlib
        if sys.modules.get(name) is stand_in:
            del sys.modules[name]
        return getattr(importlib.import_module(name), attr)

    stand_in = types.ModuleType(name)
    stand_in.group_columns = group_columns
    stand_in.__getattr__ = real_attribute
    sys.modules[name] = stand_in
    try:
        from sksundae.ida import IDA
    except ImportError:
        sys.modules.pop(name, None)
        from sksundae.ida import IDA
    finally:
        if sys.modules.get(name) is stand_in:
            del sys.modules[name]
    return IDA


IDA = _import_ida()

__all__ = ["IDA", "OrderChoice", "TransientProblem", "choose_solver", "run_transient"]

INCREMENT_SECONDS = 20.0  # wall time between incremental writes of a long run
IDA_ROOT_RETURN = 2  # IDASolve's flags: returned at a root of the root function (StepHook)
IDA_TOO_MUCH_WORK = -1  # ... max_num_steps taken in one call


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


def run_transient(step, model: Model, state, writer, progress, watch=None) -> OutputRecord:
    """Integrate one transient step from ``state`` (positions, velocities, tensions): the
    output record (arrays and attributes). On failure or interrupt the record of what was
    computed is the exception's ``partial``; ``writer.write_increment`` gets snapshots."""
    # the progress reporter runs from the step's start: the set-up may compile the kernels
    bar = reporter(progress, step.name, float(state.t), float(state.t) + float(step.duration))
    try:
        run = _Run(step, model, state, watch)
        rec = run.integrate(writer, bar)
    finally:
        bar.close()
    # hand the final state to the next step
    state.X = rec.X[-1].copy()
    state.V = rec.V[-1].copy()
    state.h = run.prob.h
    state.t = run.t_end
    return rec


class _Run:
    """One transient step in named phases: set-up (output times, IDA options, the consistent
    start) in ``__init__``, then ``integrate`` (the loop), ``attributes`` (what the results
    say of the run)."""

    def __init__(self, step, model: Model, state, watch=None):
        self.wall0, self.watch = _time.perf_counter(), watch  # watch: StepHook may stop it
        self.step, self.model = step, model
        self.prob = prob = TransientProblem(model, step, state.X, state.h)
        self.t0 = float(state.t)  # one clock for the whole case: a transient continues the time
        self.t_end = self.t0 + float(step.duration)
        self.dt_out = float(step.output_interval)
        self.times = output_times(self.t0, float(step.duration), self.dt_out)
        self.y0, self.yp0 = prob.initial(self.t0, state.X, state.V)
        self.shift = Shift(self.y0, prob.resfn)  # IDA works on displacements from here
        self.V_start = state.V
        self.X_start, self.h_start = state.X, state.h
        self._ida_options()
        self.outputs = OutputRecord(prob, self.times)
        self.n_steps = self.n_restarts = 0
        self.n_rollbacks = 0  # races lost by the trial order: the incumbent went on
        self._kept = None  # (IDA, t, k_done, n_restarts, fluid work) of a race's incumbent
        self.status = "completed"

    # ------------------------------------------------------------------ set-up
    def _ida_options(self) -> None:
        """Linear solver, tolerances (the velocity atol scaled by the lowest ω) and the BDF
        order cap (fixed, or raced by OrderChoice)."""
        step, prob, t0, y0 = self.step, self.prob, self.t0, self.y0
        self.linsolver = choose_solver(prob, step.linear_solver)
        self.omega = reference_frequency(prob, t0, y0)
        # the note's floor: jumps whose wave counts (m c Δv >= 5 % of the largest tension);
        # the error test follows any jump's wave (a small one on a taut line may be asked for)
        prob.jump_floor = jump_floor(self.model, self.model.element_state(self.X_start,
                                                                          self.h_start))
        jumps = velocity_jumps(self.model, self.V_start, t0, self.t_end)
        self.resolve, self.resolve_choice = resolve_mode(
            step.resolve, self.model.mass_model.carries_axial_waves, bool(jumps))
        atol, self.omega_error = error_weights(self.resolve, step.atol, self.omega,
                                               self.dt_out, prob.n, step.rtol)
        self.auto = step.max_order == "auto"
        self.order_choice = (OrderChoice(highest_frequency(prob, t0, y0), self.omega,
                                         self.t_end) if self.auto else None)
        options = dict(rtol=step.rtol, atol=atol,
                       max_order=self.order_choice.order if self.auto else int(step.max_order),
                       max_num_steps=100000, linsolver=self.linsolver)
        if self.linsolver == "band":
            bw = prob.bandwidth
            options.update(lband=2 * bw + 1, uband=max(2 * bw, 1), jacfn=prob.jac_dense)
        elif self.linsolver == "sparse":
            options.update(sparsity=prob.j_pattern, jacfn=prob.jac_sparse)
        else:
            options.update(jacfn=prob.jac_dense)
        options["jacfn"] = self.shift.jacobian(options["jacfn"])  # IDA's y: displacements
        self.options = options

    def make_solver(self, max_order: int) -> IDA:
        with warnings.catch_warnings():
            # sksundae warns that its own sparse approximation is unused when jacfn is given:
            # that is the intent (the analytic iteration matrix)
            warnings.filterwarnings("ignore", "Custom sparse Jacobian approximation",
                                    UserWarning)
            return IDA(self.shift.resfn, **dict(self.options, max_order=max_order),
                       eventsfn=self.hook, num_events=1)

    # ------------------------------------------------------------------ attributes
    def attributes(self, n_valid: int) -> dict:
        step, model, prob = self.step, self.model, self.prob
        oc = self.order_choice
        return {
            "n_steps": self.n_steps, "n_residual_evaluations": prob.n_res,
            "n_jacobian_evaluations": prob.n_jac,
            "n_rejected_states": prob.n_rejected,
            "wall_time": _time.perf_counter() - self.wall0, "rtol": step.rtol,
            "atol": step.atol, "atol_velocity": step.atol * self.omega_error,
            "resolve": self.resolve, "resolve_choice": self.resolve_choice,
            "error_frequency": self.omega_error, "status": self.status,
            "linear_solver": self.linsolver, "bandwidth": prob.bandwidth,
            "max_order": (oc.order if self.auto else int(step.max_order)),
            "max_order_setting": str(step.max_order),
            "order_choice": (oc.summary() + (
                f"; {self.n_rollbacks} lost race(s) taken back: the incumbent went on from "
                "the trial's start" if self.n_rollbacks else "")) if self.auto
            else "fixed by the step",
            "mass_model": model.mass_model.name, "mass_model_setting": model.mass_model.setting,
            "mass_model_choice": model.mass_model.choice,
            "inertia": step.inertia if prob.lagrangian else
            "paper" if model.mass_model.catenary else "constant mass",
            "damping": prob.damping.kind,
            "rayleigh_alpha": prob.alpha, "rayleigh_beta": prob.beta,
            "n_outputs": n_valid, "n_restarts": self.n_restarts,
            "note": note(model, prob, self.outputs, n_valid),
            "axial_damping": "none" if prob.axial is None else prob.axial.describe(),
        }

    def snapshot(self, n_valid: int) -> OutputRecord:  # the outputs kept for a batch first
        try:
            self.outputs.flush()
        except SolverError as exc:  # after the loop stopped: what was computed is kept
            if self.status == "completed":
                self.status = str(exc)
        n_valid = min(n_valid, self.outputs.n_computed)
        return self.outputs.upto(n_valid, self.attributes(n_valid))

    # ------------------------------------------------------------------ integration
    def integrate(self, writer, bar) -> OutputRecord:
        """Step IDA to the end, recording the output times; what was computed is kept when it
        fails (SolverError) or is interrupted (KeyboardInterrupt), both carrying ``partial``."""
        interrupt = None
        self.k_done = 0
        try:
            self._loop(writer, bar)
            if self.status == "completed":  # the outputs kept for a batch (SolverError)
                self.outputs.flush()
        except KeyboardInterrupt as exc:  # goes on after the partial record is attached below
            self.status = f"interrupted at {self._reached()}"
            interrupt = exc
        except SolverError as exc:
            self.status = str(exc)
        except Exception as exc:  # nothing lost: keep what was computed, say what went wrong
            self.status = (f"stopped after {self._reached()} by an unexpected error: "
                           f"{type(exc).__name__}: {exc}")
        finally:
            bar.close()
        rec = self.snapshot(self.k_done)
        if interrupt is not None:
            interrupt.partial = rec
            raise interrupt
        if self.status != "completed":
            raise SolverError(f"transient step '{self.step.name}': {self.status}",
                              termination=self.status, partial=rec)
        return rec

    def _reached(self) -> str:
        """How far a stopped run got, and the last output where it had gone past it."""
        last = float(self.times[max(self.k_done - 1, 0)])
        t = max(last, getattr(getattr(self, "hook", None), "t_seen", last))
        tail = "" if t <= last else f" (histories up to the output at t = {last:.6g} s)"
        return f"t = {t:.6g} s{tail}"

    def _stops(self):
        """Kinks and jumps of the prescribed motions and loads: the integrator stops at each and
        restarts from a consistent state (momentum balance across a velocity jump). Returns
        (stop times, the times just before each, whether the last one is at the end)."""
        groups = self.model.breakpoints(self.t0, self.t_end)
        end_jump = bool(groups) and groups[-1][1] == self.t_end
        stops = [at for _, at in groups]
        befores = [before for before, _ in groups]
        if not end_jump:
            stops.append(self.t_end)
            befores.append(self.t_end)
        return stops, befores, end_jump

    def _loop(self, writer, bar) -> None:
        """IDA once per output time (or stop); the per-step work runs inside IDA, in the
        root function ``StepHook`` (docs/theory.md §8.8), which also asks IDA to return at a
        step's end where the order race changes the order cap, the step size collapsed, or a
        snapshot is due (INCREMENT_SECONDS of wall time without one)."""
        times, t_end = self.times, self.t_end
        hook, solver = self._begin(writer, bar)
        t_int = self.t0
        stops, befores, end_jump = self._stops()
        i_stop = 0
        first = True  # IDA's first step after a start is aimed at the stop (below)
        while self.k_done < times.size:
            t_stop = stops[i_stop]
            tout = min(float(times[self.k_done]), t_stop)
            if first:  # IDA sizes its first step from the distance to the time it is given:
                hook.aim(math.nan, t_stop)  # one step towards the stop, as it always was
                res = solver.step(t_stop, method="onestep", tstop=t_stop)
            else:
                hook.aim(tout, t_stop)
                res = solver.step(tout, method="normal", tstop=t_stop)
            t_new = float(res.t)
            if res.status == IDA_ROOT_RETURN:  # the hook asked IDA to return at a step's end
                solver, t_int, first = self._hook_stop(solver, res, writer)
                if solver is None:
                    return
                continue
            if res.status == IDA_TOO_MUCH_WORK and t_new > t_int:  # max_num_steps in one call
                t_int, first = t_new, False
                continue
            if not res.success:
                self.status = f"IDA stopped at {self._reached()}: {res.message}"
                return
            t_int = t_new
            if ((t_stop < t_end or end_jump)
                    and t_int >= t_stop - 1e-13 * max(abs(t_stop), 1.0)):
                t_int = t_stop
                i_stop += 1
                self._restart(solver, t_stop, self.shift.from_ida(res.y), befores[i_stop - 1],
                              more=i_stop < len(stops))
                hook.reset(t_stop)
                first = True
            elif not first:
                self.outputs.record(self.k_done, t_int, self.shift.view(res.y, "out"), res.yp)
                self.k_done += 1
            else:
                first = False
            bar.update(t_int)
            if hook.snapshot_due():
                self._write_snapshot(writer)

    def _begin(self, writer, bar):
        """The hook and IDA at the step's start, its output recorded: (hook, IDA)."""
        hook = self.hook = StepHook(self, bar)
        if writer is not None and writer.output is not None:
            hook.written(every=INCREMENT_SECONDS)  # snapshots of a long run
        solver = self.make_solver(self.options["max_order"])
        solver.init_step(self.t0, self.shift.to_ida(self.y0), self.yp0)
        self.outputs.record(0, self.t0, self.y0, self.yp0)
        if self.outputs.work is not None:  # the fluid's work, None without a fluid
            self.outputs.work.advance(self.t0, self.y0, self.yp0)
        self.k_done = 1
        return hook, solver

    def _write_snapshot(self, writer) -> None:  # of the run so far
        self.outputs.flush()  # an output that cannot be computed stops the run here
        writer.write_increment(self.step.name, self.snapshot(self.k_done), self._reached())
        self.hook.written()

    def _hook_stop(self, solver, res, writer):
        """IDA returned where the hook asked (a step's end): a snapshot is due (written; the
        same IDA goes on as if it had not returned), the order race changed the order cap, or
        the step size collapsed (status set, solver None). Returns (the IDA to go on with, its
        time, whether it is new: its first step is then aimed at the stop)."""
        t = float(res.t)
        if self.hook.take_snapshot():  # a long stretch between outputs: the run so far
            self._write_snapshot(writer)
            return solver, t, False
        new_order = self.hook.take_order()
        if new_order is None or self.hook.stop_reason:  # stuck, or stopped by the watch
            self.status = self.hook.stop_reason or (
                f"step size collapsed at t = {t:.6g} s (IDA could not advance; "
                f"{self.prob.n_rejected} trial states rejected)")
            return None, t, False
        solver, t, fresh = self._change_order(solver, new_order, t, res.y, res.yp)
        self.hook.reset(t)  # IDA goes on from t: nothing asked of it, nothing seen after t
        return solver, t, fresh

    def _change_order(self, solver, order: int, t_int: float, y_last, yp_last):
        """The BDF order cap changed (OrderChoice): (the IDA to go on with, its time, whether it
        is a new IDA). A race's trial order starts a new IDA, and the incumbent's is kept as it
        stands. Where the incumbent wins, its IDA goes on from the trial's start, its history
        intact: the trial's outputs are recorded again, and the fluid's work and the residual's
        buffers (its carried Newton start) taken back to that time, so that the incumbent goes
        on exactly as if the trial had not run (the envelope keeps the trial's steps, states of
        the same motion within the tolerance). A lost race so costs its trial window, not a new
        IDA's start at order 1 and the damping of what the trial order left in the state
        (docs/theory.md §8.6). Where the integrator was restarted during the trial (a stop),
        the incumbent starts anew."""
        kept, self._kept = self._kept, None
        work = self.outputs.work
        if self.order_choice.mode == "trial":
            self._kept = (solver, t_int, self.k_done, self.n_restarts,
                          None if work is None else (work.t, work.W, work.P),
                          self.prob.start_state())
        elif kept is not None and kept[3] == self.n_restarts:
            solver, t_int, self.k_done, _, saved, start = kept
            if saved is not None:
                work.t, work.W, work.P = saved
            self.prob.restore_start(start)
            self.n_rollbacks += 1
            return solver, t_int, False
        new = self.make_solver(order)
        new.init_step(t_int, y_last, yp_last)  # IDA's own y (displacements, §18.7)
        return new, t_int, True

    def _restart(self, solver, t_stop: float, y_last, before, more: bool) -> None:
        """A stop (support velocity jump, or the end of a record): a consistent restart
        (docs/theory.md §8), the outputs at the stop from the restarted state, and IDA
        re-initialised there if more of the step follows."""
        y_last, yp_last = self.prob.restart(t_stop, y_last, before)
        work = self.outputs.work
        if work is not None:
            work.advance(t_stop, y_last, yp_last)
        self.n_restarts += 1
        if more:
            solver.init_step(t_stop, self.shift.to_ida(y_last), yp_last)
            if self.order_choice is not None:
                self.order_choice.restart()
        times = self.times
        while (self.k_done < times.size
               and abs(times[self.k_done] - t_stop) <= 1e-13 * max(abs(t_stop), 1.0)):
            self.outputs.record(self.k_done, times[self.k_done], y_last, yp_last)
            self.k_done += 1
