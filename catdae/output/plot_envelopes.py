"""Envelopes of a transient on its figures (catdae.output.engineering): the peaks of a node's
displacement marked on its history, and ``reactions``, each support's reaction components over
time with their largest and smallest values and times. ``catdae plot --what reactions`` writes
``<step>-reactions.png``."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from catdae._xr import xr


def mark_peaks(ax, ds: xr.Dataset, var: str, node: str, axis: str) -> None:
    """Mark ``<var>_max`` and ``<var>_min`` of a node and axis at their times, with values."""
    for how, marker in (("max", "^"), ("min", "v")):
        name = f"{var}_{how}"
        if name not in ds or f"{name}_time" not in ds:
            return
        v = float(ds[name].sel(node=node, axis=axis))
        t = float(ds[f"{name}_time"].sel(node=node, axis=axis))
        if not (np.isfinite(v) and np.isfinite(t)):
            continue
        ax.plot([t], [v], marker, color="k", gid=f"{node}|{axis}|{how}")
        # inside the axes: to the left of a peak in the later half, room above and below
        late = "time" in ds.coords and t > 0.5 * float(ds.time[0] + ds.time[-1])
        ax.annotate(f"{v:.4g} at {t:.4g} s", (t, v), textcoords="offset points",
                    xytext=(-4 if late else 4, 4 if how == "max" else -10),
                    ha="right" if late else "left", fontsize="x-small")
        ax.margins(y=0.12)


def supports(ds: xr.Dataset) -> list[str]:
    """Nodes with a reaction on some axis at some time."""
    return [str(n) for n in ds.node.values[(~ds.reaction.isnull().all(("time", "axis"))).values]]


def reactions(data) -> Figure:
    """Each support's reaction components over time, one panel per axis, with the envelope
    (largest and smallest, and when) marked."""
    ds = data.to_dataset() if isinstance(data, xr.DataTree) else data
    fig = Figure(figsize=(8, 7))
    axes = fig.subplots(3, 1, sharex=True)
    for ax, a in zip(axes, ds.axis.values, strict=True):
        for n in supports(ds):
            r = ds.reaction.sel(node=n, axis=a)
            if bool(r.isnull().all()):
                continue
            ax.plot(ds.time.values, r.values, label=n, gid=f"{n}|{a}")
            mark_peaks(ax, ds, "reaction", n, str(a))
        ax.set_ylabel(f"reaction, {a} [{ds.reaction.attrs.get('units', 'N')}]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
    axes[-1].set_xlabel("time [s]")
    fig.suptitle("force the supports exert on the cables (envelope over the output times)",
                 fontsize="medium")
    fig.tight_layout()
    return fig
