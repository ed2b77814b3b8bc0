"""The ``[seabed]`` section: a flat bottom under the cables (docs/case-format.md, "Seabed").

Validated here (pass 2, pydantic) and checked against the scene (pass 3): the bottom must not
lie above a support, contact stiffness and damping need the contact width (the materials'
``diameter``), and modal and transient steps need a finite ``stiffness``.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BaseModel, Field

from catdae.case.messages import found_text, is_number
from catdae.case.model import Seabed
from catdae.case.schema import STRICT


class _Friction(BaseModel):
    model_config = STRICT
    axial: Annotated[float, Field(ge=0)]
    lateral: Annotated[float, Field(ge=0)]


class _Seabed(BaseModel):
    model_config = STRICT
    z: float | None = None
    stiffness: Annotated[float, Field(gt=0)] | None = None
    damping: Annotated[float, Field(ge=0)] = 0.0
    friction: Any = 0.0
    friction_velocity: Annotated[float, Field(gt=0)] = 0.01


class SeabedPass:
    """Mixin of the case builder (catdae.case.build.Builder)."""

    def seabed(self, raw: dict | None, nodes: dict, supports: dict, materials: dict,
               steps: list, water_floor: float | None = None,
               water_surface: float | None = None) -> Seabed | None:
        if raw is None:
            return None
        where = ("seabed",)
        if not isinstance(raw, dict):
            self.problem(where, f"expected a table [seabed], found {found_text(raw)}")
            return None
        sb, complete = self.validate(_Seabed, raw, where)
        if sb is None:
            return None
        axial = lateral = 0.0
        fr = sb.friction
        if is_number(fr) and not isinstance(fr, bool) and fr >= 0:
            axial = lateral = float(fr)
        elif isinstance(fr, dict):
            f, ok = self.validate(_Friction, fr, where + ("friction",))
            if f is None or not ok:
                complete = False
            else:
                axial, lateral = f.axial, f.lateral
        else:
            self.problem(where + ("friction",), "expected a Coulomb coefficient >= 0 or a "
                         f"table {{ axial = .., lateral = .. }}, found {found_text(fr)}")
            complete = False
        z = sb.z if sb.z is not None else water_floor
        if z is None:
            self.problem(where + ("z",), "missing: give the height of the seabed, z = .. (m), "
                         "or a [water] depth")
            return None
        for name in supports:
            p = nodes.get(name)
            if p is not None and self.height(p) < z - 1e-9 * max(1.0, abs(z)):
                self.problem(where + ("z",), f"the seabed at z = {z:g} m lies above support "
                             f"{name!r} (z = {self.height(p):g} m): supports must be on or "
                             "above the seabed")
        if water_surface is not None and z > water_surface:
            self.problem(where + ("z",), f"the seabed at z = {z:g} m lies above the still-water "
                         f"level [water] surface = {water_surface:g} m: expected a seabed under "
                         "the water (for dry ground leave out [water])")
        if sb.stiffness is None:
            for key, value in (("friction", axial + lateral), ("damping", sb.damping)):
                if value:
                    self.problem(where + (key,), f"{key} acts on the contact springs, in "
                                 "transient steps: the rigid seabed (no stiffness) is static "
                                 f"and frictionless; give [seabed] stiffness, or leave out {key}")
            for i, st in enumerate(steps):
                if st.kind in ("modal", "transient"):
                    self.problem(("steps", i), f"{st.kind} step '{st.name}': a rigid seabed "
                                 "(no [seabed] stiffness) is for static steps only; give "
                                 "[seabed] stiffness (Pa/m) for modal and transient steps")
        elif any(getattr(m, "diameter", None) in (None, 0.0) for m in materials.values()):
            bad = sorted(k for k, m in materials.items()
                         if getattr(m, "diameter", None) in (None, 0.0))
            self.problem(where + ("stiffness",), "contact stiffness acts per unit contact "
                         f"area (diameter × length): material(s) {', '.join(bad)} need a "
                         "diameter > 0")
        if not complete:
            return None
        return Seabed(z=float(z), stiffness=sb.stiffness, damping=sb.damping,
                      friction_axial=axial, friction_lateral=lateral,
                      friction_velocity=sb.friction_velocity)

    def height(self, p) -> float:
        """Height of a point along "up" (-gravity)."""
        g = self.gravity_direction
        return -(p[0] * g[0] + p[1] * g[1] + p[2] * g[2])
