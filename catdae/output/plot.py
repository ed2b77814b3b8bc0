"""Figures of a results tree (matplotlib, Agg): what an engineer looks at first.

Each function takes a step's group (an ``xarray.Dataset``, or a DataTree node) and returns a
``matplotlib.figure.Figure``; axes are labelled from the variables' ``long_name`` and ``units``.
The figures are made without pyplot (``Figure`` objects, saved through the Agg canvas): no
window, no global state, and a notebook's own backend is left alone.

- :func:`profile`: the cable's shape at chosen times, elevation (heights up) and plan;
- :func:`history`: a node's displacement over time, per axis;
- :func:`spectrum`: the amplitude spectrum of that displacement;
- :func:`tension`: tension along each cable (at chosen times) and at the supports over time;
- :func:`modes`: mode shapes, elevation and plan, with their frequencies.

Lines are drawn through the nodes of each cable in order along it (``element_node``), so a
node shared by several cables appears on each. ``catdae plot RESULT.nc -o FOLDER`` writes
them as PNG files (:func:`write_all`).
"""

from __future__ import annotations

import os
from fractions import Fraction
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from catdae._xr import xr
from catdae.interrupts import deferred
from catdae.output.environment import axis_names, drawing_frame, still_levels
from catdae.output.plot_envelopes import mark_peaks, reactions
from catdae.output.plot_parts import PlotError, draw_connectors, label, legend
from catdae.output.plot_parts import output_times as _times
from catdae.output.plot_parts import subplots as _subplots
from catdae.output.reading import cable_paths, ratio_text

WHAT = ("profile", "history", "spectrum", "tension", "modes", "spans", "reactions")


_KINDS = {"profile": ("static", "transient"), "tension": ("static", "transient"),
          "history": ("transient",), "spectrum": ("transient",), "modes": ("modal",)}


def _ds(data, figure: str | None = None) -> xr.Dataset:
    """The step's Dataset, judged for the figure: PlotError unless it is a step group of a
    kind that makes it, with the variables of that kind (results.step_problem)."""
    from catdae.output.reading import step_problem

    if isinstance(data, xr.DataTree):
        data = data.to_dataset()
    if not isinstance(data, xr.Dataset):
        raise PlotError(f"expected a step of a results tree (an xarray Dataset or DataTree "
                        f"node), found {type(data).__name__}")
    if figure is not None:
        why = step_problem(data)
        if why is not None:
            raise PlotError(f"cannot draw a {figure} figure of this group: {why}")
        kinds = _KINDS[figure]
        if "sweep" in data.dims:
            raise PlotError("a swept step: draw one value, ds.isel(sweep=k) (its attributes: "
                            "catdae.output.reading.step_values)")
        if data.attrs["kind"] not in kinds:
            raise PlotError(f"a {figure} figure needs a {' or '.join(kinds)} step, found a "
                            f"{data.attrs['kind']} step")
        if "time" in data.dims and data.sizes["time"] == 0:
            raise PlotError(f"the step has no outputs to draw (status: "
                            f"{str(data.attrs.get('status', ''))[:80]})")
    return data


def _paths(ds: xr.Dataset) -> dict[str, list[str]]:
    if "element_node" in ds.coords:
        return cable_paths(ds)
    # a modal group has no elements: each cable's own nodes, in order (its shared ends aside)
    cab = ds.node_cable.values
    return {str(c): [str(n) for n in ds.node.values[cab == c]] for c in dict.fromkeys(cab)
            if c}


def profile(data, times=None, what: str = "position") -> Figure:
    """The cable at the given times (nearest stored ones; static: its one state): elevation
    above, plan below. Drawn in the case's axes (x-z, x-y) when z is up; under a gravity vector
    in the gravity frame (catdae.output.environment.drawing_frame): the vertical of the
    elevation is the height along up (= -g), the horizontal axes are e1, e2 normal to g. The
    seabed, the still-water level and the instantaneous surface are at their heights."""
    ds = _ds(data, "profile")
    var = ds[what]
    fig, (ax_e, ax_p) = _subplots(2, 1, figsize=(8, 7), sharex=True)
    states = [(None, var)] if "time" not in var.dims else [
        (t, var.sel(time=t)) for t in _times(ds, times)]
    paths = _paths(ds)
    R = drawing_frame(ds)
    for t, x in states:
        for k, (cab, nodes) in enumerate(paths.items()):
            pts = np.asarray(x.sel(node=nodes).transpose("node", "axis").values, float)
            if R is not None:
                pts = pts @ R.T  # (horizontal e1, e2, height along up)
            tag = cab if t is None else f"{cab}, t = {t:.4g} s"
            lab = tag if (k == 0 or len(paths) > 1) else None
            line, = ax_e.plot(pts[:, 0], pts[:, 2], marker=".", label=lab, gid=f"{cab}|{t}")
            ax_p.plot(pts[:, 0], pts[:, 1], marker=".", color=line.get_color(), gid=f"{cab}|{t}")
            if t is not None and "surface_elevation" in ds and what == "position":
                # the water surface above the cable's nodes (docs/case-format.md)
                eta = ds.surface_elevation.sel(time=t, node=nodes).values
                ax_e.plot(pts[:, 0], ds.attrs.get("water_surface", 0.0) + eta,
                          ls="--", lw=0.8, color=line.get_color(), gid=f"surface|{cab}|{t}")
        draw_connectors(ax_e, ax_p, ds, x, R, t)
    if what == "position":
        still_levels(ax_e, ds)
    name = var.attrs.get("long_name", what)
    e1, e2, up = axis_names(R)
    ax_e.set_ylabel(label(var, f"{name}, {up}"))
    ax_p.set_ylabel(label(var, f"{name}, {e2}"))
    ax_p.set_xlabel(label(var, f"{name}, {e1}"))
    ax_e.set_title("elevation")
    ax_p.set_title("plan")
    legend(ax_e, fontsize="small")
    for ax in (ax_e, ax_p):
        ax.grid(True, alpha=0.3)
    fig.suptitle(ds.attrs.get("title", ""))
    fig.tight_layout()
    return fig


def _node(ds: xr.Dataset, node: str | None) -> str:
    if node is None:  # the free node that moves most
        free = ds.reaction.isnull().all([d for d in ds.reaction.dims if d != "node"])
        d = ds.displacement.isel(node=np.flatnonzero(free.values)) if bool(free.any()) \
            else ds.displacement
        return str(np.sqrt((d**2).sum("axis")).max("time").idxmax("node").values)
    return select_node(ds, node)


def _cable_nodes(ds: xr.Dataset, cable: str) -> tuple[list[str], np.ndarray]:
    """A cable's nodes from its first end to its last and their unstrained arc lengths, m."""
    if "element_node" in ds.coords:
        sel = ds.element_cable.values == cable
        nodes = ds.element_node.values[sel]  # (n, 2), in order along the cable
        s = ds.element_s.values[sel]
        return ([str(n) for n in nodes[:, 0]] + [str(nodes[-1, 1])],
                np.append(s[:, 0], s[-1, 1]))
    on = ds.node_cable.values == cable  # a group without elements (modal)
    return [str(n) for n in ds.node.values[on]], np.asarray(ds.s.values[on], float)


def select_node(ds: xr.Dataset, spec: str) -> str:
    """The node label that ``spec`` names: a node of the results (``A``, ``main.7``), or a
    point of a cable that survives remeshing: ``<cable>@<p/q>`` (unstrained arc-length fraction,
    as ``catdae study`` names points: ``main@1/2`` is midspan; a decimal ``main@0.5`` too) or
    ``<cable>@s=<m>`` (unstrained arc length from the cable's first end). The point must be a
    node of this mesh; otherwise a PlotError names the nodes on either side."""
    spec = str(spec)
    names = [str(n) for n in ds.node.values]
    if spec in names:
        return spec
    if "@" not in spec:
        raise PlotError(f"no node {spec!r} in the results (e.g. {names[0]!r}; a point of a "
                        "cable: <cable>@<p/q> or <cable>@s=<m>)")
    cable, _, where = spec.partition("@")
    cables = list(dict.fromkeys(str(c) for c in (
        ds.element_cable.values if "element_cable" in ds.coords else ds.node_cable.values) if c))
    if cable not in cables:
        raise PlotError(f"{spec!r}: no cable {cable!r} in the results (cables: "
                        f"{', '.join(cables)})")
    nodes, s_nodes = _cable_nodes(ds, cable)
    length = float(s_nodes[-1])
    try:
        if where.startswith("s="):
            s = float(where[2:])
            if not 0.0 <= s <= length:
                raise PlotError(f"{spec!r}: expected 0 <= s <= {length:g} m (the length of cable "
                                f"{cable!r}), found {s:g}")
            at = f"s = {s:g} m"
        else:
            frac = Fraction(where)
            if not 0 <= frac <= 1:
                raise PlotError(f"{spec!r}: the fraction of the cable's length must be between "
                                f"0 and 1, found {frac}")
            s, at = float(frac) * length, str(frac)
    except (ValueError, ZeroDivisionError):
        raise PlotError(f"{spec!r}: expected <cable>@<p/q> (a fraction of the cable's length, "
                        "e.g. main@1/2) or <cable>@s=<m> (an arc length), or a node name") \
            from None
    k = int(np.abs(s_nodes - s).argmin())
    if abs(s_nodes[k] - s) <= 1e-9 * length:
        return nodes[k]
    j = int(np.searchsorted(s_nodes, s))
    near = ", ".join(f"{nodes[i]} (s = {s_nodes[i]:.6g} m)" for i in (j - 1, j))
    raise PlotError(f"{spec!r}: no mesh node at {at} of cable {cable!r} ({len(nodes) - 1} "
                    f"elements); the nodes on either side: {near}")


def history(data, node: str | None = None) -> Figure:
    """Displacement of a node over time, one panel per axis (default node: the free node that
    moves most)."""
    ds = _ds(data, "history")
    node = _node(ds, node)
    d = ds.displacement.sel(node=node)
    fig, axes = _subplots(3, 1, figsize=(8, 7), sharex=True)
    big = float(np.nanmax(np.ptp(d.values, axis=0))) if d.size else 0.0
    for ax, a in zip(axes, ds.axis.values, strict=True):
        y = d.sel(axis=a).values
        ax.plot(ds.time.values, y, gid=f"{node}|{a}")
        if np.nanmax(y) - np.nanmin(y) > 1e-9 * big:
            mark_peaks(ax, ds, "displacement", node, str(a))  # the envelope, when stored
        else:  # rounding, not motion: not drawn magnified to fill the panel
            ax.set_ylim(np.nanmean(y) - max(big, 1e-3) / 2, np.nanmean(y) + max(big, 1e-3) / 2)
            ax.text(0.5, 0.5, f"no motion along {a} (within rounding)", ha="center",
                    va="center", transform=ax.transAxes, color="0.4")
        ax.set_ylabel(label(ds.displacement, f"{a}"))
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel(label(ds.time, "time"))
    fig.suptitle(f"{ds.displacement.attrs.get('long_name', 'displacement')}, node {node}")
    fig.tight_layout()
    return fig


def amplitude_spectrum(t: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitude spectrum of x(t) on a uniform grid, mean removed, Hann window
    (amplitude-corrected): a sine of amplitude a between bins shows a peak close to a."""
    dt = float(np.median(np.diff(t)))
    n = t.size
    w = np.hanning(n)
    X = np.fft.rfft((x - x.mean()) * w)
    amp = 2.0 * np.abs(X) / w.sum()
    return np.fft.rfftfreq(n, dt), amp


def spectrum(data, node: str | None = None) -> Figure:
    """Amplitude spectrum of a node's displacement, per axis (log scale)."""
    ds = _ds(data, "spectrum")
    node = _node(ds, node)
    t = ds.time.values
    if t.size < 4 or not np.allclose(np.diff(t), np.diff(t)[0], rtol=1e-6, atol=1e-12):
        raise PlotError("a spectrum needs at least 4 outputs at a constant interval")
    fig, ax = _subplots(figsize=(8, 4.5))
    for a in ds.axis.values:
        f, amp = amplitude_spectrum(t, ds.displacement.sel(node=node, axis=a).values)
        ax.semilogy(f[1:], np.maximum(amp[1:], 1e-30), label=str(a), gid=f"{node}|{a}")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(label(ds.displacement, "amplitude"))
    ax.set_title(f"spectrum of the displacement of node {node}")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    return fig


def tension(data, times=None) -> Figure:
    """Tension along each cable (element ends at their arc length s; transient: at chosen
    times) and, for a transient, the force on the cable at each support over time."""
    ds = _ds(data, "tension")
    transient = "time" in ds.tension.dims
    fig, axes = _subplots(2 if transient else 1, 1, figsize=(8, 7 if transient else 4))
    ax_s = axes[0] if transient else axes
    states = [(t, ds.tension.sel(time=t)) for t in _times(ds, times)] if transient else [
        (None, ds.tension)]
    for t, tens in states:
        for cab in dict.fromkeys(str(c) for c in ds.element_cable.values):
            sel = ds.element_cable.values == cab
            s = ds.element_s.values[sel].ravel()  # i, j of each element in turn
            v = tens.values[sel].ravel()
            tag = cab if t is None else f"{cab}, t = {t:.4g} s"
            ax_s.plot(s, v, marker=".", label=tag, gid=f"{cab}|{t}")
    ax_s.set_xlabel(label(ds.element_s, "unstrained arc length s"))
    ax_s.set_ylabel(label(ds.tension))
    ax_s.set_title("tension along the cable")
    legend(ax_s, fontsize="small")
    ax_s.grid(True, alpha=0.3)
    if transient:
        ax_t = axes[1]
        sup = ~ds.reaction.isnull().all(("time", "axis"))
        for n in ds.node.values[sup.values]:
            r = ds.reaction.sel(node=n).fillna(0.0)
            mag = np.sqrt((r**2).sum("axis"))
            ax_t.plot(ds.time.values, mag.values, label=str(n), gid=f"{n}")
        ax_t.set_xlabel(label(ds.time, "time"))
        ax_t.set_ylabel(label(ds.reaction, "force at the support |R|"))
        ax_t.set_title("at the supports")
        legend(ax_t, fontsize="small")
        ax_t.grid(True, alpha=0.3)
    fig.tight_layout()
    return fig


def modes(data, n: int = 6) -> Figure:
    """The first n mode shapes: elevation (x-z components against x) and plan (y), each
    titled with its frequency. A damped modal step draws its damped modes (in their order,
    sorted by |s|): the real part of ``complex_shape``, titled with ``frequency`` (damped),
    ``damping_ratio`` and the ``damped_`` labels; its ``shape`` and labels are the undamped
    modes', in their own order (docs/case-format.md)."""
    ds = _ds(data, "modes")
    damped = "complex_shape" in ds
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
        raise PlotError(f"n: expected the number of modes to draw, an integer >= 1, found {n!r}")
    n = min(int(n), ds.mode.size)
    fig, axes = _subplots(n, 1, figsize=(8, 1.9 * n + 0.6), sharex=True, squeeze=False)
    paths = _paths(ds)
    x_of = ds.reference_position.sel(axis="x") if "reference_position" in ds else None
    for k, ax in enumerate(axes[:, 0]):
        sh = (ds["complex_shape"].isel(mode=k).sel(part="real") if damped
              else ds["shape"].isel(mode=k))
        mode = int(ds.mode.values[k])
        for cab, nodes in paths.items():
            x = x_of.sel(node=nodes).values if x_of is not None else _s_along(ds, cab, nodes)
            for a, style in (("y", "--"), ("z", "-")):
                ax.plot(x, sh.sel(node=nodes, axis=a).values, style, marker=".",
                        label=f"{cab} {a}", gid=f"{mode}|{cab}|{a}")
        names = ("damped_plane", "damped_symmetry") if damped else ("plane", "symmetry")
        extra = ", ".join(str(ds[v].values[k]) for v in names if v in ds)
        if damped:
            extra += f", damping ratio {ratio_text(ds.damping_ratio.values[k], '.3g')}"
        ax.set_title(f"mode {mode}: {float(ds.frequency.values[k]):.4g} "
                     f"{ds.frequency.attrs.get('units', '')}" + (f" ({extra})" if extra else ""),
                     fontsize="medium")
        ax.set_ylabel(label(ds["shape"], "shape"))
        ax.grid(True, alpha=0.3)
    legend(axes[0, 0], fontsize="small", ncol=2)
    axes[-1, 0].set_xlabel(label(x_of, "x") if x_of is not None else label(ds.s, "s"))
    fig.tight_layout()
    return fig


def _s_along(ds: xr.Dataset, cab: str, nodes: list[str]) -> np.ndarray:
    """The unstrained arc length of a cable's nodes along that cable (a shared end node's
    ``s`` is along the first cable through it; its elements' ``element_s`` are along each)."""
    if "element_s" not in ds.coords:
        return ds.s.sel(node=nodes).values
    es = ds.element_s.values[ds.element_cable.values == cab]
    return np.concatenate([es[:1, 0], es[:, 1]])


def _figure(what: str, ds: xr.Dataset, node, times) -> Figure:
    if what in ("history", "spectrum"):
        return history(ds, node) if what == "history" else spectrum(ds, node)
    if what in ("profile", "tension"):
        return profile(ds, times) if what == "profile" else tension(ds, times)
    if what == "reactions":
        return reactions(ds)
    return modes(ds)


_CAN = {"static": ("profile", "tension"), "modal": ("modes",),  # figures of each kind
        "transient": ("profile", "history", "spectrum", "tension", "reactions")}


def write_all(tree: xr.DataTree, folder: str | os.PathLike, steps=None, what=None,
              node: str | None = None, times=None) -> list[Path]:
    """PNG files ``<step>-<what>.png`` into ``folder`` for every figure that each step's kind
    can make (profile, tension: all; history, spectrum: transient; modes: modal)."""
    folder = Path(folder)
    names = list(tree.children) if not steps else [steps] if isinstance(steps, str) else list(
        steps)
    unknown = [s for s in names if s not in tree.children]
    if unknown:
        raise PlotError(f"no step {str(unknown[0])[:60]!r} in the results (steps: "
                        f"{', '.join(tree.children) or 'none'})")
    wanted = (what,) if isinstance(what, str) else tuple(what) if what else WHAT
    bad = [w for w in wanted if w not in WHAT]
    if bad:
        raise PlotError(f"what: no figure {str(bad[0])[:40]!r}; expected some of "
                        f"{', '.join(WHAT)}")
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    from catdae.output.reading import step_problem, step_values
    for group in names:  # a swept step: a figure per value, <step>-sweep<k>-<what>.png
        full = tree[group].to_dataset()
        if (why := step_problem(full)) is not None:
            raise PlotError(f"step {group[:60]!r}: {why}")
        for name, ds in step_values(group, full):
            can = _CAN.get(ds.attrs.get("kind"), ())
            for w in (w for w in wanted if w in can):
                path = folder / f"{name}-{w}.png"
                fig = _figure(w, ds, node, times)
                if (status := str(ds.attrs.get("status", "completed"))) != "completed":
                    fig.text(0.005, 0.005, f"step not completed: {status}"[:140], fontsize=7,
                             color="firebrick")  # the figure shows what was computed
                with deferred():  # a signal waits until the file is complete
                    fig.savefig(path, dpi=120)
                written.append(path)
    if "spans" in wanted:  # one figure across the static steps (catdae.output.plot_spans)
        from catdae.output.plot_spans import spans, static_groups

        if len(static_groups(tree, steps)) >= 2:
            path = folder / "spans.png"
            fig = spans(tree, steps)
            with deferred():
                fig.savefig(path, dpi=120)
            written.append(path)
    return written
