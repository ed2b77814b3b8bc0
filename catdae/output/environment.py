"""The water surface and the seabed around the cables, for the figures and the ParaView export
(docs/case-format.md, "Water and air" and "Seabed").

Every step group of a scene with ``[water]`` or ``[seabed]`` carries the attributes
``up`` (the unit vector against gravity), ``water_surface`` (m, the height of the still-water
level along ``up``), ``water_depth`` (m, with a finite depth) and ``seabed_z`` (m, the height of
the seabed along ``up``) (:func:`environment_attrs`); with a gravity vector not along -z, every
group carries ``up`` even without water or seabed. The planes are drawn in the gravity frame
(catdae.case.frame: z along ``up``) over the horizontal extent of the cables, and turned back
into the case's axes; so is the profile figure under a gravity vector (:func:`drawing_frame`).
"""

from __future__ import annotations

import math

import numpy as np

from catdae._xr import xr
from catdae.case.frame import gravity_rotation

MARGIN = 0.1  # share of the cables' horizontal extent added on each side of a plane (>= 1 m)
MAX_SIDE = 101  # points per side of a water-surface grid at most


def environment_attrs(case) -> dict:
    """The attributes of every step group of ``case`` (module docstring); {} without water and
    seabed."""
    up = np.array([-float(g) for g in case.gravity_direction]) + 0.0  # + 0.0: no "-0"
    if case.water is None and case.seabed is None:
        # a gravity vector alone: ``up``, so that the profile figure draws heights upwards
        return {} if np.array_equal(up, (0.0, 0.0, 1.0)) else {"up": up}
    out = {"up": up}
    if case.water is not None:
        out["water_surface"] = float(case.water.surface)
        if math.isfinite(case.water.depth):
            out["water_depth"] = float(case.water.depth)
    if case.seabed is not None:
        out["seabed_z"] = float(case.seabed.z)
    return out


def frame_of(ds: xr.Dataset) -> np.ndarray:
    """The rotation R (local = R global) of the group's gravity frame (identity: z up)."""
    up = np.asarray(ds.attrs.get("up", (0.0, 0.0, 1.0)), float).reshape(3)
    return gravity_rotation(-up)


def horizontal_extent(ds: xr.Dataset, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(low (2,), high (2,)): the box in the gravity frame's x-y plane that holds every node at
    every stored time, widened by ``MARGIN`` of its largest side (at least 1 m) on each side."""
    pos = np.asarray(ds.position.transpose(..., "axis").values, float).reshape(-1, 3)
    local = pos[np.all(np.isfinite(pos), axis=1)] @ R.T
    lo, hi = local[:, :2].min(axis=0), local[:, :2].max(axis=0)
    pad = max(MARGIN * float((hi - lo).max()), 1.0)
    return lo - pad, hi + pad


def grid(lo, hi, n: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """(points (nx ny, 2) of a regular grid over [lo, hi], quads (nx-1)(ny-1), 4) of indices,
    counter-clockwise seen from above)."""
    xs, ys = np.linspace(lo[0], hi[0], n[0]), np.linspace(lo[1], hi[1], n[1])
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    pts = np.column_stack([X.ravel(), Y.ravel()])
    i, j = np.meshgrid(np.arange(n[0] - 1), np.arange(n[1] - 1), indexing="ij")
    a = (i * n[1] + j).ravel()
    quads = np.column_stack([a, a + n[1], a + n[1] + 1, a + 1]).astype(np.int64)
    return pts, quads


def to_global(R: np.ndarray, xy: np.ndarray, height) -> np.ndarray:
    """Points of the gravity frame (x, y, height) in the case's axes, (n, 3)."""
    local = np.column_stack([xy, np.broadcast_to(np.asarray(height, float), (xy.shape[0],))])
    return local @ R


def wave_grid_size(waves, g: float, depth: float, lo, hi) -> tuple[int, int]:
    """Points per side of a water-surface grid: about 10 per shortest wave length, at most
    ``MAX_SIDE``, at least 2."""
    from catdae.model.fluid import wave_components

    k = float(np.max(wave_components(waves, g, depth)[2]))
    step = 2.0 * math.pi / k / 10.0
    return tuple(int(min(MAX_SIDE, max(2, math.ceil((h - low) / step) + 1)))
                 for low, h in zip(lo, hi, strict=True))


def drawing_frame(ds: xr.Dataset) -> np.ndarray | None:
    """The rotation R (local = R global) in which the profile figure draws the group: its
    gravity frame (x, y horizontal, z along ``up``) when ``up`` is not +z; None when it is (the
    case's own axes, as they are)."""
    up = np.asarray(ds.attrs.get("up", (0.0, 0.0, 1.0)), float).reshape(-1)
    if up.size != 3 or np.allclose(up, (0.0, 0.0, 1.0), rtol=0, atol=1e-12):
        return None
    return frame_of(ds)


def axis_names(R: np.ndarray | None) -> tuple[str, str, str]:
    """How the profile figure names its three directions: the case's x, y, z, or in the
    gravity frame the two horizontal unit vectors and the height along up, in global axes."""
    if R is None:
        return "x", "y", "z"

    def vec(v):
        return "(" + ", ".join(f"{float(c) + 0.0:.4g}" for c in v) + ")"

    return (f"along e1 = {vec(R[0])}", f"along e2 = {vec(R[1])}",
            f"height along up = {vec(R[2])}")


def still_levels(ax, ds: xr.Dataset) -> None:
    """The seabed (solid) and the still-water level (dotted) across the elevation, when the
    group has them. The elevation's vertical is the height along ``up`` in any frame
    (:func:`drawing_frame`), so both are horizontal lines at their heights."""
    if "seabed_z" in ds.attrs:
        ax.axhline(float(ds.attrs["seabed_z"]), color="saddlebrown", lw=1.2, label="seabed",
                   gid="seabed")
    if "water_surface" in ds.attrs:
        ax.axhline(float(ds.attrs["water_surface"]), color="tab:blue", ls=":", lw=1.0,
                   label="still-water level", gid="still water")
