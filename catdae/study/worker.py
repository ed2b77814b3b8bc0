"""One run of a study, the task shipped to a worker: :func:`execute`, its untimed warm-up and
the peak-memory probe."""

from __future__ import annotations

import math
import sys
import time
from dataclasses import replace

from catdae._xr import xr
from catdae.analysis import run
from catdae.case import AXES, Case, Step
from catdae.errors import CatdaeError
from catdae.study.core import COUNTS, StudyError, point_labels
from catdae.study.modes import mode_samples

_WARMED: set[tuple] = set()  # kinds of step already run once in this process


def execute(case_run: Case, step_name: str, memory: str = "rss") -> xr.Dataset:
    """Run a configured case and return the study step's response and costs.

    The Dataset holds ``displacement``(time, point, axis) at every node, labelled by
    :func:`point_labels` (transient), or ``frequency``(mode) and ``shape`` (modal,
    :func:`catdae.study.modes.mode_samples`), and attrs ``status``,
    ``wall_time``, ``peak_memory``, the transient's evaluation counts (NaN when absent), the
    mass model the step used (``mass_model_used``, "" for a static step) and its ``note``.
    Analysis failures become a status, never an exception.
    """
    step = next(s for s in case_run.steps if s.name == step_name)
    warm = (step.kind, step.mass_model, step.linear_solver, step.inertia)
    if warm not in _WARMED:
        _warm_up(case_run, step)
        _WARMED.add(warm)
    marks: dict[str, float] = {}

    def on_group(name, ds):
        marks[name] = time.perf_counter()

    index = [s.name for s in case_run.steps].index(step_name)
    before = case_run.steps[index - 1].name if index else None
    group, status = None, "completed"
    with MemoryProbe(memory) as probe:
        t0 = time.perf_counter()
        try:
            group = run(case_run, on_group=on_group, progress=False)[step_name].to_dataset()
        except CatdaeError as exc:
            status = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            partial = getattr(exc, "partial", None)
            if partial is not None and step_name in partial.children:
                group = partial[step_name].to_dataset()
        t1 = time.perf_counter()
    start = marks.get(before, t0) if before else t0
    wall = marks.get(step_name, t1) - start if before is None or before in marks else math.nan
    attrs = {"status": status, "wall_time": wall, "peak_memory": probe.peak,
             "memory_method": probe.method, "step_kind": step.kind}
    for k in COUNTS:
        v = group.attrs.get(k) if group is not None else None
        attrs[k] = float(v) if v is not None else math.nan
    # what the step chose and said (mass_model "auto" per run; the note: rtol below atol, ...)
    got = group.attrs if group is not None else {}
    attrs["mass_model_used"] = str(got.get("mass_model", ""))
    attrs["note"] = str(got.get("note", ""))
    if group is None or status != "completed":
        return xr.Dataset(attrs=attrs)
    if step.kind == "modal":
        return mode_samples(case_run, group, attrs)
    if step.kind == "static":
        from catdae.study.quantity import static_values

        return static_values(group, attrs)
    attrs["peak_tension"] = peak_tension(group)
    labels = point_labels(case_run, [str(n) for n in group.node.values])
    keep = [i for i, lab in enumerate(labels) if lab is not None]
    return xr.Dataset(
        {"displacement": (("time", "point", "axis"), group.displacement.values[:, keep])},
        coords={"time": group.time.values, "point": [labels[i] for i in keep],
                "axis": list(AXES)}, attrs=attrs)


def peak_tension(group: xr.Dataset) -> float:
    """The largest tension of a transient step, N: its envelope over every accepted step
    (``tension_max``), or the largest output tension for results without one."""
    var = group.get("tension_max", group.get("tension"))
    return float(var.max()) if var is not None and var.size else math.nan


def _warm_up(case_run: Case, step: Step) -> None:
    """One short, untimed run: loads the compiled kernels this kind of step uses."""
    if step.kind == "transient":
        short = min(step.duration, 3 * step.output_interval)
        steps = tuple(replace(s, duration=short, output_interval=min(s.output_interval, short))
                      if s.name == step.name else s for s in case_run.steps)
        case_run = replace(case_run, steps=steps)
    try:
        run(case_run, progress=False)
    except CatdaeError:
        pass  # the timed run reports it


class MemoryProbe:
    """Peak memory of a block in bytes, and the method that measured it (package docstring):
    ``peak_rss`` (VmHWM reset, Linux), ``maxrss`` (lifetime peak) or ``tracemalloc``."""

    def __init__(self, method: str):
        if method not in ("rss", "tracemalloc"):
            raise StudyError(f"memory: expected 'rss' or 'tracemalloc', found {method!r}")
        self.method = method
        self.peak = math.nan

    def __enter__(self):
        if self.method == "tracemalloc":
            import tracemalloc

            self._started = not tracemalloc.is_tracing()
            if self._started:
                tracemalloc.start()
            tracemalloc.reset_peak()
            self._base = tracemalloc.get_traced_memory()[0]
            return self
        try:
            with open("/proc/self/clear_refs", "w") as f:
                f.write("5")  # Linux >= 4.0: resets VmHWM to the current RSS
            self._base = _proc_status("VmRSS")
            self.method = "peak_rss"
        except OSError:
            self._base = _maxrss()
            self.method = "maxrss"
        return self

    def __exit__(self, *exc):
        if self.method == "tracemalloc":
            import tracemalloc

            self.peak = float(tracemalloc.get_traced_memory()[1] - self._base)
            if self._started:
                tracemalloc.stop()
        elif self.method == "peak_rss":
            self.peak = _proc_status("VmHWM") - self._base
        else:
            self.peak = _maxrss() - self._base
        return False


def _proc_status(field: str) -> float:
    """A size from /proc/self/status (Linux), bytes."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return 1024.0 * float(line.split()[1])  # kB
    raise OSError(f"/proc/self/status has no {field}")


def _maxrss() -> float:
    """Peak resident set size of this process, bytes (NaN where getrusage is missing)."""
    try:
        import resource
    except ImportError:  # pragma: no cover - Windows
        return math.nan
    r = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return float(r if sys.platform == "darwin" else 1024 * r)
