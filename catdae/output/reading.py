"""Reading a results file for ``catdae plot`` and ``export``: judged to be one that catdae wrote
(case-format.md, "Results") before any figure or export is made from it."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from catdae._xr import xr
from catdae.errors import ResultsError
from catdae.model.mesh import AXES
from catdae.output.results import read_tree

_NEEDS = {  # what each kind of step group holds (name -> dims), as the readers use it
    "static": {"position": ("node", "axis"), "displacement": ("node", "axis"),
               "tension": ("element", "end"), "reaction": ("node", "axis"),
               "element_node": ("element", "end"), "element_cable": ("element",),
               "element_s": ("element", "end")},
    "transient": {"time": ("time",), "position": ("time", "node", "axis"),
                  "displacement": ("time", "node", "axis"),
                  "velocity": ("time", "node", "axis"),
                  "acceleration": ("time", "node", "axis"),
                  "tension": ("time", "element", "end"),
                  "reaction": ("time", "node", "axis"),
                  "element_node": ("element", "end"), "element_cable": ("element",),
                  "element_s": ("element", "end")},
    "modal": {"frequency": ("mode",), "shape": ("mode", "node", "axis"),
              "node_cable": ("node",), "s": ("node",)},
}
_LABELS = ("node", "axis", "element_node", "element_cable", "node_cable")


def step_problem(ds: xr.Dataset) -> str | None:
    """Why a group is not a step of a catdae results file (a foreign or half-written file), or
    None: its ``kind`` and the variables and dimensions of that kind (case-format.md,
    "Results"), numbers where numbers are expected, element ends that are nodes."""
    kind = ds.attrs.get("kind")
    if kind not in _NEEDS:
        return (f"it has no kind of step (static, modal or transient; found {kind!r})"
                if kind is not None else "it is not a catdae step (no attribute 'kind')")
    names = set(ds.variables)
    swept = "sweep" in ds.dims  # a swept step: its values along a leading sweep dimension
    for name, dims in {"node": ("node",), "axis": ("axis",), **_NEEDS[kind]}.items():
        if name not in names:
            return f"a {kind} step without the variable {name!r}"
        found = tuple(ds[name].dims)
        if found != dims and not (swept and name not in _LABELS and found == ("sweep", *dims)):
            return (f"its variable {name!r} has dimensions {found}, expected "
                    f"{('sweep', *dims) if swept and name not in _LABELS else dims}")
        want_text = name in _LABELS
        # an empty label (a scene of connectors alone has no element) is stored as numbers
        if ds[name].size and want_text != (ds[name].dtype.kind in "OUS"):
            return f"its variable {name!r} holds {'numbers' if want_text else 'text'}"
    if list(map(str, ds.axis.values)) != list(AXES):
        return f"its axes are {list(map(str, ds.axis.values))}, expected {list(AXES)}"
    if ds.sizes["node"] == 0:
        return "it holds no nodes"
    if "element_node" in names:
        missing = set(map(str, ds.element_node.values.ravel())) - set(map(str, ds.node.values))
        if missing:
            return f"an element ends at {sorted(missing)[0][:40]!r}, which is not a node"
    return None


def step_values(name: str, ds: xr.Dataset) -> list[tuple[str, xr.Dataset]]:
    """A step group's datasets, each of one state of the scene: the group itself, or for a
    swept step one per value (``<name>-sweep<k>``, k from 0), with the attributes of that
    value: those listed in ``sweep_attributes`` (catdae.analysis: they differ between the
    values) are arrays over the values or their texts joined by " | "."""
    if "sweep" not in ds.dims:
        return [(name, ds)]
    n = ds.sizes["sweep"]
    listed = ds.attrs.get("sweep_attributes")
    varying = set(str(listed).split()) if listed is not None else None
    out = []
    for k in range(n):
        one = ds.isel(sweep=k)
        one.attrs = {key: _value_attr(v, k, n) if varying is None or key in varying else v
                     for key, v in ds.attrs.items()}
        value = f"{ds.attrs.get('sweep_field', 'sweep')} = {float(ds.sweep[k]):.6g}"
        one.attrs["title"] = f"{ds.attrs.get('title', '')} ({name}: {value})".strip()
        one.attrs["sweep_value"] = value
        out.append((f"{name}-sweep{k}", one))
    return out


def cable_paths(ds: xr.Dataset) -> dict[str, list[str]]:
    """Node labels of each cable from its first end to its last (from element_node)."""
    paths = {}
    for cab in dict.fromkeys(str(c) for c in ds.element_cable.values):
        nodes = ds.element_node.values[ds.element_cable.values == cab]  # (n, 2), in order
        paths[cab] = [str(n) for n in nodes[:, 0]] + [str(nodes[-1, 1])]
    return paths


def join_values(groups: list[xr.Dataset]) -> tuple[xr.Dataset, list[str]]:
    """The groups of a sweep's values as one along ``sweep`` (the inverse of
    :func:`step_values`): attributes that differ between the values, or that some lack, become
    arrays over them (numbers) or their texts joined by " | ". Returns (dataset, those
    attributes' names)."""
    ds = xr.concat(groups, dim="sweep", combine_attrs="drop_conflicts")
    varying = sorted(k for k in {k for g in groups for k in g.attrs} if k not in ds.attrs  # differ
                     or any(k not in g.attrs for g in groups))  # by value, or some lack them
    for key in varying:
        values = [g.attrs.get(key, "") for g in groups]
        numbers = all(isinstance(v, int | float | np.number) for v in values)
        ds.attrs[key] = np.array(values) if numbers else " | ".join(map(str, values))
    return ds, varying


def per_value(ds: xr.Dataset, fn) -> xr.Dataset:
    """``fn`` of a step's group, or of each value of a swept one (with that value's
    attributes), joined again: the engineering results of a swept transient (they failed on
    the sweep dimension: an independent tester's swept load and damper)."""
    if "sweep" not in ds.dims:
        return fn(ds)
    parts = []
    for _, one in step_values("", ds):
        one.attrs.pop("sweep_value", None)
        one.attrs.pop("title", None)  # step_values's per-value title: the group's own kept
        if "title" in ds.attrs:
            one.attrs["title"] = ds.attrs["title"]
        parts.append(fn(one))
    out, varying = join_values(parts)
    listed = set(str(ds.attrs.get("sweep_attributes", "")).split())
    return out.assign_attrs(sweep_field=ds.attrs.get("sweep_field", ""),
                            sweep_attributes=" ".join(sorted(listed | set(varying))))


def _value_attr(v, k: int, n: int):
    """The k-th value's attribute of a swept step's attribute ``v`` (n values)."""
    if np.ndim(v) == 1 and len(v) == n:
        return v[k]
    if isinstance(v, str) and v.count(" | ") == n - 1:
        return v.split(" | ")[k]
    return v


def read_results_file(path: str | os.PathLike, steps: bool = True) -> xr.DataTree:
    """A results file for ``catdae plot`` and ``export``: read, and judged to be catdae's (at
    least one step group, each with the variables of its kind; with ``steps`` False a file of
    catdae's without any, from a run that failed before its first step, is returned). Raises
    ResultsError ("cannot read ...") for a missing, empty, truncated, corrupted or foreign
    file."""
    path = Path(path)
    if not path.is_file():
        why = "no such file" if not path.exists() else "not a regular file"
        raise ResultsError(f"cannot read {path}: {why}")
    try:
        tree = read_tree(path)
    except MemoryError:
        raise
    except Exception as exc:  # noqa: BLE001 - the netCDF/HDF5 libraries raise many kinds
        why = str(exc).splitlines()[0][:200] if str(exc) else type(exc).__name__
        raise ResultsError(f"cannot read {path}: not a readable netCDF-4 results file "
                           f"({why})") from None
    if not tree.children and not steps and "catdae_version" in tree.attrs:
        return tree  # a run that failed before its first step: its status, no step results
    if not tree.children:
        raise ResultsError(f"cannot read {path}: it holds no step results (no groups; is it "
                           "a file written by catdae run?)")
    for name, node in tree.children.items():
        why = step_problem(node.to_dataset())
        if why is not None:
            raise ResultsError(f"cannot read {path}: group {name[:60]!r}: {why} (not a "
                               "catdae results file, or a half-written one)")
    return tree


def ratio_text(zeta, fmt: str = ".4g") -> str:
    """A damping ratio as printed: the round-off of an undamped mode (|ζ| < 1e-12, e.g.
    -5.6e-15, which would read as an instability) as 0."""
    zeta = float(zeta)
    return "0" if abs(zeta) < 1e-12 else format(zeta, fmt)
