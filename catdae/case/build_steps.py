"""Pass 3 for the steps of a case: support motions, steps with their temperature, presence
(add/remove) and damping. A mixin of :class:`~catdae.case.build.Builder`, whose
``problem`` and ``validate`` collect what is wrong (see ``build``)."""

from __future__ import annotations

import re
import unicodedata
from typing import Any

import numpy as np

from catdae.case.messages import fmt_path, found_text, is_number, shorten, unknown_word
from catdae.case.model import (
    AXES,
    AxialDamping,
    Damping,
    FrozenMap,
    Step,
    SupportMotion,
)
from catdae.case.names import cable_of
from catdae.case.schema import (
    DAMPING_MODELS,
    STEP_MODELS,
    AxialDampingSchema,
    SupportMotionSchema,
)
from catdae.case.timefunc_compose import Scaled

ABSOLUTE_ZERO = -273.15  # °C: no temperature is below it, in °C or in K (docs/case-format.md)


class StepsPass:
    """Support motions and steps (methods of ``_Builder``)."""

    def support_motions(self, raw: list[dict], nodes: dict, supports: dict) -> list:
        out = []
        seen: dict[str, int] = {}
        for i, item in enumerate(raw):
            where = ("support_motions", i)
            v, ok = self.validate(SupportMotionSchema, item, where)
            if v is None:
                continue
            if v.node not in self.node_names:
                mesh = cable_of(v.node) in self.cable_names  # a node of a cable's mesh
                held = ", ".join(map(repr, sorted(self.support_names & self.node_names)))
                self.problem(where + ("node",), (
                    f"{v.node!r} is a mesh node of cable {cable_of(v.node)!r}, and mesh nodes "
                    "cannot be supported: only a [nodes] entry that is in [supports] can be "
                    f"moved (supported nodes: {held})"
                ) if mesh else unknown_word(v.node, "node", sorted(self.node_names)))
                ok = False
            elif v.node not in self.support_names:
                self.problem(where + ("node",), f"node {v.node!r} is not supported; only a "
                             "supported node can be moved (add it to [supports])")
                ok = False
            elif v.node in seen:
                self.problem(where + ("node",), f"node {v.node!r} already moves in "
                             f"support_motions[{seen[v.node]}]; give all its axes there")
                ok = False
            else:
                seen[v.node] = i
            fixed = supports.get(v.node)
            if "direction" in item or "value" in item:
                funcs = self.directed_motion(v, item, where, fixed)
                if funcs is not None and fixed is not None and ok:
                    out.append(SupportMotion(v.node, **funcs))
                continue
            if not any(axis in item for axis in AXES):
                self.problem(where, "a support motion needs at least one of x, y, z (or "
                             "direction and value)")
                ok = False
            funcs = {}
            for axis in AXES:
                spec = getattr(v, axis)
                if spec is None:
                    continue
                if fixed is not None and axis not in fixed:
                    self.problem(where + (axis,), f"axis {axis!r} of node {v.node!r} is not "
                                 f"fixed (fixed axes: {list(fixed)}); only a fixed axis can be "
                                 "moved")
                    ok = False
                funcs[axis] = self.time_function(spec, where + (axis,), motion=True)
                ok = ok and funcs[axis] is not None
            if ok and fixed is not None:
                out.append(SupportMotion(v.node, **funcs))
        return out

    def directed_motion(self, v: Any, item: dict, where: tuple, fixed) -> dict | None:
        """``direction = [dx, dy, dz]`` with ``value = <time function>``: the displacement
        value(t) along the unit vector of the direction, as x, y, z motions of the node."""
        if any(axis in item for axis in AXES):
            self.problem(where, "give either direction and value, or x, y, z, not both")
            return None
        if v.direction is None or v.value is None:
            missing = "direction" if v.direction is None else "value"
            if missing not in item:  # present but malformed: already reported
                self.problem(where + (missing,), "missing: a motion along a direction needs "
                             "direction = [dx, dy, dz] and value = <time function> (m)")
            return None
        d = np.asarray(v.direction, float)
        norm = float(np.linalg.norm(d))
        if not norm > 0.0:
            self.problem(where + ("direction",), "expected a direction of non-zero length, "
                         "found [0, 0, 0]")
            return None
        moved = [a for a, c in zip(AXES, d, strict=True) if c != 0.0]
        if fixed is not None:
            free = [a for a in moved if a not in fixed]
            if free:
                self.problem(where + ("direction",), f"the direction has a component along "
                             f"axis {free[0]!r} of node {v.node!r}, which is not fixed (fixed "
                             f"axes: {list(fixed)}); only fixed axes can be moved")
                return None
        tf = self.time_function(v.value, where + ("value",), motion=True)
        if tf is None:
            return None
        return {a: Scaled(tf, float(c / norm)) for a, c in zip(AXES, d, strict=True)
                if c != 0.0}

    def steps(self, raw: list[dict]) -> list[Step]:
        out = []
        names: dict[str, int] = {}
        self.faulty_static: set[str] = set()  # static steps not built: their problems are said
        # what is present before each step, and why: the name -> (present, reason) of add/remove
        presence = {r: (r not in self.inactive, "active = false" if r in self.inactive else
                        "active from the start") for r in self.removable}
        for i, item in enumerate(raw):
            where = ("steps", i)
            kind = item.get("kind")
            if not isinstance(kind, str) or kind not in STEP_MODELS:
                if "kind" not in item:
                    self.problem(where + ("kind",), "missing: this key is required (one of "
                                 "'static', 'modal', 'transient')")
                elif isinstance(kind, str):
                    self.problem(where + ("kind",), unknown_word(kind, "step kind", STEP_MODELS))
                else:
                    self.problem(where + ("kind",), "expected 'static', 'modal' or "
                                 f"'transient', found {found_text(kind)}")
                continue
            model = STEP_MODELS[kind]
            foreign = {
                key: f"does not apply to a {kind} step (it belongs to {other} steps)"
                for other, m in STEP_MODELS.items() if other != kind
                for key in m.model_fields if key not in model.model_fields
            }
            v, complete = self.validate(model, item, where, foreign)
            nm = item.get("name") if isinstance(item.get("name"), str) else f"{kind}{i}"
            if nm in names:
                self.problem(where + ("name",), f"duplicate step name {nm!r} (also "
                             f"steps[{names[nm]}])")
            elif len(nm.encode()) > MAX_STEP_BYTES:
                self.problem(where + ("name",), f"a step name of {len(nm.encode())} bytes in "
                             f"UTF-8, above the limit of {MAX_STEP_BYTES}: it names files too "
                             "(figures, VTK series: at most 255 bytes a file name), found "
                             f"{shorten(nm)}")
            elif not _group_name(nm):
                self.problem(where + ("name",), "a step name names a group of the results "
                             "file: expected a letter, digit or '_' first, then also '.', '-', "
                             "'+', '@' or inner spaces (no '/'; netCDF group names), found "
                             f"{shorten(nm)}")
            names.setdefault(nm, i)
            if kind == "static":
                self.faulty_static.add(nm)  # until it is built (below)
            if v is None:
                continue
            self.add_remove(v, where, nm, presence)
            extra: dict[str, Any] = {}
            if kind == "static":
                extra = {"load_steps": v.load_steps}
            elif kind == "modal":
                extra = {"modes": v.modes, "mass_model": v.mass_model,
                         "damping": None if v.damping is None else self.damping(v.damping, where)}
            else:
                if v.output_interval > v.duration:
                    self.problem(where + ("output_interval",), "expected at most the step "
                                 f"duration {v.duration:g} s, found {v.output_interval:g}")
                damping = None if v.damping is None else self.damping(v.damping, where)
                order = v.max_order
                if not (order == "auto" or (isinstance(order, int) and not isinstance(order, bool)
                                            and 1 <= order <= 5)):
                    self.problem(where + ("max_order",), 'expected "auto" or an integer from 1 '
                                 f"to 5 (IDA's largest BDF order), found {found_text(order)}")
                extra = {"duration": float(v.duration), "output_interval": float(v.output_interval),
                         "rtol": float(v.rtol), "atol": float(v.atol), "damping": damping,
                         "max_order": v.max_order, "linear_solver": v.linear_solver,
                         "mass_model": v.mass_model, "inertia": v.inertia,
                         "axial_damping": self.axial_damping(v.axial_damping, where),
                         "resolve": v.resolve,
                         "jump_reference": self.jump_reference(v, where, out, nm,
                                                               raw[i + 1:])}
            temperature = self.step_temperature(v, where)
            sweep = self.sweep(v.sweep, where, self.connector_items)
            if complete and temperature is not False and sweep is not False:
                self.faulty_static.discard(nm)
                out.append(Step(kind=kind, name=nm, remove=tuple(v.remove),
                                add=tuple(v.add), temperature_change=temperature,
                                sweep=sweep, **extra))
        return out

    def step_temperature(self, v: Any, where: tuple) -> float | FrozenMap | None | bool:
        """A step's temperature change: its ``temperature_change``, or its ``temperature``
        less the case's ``reference_temperature`` (a number, or per cable)."""
        if v.temperature is None:
            return self.temperature(v.temperature_change, where)
        if v.temperature_change is not None:
            self.problem(where + ("temperature",), "give either temperature or "
                         "temperature_change, not both")
            return False
        if self.reference_temperature is None:
            self.problem(where + ("temperature",), "a step's temperature needs the case's "
                         "reference_temperature (the temperature at which the cables' lengths "
                         "and form targets hold), e.g. reference_temperature = 15.0 at the top "
                         "of the file; or give temperature_change instead")
            return False
        change = self.temperature(v.temperature, where, key="temperature")
        ref = self.reference_temperature
        if change is False or change is None:
            return change
        if isinstance(change, FrozenMap):
            return FrozenMap({k: t - ref for k, t in change.items()})
        return change - ref

    def below_absolute_zero(self, value: float, where: tuple, what: str) -> bool:
        """A temperature below absolute zero (-273.15 °C; 0 K is above it) is refused; True
        when it was."""
        if value >= ABSOLUTE_ZERO:
            return False
        self.problem(where, f"{what} {value:g} is below absolute zero (-273.15 °C, 0 K) in "
                     "either unit reference_temperature may have (°C or K)")
        return True

    def jump_reference(self, v: Any, where: tuple, earlier: list[Step], own: str,
                       later: list) -> str | None:
        """A transient step's ``jump_reference``: the name of an earlier static step (``own``:
        the step's name, ``later``: the raw steps after it, for a message that says what a
        wrong name names)."""
        name = v.jump_reference
        if name is None:
            return None
        static = [s.name for s in earlier if s.kind == "static"]
        if name in static:
            return name
        if name in self.faulty_static:  # a static step with problems of its own, said there
            return name
        kinds = {s.name: s.kind for s in earlier}
        after = {r.get("name") for r in later if isinstance(r, dict)}
        expected = (f"; expected a static step before this one: "
                    f"{', '.join(repr(s) for s in static)}" if static
                    else "; there is no static step before this one")
        if name == own:
            said = f"{name!r} is the step itself, not a static step before it{expected}"
        elif name in kinds:
            said = f"{name!r} is a {kinds[name]} step, not a static step{expected}"
        elif name in after:
            said = (f"{name!r} comes after this step; jump_reference names a static step "
                    f"before it{expected}")
        else:
            said = unknown_word(name, "static step before this one", static)
        self.problem(where + ("jump_reference",), said)
        return name

    def temperature(self, raw: Any, where: tuple,
                    key: str = "temperature_change") -> float | FrozenMap | None | bool:
        """A step's ``temperature_change`` (or ``temperature``, ``key``): K for every cable,
        or a table cable name -> K."""
        where = where + (key,)
        change = key == "temperature_change"
        what = ("a temperature change in K" if change
                else "a temperature (the units of reference_temperature)")
        if raw is None:
            return None
        if is_number(raw):
            return False if self.too_cold(float(raw), where, change) else float(raw)
        if not isinstance(raw, dict):
            self.problem(where, f"expected {what} (a number, for every cable) or a table "
                         f"cable name -> {'K' if change else 'temperature'}, "
                         f"found {found_text(raw)}")
            return False
        ok = True
        for key, value in raw.items():
            if key not in self.cable_names:
                self.problem(where + (key,), unknown_word(key, "cable", sorted(self.cable_names)))
                ok = False
            elif not is_number(value):
                self.problem(where + (key,), f"expected {what} (a finite number), found "
                             f"{found_text(value)}")
                ok = False
            elif self.too_cold(float(value), where + (key,), change):
                ok = False
        return FrozenMap({k: float(v) for k, v in raw.items()}) if ok else False

    def too_cold(self, value: float, where: tuple, change: bool) -> bool:
        """A ``temperature`` (or with ``reference_temperature`` a ``temperature_change``) that
        puts a cable below absolute zero; True when it was refused."""
        ref = self.reference_temperature
        if not change:
            return self.below_absolute_zero(value, where, "a temperature of")
        if ref is None or not np.isfinite(ref):
            return False
        return self.below_absolute_zero(ref + value, where, f"reference_temperature {ref:g} "
                                        f"plus a temperature_change of {value:g} is")

    def form_first_step(self, cables: dict, steps: list[Step], raw_steps: list) -> None:
        """Form-finding holds in the first static step, which must then come first."""
        found = [c.name for _, c in cables.values()
                 if c.form is not None and c.form.kind != "pretension"]
        if found and raw_steps and raw_steps[0].get("kind") != "static":
            self.problem(("steps", 0, "kind"), (
                f"cable {found[0]!r} has its length found by form-finding, which holds in the "
                "first step: expected a static step first, found "
                f"{found_text(raw_steps[0].get('kind'))}"))

    def add_remove(self, v: Any, where: tuple, step: str, presence: dict) -> None:
        """A step's ``add`` names what is absent before it, its ``remove`` what is present."""
        here = f"step {step!r} ({fmt_path(where)})"
        for key in ("add", "remove"):
            for j, r in enumerate(getattr(v, key)):
                at = where + (key, j)
                if r not in self.removable:
                    if r in self.distributed_names:
                        self.problem(at, f"{r!r} is the default name of an unnamed distributed "
                                     f'load; give it name = "..." to {key} it')
                    else:
                        self.problem(at, unknown_word(r, "point mass, load or distributed load",
                                                  sorted(self.removable)))
                    continue
                if key == "remove" and r in v.add:
                    self.problem(at, f"{r!r} is both added and removed by this step")
                    continue
                present, why = presence[r]
                if key == "add" and present:
                    self.problem(at, f"{r!r} is already present ({why}); add names what is "
                                 "absent (active = false, or removed by an earlier step)")
                elif key == "remove" and not present:
                    if why == "active = false":
                        why = "absent: it has active = false and no earlier step adds it"
                    self.problem(at, f"{r!r} is {why}")
                else:
                    presence[r] = (key == "add", f"added by {here}" if key == "add"
                                   else f"already removed by {here}")

    def axial_damping(self, raw: dict | None, step_where: tuple) -> AxialDamping | None:
        if raw is None:
            return None
        where = step_where + ("axial_damping",)  # a table: the schema's TomlTable
        v, complete = self.validate(AxialDampingSchema, raw, where)
        if v is None or not complete:
            return None
        f = v.frequency if v.frequency == "element" else float(v.frequency)
        return AxialDamping(ratio=float(v.ratio), frequency=f, rate=v.rate)

    def damping(self, raw: dict, step_where: tuple) -> Damping | None:
        where = step_where + ("damping",)
        kind, v = self.kinded(raw, where, DAMPING_MODELS, "damping kind")
        if kind is None:
            return None
        if kind == "material":
            return Damping("material")
        pair = v.alpha is not None or v.beta is not None
        ratio = v.ratio is not None or v.frequencies is not None
        if pair and ratio:
            self.problem(where, "give either alpha and beta, or ratio and frequencies, not both")
            return None
        if not pair and not ratio:
            self.problem(where, "Rayleigh damping needs alpha and beta, or ratio and "
                         "frequencies = [f1, f2] (Hz)")
            return None
        need = ("alpha", "beta") if pair else ("ratio", "frequencies")
        missing = [k for k in need if getattr(v, k) is None]
        for k in missing:
            other = need[1] if k == need[0] else need[0]
            self.problem(where + (k,), f"missing: needed together with {other}")
        if missing:
            return None
        if ratio:
            f1, f2 = v.frequencies
            if abs(f1 - f2) <= 1e-12 * max(f1, f2):
                self.problem(where + ("frequencies",), "expected two different frequencies, "
                             f"found {f1:g} Hz twice")
                return None
            return Damping("rayleigh", ratio=float(v.ratio), frequencies=(float(f1), float(f2)))
        return Damping("rayleigh", alpha=float(v.alpha), beta=float(v.beta))


_GROUP_NAME = re.compile(r"\w[\w.+\-@ ]*")
MAX_STEP_BYTES = 200  # a step name in UTF-8: <step>-sweep<k>-<what>.png within 255 bytes


def _group_name(name: str) -> bool:
    """A netCDF-4 group name that reads back as written: a letter, digit or '_' first (not
    '$', '.', '-'), no '/', no trailing space, NFC, at most 255 bytes."""
    return (_GROUP_NAME.fullmatch(name) is not None and not name.endswith(" ")
            and unicodedata.is_normalized("NFC", name) and len(name.encode()) <= 255)
