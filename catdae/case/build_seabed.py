"""The ``[seabed]`` section: a flat bottom under the cables (docs/case-format.md, "Seabed").

Validated here (pass 2, pydantic) and checked against the scene (pass 3): the bottom must not
lie above a support, contact stiffness and damping need the contact width (the materials'
``diameter``), modal and transient steps need a finite ``stiffness``, and a rigid seabed takes
no current at its height on lines with drag (:meth:`SeabedPass.rigid_bed_current`).
"""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from catdae.case.messages import found_text, is_number
from catdae.case.model import Seabed

_STRICT = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False)


class _Friction(BaseModel):
    model_config = _STRICT
    axial: Annotated[float, Field(ge=0)]
    lateral: Annotated[float, Field(ge=0)]


class _Seabed(BaseModel):
    model_config = _STRICT
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

    def rigid_bed_current(self, seabed: Seabed | None, water, cables: dict, materials: dict
                          ) -> None:
        """A rigid seabed (no ``stiffness``: static steps only, all at t = 0) under a current
        that is not zero at its height, on cables whose material has drag: refused. The exact
        grounded element carries the lying part straight along the seabed at a constant
        horizontal tension: a drag along or across that part is outside it (lumped at the
        nodes, the drag on the touchdown element's inclined chord pushes lying nodes off the
        frictionless bed; docs/case-format.md, "Seabed")."""
        if seabed is None or seabed.stiffness is not None or water is None:
            return
        cur = water.current
        if cur is None:
            return
        vel = np.asarray(cur.velocity, float).reshape(-1, 3)
        u = vel[0] if not cur.z else np.array([np.interp(seabed.z, cur.z, vel[:, a])
                                               for a in range(3)])
        if cur.time is not None:
            u = u * float(cur.time.evaluate(0.0)[0])
        speed = float(np.linalg.norm(u))
        dragged = sorted({c.material for _, c in cables.values() if (m := materials.get(
            c.material)) is not None and (m.drag_normal > 0.0 or m.drag_axial > 0.0)})
        if speed == 0.0 or not dragged:
            return
        self.problem(("water", "current"), f"a current of {speed:.3g} m/s at the height of the "
                     f"rigid [seabed] (z = {seabed.z:g} m, no stiffness) on lines with drag "
                     f"(material {', '.join(dragged)}): its exact grounded relations hold the "
                     "resting part straight at a constant tension and take no drag on it; give "
                     "[seabed] stiffness (Pa/m: contact springs), or a current profile that is "
                     "zero at the seabed's height")

    def height(self, p) -> float:
        """Height of a point along "up" (-gravity)."""
        g = self.gravity_direction
        return -(p[0] * g[0] + p[1] * g[1] + p[2] * g[2])
