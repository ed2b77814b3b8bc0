"""Labelled results: the only module that builds xarray objects (case-format.md, "Results").

Every variable carries ``units`` and ``long_name``; attributes are str or numbers only (netCDF
refuses dict, None and bool). Files are written to a temporary name beside the target and moved
into place, so an existing file is only ever replaced by a complete one.
"""

from __future__ import annotations

import errno
import os
import shutil
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from catdae._version import __version__
from catdae._xr import xr
from catdae.model.mesh import AXES, Mesh
from catdae.output.environment import environment_attrs
from catdae.output.files import INCOMPLETE_SUFFIX, clean_stale, incomplete_name  # noqa: F401

CONVENTIONS = "CF-1.10"
# CF §4.4: a time coordinate has units "<unit> since <epoch>". The case's clock has no date: its
# seconds are stored since a nominal epoch, so that t = 4 s is 1970-01-01T00:00:04 to a CF
# calendar tool. Users and their plots want seconds, and plain xarray (open_dataset,
# open_datatree with their defaults) decodes to dates only units holding a lower-case
# "since"; UDUNITS, which CF follows (cf-units, cftime, compliance-checker), reads the keyword
# in any case. So "Since" is written with a capital S: the file is CF time to CF tools and
# float seconds to xarray (tests/unit/test_plain_xarray.py holds xarray to it). Files written
# before, with "since", are read as seconds too (read_tree: decode_times=False).
TIME_UNITS = "seconds Since 1970-01-01 00:00:00"
TIME_ATTRS = {"units": TIME_UNITS, "calendar": "proleptic_gregorian", "standard_name": "time",
              "long_name": "time on the case's clock (t = 0 at the start of the case)",
              "axis": "T"}


def var(dims, data, units: str, long_name: str, **attrs) -> xr.Variable:
    return xr.Variable(dims, np.asarray(data), {"units": units, "long_name": long_name, **attrs})


def label(dims, values, long_name: str) -> xr.Variable:
    """A string coordinate: labels carry no units."""
    return xr.Variable(dims, np.array(values, dtype=object), {"long_name": long_name})


def _coords(mesh: Mesh, with_elements: bool = True) -> dict:
    """Labels and arc lengths. Nodes are stored cable by cable, each from its first end to its
    last (a node shared by cables with the first that reaches it; mesh.build_mesh)."""
    on_cable = mesh.cable_of_node >= 0
    names = np.array((*mesh.cable_names, ""), dtype=object)  # "": no cable at all
    node_cable = np.where(on_cable, names[np.maximum(mesh.cable_of_node, 0)], "")
    coords = {
        "node": label("node", mesh.node_names, "node name"),
        "axis": label("axis", AXES, "global axis (z up)"),
        "node_cable": label("node", node_cable,
                             "cable of the node (the first one through it; empty: none)"),
        "s": var("node", mesh.s_node, "m", "unstrained arc length along node_cable"),
    }
    if with_elements:
        names = np.array(mesh.node_names, dtype=object)
        s_ends = np.stack([mesh.s_start, mesh.s_start + mesh.L0], axis=1)  # (n_elem, 2) m
        coords["element"] = label("element", mesh.element_names, "element name")
        coords["end"] = label("end", ["i", "j"], "element end")
        coords["element_cable"] = label("element", np.array(mesh.cable_names, dtype=object)[
            mesh.cable_of_element], "cable of the element")
        coords["element_node"] = label(("element", "end"), names[mesh.conn],
                                        "node at the element end")
        coords["element_s"] = var(("element", "end"), s_ends, "m",
                                   "unstrained arc length of the element end along its cable")
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


def with_note(ds: xr.Dataset, text: str) -> xr.Dataset:
    """``ds`` with ``text`` added to its ``note`` attribute (advice on the result, joined by
    "; "); ``ds`` itself when ``text`` is empty."""
    if not text:
        return ds
    note = ds.attrs.get("note", "")
    return ds.assign_attrs(note=f"{note}; {text}" if note else text)


def static_dataset(mesh: Mesh, X: np.ndarray, tension: np.ndarray, reaction: np.ndarray,
                   attrs: dict, cables: dict | None = None) -> xr.Dataset:
    """One static step: positions (n_nodes, 3), tensions (n_elem, 2), reactions (n_nodes, 3).

    ``cables`` (from Model.cable_summary) adds per-cable end tensions, horizontal tension, sag.
    """
    d = ("node", "axis")
    ds = xr.Dataset(
        {
            "position": var(d, X, "m", "node position"),
            "displacement": var(d, X - mesh.X0, "m", "displacement from reference_position"),
            "reference_position": var(d, mesh.X0, "m",
                                       "meshed catenary under self-weight (reference)"),
            "tension": var(("element", "end"), tension, "N", "cable tension at element end"),
            "reaction": var(d, reaction, "N",
                             "force the support exerts on the cable (NaN where free)"),
        },
        coords=_coords(mesh),
        attrs=clean_attrs({"kind": "static", **attrs}),
    )
    if cables is not None:
        ds = ds.assign_coords(cable=label("cable", mesh.cable_names, "cable name"))
        ds["cable_end_tension"] = var(("cable", "end"), cables["end_tension"], "N",
                                       "tension at the cable's first (i) and last (j) end")
        ds["horizontal_tension"] = var("cable", cables["horizontal_tension"], "N",
                                        "horizontal tension at the cable's first end")
        ds["sag"] = var("cable", cables["sag"], "m",
                         "largest vertical distance from chord to cable")
        ds["unstrained_length"] = var("cable", cables["unstrained_length"], "m",
                                       "unstrained length L0 at the reference temperature")
    return ds


def modal_dataset(mesh: Mesh, frequency: np.ndarray, shape: np.ndarray, plane, symmetry,
                  attrs: dict) -> xr.Dataset:
    """Modal step: frequencies (n_modes,) Hz and shapes (n_modes, n_nodes, 3), unit maximum."""
    n = len(frequency)
    asked = int(attrs.get("modes_requested", n))
    if asked > n:  # a model with fewer free degrees of freedom than modes asked for
        attrs = {**attrs, "note": f"{asked} modes were asked for and the model has {n} (as "
                 "many as its free degrees of freedom): all of them are given"}
    coords = _coords(mesh)  # the elements too: the figures draw each cable through its ends
    coords["mode"] = xr.Variable("mode", np.arange(1, n + 1, dtype=np.int32),
                                 {"long_name": "mode number"})
    ds = xr.Dataset(
        {
            "frequency": var("mode", frequency, "Hz", "natural frequency"),
            "shape": var(("mode", "node", "axis"), shape, "1",
                          "mode shape (largest nodal displacement component = 1)"),
            "plane": label("mode", plane,
                            "in-plane or out-of-plane of the cable's plane through chord and sag "
                            "(single-span cables; else unclassified)"),
            "symmetry": label("mode", symmetry,
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
    coords["time"] = xr.Variable("time", np.asarray(time, float), TIME_ATTRS,
                                 encoding={"_FillValue": None})  # CF: none on coordinates
    X = np.asarray(X).reshape(len(time), mesh.X0.shape[0], 3)  # 0 outputs too: an early stop
    data = {
        "position": var(d, X, "m", "node position"),
        "displacement": var(d, X - mesh.X0[None], "m", "displacement from reference_position"),
        "velocity": var(d, np.asarray(V).reshape(X.shape), "m/s", "node velocity"),
        "acceleration": var(d, np.asarray(A).reshape(X.shape), "m/s2", "node acceleration"),
        "reference_position": var(("node", "axis"), mesh.X0, "m",
                                   "meshed catenary under self-weight (reference)"),
        "tension": var(("time", "element", "end"), tension, "N",
                        "cable tension at element end"),
        "reaction": var(d, reaction, "N",
                         "force the support exerts on the cable (NaN where free)"),
    }
    for key, (values, long_name) in energy.items():
        data[key] = var("time", values, "J", long_name)
    return xr.Dataset(data, coords=coords, attrs=clean_attrs({"kind": "transient", **attrs}))


def make_tree(case, groups: dict[str, xr.Dataset], status: str = "completed") -> xr.DataTree:
    """Root with provenance and one group per step, in step order.

    Every group also has ``Conventions``, ``history`` and a ``title``, so that a group written
    as a file of its own (``tree[name].to_dataset().to_netcdf(...)``) still declares them, and
    in water or on a seabed ``up``, ``water_surface``, ``water_depth``, ``seabed_z``
    (catdae.output.environment).
    """
    created = datetime.now(UTC).isoformat(timespec="seconds")
    given = ", ".join(f"{k} = {v!r}" for k, v in getattr(case, "overrides", ()))
    over = f" with {given} over the case file's" if given else ""
    history = f"{created} catdae {__version__}: run of case {case.name!r}{over} ({status})"
    root = xr.Dataset(attrs=clean_attrs({
        "title": case.title,
        "source": case.source,
        "case_toml": case.text,
        "case_name": case.name,
        "catdae_version": __version__,
        "created": created,
        "status": status,
        "Conventions": CONVENTIONS,
        "history": history,
        **({"overrides": given} if given else {}),  # case_toml with these re-runs the results
    }))
    env = environment_attrs(case)  # the water surface and seabed (figures, the VTK export)
    groups = {k: v.assign_attrs(Conventions=CONVENTIONS, history=history,
                                title=f"{case.title or case.name}: step {k}", **env)
              for k, v in groups.items()}
    return xr.DataTree.from_dict({"/": root, **{f"/{k}": v for k, v in groups.items()}})


def write_atomic(data: xr.DataTree | xr.Dataset, path: str | os.PathLike) -> Path:
    """Write netCDF-4 atomically: a temporary file beside the target (:func:`incomplete_name`),
    moved over it, so that a crash never leaves half a file and an existing file is only
    replaced by a complete one. Raises OSError when the file cannot be written."""
    path = Path(path)
    clean_stale(path.parent, path.name + ".")
    tmp = incomplete_name(path)
    no_fill_on_coordinates(data)
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
    """Open a results file fully into memory (the file is closed afterwards). ``time`` stays
    in seconds on the case's clock (not decoded to dates: see TIME_UNITS)."""
    with xr.open_datatree(path, engine="netcdf4", decode_times=False) as tree:
        tree = tree.load()
    return no_fill_on_coordinates(tree)  # written again, as CF asks


def no_fill_on_coordinates(data: xr.DataTree | xr.Dataset):
    """``data`` with no ``_FillValue`` on its float coordinate variables (CF §2.5.1; xarray
    gives them NaN: a sweep's values failed compliance-checker), set in their encoding."""
    nodes = data.subtree if isinstance(data, xr.DataTree) else [data]
    for node in nodes:
        for name in node.dims:
            if name in node.variables and node.variables[name].dtype.kind == "f":
                node.variables[name].encoding["_FillValue"] = None
    return data
