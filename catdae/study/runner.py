"""The study itself: :func:`run_study` builds the grid and the reference, executes the runs
not yet stored (here or on a Dask cluster) and assembles the Dataset."""

from __future__ import annotations

import itertools
import math
import os
import signal
import sys
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import ExitStack
from dataclasses import replace
from datetime import UTC, datetime
from pathlib import Path

from catdae._version import __version__
from catdae._xr import xr
from catdae.analysis import as_case
from catdae.case import AXES, Case, Step
from catdae.case.limits import MAX_SIMULATED_TIME
from catdae.case.names import cable_of
from catdae.errors import CaseError
from catdae.interrupts import deferred
from catdae.study.core import (
    COUNTS,
    SETTINGS,
    StudyError,
    common_points,
    configure,
    point_labels,
    reference_settings,
    resolve_response,
    run_key,
    settings_grid,
    study_step,
)
from catdae.study.dataset import assemble
from catdae.study.modes import mode_samples
from catdae.study.quantity import frequency_target, static_target, static_values
from catdae.study.store import clean, store_read, store_write
from catdae.study.worker import MemoryProbe, peak_tension


def run_study(case: Case | str | os.PathLike, *, step: str | None = None,
              rtol: Sequence[float] | None = None, atol: Sequence[float] | None = None,
              elements: Sequence[int] | None = None, gauss_points: Sequence[int] | None = None,
              mass_model: Sequence[str] | None = None, linear_solver: Sequence[str] | None = None,
              max_order: Sequence[int] | None = None, response: str | int | None = None,
              reference: Mapping | xr.Dataset | xr.DataTree | None = None, scheduler=None,
              store: str | os.PathLike | None = None, duration: float | None = None,
              workers: int = 2, memory: str = "rss",
              on_run: Callable[[dict, xr.Dataset], None] | None = None) -> xr.Dataset:
    """Run the study step of ``case`` over the grid of settings; see the package docstring.

    ``case``: a Case, a path or TOML text. Each setting is a list (None: the case's value).
    ``scheduler``: None (a local cluster of ``workers`` processes), ``"synchronous"`` (here, in
    turn), a scheduler address such as ``"tcp://10.0.0.5:8786"``, or a ``distributed.Client``.
    ``store``: folder of finished runs (None: keep nothing). ``duration`` shortens or lengthens a
    transient study step. ``on_run(settings, run)`` is called as each run finishes (settings is
    None for the reference). Returns the Dataset (dimensions: the settings of the step's kind).
    """
    case = as_case(case)
    st = study_step(case, step)
    if duration is not None and not (st.kind == "transient"
                                     and 0 < duration <= MAX_SIMULATED_TIME):
        raise StudyError(f"duration: expected a number > 0 and <= {MAX_SIMULATED_TIME:g} s for "
                         f"a transient step, found {duration!r} ({st.kind} step {st.name!r})")
    if not (isinstance(workers, int) and workers >= 1):
        raise StudyError(f"workers: expected an integer >= 1, found {workers!r}")
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
    MemoryProbe(memory)  # reject an unknown method before anything runs
    keys = [run_key(c, st.name, memory) for c in run_cases]
    ref_data = _given_reference(reference, st, case, duration) if given_ref else None
    if st.kind == "transient":
        given_points = set(ref_data.point.values) if given_ref else None
        target = _transient_target(case, run_cases + ([ref_case] if ref_case else []), response,
                                   grid, given_points)
    elif st.kind == "static":
        target = static_target(case, response)
    else:
        target = frequency_target(response, st.modes) or _modal_target(st, response)
    ref_key = None if given_ref else run_key(ref_case, st.name, memory)

    store_dir = Path(store) if store is not None else None
    if store_dir is not None:
        store_dir.mkdir(parents=True, exist_ok=True)
    records: dict[str, xr.Dataset] = {}
    todo: dict[str, Case] = {}
    for key, c in ([(ref_key, ref_case)] if ref_key else []) + list(zip(keys, run_cases,
                                                                          strict=True)):
        stored = store_read(store_dir, key) if store_dir is not None else None
        if stored is not None:
            records[key] = stored
        else:
            todo[key] = c
    by_key = dict(zip(keys, combos, strict=True))
    interrupt: KeyboardInterrupt | None = None
    try:
        for key, ds in _execute_all(todo, st.name, memory, scheduler, workers):
            if store_dir is not None and not ds.attrs.get("lost"):
                with deferred():  # a signal waits until the stored run is complete
                    store_write(store_dir, key, ds, by_key.get(key, ref_settings))
            records[key] = ds
            if on_run is not None:
                on_run(by_key.get(key), ds)
    except KeyboardInterrupt as exc:  # a partial report of the finished runs, then it goes on
        interrupt = exc
        why = getattr(exc, "signum", None)
        not_run = {"status": "not run (the study was interrupted"
                   + (f" by {signal.Signals(why).name})" if why else ")"),
                   "wall_time": math.nan, "peak_memory": math.nan,
                   **{k: math.nan for k in COUNTS}}
        for key in [*([ref_key] if ref_key else []), *keys]:
            records.setdefault(key, xr.Dataset(attrs=dict(not_run)))
    ref = ref_data if ref_data is not None else records[ref_key]
    out = assemble(grid, combos, keys, records, ref, st, target)
    out.attrs.update(clean({
        "title": case.title, "case_name": case.name, "step": st.name, "step_kind": st.kind,
        "duration": duration if duration is not None else st.duration,
        "catdae_version": __version__, "created": datetime.now(UTC).isoformat(timespec="seconds"),
        "scheduler": _scheduler_name(scheduler, workers), "store": str(store_dir or ""),
        "n_runs": len(combos), "n_runs_computed": len(todo) - (ref_key in todo),
        "Conventions": "CF-1.10",
    }))
    if given_ref:
        source = reference.attrs.get("reference_file")
        out.attrs["reference"] = (f"given by the user: {source}" if source
                                  else "given by the user")
        if isinstance(reference, xr.DataTree) and (other := _scene_differences(reference, case)):
            out.attrs["reference_note"] = (
                f"the reference's case differs from the study's in {', '.join(other)} (not "
                "only in the settings a study varies): its errors compare two scenes")
    else:
        out.attrs["reference"] = ", ".join(f"{k}={v}" for k, v in ref_settings.items())
        out.attrs.update({f"reference_{k}": v for k, v in ref_settings.items()})
    out.attrs["reference_status"] = str(ref.attrs.get("status", "completed"))
    if not given_ref:
        out.attrs["reference_wall_time"] = float(ref.attrs["wall_time"])
    finished = sum(not str(records[k].attrs.get("status", "")).startswith("not run")
                   for k in keys)
    out.attrs["status"] = "completed" if interrupt is None else (
        f"interrupted: {finished} of {len(keys)} runs finished (a partial report)")
    if interrupt is None and out.attrs["reference_status"] != "completed":
        out.attrs["status"] = (  # its errors are all NaN: not a completed study
            f"reference failed ({out.attrs['reference_status']}): its errors are not to be "
            "trusted (NaN past its last results); give --reference with settings that "
            "complete (fewer elements, a looser rtol) or a results file")
    if interrupt is not None:
        interrupt.partial = out
        raise interrupt
    return out


def _transient_target(case: Case, run_cases: list[Case], response, grid,
                      given_points: set[str] | None) -> str | list[str]:
    """The response point, or the candidates when the reference is to choose (package doc)."""
    common = common_points(run_cases)
    if given_points is not None:
        common &= given_points
    if response is not None:
        label = resolve_response(str(response), case)
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


# the settings a study may change: a reference differing only there is of the same scene
_SETTINGS_KEYS = {*SETTINGS, "duration", "output_interval"}


def _scene_differences(tree: xr.DataTree, case: Case) -> list[str]:
    """The sections of the scene (materials, nodes, cables, loads, ...) in which the case stored
    in the reference results differs from the study's, the study's settings aside; [] when
    they agree or the results hold no case (tester t74: another case's file was used silently,
    a 3.57 m "error")."""
    import tomllib

    try:
        theirs = tomllib.loads(str(tree.attrs["case_toml"]))
        ours = tomllib.loads(case.text)
    except (KeyError, TypeError, AttributeError, tomllib.TOMLDecodeError):
        return []

    def scene(d):
        if isinstance(d, dict):
            return {k: scene(v) for k, v in d.items() if k not in _SETTINGS_KEYS}
        return [scene(v) for v in d] if isinstance(d, list) else d

    theirs, ours = scene(theirs), scene(ours)
    return sorted(k for k in set(theirs) | set(ours)
                  if k not in ("title", "source") and theirs.get(k) != ours.get(k))


def _given_reference(reference, st: Step, case: Case, duration=None) -> xr.Dataset:
    """A user's reference results (a step group, or a tree holding it) in the stored form. A
    transient reference must cover the study's step: its errors are measured at the
    reference's output times, and a shorter one would leave the rest of the step unmeasured."""
    ds = reference
    where = reference.attrs.get("reference_file")
    where = f"reference {where!r}" if where else "reference"
    if isinstance(ds, xr.DataTree):
        if st.name not in ds.children:
            raise StudyError(f"{where}: the results have no group {st.name!r}")
        ds = ds[st.name].to_dataset()
    if st.kind == "transient" and "time" in ds.coords and ds.time.size:
        t0 = sum(s.duration for s in case.steps[:case.steps.index(st)]
                 if s.kind == "transient")
        t_end = t0 + (duration if duration is not None else st.duration)
        tol = 1e-9 * max(abs(t_end), 1.0)
        t_first, t_last = float(ds.time[0]), float(ds.time[-1])
        if t_first > t0 + tol or t_last < t_end - tol:
            raise StudyError(
                f"{where}: step {st.name!r} holds t = {t_first:.6g} to {t_last:.6g} s; the "
                f"study's step runs from {t0:.6g} to {t_end:.6g} s: give a reference that "
                "covers it, or shorten the study with --duration")
    attrs = {"status": str(ds.attrs.get("status", "completed")), "wall_time": math.nan}
    if st.kind == "static":
        return static_values(ds, attrs)
    if st.kind == "transient":
        attrs["peak_tension"] = peak_tension(ds)
    if st.kind == "modal" and ("frequency" not in ds or "shape" not in ds):
        raise StudyError(f"{where}: a modal study needs 'frequency' and 'shape' variables")
    if st.kind == "transient" and "displacement" not in ds:
        raise StudyError(f"{where}: a transient study needs a 'displacement' variable")
    names = [str(n) for n in ds.node.values]
    counts: dict[str, int] = {}
    for n in names:
        if n not in case.nodes:
            cable = cable_of(n)
            counts[cable] = counts.get(cable, 1) + 1
    ref_case = replace(case, cables=tuple(replace(c, elements=counts.get(c.name, 1))
                                          for c in case.cables))
    if st.kind == "modal":
        return mode_samples(ref_case, ds, attrs)
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
            yield key, _package().execute(c, step_name, memory)
        return
    from distributed import Client, as_completed

    with ExitStack() as stack:
        if isinstance(scheduler, Client):
            client = scheduler
        elif scheduler is None:
            try:
                cluster = stack.enter_context(local_cluster(workers))
            except RuntimeError as exc:  # "Nanny failed to start": a script without the guard
                raise StudyError(
                    f"the local Dask cluster's worker processes did not start ({exc}): a "
                    "script that calls run_study with the default scheduler needs the "
                    "'if __name__ == \"__main__\":' guard (the workers are new processes that "
                    "import the script again, and ran it), or scheduler=\"synchronous\" "
                    "to run here") from exc
            client = stack.enter_context(Client(cluster))
        else:
            client = stack.enter_context(Client(scheduler))
        futures = {client.submit(_package().execute, c, step_name, memory, pure=False): key
                   for key, c in todo.items()}
        for fut in as_completed(futures):
            key = futures[fut]
            try:
                ds = fut.result()
            except Exception as exc:  # any remote failure (lost worker, bug) becomes a status
                ds = xr.Dataset(attrs={"status": f"error: {type(exc).__name__}: {exc}",
                                       "lost": 1, "wall_time": math.nan,
                                       "peak_memory": math.nan,
                                       **{k: math.nan for k in COUNTS}})
            fut.release()
            yield key, ds


def local_cluster(workers: int, processes: bool = True):
    """A ``distributed.LocalCluster`` that claims no fixed port: the scheduler, the workers
    and the scheduler's HTTP server each take a free port on 127.0.0.1.

    ``dashboard_address=None`` alone does not do it: the scheduler still starts its HTTP server
    (health and metrics routes) on the default port 8787, and warns, or fails, when that port is
    taken. Here the dashboard is off (no Bokeh application) and the HTTP server listens on port
    0, which the operating system turns into a free one.
    """
    from distributed import LocalCluster

    return LocalCluster(n_workers=workers, threads_per_worker=1, processes=processes,
                        protocol="tcp://", host="127.0.0.1", scheduler_port=0,
                        dashboard_address=None, worker_dashboard_address=None,
                        scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"})


def _scheduler_name(scheduler, workers: int) -> str:
    if scheduler is None:
        return f"distributed.LocalCluster(n_workers={workers}, threads_per_worker=1, processes)"
    if isinstance(scheduler, str):
        return scheduler
    return str(getattr(getattr(scheduler, "scheduler", None), "address", scheduler))


def _package():
    """``catdae.study`` itself. :func:`_execute_all` calls the task as ``catdae.study.execute``,
    looked up when it runs, so that replacing that attribute (as the tests do with monkeypatch)
    replaces the task, as it did when the study was one module."""
    return sys.modules[__package__]
