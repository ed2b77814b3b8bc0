"""Nonlinear transient dynamics with SUNDIALS IDA (docs/theory.md §8): the driver.

The only module that imports sksundae. ``run_transient`` integrates one transient step: it
builds the residual and iteration matrix (``residual.TransientProblem``), picks the linear
solver, the tolerances and the BDF order cap, steps IDA one internal step at a time (stopping
and restarting at the kinks and jumps of prescribed motions and loads), records the output times
(``transient_results.Outputs``) and keeps what was computed when a run fails or is interrupted.

BDF order (``max_order = "auto"``, the default): OrderChoice measures whether order 5 is held
down by the stability of the mesh's fast modes and then goes on at order 2 (docs/theory.md
§8.6).
"""

from __future__ import annotations

import time as _time
import warnings

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla
from sksundae.ida import IDA

from ._xr import xr
from .assembly import Model
from .errors import SolverError
from .progress import reporter
from .residual import TransientProblem
from .transient_results import Outputs, note

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
    order_choice = (OrderChoice(_highest_frequency(prob, t0, y0), omega, float(step.rtol))
                    if auto else None)
    options = dict(rtol=step.rtol, atol=atol, max_order=5 if auto else int(step.max_order),
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
                while (k_done < times.size
                       and abs(times[k_done] - t_int) <= 1e-13 * max(abs(t_int), 1.0)):
                    record(k_done, times[k_done], y_last, yp_last)
                    k_done += 1
            elif order_choice is not None and not order_choice.decided:
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
    """The BDF order cap of ``max_order = "auto"``, chosen by measurement during the run.

    BDF orders 3-5 are not stable along the imaginary axis: undamped modes with h ω of order 1
    (the axial modes of a fine mesh) force their step down, whatever the accuracy needs, and the
    steps per simulated second then grow with the mesh. BDF2 is A-stable (it damps the modes
    far above 1/h). The run starts at order 5; after IDA's start-up window of ``WINDOW`` steps
    the mean step h of each following window decides: order 5 is stability-bound where h ω_max <
    ``STABILITY_HW``, and it is following the mesh's fast modes rather than the motion where it
    also takes more than ``STEPS_PER_PERIOD`` steps per period of the lowest mode (2π/ω₁). Then
    the rest of the step runs at order 2; otherwise order 5 goes on and the next window is
    tested again. At rtol < ``TIGHT_RTOL`` order 5 stays (docs/theory.md §8.6;
    measurements in benchmarks/speed_accuracy.md). ``order_choice`` says what was measured.
    """

    WINDOW = 150
    STABILITY_HW = 2.5
    STEPS_PER_PERIOD = 1.0e4

    TIGHT_RTOL = 1e-6  # below it order 5 is kept: its steps are set by accuracy there

    def __init__(self, omega_max: float | None, omega_1: float, rtol: float):
        self.omega_max = omega_max
        self.omega_1 = omega_1
        self.order = 5
        self.decided = omega_max is None or rtol < self.TIGHT_RTOL
        self.phase = "start-up"
        self.count = 0
        self.t_mark = None
        self.note = ("no highest frequency: order 5 kept" if omega_max is None else
                     f"order 5: rtol {rtol:g} < {self.TIGHT_RTOL:g} (at tight tolerances order 5 "
                     "takes far fewer steps)" if rtol < self.TIGHT_RTOL else "")

    def observe(self, t: float) -> int | None:
        """Called after every step at time t; returns the new order cap when it changes."""
        self.count += 1
        if self.t_mark is None:
            self.t_mark = t
        if self.count < self.WINDOW:
            return None
        h = (t - self.t_mark) / self.count  # mean step of the window, s
        self.count = 0
        self.t_mark = t
        if self.phase == "start-up":  # a new IDA starts at order 1 with short steps
            self.phase = "order 5"
            return None
        # every later window at order 5 is tested again: an early window can be unrepresentative
        # (IDA's first step scales with the step's duration, and order 5 may run long steps
        # before the fast modes hold it down)
        hw = h * self.omega_max
        per_period = 2.0 * np.pi / (h * self.omega_1) if h > 0 else np.inf
        if hw < self.STABILITY_HW and per_period > self.STEPS_PER_PERIOD:
            self.decided = True
            self.order = 2
            self.note = (f"order 2 from t = {t:.6g} s: order 5 was stability-bound (h ω_max = "
                         f"{hw:.3g}) at {per_period:.3g} steps per period of the lowest mode")
            return 2
        self.note = (f"order 5: h ω_max = {hw:.3g}, {per_period:.3g} steps per period of the "
                     "lowest mode")
        return None

    def summary(self) -> str:
        return self.note or f"order {self.order} ({self.phase}: too few steps to measure)"


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
        kff = prob.ff(prob.model.pattern.assemble(conf[0].stiffness6))
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

