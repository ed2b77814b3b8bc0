"""Convergence orders and the matplotlib plots of a study: work-precision and convergence
(Agg canvas, no pyplot)."""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Iterator

import numpy as np

from catdae._xr import xr
from catdae.study.core import SETTINGS


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


ROUNDING = 1e-10  # relative errors at or below this: two exact answers, to the solves' tolerance


def at_rounding(ds: xr.Dataset, sel: dict | None = None) -> bool:
    """Whether every finite relative error (of ``sel``) is rounding (a mesh-exact static
    study: 1e-15 to 4e-12, the static solves' tolerance), where a fitted order would be noise;
    False for errors in metres."""
    if ds.error.attrs.get("units") != "1":
        return False
    e = np.abs(ds.error.values if sel is None else ds.error.isel(sel).values)
    e = e[np.isfinite(e)]
    return bool(e.size) and bool((e <= ROUNDING).all())


def mixed_mass_models(ds: xr.Dataset, sel: dict | None = None) -> list[str]:
    """The mass models the runs (of ``sel``, by index) used, when more than one and the study
    does not sweep the mass model itself (``auto`` chose them); else []."""
    if "mass_model_used" not in ds or ds.sizes.get("mass_model", 1) > 1:
        return []
    used = ds.mass_model_used if sel is None else ds.mass_model_used.isel(sel)
    names = sorted({str(v) for v in np.ravel(used.values)} - {""})
    return names if len(names) > 1 else []


def _line_dim(ds: xr.Dataset) -> str:
    for d in ("rtol", "atol", "elements", "max_order", "gauss_points"):
        if d in ds.dims and ds.sizes[d] > 1:
            return d
    return "elements"


def plot_work_precision(ds: xr.Dataset, path: str | os.PathLike | None = None):
    """Error against wall time and against residual evaluations (log-log), one line per family
    of settings, along the first swept of rtol, atol, elements; for a transient a second row,
    the relative error of the largest tension (``peak_tension_error``, absolute value).
    Returns the matplotlib Figure, drawn on an Agg canvas without pyplot (so the caller's
    backend is left alone); with ``path``, also writes it as PNG."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    line = _line_dim(ds)
    costs = [c for c in ("wall_time", "n_residual_evaluations")
             if np.isfinite(ds[c].values).any()]
    errors = ["error"] + (["peak_tension_error"] if "peak_tension_error" in ds
                          and np.isfinite(ds.peak_tension_error.values).any() else [])
    fig = Figure(figsize=(5.5 * max(len(costs), 1), 4.5 * len(errors)), layout="constrained")
    FigureCanvasAgg(fig)
    for k, (err, cost) in enumerate(itertools.product(errors, costs)):
        ax = fig.add_subplot(len(errors), len(costs), k + 1)
        for label, sel in _families(ds, line):
            sub = ds.isel(sel)
            x, y = sub[cost].values, np.abs(sub[err].values)
            ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
            if ok.any():
                ax.loglog(x[ok], y[ok], "o-", label=label or None)
                for xi, yi, v in zip(x[ok], y[ok], sub[line].values[ok], strict=True):
                    ax.annotate(f"{v:g}" if isinstance(v, float) else str(v), (xi, yi),
                                fontsize=7, textcoords="offset points", xytext=(3, 3))
        ax.set_xlabel(f"{ds[cost].attrs['long_name']} ({ds[cost].attrs['units']})")
        ax.set_ylabel(f"error ({ds.error.attrs['units']})" if err == "error"
                      else "|relative error of the largest tension|")
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
        mixed = mixed_mass_models(ds, sel)  # no one order across two methods
        if ok.any():
            ax.loglog(err.elements.values[ok], err.values[ok], "o-",
                      label=f"{label + ': ' if label else ''}"
                            + (f"mass {' / '.join(mixed)}: no order" if mixed
                               else "at solver tolerance: no order" if at_rounding(ds, sel)
                               else f"order {p:.2f}"))
    ax.set_xlabel("elements per cable")
    ax.set_ylabel(f"error ({ds.error.attrs['units']})")
    ax.set_title(f"{ds.attrs.get('case_name', '')}: {ds.attrs.get('response', '')}", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    if path is not None:
        fig.savefig(path, dpi=110)
    return fig
