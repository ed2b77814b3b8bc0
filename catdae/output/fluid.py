"""Result variables of a step in water or air (docs/case-format.md, "Water and air"): the
water surface above the nodes and the fluid velocity at them."""

from __future__ import annotations

import numpy as np

from catdae._xr import xr
from catdae.element.fluid_kinematics import NONE
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


def with_static_fluid(ds: xr.Dataset, fluid: Fluid | None, X: np.ndarray, t: float) -> xr.Dataset:
    """A static group with ``fluid_velocity``(node, axis) of the still water (the current) or
    the air (the wind) at the nodes, as the step saw it (no waves), when there is a current or
    a wind; ``X`` (n_nodes, 3) in the group's node order."""
    if fluid is None or (fluid.c_kind == NONE and fluid.a_kind == NONE):
        return ds
    vel = fluid.kinematics(np.asarray(X, float).reshape(-1, 3), float(t), waves=False)[1]
    out = ds.copy()
    out["fluid_velocity"] = var(("node", "axis"), vel, "m/s", "velocity of the still water "
                                 "(below the surface) or the air at the node")
    return out


EFFECTIVE = ("effective tension, as everywhere in water: the wall tension is T_wall = T - p A, "
             "p the water pressure at that depth (docs/case-format.md, Effective tension)")
EFFECTIVE_REACTION = ("in water, the force of the effective tension at the support: the line's "
                      "wall force on it differs by p A along the line there, p the water "
                      "pressure at that depth (docs/case-format.md, Effective tension)")


def effective_tension(ds: xr.Dataset, in_water: bool) -> xr.Dataset:
    """``ds`` with its tensions (N) named effective where the case has water: the catenary of
    the submerged weight carries the effective tension, not the wall tension (theory §13.1);
    its reactions (N) say they are the effective tension's force."""
    if not in_water:
        return ds
    out = ds.copy()
    for name, v in out.data_vars.items():
        if "tension" in str(name) and v.attrs.get("units") == "N":
            text = str(v.attrs.get("long_name", name))
            text = (text.replace("cable tension", "effective cable tension", 1)
                    if "cable tension" in text else text.replace("tension", "effective tension", 1))
            out[name].attrs.update(long_name=text, comment=EFFECTIVE)
        elif str(name).startswith("reaction") and v.attrs.get("units") == "N":
            out[name].attrs.update(comment=EFFECTIVE_REACTION)
    return out
