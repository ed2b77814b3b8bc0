"""Accuracy and cost studies: work-precision sweeps, on this machine or on a Dask cluster.

:func:`run_study` runs one step of a case, the *study step*, over the cartesian product of solver
and mesh settings, measures what each run cost and how far it is from a reference run, and
returns one labelled ``xarray.Dataset`` whose dimensions are the settings. ``catdae study`` is
the same from the command line, with netCDF output and work-precision plots (PNG).

The pipeline, in order:

1. grid: each setting is a list (default: the case's own value); a run is one combination.
   Transient steps sweep ``rtol``, ``atol``, ``elements``, ``gauss_points``, ``mass_model``,
   ``linear_solver`` and ``max_order``; modal steps the last-but-three mesh and mass settings.
2. configure: one ``Case`` per run (the study step and the steps before it; later steps are
   dropped). ``elements`` and ``gauss_points`` apply to every cable, the solver settings to the
   study step only. The run's key is a hash of that configured case.
3. execute: every run not already in the store is an independent task (:func:`execute`, a
   picklable Case in, a small Dataset out). By default the tasks run on a
   ``distributed.LocalCluster`` of 2 single-threaded worker processes bound to 127.0.0.1 (a
   script that starts one needs the ``if __name__ == "__main__":`` guard, as for any
   multiprocessing); a scheduler address or a ``distributed.Client`` sends the same tasks to an
   existing cluster; ``"synchronous"`` runs them here, one after the other, and lets any
   unexpected exception through (for debugging).
4. store: the client writes each finished run to ``<store>/<key>.nc`` as it arrives, so a study
   that crashed or lost a worker resumes where it stopped: a rerun skips stored runs.
5. errors, against the reference, in the client; then the Dataset.

Reference. Unless one is given, the reference is one more run, made more accurate than every
run in what the study varies: ``rtol`` and ``atol`` are 1/100 of the smallest swept values;
when ``elements`` is swept (more than one value) it is ``2 * max(elements)``, otherwise the
runs' own mesh, so that a tolerance sweep measures the time-integration error alone, not the
spatial error of the mesh; a swept ``gauss_points`` becomes ``max + 1`` (at most 10), a swept
``mass_model`` "consistent", a swept ``max_order`` 5, a swept ``linear_solver`` "auto". A
mapping ``reference={"elements": 128}`` overrides any of these; a Dataset (the study step's
group of a catdae results file) is used as it is. The settings used are in the output attrs.

Response and error. Meshes differ between runs, so a transient error is measured at a point
that is a node of every mesh: a named node of the case (not a fully fixed support), or the mesh
node at unstrained arc-length fraction k/n from the first end of a cable, which exists in a mesh
of n' elements when k n'/n is an integer. Such points are labelled ``<cable>@<fraction>``
(``main@1/2`` is the midspan node: ``main.7`` of 14 elements, ``main.4`` of 8). The default
response is the common point that moves most in the reference; a grid whose meshes share no
point is rejected before anything runs (choose element counts with a common factor: with all
counts even, the midspan node is shared). ``response`` may name a case node, ``<cable>@<p/q>``,
or ``<cable>.<k>`` meaning node k of the case file's own mesh (fraction k/elements). The error is
the largest distance over the reference's output times between the run's displacement there
(interpolated linearly in time) and the reference's, in m. For a modal step it is the largest
relative error of the lowest natural frequencies (``response``: how many; default the step's
``modes``), with the signed errors per mode in ``frequency_error``.

Costs. ``wall_time`` is the time of the study step alone, from the end of the step before it to
the end of its results (the static steps before it are not counted), in a worker that has
already run the same kind of step once (the first, untimed, warm-up run of a process loads the
compiled kernels). ``n_steps``, ``n_residual_evaluations`` and ``n_jacobian_evaluations`` are the
transient step's own attrs. ``peak_memory`` is, by default (``memory="rss"``), how much the
worker process's resident set grew during the run: on Linux exactly, by resetting the process's
peak (VmHWM, through /proc/self/clear_refs) before the run and reading it after; elsewhere the
growth of ``getrusage``'s lifetime peak ``ru_maxrss``, which reads 0 when an earlier run in the
same process went higher. It counts everything (numpy, SUNDIALS, numba) at no cost, one run per
process at a time (threads_per_worker=1). ``memory="tracemalloc"`` records the peak of Python
and numpy allocations only, and makes the runs about 3-4 times slower, their wall time too. The
method used is in the variable's long_name and the attr ``peak_memory_method``.
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import math
import os
import sys
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import ExitStack
from dataclasses import replace
from datetime import UTC, datetime
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from . import __version__
from .analysis import as_case, run
from .case import AXES, Case, Step
from .errors import CaseError, CatdaeError

__all__ = ["SETTINGS", "StudyError", "convergence_order", "execute", "main", "plot_convergence",
           "plot_work_precision", "run_study", "write_study"]

SETTINGS = ("rtol", "atol", "elements", "gauss_points", "mass_model", "linear_solver",
            "max_order")
MODAL_SETTINGS = ("elements", "gauss_points", "mass_model")
STORE_FORMAT = 1  # bump when the stored runs change meaning

_COORD_META = {  # setting -> (units, long_name)
    "rtol": ("1", "relative tolerance of IDA"),
    "atol": ("m", "absolute tolerance of IDA on displacements"),
    "elements": ("1", "elements per cable (0: as in the case file)"),
    "gauss_points": ("1", "Gauss points per element (0: as in the case file)"),
    "mass_model": ("1", "mass model"),
    "linear_solver": ("1", "linear solver requested"),
    "max_order": ("1", "largest BDF order of IDA"),
}
_CHOICES = {"mass_model": ("consistent", "lumped", "linear"),
            "linear_solver": ("auto", "band", "sparse", "dense")}
_COUNTS = ("n_steps", "n_residual_evaluations", "n_jacobian_evaluations")
_MEMORY_NAMES = {
    "peak_rss": "growth of the worker's resident set size during the run (VmHWM reset)",
    "maxrss": "growth of the worker's lifetime peak resident set size (ru_maxrss)",
    "tracemalloc": "peak of Python and numpy allocations (tracemalloc)",
}
_WARMED: set[tuple] = set()  # kinds of step already run once in this process


class StudyError(CatdaeError):
    """A study cannot be set up: an invalid setting, step, response or reference."""


# ---------------------------------------------------------------------------------------------
# Grid, configuration, keys
# ---------------------------------------------------------------------------------------------


def study_step(case: Case, step: str | None = None) -> Step:
    """The step named ``step``; by default the first transient step, else the first modal one."""
    if step is not None:
        for s in case.steps:
            if s.name == step:
                if s.kind == "static":
                    raise StudyError(f"step {step!r} is static: a study needs a transient or "
                                     "modal step")
                return s
        names = ", ".join(repr(s.name) for s in case.steps) or "none"
        raise StudyError(f"the case has no step named {step!r} (steps: {names})")
    for kind in ("transient", "modal"):
        for s in case.steps:
            if s.kind == kind:
                return s
    raise StudyError("the case has no transient or modal step to study")


def settings_grid(case: Case, step: Step, given: Mapping[str, Sequence | None]) -> dict:
    """Each setting of the step's kind -> its list of values (the case's value when not given).

    Raises StudyError listing every invalid value, and any setting that does not apply to the
    step's kind.
    """
    names = SETTINGS if step.kind == "transient" else MODAL_SETTINGS
    problems = [f"{k}: not a setting of the {step.kind} step {step.name!r} (its settings: "
                f"{', '.join(names)})"
                for k, v in given.items() if v is not None and k not in names]
    elems = {c.elements for c in case.cables}
    gauss = {c.gauss_points for c in case.cables}
    default = {"elements": elems.pop() if len(elems) == 1 else 0,  # 0: as in the case file
               "gauss_points": gauss.pop() if len(gauss) == 1 else 0}
    grid = {}
    for name in names:
        values = given.get(name)
        if values is None:
            values = [default[name] if name in default else getattr(step, name)]
        elif isinstance(values, str | int | float):
            values = [values]
        values = list(dict.fromkeys(values))  # unique, in the order given
        if not values:
            problems.append(f"{name}: expected at least one value")
        for v in values:
            msg = _check_value(name, v)
            if msg and not (v == 0 and given.get(name) is None):
                problems.append(f"{name}: {msg}")
        grid[name] = values
    if problems:
        raise StudyError("invalid study settings:\n  " + "\n  ".join(problems))
    return grid


def _check_value(name: str, v) -> str | None:
    if name in ("rtol", "atol"):
        ok = isinstance(v, int | float) and not isinstance(v, bool) and 0 < v < math.inf
        return None if ok else f"expected a finite number > 0, found {v!r}"
    if name in _CHOICES:
        return None if v in _CHOICES[name] else f"expected one of {_CHOICES[name]}, found {v!r}"
    lo, hi = {"elements": (1, 10**6), "gauss_points": (1, 10), "max_order": (1, 5)}[name]
    ok = isinstance(v, int | np.integer) and not isinstance(v, bool) and lo <= v <= hi
    return None if ok else f"expected an integer from {lo} to {hi}, found {v!r}"


def reference_settings(grid: Mapping[str, list], overrides: Mapping | None = None) -> dict:
    """The automatic reference (module docstring), with ``overrides`` applied."""
    ref = {}
    for name, values in grid.items():
        swept = len(values) > 1
        if name in ("rtol", "atol"):
            ref[name] = min(values) / 100.0
        elif name == "elements":
            ref[name] = 2 * max(values) if swept else values[0]
        elif name == "gauss_points":
            ref[name] = min(max(values) + 1, 10) if swept else values[0]
        else:
            ref[name] = {"mass_model": "consistent", "linear_solver": "auto",
                         "max_order": 5}[name] if swept else values[0]
    for name, v in (overrides or {}).items():
        msg = (f"not a setting of this study (its settings: {', '.join(grid)})"
               if name not in grid else _check_value(name, v))
        if msg:
            raise StudyError(f"reference {name}: {msg}")
        ref[name] = v
    return ref


def configure(case: Case, step_name: str, settings: Mapping[str, Any],
              duration: float | None = None) -> Case:
    """The case of one run: steps up to the study step, with ``settings`` applied.

    ``elements`` or ``gauss_points`` of 0 leave the cables as they are. Raises CaseError when a
    load or point mass names a mesh node that the new element count does not have.
    """
    steps = []
    for s in case.steps:
        if s.name == step_name:
            changes = {k: v for k, v in settings.items()
                       if k not in ("elements", "gauss_points")}
            for k in ("rtol", "atol"):
                if k in changes:
                    changes[k] = float(changes[k])
            if duration is not None and s.kind == "transient":
                changes["duration"] = float(duration)
                changes["output_interval"] = min(s.output_interval, float(duration))
            steps.append(replace(s, **changes))
            break
        steps.append(s)
    cables = case.cables
    if settings.get("gauss_points"):
        cables = tuple(replace(c, gauss_points=int(settings["gauss_points"])) for c in cables)
    out = replace(case, steps=tuple(steps), cables=cables)
    if settings.get("elements"):
        out = out.with_overrides(elements=int(settings["elements"]))
    return out


def run_key(case_run: Case, step_name: str, memory: str) -> str:
    """Hash of everything that decides a run's numbers: the configured case and the probe."""
    text = "\n".join([f"catdae-study {STORE_FORMAT} {__version__}", step_name, memory,
                      repr(replace(case_run, path=None))])
    return hashlib.sha256(text.encode()).hexdigest()[:24]


# ---------------------------------------------------------------------------------------------
# One run (the task shipped to a worker)
# ---------------------------------------------------------------------------------------------


def execute(case_run: Case, step_name: str, memory: str = "rss") -> xr.Dataset:
    """Run a configured case and return the study step's response and costs.

    The Dataset holds ``displacement``(time, point, axis) at every node, labelled by
    :func:`point_labels` (transient), or ``frequency``(mode) (modal), and attrs ``status``,
    ``wall_time``, ``peak_memory`` and the transient's evaluation counts (NaN when absent).
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
    with _MemoryProbe(memory) as probe:
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
    for k in _COUNTS:
        v = group.attrs.get(k) if group is not None else None
        attrs[k] = float(v) if v is not None else math.nan
    if group is None or status != "completed":
        return xr.Dataset(attrs=attrs)
    if step.kind == "modal":
        return xr.Dataset({"frequency": ("mode", group.frequency.values)}, attrs=attrs)
    labels = point_labels(case_run, [str(n) for n in group.node.values])
    keep = [i for i, lab in enumerate(labels) if lab is not None]
    return xr.Dataset(
        {"displacement": (("time", "point", "axis"), group.displacement.values[:, keep])},
        coords={"time": group.time.values, "point": [labels[i] for i in keep],
                "axis": list(AXES)}, attrs=attrs)


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


class _MemoryProbe:
    """Peak memory of a block in bytes, and the method that measured it (module docstring):
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


# ---------------------------------------------------------------------------------------------
# Response points
# ---------------------------------------------------------------------------------------------


def point_labels(case_run: Case, node_names: Sequence[str]) -> list[str | None]:
    """Mesh-independent labels of nodes: a case node keeps its name, ``<cable>.<k>`` of n
    elements becomes ``<cable>@<k/n>``; fully fixed supports get None (their motion is given).
    """
    counts = {c.name: c.elements for c in case_run.cables}
    out: list[str | None] = []
    for name in node_names:
        if name in case_run.nodes:
            fixed = len(case_run.supports.get(name, ())) == len(AXES)
            out.append(None if fixed else name)
            continue
        cable, _, k = name.rpartition(".")
        out.append(f"{cable}@{Fraction(int(k), counts[cable])}")
    return out


def _mesh_points(case_run: Case) -> set[str]:
    nodes = list(case_run.nodes)
    for c in case_run.cables:
        nodes += [f"{c.name}.{k}" for k in range(1, c.elements)]
    return {lab for lab in point_labels(case_run, nodes) if lab is not None}


def _resolve_response(response: str, case: Case) -> str:
    """A user's response name -> a point label (module docstring)."""
    if response in case.nodes or "@" in response:
        if "@" in response:
            cable, _, frac = response.partition("@")
            try:
                f = Fraction(frac)
            except ValueError:
                raise StudyError(f"response {response!r}: expected <cable>@<fraction>, e.g. "
                                 "main@1/2") from None
            if not 0 < f < 1:
                raise StudyError(f"response {response!r}: the fraction must be inside (0, 1)")
            return f"{cable}@{f}"
        return response
    cable, dot, k = response.rpartition(".")
    names = [c.name for c in case.cables]
    if dot and cable in names and k.isdigit() and 0 < int(k) < case.cable(cable).elements:
        return f"{cable}@{Fraction(int(k), case.cable(cable).elements)}"
    raise StudyError(f"response {response!r}: expected a case node ({', '.join(case.nodes)}), "
                     "<cable>@<fraction> or a mesh node <cable>.<k> of the case file's mesh")


def _common_points(cases: Sequence[Case]) -> set[str]:
    common = None
    for c in cases:
        pts = _mesh_points(c)
        common = pts if common is None else common & pts
    return common or set()


# ---------------------------------------------------------------------------------------------
# The study
# ---------------------------------------------------------------------------------------------


def run_study(case: Case | str | os.PathLike, *, step: str | None = None,
              rtol: Sequence[float] | None = None, atol: Sequence[float] | None = None,
              elements: Sequence[int] | None = None, gauss_points: Sequence[int] | None = None,
              mass_model: Sequence[str] | None = None, linear_solver: Sequence[str] | None = None,
              max_order: Sequence[int] | None = None, response: str | int | None = None,
              reference: Mapping | xr.Dataset | xr.DataTree | None = None, scheduler=None,
              store: str | os.PathLike | None = None, duration: float | None = None,
              workers: int = 2, memory: str = "rss",
              on_run: Callable[[dict, xr.Dataset], None] | None = None) -> xr.Dataset:
    """Run the study step of ``case`` over the grid of settings; see the module docstring.

    ``case``: a Case, a path or TOML text. Each setting is a list (None: the case's value).
    ``scheduler``: None (a local cluster of ``workers`` processes), ``"synchronous"`` (here, in
    turn), a scheduler address such as ``"tcp://10.0.0.5:8786"``, or a ``distributed.Client``.
    ``store``: folder of finished runs (None: keep nothing). ``duration`` shortens or lengthens a
    transient study step. ``on_run(settings, run)`` is called as each run finishes (settings is
    None for the reference). Returns the Dataset (dimensions: the settings of the step's kind).
    """
    case = as_case(case)
    st = study_step(case, step)
    if duration is not None and not (st.kind == "transient" and 0 < duration < math.inf):
        raise StudyError(f"duration: expected a number > 0 for a transient step, found "
                         f"{duration!r} ({st.kind} step {st.name!r})")
    grid = settings_grid(case, st, {"rtol": rtol, "atol": atol, "elements": elements,
                                    "gauss_points": gauss_points, "mass_model": mass_model,
                                    "linear_solver": linear_solver, "max_order": max_order})
    names = list(grid)
    combos = [dict(zip(names, vals, strict=True)) for vals in itertools.product(*grid.values())]
    try:
        run_cases = [configure(case, st.name, s, duration) for s in combos]
        given_ref = isinstance(reference, xr.Dataset | xr.DataTree)
        ref_settings = None if given_ref else reference_settings(grid, reference)
        ref_case = None if given_ref else configure(case, st.name, ref_settings, duration)
    except CaseError as exc:
        raise StudyError(f"a setting of the study makes the case invalid:\n{exc}") from None
    _MemoryProbe(memory)  # reject an unknown method before anything runs
    keys = [run_key(c, st.name, memory) for c in run_cases]
    ref_data = _given_reference(reference, st, case) if given_ref else None
    if st.kind == "transient":
        given_points = set(ref_data.point.values) if given_ref else None
        target = _transient_target(case, run_cases + ([ref_case] if ref_case else []), response,
                                   grid, given_points)
    else:
        target = _modal_target(st, response)
    ref_key = None if given_ref else run_key(ref_case, st.name, memory)

    store_dir = Path(store) if store is not None else None
    if store_dir is not None:
        store_dir.mkdir(parents=True, exist_ok=True)
    records: dict[str, xr.Dataset] = {}
    todo: dict[str, Case] = {}
    for key, c in ([(ref_key, ref_case)] if ref_key else []) + list(zip(keys, run_cases,
                                                                          strict=True)):
        stored = _store_read(store_dir, key) if store_dir is not None else None
        if stored is not None:
            records[key] = stored
        else:
            todo[key] = c
    by_key = dict(zip(keys, combos, strict=True))
    for key, ds in _execute_all(todo, st.name, memory, scheduler, workers):
        if store_dir is not None and not ds.attrs.get("lost"):
            _store_write(store_dir, key, ds, by_key.get(key, ref_settings))
        records[key] = ds
        if on_run is not None:
            on_run(by_key.get(key), ds)
    ref = ref_data if ref_data is not None else records[ref_key]
    out = _assemble(grid, combos, keys, records, ref, st, target)
    out.attrs.update(_clean({
        "title": case.title, "case_name": case.name, "step": st.name, "step_kind": st.kind,
        "duration": duration if duration is not None else st.duration,
        "catdae_version": __version__, "created": datetime.now(UTC).isoformat(timespec="seconds"),
        "scheduler": _scheduler_name(scheduler, workers), "store": str(store_dir or ""),
        "n_runs": len(combos), "n_runs_computed": len(todo) - (ref_key in todo),
        "Conventions": "CF-1.10",
    }))
    if given_ref:
        out.attrs["reference"] = "given by the user"
    else:
        out.attrs["reference"] = ", ".join(f"{k}={v}" for k, v in ref_settings.items())
        out.attrs.update({f"reference_{k}": v for k, v in ref_settings.items()})
    out.attrs["reference_status"] = str(ref.attrs.get("status", "completed"))
    if not given_ref:
        out.attrs["reference_wall_time"] = float(ref.attrs["wall_time"])
    return out


def _transient_target(case: Case, run_cases: list[Case], response, grid,
                      given_points: set[str] | None) -> str | list[str]:
    """The response point, or the candidates when the reference is to choose (module doc)."""
    common = _common_points(run_cases)
    if given_points is not None:
        common &= given_points
    if response is not None:
        label = _resolve_response(str(response), case)
        if label not in common:
            raise StudyError(f"response {response!r} ({label}) is not a node of every mesh of "
                             f"the study (elements {grid['elements']} and the reference); "
                             f"common points: {', '.join(sorted(common)) or 'none'}")
        return label
    if not common:
        raise StudyError(
            f"no node is common to every mesh of the study (elements {grid['elements']} and the "
            "reference): choose element counts with a common factor (with all counts even the "
            "midspan node is shared) or a case with a free named node")
    return sorted(common)


def _modal_target(st: Step, response) -> int:
    if response is None:
        return int(st.modes)
    try:
        n = int(response)
    except (TypeError, ValueError):
        n = 0
    if not 1 <= n <= st.modes:
        raise StudyError(f"response of a modal study: expected the number of modes compared, "
                         f"1 to {st.modes}, found {response!r}")
    return n


def _given_reference(reference, st: Step, case: Case) -> xr.Dataset:
    """A user's reference results (a step group, or a tree holding it) in the stored form."""
    ds = reference
    if isinstance(ds, xr.DataTree):
        if st.name not in ds.children:
            raise StudyError(f"reference: the results have no group {st.name!r}")
        ds = ds[st.name].to_dataset()
    attrs = {"status": str(ds.attrs.get("status", "completed")), "wall_time": math.nan}
    if st.kind == "modal":
        if "frequency" not in ds:
            raise StudyError("reference: a modal study needs a 'frequency' variable")
        return xr.Dataset({"frequency": ("mode", ds.frequency.values)}, attrs=attrs)
    if "displacement" not in ds:
        raise StudyError("reference: a transient study needs a 'displacement' variable")
    names = [str(n) for n in ds.node.values]
    counts: dict[str, int] = {}
    for n in names:
        if n not in case.nodes:
            cable = n.rpartition(".")[0]
            counts[cable] = counts.get(cable, 1) + 1
    ref_case = replace(case, cables=tuple(replace(c, elements=counts.get(c.name, 1))
                                          for c in case.cables))
    labels = point_labels(ref_case, names)
    keep = [i for i, lab in enumerate(labels) if lab is not None]
    return xr.Dataset(
        {"displacement": (("time", "point", "axis"), ds.displacement.values[:, keep])},
        coords={"time": ds.time.values, "point": [labels[i] for i in keep], "axis": list(AXES)},
        attrs=attrs)


def _execute_all(todo: Mapping[str, Case], step_name: str, memory: str, scheduler,
                 workers: int) -> Iterator[tuple[str, xr.Dataset]]:
    """Yield (key, run) as runs finish. A task that failed outside catdae (a lost worker, a bug)
    yields a run with status 'error: ...' and attr ``lost``, which is not stored."""
    if not todo:
        return
    if scheduler == "synchronous":
        for key, c in todo.items():
            yield key, execute(c, step_name, memory)
        return
    from distributed import Client, LocalCluster, as_completed

    with ExitStack() as stack:
        if isinstance(scheduler, Client):
            client = scheduler
        elif scheduler is None:
            cluster = stack.enter_context(LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                dashboard_address=None))
            client = stack.enter_context(Client(cluster))
        else:
            client = stack.enter_context(Client(scheduler))
        futures = {client.submit(execute, c, step_name, memory, pure=False): key
                   for key, c in todo.items()}
        for fut in as_completed(futures):
            key = futures[fut]
            try:
                ds = fut.result()
            except Exception as exc:  # any remote failure (lost worker, bug) becomes a status
                ds = xr.Dataset(attrs={"status": f"error: {type(exc).__name__}: {exc}",
                                       "lost": 1, "wall_time": math.nan,
                                       "peak_memory": math.nan,
                                       **{k: math.nan for k in _COUNTS}})
            fut.release()
            yield key, ds


def _scheduler_name(scheduler, workers: int) -> str:
    if scheduler is None:
        return f"distributed.LocalCluster(n_workers={workers}, threads_per_worker=1, processes)"
    if isinstance(scheduler, str):
        return scheduler
    return str(getattr(getattr(scheduler, "scheduler", None), "address", scheduler))


# ---------------------------------------------------------------------------------------------
# Store
# ---------------------------------------------------------------------------------------------


def _store_read(store: Path, key: str) -> xr.Dataset | None:
    path = store / f"{key}.nc"
    if not path.exists():
        return None
    try:
        ds = xr.load_dataset(path, engine="netcdf4")
    except (OSError, ValueError):
        return None  # unreadable: computed again
    if ds.attrs.get("key") != key or ds.attrs.get("store_format") != STORE_FORMAT:
        return None
    return ds


def _store_write(store: Path, key: str, ds: xr.Dataset, settings: Mapping | None) -> None:
    """Atomically: a temporary file moved into place, so a crash never leaves half a run."""
    out = ds.copy()
    out.attrs.update(key=key, store_format=STORE_FORMAT,
                     settings=json.dumps({k: _plain(v) for k, v in (settings or {}).items()}))
    path = store / f"{key}.nc"
    tmp = store / f".{key}.nc.tmp{os.getpid()}"
    try:
        out.to_netcdf(tmp, engine="netcdf4")
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def _plain(v):
    return v.item() if isinstance(v, np.generic) else v


def _clean(attrs: dict) -> dict:
    return {k: _plain(v) for k, v in attrs.items() if v is not None}


# ---------------------------------------------------------------------------------------------
# Errors and the Dataset
# ---------------------------------------------------------------------------------------------


def _motion(ref: xr.Dataset, label: str) -> float:
    return float(np.linalg.norm(ref.displacement.sel(point=label).values, axis=1).max())


def _transient_error(run_ds: xr.Dataset, ref: xr.Dataset, label: str) -> float:
    """max over the reference's output times of |u_run - u_ref| at the point, m."""
    t_ref = ref.time.values
    t = run_ds.time.values
    u_ref = ref.displacement.sel(point=label).values  # (n_t_ref, 3) m
    u = run_ds.displacement.sel(point=label).values  # (n_t, 3) m
    span = max(abs(t_ref[-1]), 1.0) * 1e-9
    inside = (t_ref >= t[0] - span) & (t_ref <= t[-1] + span)
    if not inside.any():
        return math.nan
    ui = np.column_stack([np.interp(t_ref[inside], t, u[:, a]) for a in range(u.shape[1])])
    return float(np.linalg.norm(ui - u_ref[inside], axis=1).max())


def _assemble(grid, combos, keys, records, ref, st: Step, target) -> xr.Dataset:
    names = list(grid)
    shape = tuple(len(v) for v in grid.values())
    data = {v: np.full(shape, np.nan) for v in ("wall_time", *_COUNTS, "peak_memory", "error")}
    status = np.full(shape, "", dtype=object)
    ref_ok = ref.attrs.get("status", "completed") == "completed"
    if st.kind == "transient":
        if isinstance(target, list):  # the common point that moves most in the reference
            target = max(target, key=lambda p: _motion(ref, p)) if ref_ok else target[0]
        label = target
    else:
        n_modes = target
        ref_f = ref.frequency.values[:n_modes] if ref_ok else np.full(n_modes, np.nan)
        ferr = np.full((*shape, n_modes), np.nan)
    for combo, key in zip(combos, keys, strict=True):
        idx = tuple(grid[n].index(combo[n]) for n in names)
        rec = records[key]
        status[idx] = str(rec.attrs["status"])
        for v in ("wall_time", *_COUNTS, "peak_memory"):
            data[v][idx] = float(rec.attrs.get(v, math.nan))
        if status[idx] != "completed" or not ref_ok:
            continue
        if st.kind == "transient":
            data["error"][idx] = _transient_error(rec, ref, label)
        else:
            f = rec.frequency.values[:n_modes]
            ferr[idx][: f.size] = (f - ref_f[: f.size]) / ref_f[: f.size]
            data["error"][idx] = float(np.nanmax(np.abs(ferr[idx])))
    dims = tuple(names)
    coords = {}
    for n in names:
        vals = np.array(grid[n], dtype=object if n in _CHOICES else None)
        coords[n] = xr.Variable(n, vals, {"units": _COORD_META[n][0],
                                          "long_name": _COORD_META[n][1]})
    methods = sorted({str(r.attrs.get("memory_method", "")) for r in records.values()} - {""})
    memory = "+".join(methods)
    mem_name = "; ".join(_MEMORY_NAMES[m] for m in methods)
    if st.kind == "transient":
        err_units, err_name = "m", (f"largest distance over time between the displacement at "
                                    f"{label} and the reference's")
    else:
        err_units, err_name = "1", (f"largest relative error of the {n_modes} lowest natural "
                                    "frequencies")
    meta = {
        "wall_time": ("s", "wall time of the study step (warm worker)"),
        "n_steps": ("1", "IDA internal steps"),
        "n_residual_evaluations": ("1", "residual evaluations"),
        "n_jacobian_evaluations": ("1", "iteration matrix evaluations"),
        "peak_memory": ("B", mem_name),
        "error": (err_units, err_name),
    }
    variables = {v: xr.Variable(dims, data[v], {"units": u, "long_name": ln})
                 for v, (u, ln) in meta.items()}
    variables["status"] = xr.Variable(dims, status, {"units": "1", "long_name": "run status "
                                                     "('completed' or why it stopped)"})
    out = xr.Dataset(variables, coords=coords)
    if st.kind == "modal":
        out = out.assign_coords(mode=xr.Variable("mode", np.arange(1, n_modes + 1),
                                                 {"long_name": "mode number"}))
        out["frequency_error"] = xr.Variable(
            (*dims, "mode"), ferr, {"units": "1", "long_name": "relative error of the natural "
                                    "frequency (f - f_ref) / f_ref"})
        out.attrs["response"] = f"{n_modes} lowest natural frequencies"
        out.attrs["error_definition"] = "max over the modes of |f - f_ref| / f_ref"
    else:
        out.attrs["response"] = label
        out.attrs["error_definition"] = (f"max over the reference's output times of |u_run - "
                                         f"u_ref| at {label}, linear interpolation in time")
    out.attrs["peak_memory_method"] = memory
    return out


# ---------------------------------------------------------------------------------------------
# Orders and plots
# ---------------------------------------------------------------------------------------------


def convergence_order(error: xr.DataArray, dim: str = "elements") -> float:
    """p in error ~ C n^-p: minus the slope of a least-squares line through log(error) against
    log(n) (finite positive errors only; NaN with fewer than two)."""
    n = np.asarray(error[dim].values, float)
    e = np.asarray(error.values, float)
    ok = np.isfinite(e) & (e > 0) & (n > 0)
    if ok.sum() < 2:
        return math.nan
    return float(-np.polyfit(np.log(n[ok]), np.log(e[ok]), 1)[0])


def _families(ds: xr.Dataset, line_dim: str) -> Iterator[tuple[str, dict]]:
    """(label, selection) of each combination of the swept settings other than ``line_dim``."""
    swept = [d for d in SETTINGS if d in ds.dims and d != line_dim and ds.sizes[d] > 1]
    fixed = {d: 0 for d in SETTINGS if d in ds.dims and d != line_dim and ds.sizes[d] == 1}
    for vals in itertools.product(*(range(ds.sizes[d]) for d in swept)):
        sel = {**fixed, **dict(zip(swept, vals, strict=True))}
        label = ", ".join(f"{d}={ds[d].values[i]}" for d, i in zip(swept, vals, strict=True))
        yield label, sel


def _line_dim(ds: xr.Dataset) -> str:
    for d in ("rtol", "atol", "elements", "max_order", "gauss_points"):
        if d in ds.dims and ds.sizes[d] > 1:
            return d
    return "elements"


def plot_work_precision(ds: xr.Dataset, path: str | os.PathLike | None = None):
    """Error against wall time and against residual evaluations (log-log), one line per family
    of settings, along the first swept of rtol, atol, elements. Returns the matplotlib Figure,
    drawn on an Agg canvas without pyplot (so the caller's backend is left alone); with
    ``path``, also writes it as PNG."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    line = _line_dim(ds)
    costs = [c for c in ("wall_time", "n_residual_evaluations")
             if np.isfinite(ds[c].values).any()]
    fig = Figure(figsize=(5.5 * max(len(costs), 1), 4.5), layout="constrained")
    FigureCanvasAgg(fig)
    for k, cost in enumerate(costs):
        ax = fig.add_subplot(1, len(costs), k + 1)
        for label, sel in _families(ds, line):
            sub = ds.isel(sel)
            x, y = sub[cost].values, sub["error"].values
            ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
            if ok.any():
                ax.loglog(x[ok], y[ok], "o-", label=label or None)
                for xi, yi, v in zip(x[ok], y[ok], sub[line].values[ok], strict=True):
                    ax.annotate(f"{v:g}" if isinstance(v, float) else str(v), (xi, yi),
                                fontsize=7, textcoords="offset points", xytext=(3, 3))
        ax.set_xlabel(f"{ds[cost].attrs['long_name']} ({ds[cost].attrs['units']})")
        ax.set_ylabel(f"error ({ds.error.attrs['units']})")
        ax.set_title(f"{ds.attrs.get('case_name', '')}: points labelled by {line}", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    if path is not None:
        fig.savefig(path, dpi=110)
    return fig


def plot_convergence(ds: xr.Dataset, path: str | os.PathLike | None = None):
    """Error against element count (log-log), one line per family of the other swept settings,
    the fitted order p (error ~ n^-p) in the legend. Returns the Figure (Agg canvas, no
    pyplot) and with ``path`` writes it as PNG; None (and no file) with fewer than two element
    counts."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    if ds.sizes.get("elements", 0) < 2:
        return None
    fig = Figure(figsize=(5.5, 4.5), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for label, sel in _families(ds, "elements"):
        err = ds.error.isel(sel)
        p = convergence_order(err)
        ok = np.isfinite(err.values) & (err.values > 0)
        if ok.any():
            ax.loglog(err.elements.values[ok], err.values[ok], "o-",
                      label=f"{label + ': ' if label else ''}order {p:.2f}")
    ax.set_xlabel("elements per cable")
    ax.set_ylabel(f"error ({ds.error.attrs['units']})")
    ax.set_title(f"{ds.attrs.get('case_name', '')}: {ds.attrs.get('response', '')}", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    if path is not None:
        fig.savefig(path, dpi=110)
    return fig


def write_study(ds: xr.Dataset, path: str | os.PathLike, plots: bool = True) -> list[Path]:
    """The Dataset to netCDF (atomically) and, with ``plots``, ``<stem>-work-precision.png``
    and ``<stem>-convergence.png`` beside it. Returns the files written."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    try:
        ds.to_netcdf(tmp, engine="netcdf4")
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    written = [path]
    if plots:
        wp = path.with_name(f"{path.stem}-work-precision.png")
        plot_work_precision(ds, wp)
        written.append(wp)
        conv = path.with_name(f"{path.stem}-convergence.png")
        if plot_convergence(ds, conv) is not None:
            written.append(conv)
    return written


# ---------------------------------------------------------------------------------------------
# Command line
# ---------------------------------------------------------------------------------------------


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="catdae study", description="Work-precision study of one step of a case: runs the "
        "grid of settings (cartesian product), measures cost and error against a reference, "
        "writes a netCDF Dataset and PNG plots.")
    p.add_argument("case", help="case file (TOML)")
    p.add_argument("--step", help="step to study (default: the first transient, else modal)")
    p.add_argument("--rtol", type=float, nargs="+")
    p.add_argument("--atol", type=float, nargs="+", help="m")
    p.add_argument("--elements", type=int, nargs="+", help="elements per cable")
    p.add_argument("--gauss-points", type=int, nargs="+")
    p.add_argument("--mass-model", nargs="+", choices=_CHOICES["mass_model"])
    p.add_argument("--linear-solver", nargs="+", choices=_CHOICES["linear_solver"])
    p.add_argument("--max-order", type=int, nargs="+")
    p.add_argument("--response", help="transient: a case node, <cable>@<p/q> or <cable>.<k> of "
                   "the case file's mesh (default: the common node moving most); modal: how "
                   "many of the lowest frequencies are compared")
    p.add_argument("--reference", nargs="+", metavar="KEY=VALUE|FILE.nc",
                   help="reference settings (e.g. elements=64 rtol=1e-10) or a catdae results "
                   "file holding the study step")
    p.add_argument("--duration", type=float, help="duration of the transient step, s")
    p.add_argument("--scheduler", help="address of a running Dask scheduler, or 'synchronous' "
                   "(default: a local cluster of --workers processes)")
    p.add_argument("--workers", type=int, default=2, help="local cluster size (default 2)")
    p.add_argument("--store", help="folder of finished runs (default: <case stem>-study/)")
    p.add_argument("--memory", choices=("rss", "tracemalloc"), default="rss",
                   help="peak memory probe (tracemalloc is exact but slows runs 3-4x)")
    p.add_argument("-o", "--output", help="output netCDF (default: <case stem>-study.nc)")
    p.add_argument("--plots", action=argparse.BooleanOptionalAction, default=True,
                   help="write the PNG plots beside the output (default: yes)")
    return p


def _reference_arg(items: list[str] | None):
    if not items:
        return None
    if len(items) == 1 and "=" not in items[0]:
        from .results import read_tree

        try:
            return read_tree(items[0])
        except (OSError, ValueError) as exc:
            raise StudyError(f"reference: cannot read {items[0]!r}: {exc}") from None
    out: dict[str, Any] = {}
    for item in items:
        key, eq, value = item.partition("=")
        key = key.strip().replace("-", "_")
        if not eq:
            raise StudyError(f"reference: expected KEY=VALUE, found {item!r}")
        if key in _CHOICES:
            out[key] = value
        else:
            try:
                out[key] = int(value) if key in ("elements", "gauss_points", "max_order") \
                    else float(value)
            except ValueError:
                raise StudyError(f"reference {key}: expected a number, found {value!r}") from None
    return out


def main(argv: list[str] | None = None) -> int:
    """``catdae study CASE ...``: 0 all runs completed, 1 some failed (results still written),
    2 invalid case or settings, 130 interrupted."""
    args = _parser().parse_args(argv)
    from .case import load_case

    try:
        case = load_case(args.case)
        stem = Path(args.case).stem
        out = Path(args.output) if args.output else Path(f"{stem}-study.nc")
        store = Path(args.store) if args.store else Path(f"{stem}-study")

        swept = {k for k, v in vars(args).items() if isinstance(v, list) and len(v) > 1}

        def report(settings, run_ds):
            what = ", ".join(f"{k}={v}" for k, v in settings.items()
                             if k in swept) or "run" if settings else "reference"
            print(f"  {what}: {run_ds.attrs['status']}, {run_ds.attrs['wall_time']:.3g} s",
                  flush=True)

        ds = run_study(
            case, step=args.step, rtol=args.rtol, atol=args.atol, elements=args.elements,
            gauss_points=args.gauss_points, mass_model=args.mass_model,
            linear_solver=args.linear_solver, max_order=args.max_order,
            response=args.response, reference=_reference_arg(args.reference),
            scheduler=args.scheduler, store=store, duration=args.duration,
            workers=args.workers, memory=args.memory, on_run=report)
        files = write_study(ds, out, plots=args.plots)
    except (CaseError, StudyError) as exc:
        print(f"catdae study: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"catdae study: interrupted; finished runs are kept in {store}", file=sys.stderr)
        return 130
    print(summary(ds))
    print("written: " + ", ".join(str(f) for f in files))
    failed = int((ds.status.values != "completed").sum())
    if failed or ds.attrs["reference_status"] != "completed":
        print(f"catdae study: {failed} run(s) failed; reference: {ds.attrs['reference_status']}",
              file=sys.stderr)
        return 1
    return 0


def summary(ds: xr.Dataset) -> str:
    """One line per run: its swept settings, cost and error."""
    swept = [d for d in SETTINGS if d in ds.dims and ds.sizes[d] > 1]
    lines = [f"study of step '{ds.attrs['step']}' of {ds.attrs['case_name']}: response "
             f"{ds.attrs['response']}; reference {ds.attrs['reference']}"]
    flat = ds.drop_vars([v for v in ("frequency_error",) if v in ds]).stack(run=list(
        d for d in SETTINGS if d in ds.dims))
    for i in range(flat.sizes["run"]):
        r = flat.isel(run=i)
        what = ", ".join(f"{d}={r[d].item()}" for d in swept) or "run"
        lines.append(f"  {what}: {r.status.item()}, {float(r.wall_time):.3g} s, "
                     f"{float(r.n_residual_evaluations):.0f} residuals, error "
                     f"{float(r.error):.3g} {ds.error.attrs['units']}")
    return "\n".join(lines)
