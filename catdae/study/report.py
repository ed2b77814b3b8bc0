"""A study's outputs: the netCDF file and its plots (:func:`write_study`), and the text
summary (:func:`summary`)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from catdae._xr import xr
from catdae.output.results import write_atomic
from catdae.study.core import SETTINGS
from catdae.study.plots import (
    at_rounding,
    mixed_mass_models,
    plot_convergence,
    plot_work_precision,
)


def write_study(ds: xr.Dataset, path: str | os.PathLike, plots: bool = True) -> list[Path]:
    """The Dataset to netCDF (atomically) and, with ``plots``, ``<stem>-work-precision.png``
    and ``<stem>-convergence.png`` beside it. Returns the files written."""
    path = write_atomic(ds, path)
    written = [path]
    if plots:
        wp = path.with_name(f"{path.stem}-work-precision.png")
        plot_work_precision(ds, wp)
        written.append(wp)
        conv = path.with_name(f"{path.stem}-convergence.png")
        if plot_convergence(ds, conv) is not None:
            written.append(conv)
    return written


def summary(ds: xr.Dataset) -> str:
    """One line per run: its swept settings, cost and error (and the mass model where
    ``auto`` chose different ones, and the step's note)."""
    swept = [d for d in SETTINGS if d in ds.dims and ds.sizes[d] > 1]
    lines = [f"study of step '{ds.attrs['step']}' of {ds.attrs['case_name']}: response "
             f"{ds.attrs['response']}; reference {ds.attrs['reference']}"]
    per_mode = [v for v in ("frequency_error", "matched_mode", "shape_correlation") if v in ds]
    used = mixed_mass_models(ds)
    notes = {str(v) for v in np.ravel(ds.note.values)} if "note" in ds else set()
    common = notes.pop() if len(notes) == 1 and ds.note.size > 1 else ""  # said once
    flat = ds.drop_vars(per_mode).stack(run=list(d for d in SETTINGS if d in ds.dims))
    units = ds.error.attrs["units"]
    matched = (ds.matched_mode.stack(run=list(flat.indexes["run"].names))
               if "matched_mode" in ds else None)
    for i in range(flat.sizes["run"]):
        r = flat.isel(run=i)
        what = ", ".join(f"{d}={r[d].item()}" for d in swept) or "run"
        counts = "".join(f", {float(r[v]):.0f} {name}" for v, name in (
            ("n_steps", "steps"), ("n_residual_evaluations", "residuals"))
            if v in r and np.isfinite(float(r[v])))
        peak = (f", peak tension error {float(r.peak_tension_error):+.3%}"
                if "peak_tension_error" in r else "")
        err = f"error {float(r.error):.3g}" + (f" {units}" if units != "1" else "")
        if matched is not None and r.status.item() == "completed":
            missing = [str(m) for m, k in zip(ds.mode.values, matched.isel(run=i).values,
                                              strict=True)
                       if k == 0 and ds.attrs.get("response_mode", m) == m]
            if missing:
                err += (f" (no mode of the shape of the reference's mode"
                        f"{'s' if len(missing) > 1 else ''} {', '.join(missing)}: this run "
                        "does not resolve it)")
        mass = f", mass {r.mass_model_used.item()}" if used else ""
        lines.append(f"  {what}: {r.status.item()}{mass}, {float(r.wall_time):.3g} s{counts}, "
                     f"{err}{peak}")
        if "note" in r and str(r.note.item()) and not common:
            lines.append(f"    note: {r.note.item()}")
    if common:
        lines.append(f"  note of every run: {common}")
    if used:
        lines.append(f"  (mass_model \"auto\" chose {' and '.join(used)} in different runs: "
                     "their errors mix two methods and are not one method's convergence; "
                     "give --mass-model to hold it)")
    if "reference_note" in ds.attrs:
        lines.append(f"  note: {ds.attrs['reference_note']}")
    if at_rounding(ds):
        lines.append("  (every error is at the level of the solves' tolerance, 1e-10 or less: "
                     "the runs agree with the reference, and no order can be read)")
    elif "reference_elements" in ds.attrs and ds.sizes.get("elements", 1) > 1:  # automatic
        lines.append("  (the reference is computed, not exact: the errors of the finest runs "
                     "include its own, about theirs / (2^p - 1) for a mesh twice as fine at "
                     "order p, as large as theirs at first order; check them against a finer "
                     "--reference)")
    return "\n".join(lines)
