"""Result variables of a transient step in water or air (docs/case-format.md, "Water and air"):
the water surface above the nodes and the fluid velocity at them."""

from __future__ import annotations

import numpy as np

from catdae._xr import xr
from catdae.model.fluid import Fluid
from catdae.output.results import var


def with_fluid(ds: xr.Dataset, fluid: Fluid, times: np.ndarray, X: np.ndarray) -> xr.Dataset:
    """``ds`` with ``fluid_velocity``(time, node, axis) and, when there are waves,
    ``surface_elevation``(time, node); ``X`` (time, node, 3) the node positions."""
    eta = np.full(X.shape[:2], np.nan)
    vel = np.full(X.shape, np.nan)
    for k, t in enumerate(times):
        if np.all(np.isfinite(X[k])):
            eta[k], vel[k] = fluid.kinematics(X[k], float(t))
    out = ds.copy()
    if fluid.water is not None:
        out.attrs["water_surface"] = float(fluid.surface)  # m, z of the still-water level
    out["fluid_velocity"] = var(("time", "node", "axis"), vel, "m/s",
                                 "velocity of the water (below the surface) or the air at the node")
    if fluid.waves is not None:
        out["surface_elevation"] = var(("time", "node"), eta, "m",
                                         "elevation of the water surface above the still-water "
                                         "level at the node's (x, y)")
    return out
