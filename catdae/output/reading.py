"""Reading a results file for ``catdae plot`` and ``export``: judged to be one that catdae wrote
(case-format.md, "Results") before any figure or export is made from it."""

from __future__ import annotations

import os
from pathlib import Path

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
    for name, dims in {"node": ("node",), "axis": ("axis",), **_NEEDS[kind]}.items():
        if name not in names:
            return f"a {kind} step without the variable {name!r}"
        if tuple(ds[name].dims) != dims:
            return (f"its variable {name!r} has dimensions {tuple(ds[name].dims)}, expected "
                    f"{dims}")
        want_text = name in _LABELS
        if want_text != (ds[name].dtype.kind in "OUS"):
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


def read_results_file(path: str | os.PathLike) -> xr.DataTree:
    """A results file for ``catdae plot`` and ``export``: read, and judged to be catdae's
    (at least one step group, each with the variables of its kind). Raises ResultsError
    ("cannot read ...") for a missing, empty, truncated, corrupted or foreign file."""
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
    if not tree.children:
        raise ResultsError(f"cannot read {path}: it holds no step results (no groups; is it "
                           "a file written by catdae run?)")
    for name, node in tree.children.items():
        why = step_problem(node.to_dataset())
        if why is not None:
            raise ResultsError(f"cannot read {path}: group {name[:60]!r}: {why} (not a "
                               "catdae results file, or a half-written one)")
    return tree
