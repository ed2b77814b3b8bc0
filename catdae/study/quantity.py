"""Errors in one number (issue 23): a natural frequency of a modal step, or a static quantity of
a cable (a sag, an end tension) of a static step, instead of a displacement history.

Responses, as ``--response`` or ``run_study(response=...)``:

- modal: ``frequency:<k>``, the relative error of mode k's frequency (``<n>`` alone still
  compares the n lowest and takes the largest error);
- static: ``<quantity>:<cable>``, with quantity one of :data:`STATIC_QUANTITIES`, or
  ``end_tension:<cable>:<i|j>`` (default: ``sag`` of the first cable); the error is relative,
  |q - q_ref| / |q_ref|.

A static step's settings are the mesh's: ``elements`` and ``gauss_points``.
"""

from __future__ import annotations

import math

import numpy as np

from catdae._xr import xr
from catdae.study.core import STATIC_SETTINGS as STATIC_SETTINGS
from catdae.study.core import StudyError

STATIC_QUANTITIES = {  # name in the response -> (variable of the static group, long name)
    "sag": ("sag", "sag (largest vertical distance from the chord)"),
    "sag_midspan": ("sag_midspan", "sag at midspan"),
    "sag_lowest_point": ("sag_lowest_point", "depth of the lowest point below the lower end"),
    "horizontal_tension": ("horizontal_tension", "horizontal tension"),
    "horizontal_tension_along_chord": ("horizontal_tension_along_chord",
                                       "horizontal tension along the chord"),
    "end_tension": ("cable_end_tension", "tension at the cable's end"),
    "tension_max": ("tension_max_along_cable", "largest tension along the cable"),
}


def static_target(case, response) -> tuple[str, str, str | None]:
    """``(quantity, cable, end)`` named by a static study's response (module docstring)."""
    cables = [c.name for c in case.cables]
    if response is None:
        return "sag", cables[0], None
    parts = str(response).split(":")
    q = parts[0]
    expect = (f"expected <quantity>:<cable> with quantity one of "
              f"{', '.join(STATIC_QUANTITIES)} (end_tension:<cable>:<i|j>), e.g. sag:{cables[0]}")
    if q not in STATIC_QUANTITIES or len(parts) not in (2, 3):
        raise StudyError(f"response {response!r} of a static study: {expect}")
    cable = parts[1]
    if cable not in cables:
        raise StudyError(f"response {response!r}: no cable {cable!r} (cables: "
                         f"{', '.join(cables)})")
    if q == "end_tension":
        if len(parts) != 3 or parts[2] not in ("i", "j"):
            raise StudyError(f"response {response!r}: expected end_tension:{cable}:i (the "
                             f"first end) or end_tension:{cable}:j (the last)")
        return q, cable, parts[2]
    if len(parts) != 2:
        raise StudyError(f"response {response!r} of a static study: {expect}")
    return q, cable, None


def frequency_target(response, modes: int) -> tuple[str, int] | None:
    """``("mode", k)`` for ``frequency:<k>``; None when the response is not of that form."""
    if not (isinstance(response, str) and response.startswith("frequency:")):
        return None
    try:
        k = int(response.partition(":")[2])
    except ValueError:
        k = 0
    if not 1 <= k <= modes:
        raise StudyError(f"response {response!r}: expected frequency:<k> with k from 1 to "
                         f"{modes} (the step's modes)")
    return "mode", k


def static_values(group: xr.Dataset, attrs: dict) -> xr.Dataset:
    """What a worker keeps of a static run: every quantity of STATIC_QUANTITIES per cable."""
    data = {}
    for name, (var, _) in STATIC_QUANTITIES.items():
        if var in group:
            data[name] = (group[var].dims, group[var].values)
    coords = {"cable": [str(c) for c in group.cable.values]}
    if "end" in group.coords:
        coords["end"] = [str(e) for e in group.end.values]
    return xr.Dataset(data, coords=coords, attrs=attrs)


def static_value(ds: xr.Dataset, target: tuple[str, str, str | None]) -> float:
    q, cable, end = target
    if q not in ds:
        return math.nan
    v = ds[q].sel(cable=cable)
    return float(v.sel(end=end) if end is not None else v)


def describe(target: tuple[str, str, str | None]) -> str:
    q, cable, end = target
    name = STATIC_QUANTITIES[q][1]
    return f"{name} of cable {cable!r}" + (f" at end {end}" if end else "")


def static_errors(records, combos, keys, grid, ref, target, data) -> None:
    """Fill ``data["error"]`` with |q - q_ref| / |q_ref| of each completed run."""
    q_ref = static_value(ref, target)
    names = list(grid)
    for combo, key in zip(combos, keys, strict=True):
        rec = records[key]
        if str(rec.attrs["status"]) != "completed" or not np.isfinite(q_ref):
            continue
        idx = tuple(grid[n].index(combo[n]) for n in names)
        data["error"][idx] = abs(static_value(rec, target) - q_ref) / abs(q_ref)
