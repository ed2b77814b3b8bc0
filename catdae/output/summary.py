"""What ``catdae run`` prints after a run: per step, what a user looks at first (per value of a
sweep). It reads the result datasets only (docs/case-format.md, "What an engineer reads")."""

from __future__ import annotations

import numpy as np

from catdae.output.end_peaks import at_end
from catdae.output.reading import ratio_text, step_values


def summary(tree) -> str:
    """A short printed summary: per step, what a user looks at first (per value of a sweep)."""
    lines = [f"{tree.attrs.get('title') or 'catdae run'}"]
    for name, node in tree.children.items():
        lines.append(step_summary(name, node.to_dataset()))
    return "\n".join(x for x in lines if x)


def step_summary(name: str, ds) -> str:
    """The summary of one step's group (``catdae run`` prints it as the step ends, so that an
    interrupted or failed run has printed the steps it finished)."""
    if "sweep" not in ds.dims:
        return "\n".join(_step_lines(name, ds))
    field = ds.attrs.get("sweep_field", "sweep")
    lines = [f"[{name}] swept over {field}: {ds.sizes['sweep']} values"]
    for _, one in step_values(name, ds):
        lines.extend(_step_lines(f"{name} {one.attrs['sweep_value']}", one))
    return "\n".join(lines)


def _step_lines(name: str, ds) -> list[str]:
    """The summary of one step's dataset (of one value of a sweep)."""
    kind = ds.attrs.get("kind", "")
    if kind == "static":
        lines = [f"[{name}] static{_temperatures(ds)}: {ds.attrs.get('iterations')} Newton "
                 f"iterations, residual {ds.attrs.get('residual_norm', 0):.2e} N"]
        lines += _cable_lines(ds) + _connector_lines(ds)
    elif kind == "modal":
        lines = _mode_lines(name, ds)
    elif kind == "transient":
        lines = _transient_lines(name, ds) + _jump_lines(ds) + _connector_lines(ds)
    else:
        return []
    if ds.attrs.get("note"):
        lines.append(f"    note: {ds.attrs['note']}")
    return lines


def _transient_lines(name: str, ds) -> list[str]:
    """The transient's run and the largest distance a free node moves from its start."""
    a = ds.attrs
    lines = [f"[{name}] transient: {ds.time.size} outputs to t = "
             f"{float(ds.time[-1]):.4g} s, {a.get('n_steps')} steps, "
             f"{a.get('n_residual_evaluations')} residuals, "
             f"{a.get('wall_time', 0):.2f} s wall, status {a.get('status')}"]
    # supports (reaction defined on some axis) are prescribed: the free nodes' motion
    free = ds.reaction.isnull().all(("time", "axis"))
    d = ds.displacement.isel(node=np.flatnonzero(free.values)) if bool(free.any()) \
        else ds.displacement
    d = d - d.isel(time=0)  # during the step (displacement is from the case's geometry)
    mag = np.sqrt((d**2).sum("axis"))
    node = str(mag.max("time").idxmax("node").values)
    tmax = ds.tension_max if "tension_max" in ds else ds.get("tension")  # envelope
    top = (f"; max tension {float(tmax.max()):.6g} N" if ds.sizes.get("element")
           and tmax is not None else "")  # a scene of connectors alone has no element
    lines.append(f"    largest distance of a free node from its place at the step's start: "
                 f"{float(mag.sel(node=node).max()):.4g} m, at {node}{top}")
    return lines


def _deg(angle: float) -> str:
    """An angle in degrees as printed: 0 below 1e-6 deg (the rounding of a static solve, whose
    force residual is 1e-11 of the loads: a still-air span's 3.6e-9 deg)."""
    return "0" if abs(angle) < 1e-6 else f"{angle:.6g}"


def _connector_lines(ds) -> list[str]:
    """Per spring and bar: its force and swing angle from the vertical (a static step), or the
    range of its swing angle over the outputs and when it is largest (a transient)."""
    if "connector_swing_angle" not in ds:
        return []
    out = []
    for k, name in enumerate(ds.connector.values):
        kind = str(ds.connector_kind.values[k])
        if kind == "damper" and "connector_force_max" in ds:  # a transient: its force range
            out.append(f"    damper {name}: force {float(ds.connector_force_min.values[k]):.6g}"
                       f" to {float(ds.connector_force_max.values[k]):.6g} N")
        if kind == "damper":
            continue
        if "time" not in ds.connector_swing_angle.dims:
            out.append(f"    {kind} {name}: force {float(ds.connector_force.values[k]):.6g} N, "
                       f"swing angle {_deg(float(ds.connector_swing_angle.values[k]))} deg"
                       f"{_axis_text(ds, k)}")
        elif "connector_swing_angle_max" in ds:
            top = float(ds.connector_swing_angle_max.values[k])
            when = float(ds.connector_swing_angle_max_time.values[k])
            out.append(f"    {kind} {name}: swing angle "
                       f"{_deg(float(ds.connector_swing_angle_min.values[k]))} to {_deg(top)} "
                       f"deg, largest at t = {when:.6g} s{_axis_text(ds, k, when)}")
    return out


def _axis_text(ds, k: int, when: float | None = None) -> str:
    """Where connector k's end b is from its end a (its unit axis), at ``when`` in a transient:
    the side a string swings to, which the angle alone does not say."""
    if "connector_axis" not in ds:
        return ""
    a = ds.connector_axis.isel(connector=k)
    if when is not None:
        a = a.sel(time=when, method="nearest")
    v = np.asarray(a.values, float)
    v = np.where(np.abs(v) < 5e-5, 0.0, v)  # no "-0.0000"
    return "" if not np.isfinite(v).all() else (
        f" (axis a to b {', '.join(f'{x:+.4f}' for x in v)})")


def _temperatures(ds) -> str:
    """The step's temperature: uniform over the cables (the attr), or each cable's when they
    differ (its temperature, or without a reference temperature its temperature change)."""
    if "temperature" in ds.attrs:
        return f" at {float(ds.attrs['temperature']):.6g} deg"
    if "temperature_change" in ds.attrs:  # uniform, without a reference temperature
        return ""
    for var, unit, fmt in (("temperature", "deg", ".6g"), ("temperature_change", "K", "+.6g")):
        if var in ds and ds[var].ndim == 1:
            each = ", ".join(f"{c} {float(t):{fmt}}" for c, t in zip(
                ds.cable.values, ds[var].values, strict=True))
            return (f" at {each} {unit}" if var == "temperature"
                    else f" with temperature changes {each} {unit}")
    return ""


def _mode_lines(name: str, ds) -> list[str]:
    """Every mode of a modal step: its frequency and labels (plane, symmetry); with damping
    the damped frequency, the damped modes' labels and the damping ratio."""
    damped = "damping_ratio" in ds
    out = [f"[{name}] modal: {ds.mode.size} modes"
           + (" (damped: frequency Im s/2π, damping ratio -Re s/|s|)" if damped else "")]
    names = ("damped_plane", "damped_symmetry") if damped else ("plane", "symmetry")
    for k, mode in enumerate(ds.mode.values):
        labels = ", ".join(str(ds[v].values[k]) for v in names if v in ds)
        line = (f"    mode {int(mode)}: {float(ds.frequency.values[k]):.6g} Hz"
                + (f", {labels}" if labels else ""))
        if damped:
            line += f", damping ratio {ratio_text(ds.damping_ratio.values[k])}"
            like = int(ds.undamped_mode.values[k]) if "undamped_mode" in ds else k + 1
            if like >= 1:  # the undamped mode it is most like, not the k-th (sorted by |s|)
                f_u = float(ds.undamped_frequency.sel(mode=like))
                line += f" (like undamped mode {like}: {f_u:.6g} Hz)"
        out.append(line)
    return out


SWING_SAID = 1.0  # degrees: a transient's largest swing angle is printed from this up


def _jump_lines(ds) -> list[str]:
    """Per cable of a transient: its largest rise above the jump_reference step, the largest
    tension as a percentage of the rated strength (catdae.output.engineering)."""
    out = []
    for k, cab in enumerate(ds.cable.values if "cable" in ds.coords else ()):
        parts = []
        if "jump_height" in ds:
            when = float(ds.jump_time.values[k])
            parts.append(f"jump {float(ds.jump_height.values[k]):.6g} m above step "
                         f"'{ds.attrs.get('jump_reference', '')}' at t = {when:.6g} s"
                         + (" (at the step's end: may still be rising)" if at_end(when, ds)
                            else "") + f", s = {float(ds.jump_s.values[k]):.6g} m")
        parts += _rated(ds, k)
        if "swing_angle_max" in ds and float(ds.swing_angle_max.values[k]) >= SWING_SAID:
            above = int(np.isnan(ds.swing_angle.values[:, k]).sum())
            parts.append(f"largest swing angle {_deg(float(ds.swing_angle_max.values[k]))} "
                         f"deg at t = {float(ds.swing_angle_max_time.values[k]):.6g} s"
                         + (f" (at {above} of {ds.sizes['time']} outputs above its chord more "
                            "than beside it, where it has no swing: the largest is of the "
                            "others)" if above else ""))
        if "clearance_time" in ds:
            parts.append(f"least clearance {float(ds.clearance.values[k]):.6g} m at t = "
                         f"{float(ds.clearance_time.values[k]):.6g} s")
        if parts:
            out.append(f"    cable {cab}: " + "; ".join(parts))
    return out


def _rated(ds, k: int) -> list[str]:
    """Cable k's largest tension as a percentage of its rated strength, when it has one."""
    if "tension_percent_rated" not in ds or not np.isfinite(ds.tension_percent_rated.values[k]):
        return []
    return [f"largest tension {float(ds.tension_percent_rated.values[k]):.4g} % of rated "
            "strength"]


def _span_lines(ds, k: int) -> list[str]:
    """The span quantities of cable k (catdae.output.engineering), when the group has them."""
    if "sag_midspan" not in ds:
        return []
    mid = float(ds.sag_midspan.values[k])
    low = float(ds.sag_lowest_point.values[k])
    if abs(low) < 1e-9 * max(abs(mid), 1.0):  # rounding of a lowest point at the end: 0
        low = 0.0
    swing = float(ds.swing_angle.values[k])
    if not (np.isfinite(mid) or np.isfinite(swing)):  # engineering.py: NaN for a vertical chord
        parts = ["vertical chord: no sag at midspan or swing angle (no vertical plane through "
                 "the chord; the largest offset from it is the sag above)",
                 f"lowest point {low:.6g} m below the lower end"]
    else:
        largest = float(ds.sag.values[k]) if "sag" in ds else np.nan
        same = abs(mid - largest) <= 1e-6 * max(abs(largest), 1e-9)  # a level span's
        parts = ["the largest sag is at midspan" if same else
                 f"sag at midspan {mid:.6g} m" + (" (above the chord: the cable bulges up)"
                                                   if mid < 0 else ""),
                 f"lowest point {low:.6g} m below the lower end",
                 f"swing angle {_deg(swing)} deg"]
    parts += _rated(ds, k) + _seabed_part(ds, k)
    if "clearance" in ds:
        parts.append(f"clearance above the ground {float(ds.clearance.values[k]):.6g} m at "
                     f"s = {float(ds.clearance_s.values[k]):.6g} m")
    return ["      " + "; ".join(parts)]


def _seabed_part(ds, k: int) -> list[str]:
    """Cable k's length on the seabed and its touchdown point, when it rests on it."""
    if "seabed_length" not in ds or not float(ds.seabed_length.values[k]) > 0.0:
        return []
    text = f"on the seabed {float(ds.seabed_length.values[k]):.6g} m"
    if "touchdown" in ds and np.isfinite(ds.touchdown.values[k]).all():
        text += ", touchdown at (" + ", ".join(f"{x:.6g}" for x in ds.touchdown.values[k]) + ") m"
    return [text]


def _across(whole: float, along: float) -> bool:
    """Whether the horizontal tension at the first end has a part across the chord (a load
    across it: wind, a swung support), beyond rounding: ``horizontal_tension`` is the whole
    horizontal part of the end's tension, ``horizontal_tension_along_chord`` its component
    along the chord (catdae.model.span), equal to it when nothing acts across the chord."""
    return bool(np.isfinite(along)) and np.sqrt(max(whole**2 - along**2, 0.0)) > 1e-6 * whole


CABLES_SAID = 20  # more cables than this (a net): the summary names the extremes only


def _cable_lines(ds) -> list[str]:
    """Per cable: end tensions, horizontal tension, sag (and unstrained length); above
    CABLES_SAID cables only the cables of the largest end tension and of the largest sag, and a
    line saying how many more there are (a 25x25 net printed 5 206 lines; tester t77)."""
    if "cable" not in ds.coords:
        return []
    out = []
    shown = range(ds.cable.size)
    if ds.cable.size > CABLES_SAID:
        shown = sorted({int(np.nanargmax(ds.cable_end_tension.values.max(axis=1))),
                        int(np.nanargmax(ds.sag.values))})
    for k in shown:
        cab = ds.cable.values[k]
        t_i, t_j = (float(v) for v in ds.cable_end_tension.values[k])
        first = str(ds.element_node.values[ds.element_cable.values == cab][0, 0])
        whole = float(ds.horizontal_tension.values[k])
        along = (float(ds.horizontal_tension_along_chord.values[k])
                 if "horizontal_tension_along_chord" in ds else np.nan)
        line = (f"    cable {cab}: end tensions {t_i:.6g} N, {t_j:.6g} N; horizontal tension "
                f"{whole:.6g} N at {first}" + (" (includes the part across the chord)"
                                               if _across(whole, along) else ""))
        if np.isfinite(along):
            line += f", along the chord {along:.6g} N"
        line += f"; largest sag {float(ds.sag.values[k]):.6g} m"
        if "unstrained_length" in ds:
            line += f"; L0 {float(ds.unstrained_length.values[k]):.9g} m"
        out.append(line)
        out.extend(_span_lines(ds, k))
    if len(shown) < ds.cable.size:
        out.append(f"    ... {ds.cable.size - len(shown)} more cables (above: the largest end "
                   "tension and the largest sag; every cable's figures are in the results)")
    return out
