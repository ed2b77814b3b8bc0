"""The figure of a span across static steps: sag and tension against the conductor
temperature (a sag-temperature table) or against the steps, for every cable.

``catdae plot RESULT.nc -o FOLDER --what spans`` writes it as ``spans.png`` when the results
hold two or more static steps with span quantities (catdae.output.engineering).
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from catdae._xr import xr


def static_groups(tree: xr.DataTree, steps=None) -> list[tuple[str, xr.Dataset]]:
    """(name, dataset) of the static steps with span quantities, in step order; a swept
    static step gives one per value (a temperature sweep: a sag-temperature table)."""
    from catdae.output.reading import step_values

    names = list(tree.children) if not steps else [steps] if isinstance(steps, str) else list(
        steps)
    out = []
    for group in names:
        full = tree[group].to_dataset()
        if full.attrs.get("kind") == "static" and "sag_midspan" in full:
            out.extend(step_values(group, full))
    return out


def uniform_temperature(ds: xr.Dataset) -> float | None:
    """The step's temperature when it is the same for every cable (the attr, or the per-cable
    ``temperature`` when its values agree), else None."""
    if "temperature" in ds.attrs:
        return float(ds.attrs["temperature"])
    t = ds.get("temperature")
    if t is None or t.ndim != 1 or not t.size or not np.all(t.values == t.values[0]):
        return None
    return float(t.values[0])


def _label(name: str, ds: xr.Dataset, temperature: float | None) -> str:
    """A static step's tick: its name, or a swept step's name and value (``ice: ice_thickness =
    0.01``, not ``ice-sweep1``), with its temperature."""
    value = ds.attrs.get("sweep_value")
    text = f"{name.rsplit('-sweep', 1)[0]}: {value}" if value else name
    return text if temperature is None else f"{text} ({temperature:g}°)"


def spans(tree: xr.DataTree, steps=None) -> Figure:
    """Sag at midspan and at the lowest point (above), the largest tension as a percentage of
    the rated strength, or else the horizontal tension along the chord (below), per cable,
    against the steps' ``temperature`` when every step has one the same for every cable and no
    two steps share it, else against the steps (named, with their temperature)."""
    groups = static_groups(tree, steps)
    temps = [uniform_temperature(ds) for _, ds in groups]
    # against the temperature only where it tells the steps apart: load cases at one
    # temperature (bare and iced at -5 °C) would be drawn one above the other, unnamed
    by_temperature = (all(t is not None for t in temps)
                      and len(set(temps)) == len(temps))
    x = np.array(temps, float) if by_temperature else np.arange(len(groups), dtype=float)
    order = np.argsort(x, kind="stable")
    fig = Figure(figsize=(8, 7))
    ax_s, ax_t = fig.subplots(2, 1, sharex=True)
    rated = all("tension_percent_rated" in ds for _, ds in groups)
    tension = "tension_percent_rated" if rated else "horizontal_tension_along_chord"
    for k, cab in enumerate(str(c) for c in groups[0][1].cable.values):
        color = f"C{k % 10}"  # one colour per cable in both panels (the style tells the sags)
        for var, style in (("sag_midspan", "-"), ("sag_lowest_point", "--")):
            y = np.array([float(ds[var].sel(cable=cab)) for _, ds in groups])
            ax_s.plot(x[order], y[order], style, marker="o", label=f"{cab}, {var}",
                      gid=f"{cab}|{var}", color=color)
        y = np.array([float(ds[tension].sel(cable=cab)) for _, ds in groups])
        ax_t.plot(x[order], y[order], marker="o", label=cab, gid=f"{cab}|{tension}",
                  color=color)
    ax_s.set_ylabel("sag [m]")
    ax_s.set_title("sag at midspan (solid) and of the lowest point below the lower end (dashed)",
                   fontsize="medium")
    ax_t.set_ylabel("largest tension [% of rated strength]" if rated
                    else "horizontal tension along the chord [N]")
    if by_temperature:
        ax_t.set_xlabel("temperature (the case's reference_temperature units)")
    else:
        ax_t.set_xticks(x, [_label(name, ds, t) for (name, ds), t in
                            zip(groups, temps, strict=True)], rotation=30)
        ax_t.set_xlabel("static step")
    for ax in (ax_s, ax_t):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
    fig.suptitle(tree.attrs.get("title", ""), fontsize="medium")
    fig.tight_layout()
    return fig
