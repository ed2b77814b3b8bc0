"""Seabed results of a static step (docs/case-format.md, "Seabed"): per cable, the unstrained
length resting on the seabed and the touchdown point."""

from __future__ import annotations

from catdae._xr import xr
from catdae.output.results import _label, _var


def add_seabed(ds: xr.Dataset, mesh, summary: dict) -> xr.Dataset:
    """``ds`` with ``seabed_length``(cable) and ``touchdown``(cable, axis)."""
    if "cable" not in ds.coords:
        ds = ds.assign_coords(cable=_label("cable", mesh.cable_names, "cable name"))
    ds["seabed_length"] = _var("cable", summary["seabed_length"], "m",
                               "unstrained length of cable resting on the seabed")
    ds["touchdown"] = _var(("cable", "axis"), summary["touchdown"], "m",
                           "touchdown point: where the cable leaves the seabed (NaN: none)")
    return ds
