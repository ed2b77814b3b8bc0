"""Pass 3 for the fluids around the cables: ``[water]`` and ``[air]`` (docs/case-format.md,
"Water and air"). A mixin of :class:`~catdae.case.build.Builder`, whose ``problem``,
``validate`` and ``time_function`` collect what is wrong."""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import BaseModel, Field

from catdae.case.fluid import Air, Current, Water, Waves, Wind
from catdae.case.frame import gravity_rotation
from catdae.case.messages import found_text
from catdae.case.schema import STRICT, VEC3, NonNeg, Pos, TomlTable, Vec3

_Angle = Annotated[float, Field(ge=-360.0, le=360.0)]


class _Water(BaseModel):
    model_config = STRICT
    density: Pos = 1025.0
    surface: float = 0.0
    depth: Pos | None = None
    current: Any = None  # a vector, or a profile table: checked by the builder
    waves: TomlTable | None = None


class _Air(BaseModel):
    model_config = STRICT
    density: Pos = 1.225
    wind: Any = None  # a vector, or a profile table: checked by the builder


class _Profile(BaseModel):
    model_config = STRICT
    z: Annotated[list[float], Field(min_length=1)]
    velocity: Annotated[list[Vec3], Field(min_length=1)]
    time: TomlTable | None = None


class _UniformFlow(BaseModel):
    model_config = STRICT
    velocity: Vec3
    time: TomlTable | None = None


class _WindProfile(BaseModel):
    model_config = STRICT
    speed: NonNeg
    direction: _Angle = 0.0
    profile: Literal["power", "log", "uniform"] = "uniform"
    exponent: NonNeg | None = None
    roughness: Pos | None = None
    reference_height: Pos = 10.0
    ground: float | None = None
    time: TomlTable | None = None


class _Airy(BaseModel):
    model_config = STRICT
    kind: Literal["airy"]
    height: Pos
    period: Pos
    heading: _Angle = 0.0
    phase: _Angle = 0.0
    ramp: NonNeg = 0.0


class _Jonswap(BaseModel):
    model_config = STRICT
    kind: Literal["jonswap"]
    hs: Pos
    tp: Pos
    gamma: Annotated[float, Field(ge=1.0, le=20.0)] = 3.3
    seed: Annotated[int, Field(ge=0)] = 0
    components: Annotated[int, Field(ge=1, le=2000)] = 100
    heading: _Angle = 0.0
    ramp: NonNeg = 0.0


_WAVE_MODELS: dict[str, type[BaseModel]] = {"airy": _Airy, "jonswap": _Jonswap}


class FluidPass:
    """``[water]`` and ``[air]`` (methods of ``_Builder``)."""

    def water(self, raw: dict | None) -> Water | None:
        if raw is None:
            return None
        where = ("water",)
        if not isinstance(raw, dict):
            self.problem(where, f"expected a table [water], found {found_text(raw)}")
            return None
        v, complete = self.validate(_Water, raw, where)
        if v is None:
            return None
        current = self.flow(v.current, where + ("current",))
        waves = None
        if v.waves is not None:
            kind, w = self.kinded(v.waves, where + ("waves",), _WAVE_MODELS, "wave kind")
            if kind is not None:
                waves = Waves(kind=kind, **w.model_dump(exclude={"kind"}))
            if kind is not None and not self.gravity > 0.0:
                self.problem(where + ("waves",), "waves need gravity > 0 (their dispersion "
                             f"ω² = g k tanh(k h)), found gravity = {self.gravity:g} m/s²")
        if not complete:
            return None
        depth = math.inf if v.depth is None else float(v.depth)
        return Water(float(v.density), float(v.surface), depth, current, waves)

    def air(self, raw: dict | None) -> Air | None:
        if raw is None:
            return None
        where = ("air",)
        if not isinstance(raw, dict):
            self.problem(where, f"expected a table [air], found {found_text(raw)}")
            return None
        if "waves" in raw:
            self.problem(where + ("waves",), "waves belong to [water]: there are no waves in "
                         "air (add a [water] table with its surface and waves)")
            raw = {k: x for k, x in raw.items() if k != "waves"}
        v, complete = self.validate(_Air, raw, where)
        if v is None:
            return None
        wind = None
        w_where = where + ("wind",)
        if isinstance(v.wind, dict) and "speed" in v.wind:
            p, ok = self.validate(_WindProfile, v.wind, w_where)
            if ok:
                wind = self.wind_profile(p, w_where)
        elif v.wind is not None:
            flow = self.flow(v.wind, w_where, profile=False)
            if flow is not None:
                wind = Wind("uniform", flow.velocity[0], time=flow.time)
        if not complete:
            return None
        return Air(float(v.density), wind)

    def wind_profile(self, p: _WindProfile, where: tuple) -> Wind | None:
        tf = None if p.time is None else self.time_function(p.time, where + ("time",))
        if p.time is not None and tf is None:
            return None
        if p.profile == "power" and p.exponent is None:
            self.problem(where + ("exponent",), 'missing: profile = "power" needs its '
                         "exponent (e.g. 0.14 over open sea, 0.16 over open country)")
            return None
        if p.profile == "log" and p.roughness is None:
            self.problem(where + ("roughness",), 'missing: profile = "log" needs the '
                         "roughness length z0 in m (e.g. 0.0002 over sea, 0.03 over grass)")
            return None
        if p.profile != "power" and p.exponent is not None:
            self.problem(where + ("exponent",), 'only a profile = "power" has an exponent')
            return None
        if p.profile != "log" and p.roughness is not None:
            self.problem(where + ("roughness",), 'only a profile = "log" has a roughness')
            return None
        if p.profile == "log" and p.roughness >= p.reference_height:
            self.problem(where + ("roughness",), f"expected a roughness length below the "
                         f"reference_height {p.reference_height:g} m, found {p.roughness:g}")
            return None
        # towards ``direction`` in the plane normal to gravity, from the gravity frame's first
        # axis towards its second (global x and y with gravity along -z; catdae.case.frame)
        th = math.radians(p.direction)
        e1, e2, _ = gravity_rotation(self.gravity_direction)
        vec = tuple(float(p.speed * (math.cos(th) * a + math.sin(th) * b))
                    for a, b in zip(e1, e2, strict=True))
        return Wind(p.profile, vec, float(p.exponent or p.roughness or 0.0),
                    float(p.reference_height), p.ground, tf)

    def flow(self, raw: Any, where: tuple, profile: bool = True) -> Current | None:
        """A uniform vector ``[ux, uy, uz]``, ``{ velocity = [...], time = {...} }`` or (current
        only) a depth profile ``{ z = [...], velocity = [[...], ...], time = {...} }``."""
        if raw is None:
            return None
        if isinstance(raw, list):
            try:
                vec = VEC3.validate_python(raw)
            except Exception:  # noqa: BLE001 - reported below
                vec = None
            if vec is None:
                self.problem(where, f"expected a velocity [ux, uy, uz] of 3 finite numbers "
                             f"(m/s), found {found_text(raw)}")
                return None
            return Current((), (tuple(float(x) for x in vec),), None)
        if not isinstance(raw, dict):
            self.problem(where, "expected a velocity [ux, uy, uz] (m/s) or a table "
                         + ("{ z = [...], velocity = [[ux, uy, uz], ...] }" if profile else
                            "{ speed, direction, profile, ... }") + f", found {found_text(raw)}")
            return None
        if "z" in raw and profile:
            v, ok = self.validate(_Profile, raw, where)
            if not ok:
                return None
            if len(v.z) != len(v.velocity):
                self.problem(where + ("velocity",), f"expected one velocity per depth in z "
                             f"({len(v.z)}), found {len(v.velocity)}")
                return None
            for k in range(1, len(v.z)):
                if not v.z[k] > v.z[k - 1]:
                    self.problem(where + ("z",), f"expected heights increasing strictly "
                                 f"(z[{k}] = {v.z[k]:g} follows z[{k - 1}] = {v.z[k - 1]:g}): "
                                 "a profile is listed from the bottom up, each z once")
                    return None
            z, vel, time = v.z, v.velocity, v.time
        else:
            v, ok = self.validate(_UniformFlow, raw, where)
            if not ok:
                return None
            z, vel, time = [], [v.velocity], v.time
        tf = None if time is None else self.time_function(time, where + ("time",))
        if time is not None and tf is None:
            return None
        return Current(tuple(float(x) for x in z),
                       tuple(tuple(float(x) for x in u) for u in vel), tf)

    def fluid_lines(self, materials_raw: dict) -> None:
        """Fluid coefficients need a diameter."""
        for key, item in materials_raw.items():
            if not isinstance(item, dict) or item.get("diameter") is not None:
                continue
            for f in ("drag_normal", "drag_axial", "added_mass_normal", "added_mass_axial"):
                if f in item:
                    self.problem(("materials", key, f), f"{f} needs the line's diameter "
                                 "(add diameter = ... in m)")

    def water_floor(self, water: Water | None, nodes: dict, supports: dict, seabed) -> None:
        """With waves over a finite depth, the wave kinematics hold down to the floor at
        surface - depth only: no support and no seabed below it."""
        if water is None or water.waves is None or not math.isfinite(water.depth):
            return
        floor = water.surface - water.depth
        tol = 1e-9 * max(1.0, abs(floor))
        if seabed is not None and seabed.z < floor - tol:
            self.problem(("seabed", "z"), f"the seabed at z = {seabed.z:g} m lies below the "
                         f"water's floor surface - depth = {floor:g} m, where the waves' "
                         "kinematics end: expected a [water] depth reaching the seabed")
        for name in supports:
            p = nodes.get(name)
            if p is not None and self.height(p) < floor - tol:
                self.problem(("water", "depth"), f"support {name!r} (z = {self.height(p):g} "
                             f"m) lies below the water's floor surface - depth = {floor:g} m, "
                             "where the waves' kinematics end: expected a depth reaching it")

