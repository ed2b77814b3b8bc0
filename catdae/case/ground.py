"""``[ground]`` of a case: a height, or a ground profile, below the cables, for the clearance
results (docs/case-format.md, "Line engineering"). Under a gravity vector heights are along up
(= -g) and a profile's stations along the gravity frame's first horizontal axis e1. A builder
pass (a mixin of :class:`~catdae.case.build.Builder`) and the frozen :class:`Ground` it makes."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from pydantic import BaseModel

from catdae.case.schema import STRICT


class _GroundTable(BaseModel):
    model_config = STRICT
    elevation: float | None = None  # m: a level ground (or a height to keep clear of)
    x: list[float] | None = None  # m: a profile, the ground's height z at these x
    z: list[float] | None = None


@dataclass(frozen=True)
class Ground:
    """A level ground at ``elevation`` (m, along -gravity), or a profile: height ``z`` (m, along
    up = -gravity) at the stations ``x`` (m, strictly increasing), linear between points, held
    beyond the ends. A station is the point's coordinate along e1, the gravity frame's first
    horizontal axis (catdae.case.frame.gravity_rotation, its first row: +x with gravity along
    -z), so the profile is the section of the ground along e1, the same at every e2."""

    elevation: float | None = None
    x: tuple[float, ...] = ()
    z: tuple[float, ...] = ()

    def height(self, x) -> np.ndarray:
        """The ground's height below the points at the stations ``x`` (along e1), m."""
        if self.elevation is not None:
            return np.full(np.shape(x), self.elevation)
        return np.interp(x, self.x, self.z)

    def gap(self, points, R=None) -> np.ndarray:
        """Height of the points (..., 3) (global axes) above the ground, m; ``R`` the gravity
        frame's rotation (local = R global; None: gravity along -z)."""
        local = np.asarray(points, float) if R is None else np.asarray(points, float) @ R.T
        return local[..., 2] - self.height(local[..., 0])


class GroundPass:
    """``[ground]`` (methods of ``_Builder``)."""

    def ground(self, raw: Any) -> Ground | None:
        if raw is None:
            return None
        where = ("ground",)
        v, complete = self.validate(_GroundTable, raw, where)
        if v is None or not complete:
            return None
        profile = v.x is not None or v.z is not None
        if (v.elevation is None) == (not profile):
            self.problem(where, "give either elevation = <m> (a level ground or a height), or a "
                         "profile x = [...] and z = [...] (m), not both and not neither")
            return None
        if v.elevation is not None:
            if not math.isfinite(v.elevation):
                self.problem(where + ("elevation",), f"expected a finite number, found "
                             f"{v.elevation}")
                return None
            return Ground(elevation=float(v.elevation))
        ok = True
        for key in ("x", "z"):
            if getattr(v, key) is None:
                self.problem(where + (key,), "missing: a ground profile needs x = [...] and "
                             "z = [...] of the same length")
                ok = False
        if not ok:
            return None
        x, z = np.asarray(v.x, float), np.asarray(v.z, float)
        if x.size != z.size or x.size < 2:
            self.problem(where, f"expected x and z of the same length, at least 2, found "
                         f"{x.size} and {z.size}")
            return None
        if not (np.isfinite(x).all() and np.isfinite(z).all()):
            self.problem(where, "expected finite numbers in x and z")
            return None
        if not (np.diff(x) > 0).all():
            self.problem(where + ("x",), "expected strictly increasing x")
            return None
        return Ground(x=tuple(map(float, x)), z=tuple(map(float, z)))
