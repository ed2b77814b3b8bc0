"""Labelled results: the only module that builds xarray objects (case-format.md, "Results").

Every variable carries ``units`` and ``long_name``; attributes are str or numbers only (netCDF
refuses dict, None and bool). Files are written to a temporary name beside the target and moved
into place, so an existing file is only ever replaced by a complete one.
"""

from __future__ import annotations

import errno
import os
import shutil
import uuid
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import xarray as xr

from . import __version__
from .mesh import AXES, Mesh


def _var(dims, data, units: str, long_name: str, **attrs) -> xr.Variable:
    return xr.Variable(dims, np.asarray(data), {"units": units, "long_name": long_name, **attrs})


def _coords(mesh: Mesh, with_elements: bool = True) -> dict:
    coords = {
        "node": xr.Variable("node", np.array(mesh.node_names, dtype=object),
                            {"units": "1", "long_name": "node name"}),
        "axis": xr.Variable("axis", np.array(AXES, dtype=object),
                            {"units": "1", "long_name": "global axis (z up)"}),
    }
    if with_elements:
        coords["element"] = xr.Variable("element", np.array(mesh.element_names, dtype=object),
                                        {"units": "1", "long_name": "element name"})
        coords["end"] = xr.Variable("end", np.array(["i", "j"], dtype=object),
                                    {"units": "1", "long_name": "element end"})
    return coords


def clean_attrs(attrs: dict) -> dict:
    """Attributes netCDF can store: bool -> int, None dropped, numpy scalars -> python."""
    out = {}
    for k, v in attrs.items():
        if v is None:
            continue
        if isinstance(v, bool | np.bool_):
            v = int(v)
        elif isinstance(v, np.generic):
            v = v.item()
        out[k] = v
    return out


def static_dataset(mesh: Mesh, X: np.ndarray, tension: np.ndarray, reaction: np.ndarray,
                   attrs: dict, cables: dict | None = None) -> xr.Dataset:
    """One static step: positions (n_nodes, 3), tensions (n_elem, 2), reactions (n_nodes, 3).

    ``cables`` (from Model.cable_summary) adds per-cable end tensions, horizontal tension, sag.
    """
    d = ("node", "axis")
    ds = xr.Dataset(
        {
            "position": _var(d, X, "m", "node position"),
            "displacement": _var(d, X - mesh.X0, "m", "displacement from reference_position"),
            "reference_position": _var(d, mesh.X0, "m",
                                       "meshed catenary under self-weight (reference)"),
            "tension": _var(("element", "end"), tension, "N", "cable tension at element end"),
            "reaction": _var(d, reaction, "N",
                             "force the support exerts on the cable (NaN where free)"),
        },
        coords=_coords(mesh),
        attrs=clean_attrs({"kind": "static", **attrs}),
    )
    if cables is not None:
        ds = ds.assign_coords(cable=xr.Variable("cable", np.array(mesh.cable_names, dtype=object),
                                                {"units": "1", "long_name": "cable name"}))
        ds["cable_end_tension"] = _var(("cable", "end"), cables["end_tension"], "N",
                                       "tension at the cable's first (i) and last (j) end")
        ds["horizontal_tension"] = _var("cable", cables["horizontal_tension"], "N",
                                        "horizontal tension at the cable's first end")
        ds["sag"] = _var("cable", cables["sag"], "m",
                         "largest vertical distance from chord to cable")
    return ds


def modal_dataset(mesh: Mesh, frequency: np.ndarray, shape: np.ndarray, plane, symmetry,
                  attrs: dict) -> xr.Dataset:
    """Modal step: frequencies (n_modes,) Hz and shapes (n_modes, n_nodes, 3), unit maximum."""
    n = len(frequency)
    coords = _coords(mesh, with_elements=False)
    coords["mode"] = xr.Variable("mode", np.arange(1, n + 1),
                                 {"units": "1", "long_name": "mode number"})
    ds = xr.Dataset(
        {
            "frequency": _var("mode", frequency, "Hz", "natural frequency"),
            "shape": _var(("mode", "node", "axis"), shape, "1",
                          "mode shape (largest nodal displacement component = 1)"),
            "plane": _var("mode", np.array(plane, dtype=object), "1",
                          "in-plane or out-of-plane (single-span cables; else unclassified)"),
            "symmetry": _var("mode", np.array(symmetry, dtype=object), "1",
                             "symmetric or antisymmetric about midspan (single-span cables)"),
        },
        coords=coords,
        attrs=clean_attrs({"kind": "modal", **attrs}),
    )
    return ds


def transient_dataset(mesh: Mesh, time: np.ndarray, X, V, A, tension, reaction, energy,
                      attrs: dict) -> xr.Dataset:
    """Transient step: histories with time first."""
    d = ("time", "node", "axis")
    coords = _coords(mesh)
    coords["time"] = xr.Variable("time", np.asarray(time), {"units": "s", "long_name": "time"})
    X = np.asarray(X).reshape(len(time), -1, 3)
    data = {
        "position": _var(d, X, "m", "node position"),
        "displacement": _var(d, X - mesh.X0[None], "m", "displacement from reference_position"),
        "velocity": _var(d, np.asarray(V).reshape(X.shape), "m/s", "node velocity"),
        "acceleration": _var(d, np.asarray(A).reshape(X.shape), "m/s2", "node acceleration"),
        "reference_position": _var(("node", "axis"), mesh.X0, "m",
                                   "meshed catenary under self-weight (reference)"),
        "tension": _var(("time", "element", "end"), tension, "N",
                        "cable tension at element end"),
        "reaction": _var(d, reaction, "N",
                         "force the support exerts on the cable (NaN where free)"),
    }
    for key, (values, long_name) in energy.items():
        data[key] = _var("time", values, "J", long_name)
    return xr.Dataset(data, coords=coords, attrs=clean_attrs({"kind": "transient", **attrs}))


def make_tree(case, groups: dict[str, xr.Dataset], status: str = "completed") -> xr.DataTree:
    """Root with provenance and one group per step, in step order."""
    root = xr.Dataset(attrs=clean_attrs({
        "title": case.title,
        "source": case.source,
        "case_toml": case.text,
        "case_name": case.name,
        "catdae_version": __version__,
        "created": datetime.now(UTC).isoformat(timespec="seconds"),
        "status": status,
        "Conventions": "CF-1.10",
    }))
    return xr.DataTree.from_dict({"/": root, **{f"/{k}": v for k, v in groups.items()}})


INCOMPLETE_SUFFIX = ".incomplete"
"""The temporary name ends so: ``<name>.<pid>-<random>.incomplete``, never ``.nc``."""


def incomplete_name(path: Path) -> Path:
    """The temporary file that :func:`write_atomic` writes before moving it to ``path``. Only a
    process killed outright (SIGKILL, power loss) leaves one behind; its name says what it is
    and no ``*.nc`` pattern matches it, so it is never taken for a result."""
    return path.with_name(f"{path.name}.{os.getpid()}-{uuid.uuid4().hex[:8]}{INCOMPLETE_SUFFIX}")


def write_atomic(data: xr.DataTree | xr.Dataset, path: str | os.PathLike) -> Path:
    """Write netCDF-4 atomically: a temporary file beside the target (:func:`incomplete_name`),
    moved over it, so that a crash never leaves half a file and an existing file is only
    replaced by a complete one. Raises OSError when the file cannot be written."""
    path = Path(path)
    tmp = incomplete_name(path)
    try:
        data.to_netcdf(tmp, engine="netcdf4")
        os.replace(tmp, path)
    except RuntimeError as exc:  # how the netCDF/HDF5 library reports a failed write
        tmp.unlink(missing_ok=True)
        raise _write_failure(data, path, exc) from exc
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def _write_failure(data, path: Path, exc: RuntimeError) -> OSError:
    """The OSError behind a netCDF library error: ENOSPC when the disk has less room left than
    the data needs (the library says only "HDF error"), else EIO with the library's words."""
    try:
        free = shutil.disk_usage(path.parent).free
    except OSError:
        free = None
    if free is not None and free < data.nbytes + (1 << 20):
        return OSError(errno.ENOSPC, f"{os.strerror(errno.ENOSPC)} ({free} bytes free)")
    return OSError(errno.EIO, f"the netCDF library failed to write: {exc}")


def write_tree(tree: xr.DataTree, path: str | os.PathLike) -> Path:
    """Write netCDF-4 with groups atomically (see :func:`write_atomic`)."""
    return write_atomic(tree, path)


def read_tree(path: str | os.PathLike) -> xr.DataTree:
    """Open a results file fully into memory (the file is closed afterwards)."""
    with xr.open_datatree(path, engine="netcdf4") as tree:
        return tree.load()
