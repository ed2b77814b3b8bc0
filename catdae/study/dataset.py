"""Errors of the runs against the reference, and the study's labelled Dataset."""

from __future__ import annotations

import math

import numpy as np

from catdae._xr import xr
from catdae.case import Step
from catdae.study import modes, quantity
from catdae.study.core import CHOICES, COORD_META, COUNTS, MEMORY_NAMES


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


def assemble(grid, combos, keys, records, ref, st: Step, target) -> xr.Dataset:
    names = list(grid)
    shape = tuple(len(v) for v in grid.values())
    data = {v: np.full(shape, np.nan) for v in ("wall_time", *COUNTS, "peak_memory", "error",
                                                "peak_tension_error")}
    status = np.full(shape, "", dtype=object)
    said = {v: np.full(shape, "", dtype=object) for v in ("mass_model_used", "note")}
    ref_ok = ref.attrs.get("status", "completed") == "completed"
    single = target[1] if isinstance(target, tuple) and target[0] == "mode" else None
    if st.kind == "transient":
        if isinstance(target, list):  # the common point that moves most in the reference
            target = max(target, key=lambda p: _motion(ref, p)) if ref_ok else target[0]
        label = target
    elif st.kind == "modal":
        n_modes = single or target
        ref_f = ref.frequency.values[:n_modes] if ref_ok else np.full(n_modes, np.nan)
        n_modes = ref_f.size if ref_ok else n_modes
        ferr = np.full((*shape, n_modes), np.nan)
        paired = np.zeros((*shape, n_modes), int)  # the run's mode number; 0: none
        mac = np.full((*shape, n_modes), np.nan)
    for combo, key in zip(combos, keys, strict=True):
        idx = tuple(grid[n].index(combo[n]) for n in names)
        rec = records[key]
        status[idx] = str(rec.attrs["status"])
        for v, texts in said.items():
            texts[idx] = str(rec.attrs.get(v, ""))
        for v in ("wall_time", *COUNTS, "peak_memory"):
            data[v][idx] = float(rec.attrs.get(v, math.nan))
        if status[idx] != "completed" or not ref_ok:
            continue
        if st.kind == "transient":
            data["error"][idx] = _transient_error(rec, ref, label)
            ref_peak = float(ref.attrs.get("peak_tension", math.nan))
            data["peak_tension_error"][idx] = (float(rec.attrs.get("peak_tension", math.nan))
                                               / ref_peak - 1.0)
        elif st.kind == "modal":
            pair, score = modes.match(ref, rec)
            pair, score = pair[:n_modes], score[:n_modes]
            found = pair >= 0
            f = rec.frequency.values[np.maximum(pair, 0)]
            ferr[idx] = np.where(found, (f - ref_f) / ref_f, np.nan)
            paired[idx], mac[idx] = pair + 1, np.where(found, score, np.nan)
            # a mode the run does not resolve: no finite error (the run misses what is asked)
            compared = [single - 1] if single else range(n_modes)
            data["error"][idx] = (math.inf if not found[compared].all()
                                  else float(np.abs(ferr[idx][compared]).max()))
    if st.kind == "static" and ref_ok:
        quantity.static_errors(records, combos, keys, grid, ref, target, data)
    dims = tuple(names)
    coords = {}
    for n in names:
        vals = np.array(grid[n], dtype=object if n in CHOICES else None)
        units, long_name = COORD_META[n]
        coords[n] = xr.Variable(n, vals, {"units": units, "long_name": long_name} if units
                                else {"long_name": long_name})
    methods = sorted({str(r.attrs.get("memory_method", "")) for r in records.values()} - {""})
    memory = "+".join(methods)
    mem_name = "; ".join(MEMORY_NAMES[m] for m in methods)
    if st.kind == "transient":
        err_units, err_name = "m", (f"largest distance over time between the displacement at "
                                    f"{label} and the reference's")
    elif st.kind == "static":
        err_units, err_name = "1", f"relative error of the {quantity.describe(target)}"
    elif single:
        err_units, err_name = "1", f"relative error of the natural frequency of mode {single}"
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
    variables["status"] = xr.Variable(dims, status, {"long_name": "run status "
                                                     "('completed' or why it stopped)"})
    if st.kind != "static":
        variables["mass_model_used"] = xr.Variable(dims, said["mass_model_used"], {
            "long_name": "mass model the run's step used (what mass_model \"auto\" chose)"})
    variables["note"] = xr.Variable(dims, said["note"], {
        "long_name": "the run's step note (what catdae run would print; '' for none)"})
    if st.kind == "transient":
        variables["peak_tension_error"] = xr.Variable(dims, data["peak_tension_error"], {
            "units": "1", "long_name": "relative error of the step's largest tension (its "
            "envelope tension_max over every accepted step) against the reference's"})
    out = xr.Dataset(variables, coords=coords)
    if st.kind == "modal":
        out = out.assign_coords(mode=xr.Variable("mode", np.arange(1, n_modes + 1),
                                                 {"long_name": "mode number"}))
        out["frequency_error"] = xr.Variable(
            (*dims, "mode"), ferr, {"units": "1", "long_name": "relative error of the natural "
                                    "frequency (f - f_ref) / f_ref of the run's mode of the "
                                    "same shape (NaN: the run has none)"})
        out["matched_mode"] = xr.Variable(
            (*dims, "mode"), paired, {"long_name": "the run's mode paired with the "
                                      "reference's mode by shape (0: none within 45 degrees)"})
        out["shape_correlation"] = xr.Variable(
            (*dims, "mode"), mac, {"units": "1", "long_name": "modal assurance criterion of "
                                   "the pair, the squared cosine of the angle between shapes"})
        if single:
            out.attrs["response_mode"] = single
        out.attrs["response"] = (f"natural frequency of mode {single}" if single
                                 else f"{n_modes} lowest natural frequencies")
        out.attrs["error_definition"] = (
            (f"|f - f_ref| / f_ref of mode {single}" if single
             else "max over the modes of |f - f_ref| / f_ref")
            + ", f the run's mode of the reference mode's shape (modal assurance criterion); "
            "inf when the run has no mode of that shape")
    elif st.kind == "static":
        out.attrs["response"] = quantity.describe(target)
        out.attrs["error_definition"] = "|q - q_ref| / |q_ref|"
    else:
        out.attrs["response"] = label
        out.attrs["error_definition"] = (f"max over the reference's output times of |u_run - "
                                         f"u_ref| at {label}, linear interpolation in time")
    out.attrs["peak_memory_method"] = memory
    return out
