"""Settings of a study, its grid, the configured case and key of each run, and the response
points that every mesh shares (see the ``catdae.study`` docstring)."""

from __future__ import annotations

import hashlib
import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from fractions import Fraction
from typing import Any

import numpy as np

from catdae._version import __version__
from catdae.case import AXES, Case, Step
from catdae.case.names import mesh_node, split_mesh_node
from catdae.case.schema import MASS_MODEL_NAMES
from catdae.errors import CatdaeError

SETTINGS = ("rtol", "atol", "elements", "gauss_points", "mass_model", "linear_solver",
            "max_order")
MODAL_SETTINGS = ("elements", "gauss_points", "mass_model")
STATIC_SETTINGS = ("elements", "gauss_points")  # catdae.study.quantity
STORE_FORMAT = 3  # bump when the stored runs change meaning

COORD_META = {  # setting -> (units, long_name); labels (strings) get no units
    "rtol": ("1", "relative tolerance of IDA"),
    "atol": ("m", "absolute tolerance of IDA on displacements"),
    "elements": ("1", "elements per cable (0: as in the case file)"),
    "gauss_points": ("1", "Gauss points per element (0: as in the case file)"),
    "mass_model": ("", "mass model"),
    "linear_solver": ("", "linear solver requested"),
    "max_order": ("1", "largest BDF order of IDA"),
}
CHOICES = {"mass_model": MASS_MODEL_NAMES,
            "linear_solver": ("auto", "band", "sparse", "dense")}
COUNTS = ("n_steps", "n_residual_evaluations", "n_jacobian_evaluations")
MEMORY_NAMES = {
    "peak_rss": "growth of the worker's resident set size during the run (VmHWM reset)",
    "maxrss": "growth of the worker's lifetime peak resident set size (ru_maxrss)",
    "tracemalloc": "peak of Python and numpy allocations (tracemalloc)",
}


class StudyError(CatdaeError):
    """A study cannot be set up: an invalid setting, step, response or reference."""


# ---------------------------------------------------------------------------------------------
# Grid, configuration, keys
# ---------------------------------------------------------------------------------------------


def study_step(case: Case, step: str | None = None) -> Step:
    """The step named ``step``; by default the first transient step, else the first modal one,
    else the first static one (catdae.study.quantity)."""
    if step is not None:
        found = [s for s in case.steps if s.name == step]
        if not found:
            names = ", ".join(repr(s.name) for s in case.steps) or "none"
            raise StudyError(f"the case has no step named {step!r} (steps: {names})")
        return _not_swept(case, found[0])
    for kind in ("transient", "modal", "static"):
        for s in case.steps:
            if s.kind == kind:
                return _not_swept(case, s)
    raise StudyError("the case has no step to study")


def _not_swept(case: Case, step: Step) -> Step:
    """The study step, refused when it is swept: a study measures one state per run."""
    if step.sweep is None:
        return step
    k = case.steps.index(step)
    raise StudyError(f"{case.path}: steps[{k}].sweep: the study step {step.name!r} is swept over "
                     f"{step.sweep.field}; a study measures one state of its step per run: "
                     "study a copy of the step without its sweep (the value set in the case), "
                     "or name another step with --step")


def settings_grid(case: Case, step: Step, given: Mapping[str, Sequence | None]) -> dict:
    """Each setting of the step's kind -> its list of values (the case's value when not given).

    Raises StudyError listing every invalid value, and any setting that does not apply to the
    step's kind.
    """
    names = {"transient": SETTINGS, "modal": MODAL_SETTINGS}.get(step.kind, STATIC_SETTINGS)
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
    if name in CHOICES:
        return None if v in CHOICES[name] else f"expected one of {CHOICES[name]}, found {v!r}"
    if name == "max_order" and v == "auto":
        return None
    lo, hi = {"elements": (1, 10**6), "gauss_points": (1, 10), "max_order": (1, 5)}[name]
    ok = isinstance(v, int | np.integer) and not isinstance(v, bool) and lo <= v <= hi
    return None if ok else f"expected an integer from {lo} to {hi}, found {v!r}"


def reference_settings(grid: Mapping[str, list], overrides: Mapping | None = None) -> dict:
    """The automatic reference (package docstring), with ``overrides`` applied."""
    ref = {}
    for name, values in grid.items():
        swept = len(values) > 1
        if name in ("rtol", "atol"):
            ref[name] = float(f"{min(values) / 100.0:.12g}")  # 1e-07, not 1.0000000000000001e-07
            if name == "rtol":  # not below what a case accepts (a double's digits)
                ref[name] = max(ref[name], 1e-13)
        elif name == "elements":
            ref[name] = 2 * max(values) if swept else values[0]
        elif name == "gauss_points":
            ref[name] = min(max(values) + 1, 10) if swept else values[0]
        else:
            ref[name] = {"mass_model": "auto", "linear_solver": "auto",
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
        cable, k = split_mesh_node(name)
        out.append(f"{cable}@{Fraction(int(k), counts[cable])}")
    return out


def _mesh_points(case_run: Case) -> set[str]:
    nodes = list(case_run.nodes)
    for c in case_run.cables:
        nodes += [mesh_node(c.name, k) for k in range(1, c.elements)]
    return {lab for lab in point_labels(case_run, nodes) if lab is not None}


def resolve_response(response: str, case: Case) -> str:
    """A user's response name -> a point label (package docstring)."""
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
    cable, k = split_mesh_node(response) or ("", "")
    names = [c.name for c in case.cables]
    if cable in names and k.isdigit() and 0 < int(k) < case.cable(cable).elements:
        return f"{cable}@{Fraction(int(k), case.cable(cable).elements)}"
    raise StudyError(f"response {response!r}: expected a case node ({', '.join(case.nodes)}), "
                     "<cable>@<fraction> or a mesh node <cable>.<k> of the case file's mesh")


def common_points(cases: Sequence[Case]) -> set[str]:
    common = None
    for c in cases:
        pts = _mesh_points(c)
        common = pts if common is None else common & pts
    return common or set()
