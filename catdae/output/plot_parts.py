"""Pieces of catdae's figures (catdae.output.plot): axis labels, figures without pyplot,
legends, and the connectors drawn beside the cables."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from catdae._xr import xr
from catdae.errors import CatdaeError


class PlotError(CatdaeError):
    """A figure that the data cannot make (no such node, step or time)."""


def label(var: xr.DataArray, name: str | None = None) -> str:
    """'long_name [units]' from the variable's attributes (time: 's')."""
    text = name or var.attrs.get("long_name", var.name)
    units = var.attrs.get("units")
    if units and " since " in str(units).lower():  # CF time: "seconds Since <epoch>"
        units = str(units)[:str(units).lower().index(" since ")].replace("seconds", "s")
    return f"{text} [{units}]" if units else str(text)


def subplots(*args, figsize, **kwargs):
    fig = Figure(figsize=figsize)
    return fig, fig.subplots(*args, **kwargs)


def legend(ax, **kwargs) -> None:
    """The axes' legend, where something drawn has a label (a scene of connectors alone has
    no cable to name)."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(**kwargs)


def draw_connectors(ax_e, ax_p, ds: xr.Dataset, x: xr.DataArray, R, t) -> None:
    """Springs, dampers and bars as dashed lines between their end nodes (``connector_node``),
    in elevation and plan, at the positions ``x`` (node, axis) of time t (None: static)."""
    if "connector_node" not in ds.coords or not ds.sizes.get("connector"):
        return
    for k, (name, ends) in enumerate(zip(ds.connector.values, ds.connector_node.values,
                                         strict=True)):
        pts = np.asarray(x.sel(node=[str(e) for e in ends]).transpose("node", "axis").values,
                         float)
        if R is not None:
            pts = pts @ R.T  # (horizontal e1, e2, height along up)
        tag = ("connectors" if t is None else f"connectors, t = {t:.4g} s") if k == 0 else None
        ax_e.plot(pts[:, 0], pts[:, 2], ls="--", marker="o", ms=3, lw=1.2, color="0.35",
                  label=tag, gid=f"{name}|{t}")
        ax_p.plot(pts[:, 0], pts[:, 1], ls="--", marker="o", ms=3, lw=1.2, color="0.35",
                  gid=f"{name}|{t}")


def output_times(ds: xr.Dataset, times) -> np.ndarray:
    """The stored times nearest to the requested ones (default: 5 spread over the step)."""
    t = ds.time.values
    if times is None:
        return t[np.unique(np.linspace(0, t.size - 1, min(5, t.size)).round().astype(int))]
    try:
        wanted = np.atleast_1d(np.asarray(times, dtype=float))
    except (TypeError, ValueError):
        raise PlotError(f"times: expected numbers (s), found {times!r:.60}") from None
    half = 0.5 * float(np.diff(t).max()) if t.size > 1 else 0.0  # nearest output within reach
    if wanted.ndim != 1 or wanted.size == 0 or not np.isfinite(wanted).all():
        why = "expected one or more finite times (s)"
    elif ((wanted < t[0] - half) | (wanted > t[-1] + half)).any():
        why = (f"the step's outputs run from {t[0]:g} to {t[-1]:g} s (another step: catdae "
               "plot --step, or its group in Python)")
    else:
        return np.array([t[np.abs(t - x).argmin()] for x in wanted])
    raise PlotError(f"times: {why}, found {np.array2string(wanted, threshold=6)}")
