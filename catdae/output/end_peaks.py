"""Envelope peaks that a transient reaches at its last output time (docs/case-format.md, "Line
engineering"): such a peak may still be growing when the step stops, so the step's ``note``
says which, and the printed jump says so.

Looked at: per cable its ``jump_height``, its largest ``tension_max`` and its least
``clearance``; per spring and bar its largest ``connector_swing_angle``; and of the
``displacement`` and ``reaction`` envelopes only the headline entries, the free node's
component that rises (``_max``) or falls (``_min``) most from the step's start and the
support's reaction component that changes most, since some node's component always happens to
be largest at the end of a step.
"""

from __future__ import annotations

import numpy as np

from catdae._xr import xr
from catdae.output.results import with_note

_EPS = 1e-9  # a time within this (relative to the step's clock) of its end is at its end


def at_end(when, ds: xr.Dataset) -> np.ndarray:
    """Whether times ``when`` (s, the case's clock) are the step's last output time."""
    t_end = float(ds.time.values[-1])
    return np.asarray(when, float) >= t_end - _EPS * max(1.0, abs(t_end))


def _per_cable(ds: xr.Dataset, var: str, time: str, what: str) -> list[str]:
    if var not in ds or time not in ds:
        return []
    hit = [str(c) for c, t in zip(ds.cable.values, ds[time].values, strict=True)
           if np.isfinite(t) and at_end(t, ds)]
    return [f"{what} of cable {', '.join(hit)}"] if hit else []


def _tension(ds: xr.Dataset) -> list[str]:
    """Cables whose largest tension_max is reached at the end."""
    if "time_tension_max" not in ds or not ds.sizes.get("element"):
        return []
    hit = []
    for c in dict.fromkeys(str(c) for c in ds.element_cable.values):
        sel = ds.element_cable.values == c
        top, when = ds.tension_max.values[sel], ds.time_tension_max.values[sel]
        if at_end(when.flat[int(np.argmax(top))], ds):
            hit.append(c)
    return [f"tension_max of cable {', '.join(hit)}"] if hit else []


def _swing(ds: xr.Dataset) -> list[str]:
    if "connector_swing_angle_max_time" not in ds:
        return []
    when = ds.connector_swing_angle_max_time.values
    hit = [str(c) for c, t in zip(ds.connector.values, when, strict=True)
           if np.isfinite(t) and at_end(t, ds)]
    return [f"connector_swing_angle_max of {', '.join(hit)}"] if hit else []


def _headline(ds: xr.Dataset, var: str, nodes: np.ndarray) -> list[str]:
    """``var``'s largest rise (``_max``) and fall (``_min``) from the step's start over the
    ``nodes`` (a mask) and axes, when either is reached at the end."""
    if not nodes.any():
        return []
    out = []
    start = ds[var].isel(time=0).values[nodes]
    for how, sign in (("max", 1.0), ("min", -1.0)):
        change = sign * (ds[f"{var}_{how}"].values[nodes] - start)
        if not np.isfinite(change).any() or np.nanmax(change) <= 0.0:
            continue  # it never moved that way
        k = np.unravel_index(int(np.nanargmax(change)), change.shape)
        if at_end(ds[f"{var}_{how}_time"].values[nodes][k], ds):
            node = str(ds.node.values[np.flatnonzero(nodes)[k[0]]])
            out.append(f"{var}_{how} at {node} ({ds.axis.values[k[1]]})")
    return out


def end_peaks(ds: xr.Dataset) -> list[str]:
    """What reaches its envelope's peak at the step's last output time (texts for the note)."""
    support = ~ds.reaction.isnull().all(("time", "axis")).values
    return (_per_cable(ds, "jump_height", "jump_time", "jump_height")
            + _tension(ds)
            + _per_cable(ds, "clearance", "clearance_time", "least clearance")
            + _swing(ds)
            + _headline(ds, "displacement", ~support)
            + _headline(ds, "reaction", support))


def with_end_note(ds: xr.Dataset) -> xr.Dataset:
    """The group with its ``note`` telling which envelope peaks are at the step's end."""
    peaks = end_peaks(ds)
    if not peaks:
        return ds
    return with_note(ds, f"reached at the step's last output time (t = "
                     f"{float(ds.time.values[-1]):.6g} s), so they may still be growing (a "
                     f"longer step shows the peak): {'; '.join(peaks)}")
