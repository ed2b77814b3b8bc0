"""Export of results for ParaView: VTK unstructured grids (``.vtu``, written by meshio), one per
output time, and a ``.pvd`` collection that ParaView opens as one time series.

Per step (static and transient; modal groups have no motion to animate):

    <folder>/<step>.pvd              the collection: one <DataSet timestep=t file=...> per time
    <folder>/<step>/<step>_00000.vtu node positions (points), elements (lines)

Point data: ``displacement`` (and ``velocity``, ``acceleration`` in transients) in m, m/s,
m/s²; cell data: ``tension_i``, ``tension_j`` (N, at the element's two ends) and
``tension`` (their mean). Node and element order are those of the results (``node``,
``element``), so point k is ``node[k]`` and cell e is ``element[e]``.

In water or on a seabed (the group's ``water_surface`` and ``seabed_z``,
catdae.output.environment) the collection has two more parts, planes normal to ``up`` over
the cables' horizontal extent (widened by 10 %, at least 1 m, on each side):

    <folder>/<step>/<step>_seabed.vtu         part 1: the seabed, one quad, at every time
    <folder>/<step>/<step>_water.vtu          part 2: the still-water level (no waves)
    <folder>/<step>/<step>_water_00000.vtu    part 2 with waves: a grid (about 10 points per
                                              shortest wave length, at most 101 a side) at the
                                              surface of each output time, point data
                                              ``elevation`` (m above the still level)

The waves come from the case in the results (the root's ``case_toml``); when it cannot be read
back (a table file no longer where it was), the still-water plane stands in for them.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from catdae._xr import xr
from catdae.errors import CatdaeError
from catdae.interrupts import deferred
from catdae.output import environment as env


class ExportError(CatdaeError):
    """Results that cannot be exported (no such step, no elements)."""


def _cells(ds: xr.Dataset, ends: str = "element_node") -> np.ndarray:
    """(n, 2) node indices of each element's (or connector's: connector_node) ends."""
    index = {str(n): k for k, n in enumerate(ds.node.values)}
    return np.vectorize(index.__getitem__, otypes=[np.int64])(ds[ends].values.astype(str))


def _blocks(ds: xr.Dataset, at: xr.Dataset) -> tuple[list, dict]:
    """The line cells (the elements, then the connectors: ``connector`` 1) with their cell data
    (a connector's tension is its ``connector_force``) of one time ``at`` of the step ds."""
    blocks, data = [], {"tension": [], "tension_i": [], "tension_j": [], "connector": []}
    if ds.sizes.get("element"):
        tens = at.tension.values  # (n_elem, 2) N
        blocks.append(("line", _cells(ds)))
        for key, v in (("tension", tens.mean(axis=1)), ("tension_i", tens[:, 0]),
                       ("tension_j", tens[:, 1]), ("connector", np.zeros(len(tens)))):
            data[key].append(v)
    if "connector_node" in ds.coords and ds.sizes.get("connector"):
        force = at.connector_force.values  # (n_connector,) N
        blocks.append(("line", _cells(ds, "connector_node")))
        for key in ("tension", "tension_i", "tension_j"):
            data[key].append(force)
        data["connector"].append(np.ones(len(force)))
    return blocks, data


def _write(f: Path, points, cells, **data) -> None:
    with deferred():  # a signal waits until the file is complete
        meshio.write(f, meshio.Mesh(points, cells, **data), file_format="vtu")


def _environment(ds: xr.Dataset, sub: Path, name: str, times, case) -> list[list[Path]]:
    """The seabed's and the water surface's files: per part, one file per time (or one for
    all)."""
    if "seabed_z" not in ds.attrs and "water_surface" not in ds.attrs:
        return []
    R = env.frame_of(ds)
    lo, hi = env.horizontal_extent(ds, R)
    parts = []
    if "seabed_z" in ds.attrs:
        xy, quads = env.grid(lo, hi, (2, 2))
        f = sub / f"{name}_seabed.vtu"
        _write(f, env.to_global(R, xy, float(ds.attrs["seabed_z"])), [("quad", quads)])
        parts.append([f])
    if "water_surface" in ds.attrs:
        h = float(ds.attrs["water_surface"])
        water = getattr(case, "water", None)
        if water is None or water.waves is None or "surface_elevation" not in ds:
            xy, quads = env.grid(lo, hi, (2, 2))
            f = sub / f"{name}_water.vtu"
            _write(f, env.to_global(R, xy, h), [("quad", quads)])
            parts.append([f])
        else:
            from catdae.model.fluid import elevation

            size = env.wave_grid_size(water.waves, case.gravity, water.depth, lo, hi)
            xy, quads = env.grid(lo, hi, size)
            eta = elevation(water.waves, case.gravity, water.depth, xy, times)
            files = []
            for k in range(len(times)):
                f = sub / f"{name}_water_{k:05d}.vtu"
                _write(f, env.to_global(R, xy, h + eta[k]), [("quad", quads)],
                       point_data={"elevation": eta[k]})
                files.append(f)
            parts.append(files)
    return parts


def _case_of(tree: xr.DataTree):
    """The case in the results' root (for its waves), or None when it cannot be read back."""
    from catdae.case import load_case

    text = tree.attrs.get("case_toml")
    if not text:
        return None
    try:
        return load_case(str(text), name=str(tree.attrs.get("case_name", "case")))
    except (CatdaeError, OSError, ValueError):
        return None


def write_step(ds: xr.Dataset, folder: str | os.PathLike, name: str, case=None) -> Path:
    """One step's time series: the ``.vtu`` files and the ``.pvd`` collection; returns the
    collection's path. ``case`` (its waves) draws the water surface of each time."""
    from catdae.output.reading import step_problem

    if (why := step_problem(ds)) is not None:
        raise ExportError(f"step {name[:60]!r}: {why}")
    if "element_node" not in ds.coords or ds.attrs.get("kind") not in ("static", "transient"):
        raise ExportError(f"step {name!r} has no cable positions to export (a "
                          f"{ds.attrs.get('kind')} step: static and transient steps are)")
    folder = Path(folder)
    sub = folder / name
    sub.mkdir(parents=True, exist_ok=True)
    times = ds.time.values if "time" in ds.dims else np.array([float(ds.attrs.get("t", 0.0))])
    point_vars = [v for v in ("displacement", "velocity", "acceleration") if v in ds]
    files = []
    for k in range(times.size):
        at = ds.isel(time=k) if "time" in ds.dims else ds
        cells, cell_data = _blocks(ds, at)
        f = sub / f"{name}_{k:05d}.vtu"
        _write(f, at.position.values, cells, point_data={v: at[v].values for v in point_vars},
               cell_data=cell_data)
        files.append(f)
    # part 0 the cables; parts 1, 2 the seabed and the water surface (one file, or one a time)
    parts = [files, *_environment(ds, sub, name, times, case)]
    entries = [f'    <DataSet timestep="{float(t)!r}" part="{p}" '
               f'file={quoteattr(fs[min(k, len(fs) - 1)].relative_to(folder).as_posix())}/>'
               for k, t in enumerate(times) for p, fs in enumerate(parts)]
    _drop_stale(sub, name, {f for fs in parts for f in fs})
    pvd = folder / f"{name}.pvd"
    status = str(ds.attrs.get("status", "completed"))
    said = ("" if status == "completed" else  # a comment may not hold "--"
            f"  <!-- step not completed: {status.replace('--', '- -')} -->\n")
    with deferred():
        pvd.write_text('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
                       + said + "  <Collection>\n" + "\n".join(entries)
                       + "\n  </Collection>\n</VTKFile>\n")
    return pvd


def _drop_stale(sub: Path, name: str, written: set[Path]) -> None:
    """Remove the files of an earlier export of the same step that this one did not write (a
    longer run's later times): ParaView's grouping of numbered files would mix them in. Only
    files named as this export names them (``<name>_00012.vtu``, ``<name>_water_00012.vtu``,
    ``<name>_seabed.vtu``) in the step's own folder."""
    pattern = re.compile(re.escape(name) + r"_((water_)?\d{5}|seabed)\.vtu")
    for f in sub.glob("*.vtu"):
        if f not in written and pattern.fullmatch(f.name):
            f.unlink(missing_ok=True)


def write_vtk(tree: xr.DataTree, folder: str | os.PathLike, steps=None) -> list[Path]:
    """Every static and transient step of a results tree (or the named ones) as VTK time
    series in ``folder``; returns the ``.pvd`` collections written."""
    names = list(steps) if steps else [n for n in tree.children if tree[n].to_dataset().attrs
                                       .get("kind") in ("static", "transient")]
    unknown = [s for s in names if s not in tree.children]
    if unknown:
        raise ExportError(f"no step {unknown[0]!r} in the results (steps: "
                          f"{', '.join(tree.children)})")
    Path(folder).mkdir(parents=True, exist_ok=True)
    waves = any("surface_elevation" in tree[n].to_dataset() for n in names)
    case = _case_of(tree) if waves else None
    from catdae.output.reading import step_problem, step_values

    written = []
    for group in names:  # a swept step: a series per value, <step>-sweep<k>
        full = tree[group].to_dataset()
        if (why := step_problem(full)) is not None:
            raise ExportError(f"step {group[:60]!r}: {why}")
        written += [write_step(ds, folder, name, case)
                    for name, ds in step_values(group, full)]
    return written
