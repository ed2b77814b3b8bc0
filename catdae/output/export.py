"""Export of results for ParaView: VTK unstructured grids (``.vtu``, written by meshio), one per
output time, and a ``.pvd`` collection that ParaView opens as one time series.

Per step (static and transient; modal groups have no motion to animate):

    <folder>/<step>.pvd              the collection: one <DataSet timestep=t file=...> per time
    <folder>/<step>/<step>_00000.vtu node positions (points), elements (lines)

Point data: ``displacement`` (and ``velocity``, ``acceleration`` in transients) in m, m/s,
m/s²; cell data: ``tension_i``, ``tension_j`` (N, at the element's two ends) and
``tension`` (their mean). Node and element order are those of the results (``node``,
``element``), so point k is ``node[k]`` and cell e is ``element[e]``.
"""

from __future__ import annotations

import os
from pathlib import Path
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from catdae._xr import xr
from catdae.errors import CatdaeError
from catdae.interrupts import deferred


class ExportError(CatdaeError):
    """Results that cannot be exported (no such step, no elements)."""


def _cells(ds: xr.Dataset) -> np.ndarray:
    """(n_elem, 2) node indices of each element's ends, from element_node."""
    index = {str(n): k for k, n in enumerate(ds.node.values)}
    return np.vectorize(index.__getitem__, otypes=[np.int64])(ds.element_node.values.astype(str))


def write_step(ds: xr.Dataset, folder: str | os.PathLike, name: str) -> Path:
    """One step's time series: the ``.vtu`` files and the ``.pvd`` collection; returns the
    collection's path."""
    from catdae.output.reading import step_problem

    if (why := step_problem(ds)) is not None:
        raise ExportError(f"step {name[:60]!r}: {why}")
    if "element_node" not in ds.coords:
        raise ExportError(f"step {name!r} has no elements to export (a {ds.attrs.get('kind')} "
                          "step)")
    folder = Path(folder)
    sub = folder / name
    sub.mkdir(parents=True, exist_ok=True)
    cells = [("line", _cells(ds))]
    times = ds.time.values if "time" in ds.dims else np.array([float(ds.attrs.get("t", 0.0))])
    point_vars = [v for v in ("displacement", "velocity", "acceleration") if v in ds]
    entries = []
    for k, t in enumerate(times):
        at = ds.isel(time=k) if "time" in ds.dims else ds
        tens = at.tension.values  # (n_elem, 2) N
        mesh = meshio.Mesh(
            at.position.values,
            cells,
            point_data={v: at[v].values for v in point_vars},
            cell_data={"tension": [tens.mean(axis=1)], "tension_i": [tens[:, 0]],
                       "tension_j": [tens[:, 1]]},
        )
        f = sub / f"{name}_{k:05d}.vtu"
        with deferred():  # a signal waits until the file is complete
            meshio.write(f, mesh, file_format="vtu")
        entries.append(f'    <DataSet timestep="{float(t)!r}" part="0" '
                       f'file={quoteattr(f.relative_to(folder).as_posix())}/>')
    pvd = folder / f"{name}.pvd"
    with deferred():
        pvd.write_text('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
                       "  <Collection>\n" + "\n".join(entries)
                       + "\n  </Collection>\n</VTKFile>\n")
    return pvd


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
    return [write_step(tree[n].to_dataset(), folder, n) for n in names]
