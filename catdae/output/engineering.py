"""Engineering results of a step: span quantities, tension against the rated strength, and the
envelopes of a transient over its output times (docs/case-format.md, "What an engineer reads").

Static groups get, per cable, the span quantities of :func:`catdae.model.span.span_quantities`
and ``tension_percent_rated``. Transient groups get per node the extremes of ``reaction`` and
``displacement`` with their times, per cable ``tension_percent_rated`` (of the step's
``tension_max`` envelope, which sees peaks between outputs) and, when the step names a
``jump_reference`` static step, the largest rise of each cable above its position there
(``jump_height``, an ice-shedding jump). The envelopes of reactions and displacements are
taken over the stored output times: a peak between two outputs is missed by at most what the
motion does in one output interval.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from catdae._xr import xr
from catdae.case.build_cables import MAX_STRAIN
from catdae.case.frame import gravity_rotation
from catdae.output.end_peaks import with_end_note
from catdae.output.results import with_note
from catdae.output.swing import swing_over_time

_SPAN = {  # name: (units, long_name)
    "horizontal_tension_along_chord": (
        "N", "horizontal tension along the chord (the first end's tension along the chord's "
        "horizontal direction; without the part across the chord)"),
    "sag_midspan": ("m", "vertical distance from the chord to the cable at midspan (halfway "
                    "between the ends in plan)"),
    "swing_angle": ("degree", "angle from the vertical of the line from the chord to the "
                    "cable at midspan (swing under loads across the span)"),
    "sag_lowest_point": ("m", "depth of the cable's lowest point below its lower end (0: the "
                         "lowest point is an end)"),
    "lowest_point_s": ("m", "unstrained arc length of the cable's lowest point"),
    "lowest_point_elevation": ("m", "height of the cable's lowest point"),
    "tension_max_along_cable": ("N", "largest tension along the cable"),
}


_CLEARANCE = "least height of the cable above the case's [ground] (negative: below it)"


def _cable_var(values, units: str, long_name: str) -> xr.Variable:
    return xr.Variable("cable", np.asarray(values, float),
                       {"units": units, "long_name": long_name})


def rated_strengths(case, cable_names) -> np.ndarray:
    """The material's ``rated_strength`` of each cable, N (NaN where not given)."""
    out = []
    for name in cable_names:
        r = case.material_of(str(name)).rated_strength
        out.append(np.nan if r is None else float(r))
    return np.array(out)


def add_static(ds: xr.Dataset, quantities: dict[str, np.ndarray], case) -> xr.Dataset:
    """The static group with the span quantities (per ``cable``) and the largest tension as a
    percentage of the rated strength."""
    rated = rated_strengths(case, [str(c) for c in ds.cable.values])
    data = {}
    for key, (units, long_name) in _SPAN.items():
        source = "tension_max" if key == "tension_max_along_cable" else key
        data[key] = _cable_var(quantities[source], units, long_name)
    if np.isfinite(rated).any():
        data["tension_percent_rated"] = _cable_var(
            100.0 * quantities["tension_max"] / rated, "percent",
            "largest tension along the cable as a percentage of the material's rated_strength")
    if "clearance" in quantities:
        data["clearance"] = _cable_var(quantities["clearance"], "m", _CLEARANCE)
        data["clearance_s"] = _cable_var(quantities["clearance_s"], "m",
                                         "unstrained arc length where the clearance is least")
    out = ds.assign(data)
    return with_note(out, "; ".join(n for n in (_limit_note(out, data), strain_note(out, case))
                                    if n))


def strain_note(ds: xr.Dataset, case) -> str:
    """Cables whose largest tension passed MAX_STRAIN of their EA: a strain beyond the range
    the model accepts (a linear elastic material; a case that needs more is refused when it is
    read), reached in a run (tester t63: a support pulled 200 m, "completed" at 197 %)."""
    var = ds.get("tension_max", ds.get("tension"))
    if var is None or "element_cable" not in ds.coords or var.size == 0:
        return ""
    top = np.asarray(var.max("time").values if "time" in var.dims else var.values, float)
    said = []
    names = list(dict.fromkeys(str(c) for c in ds.element_cable.values))
    for name, t in zip(names, cable_max(ds, top, names), strict=True):
        ea = case.material_of(name).EA
        if t > MAX_STRAIN * ea:
            said.append(f"cable {name!r} reached a strain of {100 * t / ea:.3g} % (tension "
                        f"{t:.4g} N, T / EA), far beyond what a cable carries and the "
                        f"{MAX_STRAIN:.0%} this model accepts (a linear elastic material; a "
                        "case that needs more is refused when read): check the loads, the "
                        "support motions and their units")
    return "; ".join(said)


def cable_max(ds: xr.Dataset, top: np.ndarray, cables: list[str]) -> np.ndarray:
    """Per cable (in ``cables`` order) the largest of ``top`` (element, end), NaN where it has
    none: one pass over the elements (a mask per cable was cables times elements)."""
    code = {c: i for i, c in enumerate(cables)}
    which = np.array([code[str(c)] for c in ds.element_cable.values], dtype=np.intp)
    out = np.full(len(cables), -np.inf)
    np.fmax.at(out, which, np.fmax.reduce(np.asarray(top, float).reshape(len(which), -1),
                                           axis=1))
    return np.where(np.isfinite(out), out, np.nan)


def _limit_note(ds: xr.Dataset, data: dict) -> str:
    """What a line engineer must not miss: a cable past its rated strength, or below the
    ground (a length given in mm read as m gave 1711 % and -155 km with no word)."""
    names = [str(c) for c in ds.cable.values] if "cable" in ds.coords else []
    said = []
    pct = data.get("tension_percent_rated")
    if pct is not None:
        over = [(n, float(v)) for n, v in zip(names, np.ravel(pct.values), strict=False)
                if v > 100.0]
        said += [f"cable {n!r} is at {v:.4g} % of its rated strength (past breaking)"
                 for n, v in over]
    gap = data.get("clearance")
    if gap is not None:
        said += [f"cable {n!r} passes {-float(v):.4g} m below the ground"
                 for n, v in zip(names, np.ravel(gap.values), strict=False) if v < 0.0]
    return "; ".join(said)


def cable_temperature_changes(names: list[str], change) -> np.ndarray:
    """Each cable's temperature change from the reference temperature, K, in ``names`` order:
    (n_cables,) for a step's change (one number, or per cable: a cable the table does not
    name is at the reference temperature, 0), (n_values, n_cables) for an array over the values
    of a temperature sweep."""
    if isinstance(change, Mapping):
        return np.array([float(change.get(n, 0.0)) for n in names])
    c = np.asarray(change, float)
    return np.repeat(c[..., None], len(names), axis=-1)


def add_temperatures(ds: xr.Dataset, names: list[str], change,
                     reference: float | None) -> xr.Dataset:
    """``temperature_change``(cable) K, and with the case's ``reference`` temperature
    ``temperature``(cable) (its units: °C or K), of each cable in the step (``change`` as
    :func:`cable_temperature_changes` takes it; (sweep, cable) over a temperature sweep)."""
    per = cable_temperature_changes(names, change)
    dims = ("sweep", "cable") if per.ndim == 2 else ("cable",)
    if "cable" in ds.coords:  # the group's own order of the cables
        per = per[..., [names.index(str(c)) for c in ds.cable.values]]
    else:
        ds = ds.assign_coords(cable=xr.Variable("cable", np.array(names, dtype=object),
                                                {"long_name": "cable name"}))
    data = {"temperature_change": xr.Variable(dims, per, {
        "units": "K", "long_name": "temperature change of the cable in this step from the "
        "case's reference temperature (0: at the reference temperature)"})}
    if reference is not None:
        data["temperature"] = xr.Variable(dims, reference + per, {
            "long_name": "temperature of the cable in this step, in the units of the case's "
            "reference_temperature (degrees Celsius or kelvins)"})
    return ds.assign(data)


def _extreme(var: xr.DataArray, how: str, what: str) -> dict[str, xr.Variable]:
    """``<name>_<how>`` and ``<name>_<how>_time`` over time (NaN where the variable is NaN
    throughout, e.g. reactions at free nodes)."""
    v = var.values  # (time, ...)
    t = var["time"].values
    finite = np.isfinite(v).any(axis=0)
    filled = np.where(np.isfinite(v), v, -np.inf if how == "max" else np.inf)
    k = filled.argmax(axis=0) if how == "max" else filled.argmin(axis=0)
    value = np.take_along_axis(v, k[None], axis=0)[0]
    when = np.where(finite, t[k], np.nan)
    value = np.where(finite, value, np.nan)
    dims = var.dims[1:]
    word = "largest" if how == "max" else "smallest"
    name = str(var.name)
    return {
        f"{name}_{how}": xr.Variable(dims, value, {
            "units": var.attrs.get("units", ""),
            "long_name": f"{word} {what} over the output times"}),
        f"{name}_{how}_time": xr.Variable(dims, when, {
            "units": "s", "long_name": f"time of the {word} {what}"}),
    }


def start_tension(step, groups: Mapping[str, xr.Dataset]) -> np.ndarray | None:
    """The tensions (element, end) a transient starts from, where they hold at its first
    instant too: a load or a mass added or removed moves nothing at once, so a cable's tension
    is continuous there, while each element's quasi-static sag jumps with its own loads (a
    shed ice load dropped the first tension 0.33 % below the iced one at 20 elements, 0.03 %
    at 80). None without ``add`` or ``remove``, after a temperature change (a thermal strain
    changes the tension at once), or after a group that holds no single state (swept, or a modal
    step that found its own equilibrium); a modal step about the state it found is passed over."""
    if not (step.add or step.remove) or step.temperature_change is not None or not groups:
        return None
    before = [g for g in groups.values()
              if g.attrs.get("kind") != "modal" or "equilibrium" in g.attrs]
    if not before:  # a modal step about the state it found leaves the state as it was
        return None
    prev = before[-1]
    if (prev.attrs.get("kind") not in ("static", "transient") or "sweep" in prev.dims
            or "tension" not in prev or prev.tension.size == 0):
        return None
    t = prev.tension
    return np.asarray((t.isel(time=-1) if "time" in t.dims else t).values, float)


def _with_start(ds: xr.Dataset, start: np.ndarray) -> xr.Dataset:
    """The tension envelope with the tensions the step starts from, at its first time."""
    out = ds.copy()
    t0 = float(ds.time.values[0])
    for name, sign in (("tension_max", 1.0), ("tension_min", -1.0)):
        env = out[name].values.copy()
        when = out[f"time_{name}"].values.copy()
        beyond = sign * (start - env) > 0
        env[beyond], when[beyond] = start[beyond], t0
        out[name] = out[name].copy(data=env)
        out[name].attrs["long_name"] += (", and the tension the step starts from (a load "
                                         "added or removed moves nothing at once)")
        out[f"time_{name}"] = out[f"time_{name}"].copy(data=when)
    return out


def add_transient(ds: xr.Dataset, case, reference: xr.Dataset | None = None,
                  up: np.ndarray | None = None, start: np.ndarray | None = None) -> xr.Dataset:
    """The transient group with its envelopes over the output times: ``reaction_max``,
    ``reaction_min`` (node, axis) and their ``_time``, the same for ``displacement`` and
    ``connector_swing_angle`` (connector); per
    cable ``tension_percent_rated`` (of ``tension_max``) when a material has a rated strength;
    and with ``reference`` (the named static step's group) ``jump_height``, ``jump_time`` and
    ``jump_s`` per cable, the rise measured along ``up`` (a unit vector, default +z). Its
    ``note`` says which peaks are at the step's last output time
    (catdae.output.end_peaks). ``start``: the tensions the step starts from
    (:func:`start_tension`), taken into ``tension_max`` and ``tension_min`` at its first time."""
    if ds.sizes.get("time", 0) == 0:
        return ds
    if start is not None and "tension_max" in ds and start.shape == ds.tension_max.shape:
        ds = _with_start(ds, start)
    data = {}
    for how in ("max", "min"):
        data.update(_extreme(ds.reaction, how, "force the support exerts on the cable"))
        data.update(_extreme(ds.displacement, how, "displacement"))
        if "connector_swing_angle" in ds:
            data.update(_extreme(ds.connector_swing_angle, how,
                                 "angle of the connector's axis from the vertical"))
            data.update(_extreme(ds.connector_force, how, "axial force of the connector "
                                 "(tension positive)"))
    cables = list(dict.fromkeys(str(c) for c in ds.element_cable.values))
    rated = rated_strengths(case, cables)
    if np.isfinite(rated).any():
        # the envelope of every accepted step (a peak between outputs counts), else the outputs
        top = (ds.tension_max if "tension_max" in ds else ds.tension.max("time")).values
        data["tension_percent_rated"] = _cable_var(
            100.0 * cable_max(ds, top, cables) / rated, "percent",
            "largest tension along the cable during the step (its tension_max envelope) as a "
            "percentage of the material's rated_strength")
    out = ds.assign_coords(cable=xr.Variable("cable", np.array(cables, dtype=object),
                                             {"long_name": "cable name"})).assign(data)
    out = out.assign(swing_over_time(ds, cables, up))
    if reference is not None:
        out = out.assign(jump(ds, reference, cables, up))
    if getattr(case, "ground", None) is not None:
        out = out.assign(clearance_over_time(ds, case.ground, cables, up))
    return with_end_note(with_note(out, strain_note(out, case)))


def clearance_over_time(ds: xr.Dataset, ground, cables: list[str],
                        up: np.ndarray | None = None) -> dict[str, xr.Variable]:
    """Per cable the least height of its nodes above the ground over the output times, when
    and where (at the nodes: between nodes the exact curve is not stored in a transient)."""
    R = None if up is None else gravity_rotation(-np.asarray(up, float))
    gap = ground.gap(ds.position.transpose(..., "axis").values, R)  # (time, node) m
    least, when, where = [], [], []
    for c in cables:
        sel = ds.element_cable.values == c
        nodes = np.unique(ds.element_node.values[sel])
        k = np.flatnonzero(np.isin(ds.node.values.astype(str), nodes.astype(str)))
        g = gap[:, k]
        k_t, k_n = np.unravel_index(int(np.argmin(g)), g.shape)
        least.append(float(g[k_t, k_n]))
        when.append(float(ds.time.values[k_t]))
        node = str(ds.node.values[k[k_n]])
        at = (ds.element_node.values == node) & sel[:, None]
        where.append(float(ds.element_s.values[at][0]))
    return {
        "clearance": _cable_var(least, "m", _CLEARANCE + ", at the nodes, over the output "
                                "times"),
        "clearance_time": _cable_var(when, "s", "time of the least clearance"),
        "clearance_s": _cable_var(where, "m", "unstrained arc length of the node of least "
                                  "clearance"),
    }


def jump(ds: xr.Dataset, reference: xr.Dataset, cables: list[str],
         up: np.ndarray | None = None) -> dict[str, xr.Variable]:
    """Per cable the largest rise of a node of the cable above its position in ``reference``
    over the output times (m, along ``up``), when and where (the node's arc length)."""
    up = np.array([0.0, 0.0, 1.0]) if up is None else np.asarray(up, float)
    rise = ((ds.position - reference.position.sel(node=ds.node)) * xr.DataArray(
        up, dims="axis", coords={"axis": ds.axis})).sum("axis")  # (time, node) m
    height, when, where = [], [], []
    for c in cables:
        nodes = np.unique(ds.element_node.values[ds.element_cable.values == c])
        r = rise.sel(node=nodes)
        k_t, k_n = np.unravel_index(int(np.nanargmax(r.values)), r.shape)
        height.append(float(r.values[k_t, k_n]))
        when.append(float(ds.time.values[k_t]))
        node = str(r.node.values[k_n])
        sel = (ds.element_node.values == node) & (ds.element_cable.values == c)[:, None]
        where.append(float(ds.element_s.values[sel][0]))
    return {
        "jump_height": _cable_var(height, "m", "largest rise of the cable above its position "
                                  "in the jump_reference step, over the output times"),
        "jump_time": _cable_var(when, "s", "time of the largest rise"),
        "jump_s": _cable_var(where, "m", "unstrained arc length of the node that rises most"),
    }
