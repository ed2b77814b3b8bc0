"""The frozen fluids of a scene: ``[water]`` (density, still-water level, depth, current, waves)
and ``[air]`` (density, wind). Built and checked by ``build_fluid``; used by
``catdae.model.fluid`` (docs/case-format.md, "Water and air"; docs/theory.md §13)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from catdae.case.timefunc import TimeFunction

# defaults of the line's fluid coefficients when a material gives its diameter alone
DRAG_NORMAL = 1.2
DRAG_AXIAL = 0.008
ADDED_MASS_NORMAL = 1.0
ADDED_MASS_AXIAL = 0.0


def line_fluid(m) -> dict[str, float]:
    """The fluid fields of a validated material ``m`` (schema ``_Material``): those given, the
    defaults above for the coefficients of a line with a diameter, zeros without one."""
    d = m.diameter
    if d is None:
        return {}
    given = {"drag_normal": m.drag_normal, "drag_axial": m.drag_axial,
             "added_mass_normal": m.added_mass_normal, "added_mass_axial": m.added_mass_axial}
    default = {"drag_normal": DRAG_NORMAL, "drag_axial": DRAG_AXIAL,
               "added_mass_normal": ADDED_MASS_NORMAL, "added_mass_axial": ADDED_MASS_AXIAL}
    out = {k: float(default[k] if v is None else v) for k, v in given.items()}
    out["diameter"] = float(d)
    return out


@dataclass(frozen=True)
class Current:
    """A current (or a uniform wind): ``velocity`` (m/s, global axes) at the heights ``z``
    (m, increasing; linear in between, constant beyond), or one velocity everywhere when ``z``
    is empty; times the time function ``time`` (``None``: 1)."""

    z: tuple[float, ...]
    velocity: tuple[tuple[float, float, float], ...]
    time: TimeFunction | None = None


@dataclass(frozen=True)
class Waves:
    """Long-crested waves travelling along ``heading`` (deg from +x towards +y).

    ``kind = "airy"``: one regular wave of ``height`` (m, crest to trough) and ``period`` (s),
    ``phase`` (deg). ``kind = "jonswap"``: ``components`` regular waves whose amplitudes sample
    a JONSWAP spectrum of significant height ``hs``, peak period ``tp`` and peak enhancement
    ``gamma``, with random phases drawn from ``seed``. ``ramp`` (s): the kinematics rise
    smoothly from 0 over the first ``ramp`` seconds.
    """

    kind: str
    height: float = 0.0
    period: float = 0.0
    heading: float = 0.0
    phase: float = 0.0
    ramp: float = 0.0
    hs: float = 0.0
    tp: float = 0.0
    gamma: float = 3.3
    seed: int = 0
    components: int = 100


@dataclass(frozen=True)
class Water:
    """Water around the cables: ``density`` (kg/m³), still-water level ``surface`` (z, m),
    ``depth`` (m below the surface, ``inf`` for deep water), ``current`` and ``waves``."""

    density: float = 1025.0
    surface: float = 0.0
    depth: float = math.inf
    current: Current | None = None
    waves: Waves | None = None


@dataclass(frozen=True)
class Wind:
    """A wind: ``profile`` "uniform" (``vector`` everywhere), "power" (``vector`` at the
    ``reference_height`` above ``ground``, times (height / reference_height)^``parameter``) or
    "log" (times ln(height / z0) / ln(reference_height / z0), ``parameter`` = z0), zero at and
    below the ground; times the time function ``time``. ``ground`` ``None``: the water surface,
    or z = 0 without water."""

    profile: str
    vector: tuple[float, float, float]
    parameter: float = 0.0
    reference_height: float = 10.0
    ground: float | None = None
    time: TimeFunction | None = None


@dataclass(frozen=True)
class Air:
    """Air around the cables (above the water surface if there is water)."""

    density: float = 1.225
    wind: Wind | None = None
