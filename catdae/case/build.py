"""Passes 2 and 3: validate each item, check cross references and physics, build the model.

Every problem is collected (:meth:`Builder.problem`) before anything is raised, so that one
:class:`~catdae.errors.CaseError` lists all of them with their field paths. An item that fails
pass 2 is left out of pass 3, but its name still counts as declared, so that one typo does not
cascade into a list of "unknown" errors elsewhere.
"""

from __future__ import annotations

import math
import unicodedata
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from catdae.case.build_cables import COINCIDENT_TOL, MAX_STRAIN, CablesPass  # noqa: F401
from catdae.case.build_connectors import ConnectorsPass, connector_ends
from catdae.case.build_fluid import FluidPass
from catdae.case.build_seabed import SeabedPass
from catdae.case.build_steps import StepsPass
from catdae.case.build_time import TimePass
from catdae.case.fluid import line_fluid
from catdae.case.frame import gravity_rotation, local_axes
from catdae.case.ground import GroundPass
from catdae.case.limits import MAX_NAME_LENGTH, size_problems
from catdae.case.messages import (
    fmt_path,
    found_text,
    is_number,
    pydantic_message,
    shorten,
    unknown_word,
)
from catdae.case.model import (
    AXES,
    Case,
    FrozenMap,
    Material,
)
from catdae.case.names import cable_of
from catdae.case.schema import (
    POSITION,
    VEC3,
    LoadSchema,
    MaterialSchema,
    PointMassSchema,
    TopSchema,
)
from catdae.case.sweep import SweepPass
from catdae.errors import CaseError

# bidirectional formatting: embeddings, overrides, isolates (and in names the marks too)
_BIDI_OVERRIDES = frozenset("\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069")
_BIDI = _BIDI_OVERRIDES | frozenset("\u200e\u200f\u061c")


MAX_MESSAGE = 400  # characters of one problem: a name of 100 000 characters is not repeated


def _bounded(message: str) -> str:
    """A message cut to MAX_MESSAGE characters, saying so (it may quote a long name)."""
    if len(message) <= MAX_MESSAGE:
        return message
    return f"{message[:MAX_MESSAGE - 40]}... (message cut, {len(message)} characters)"


class Builder(CablesPass, ConnectorsPass, StepsPass, SweepPass, TimePass, FluidPass,
               GroundPass, SeabedPass):
    """Collects problems while turning the parsed TOML into frozen objects."""

    def __init__(self, path: str | None, base_dir: Path):
        self.path = path
        self.base_dir = base_dir
        self.problems: list[tuple[str, str]] = []

    def problem(self, parts: Iterable[str | int], message: str) -> None:
        self.problems.append((fmt_path(parts), _bounded(message)))

    def validate(self, model: type[BaseModel], data: Any, prefix: tuple,
                 foreign: Mapping[str, str] | None = None) -> tuple[Any, bool]:
        """Validate ``data`` against ``model``, recording problems under ``prefix``.

        Returns ``(item, complete)``. When some keys are bad, ``item`` is validated again
        without them (so their defaults stand in) and ``complete`` is False: cross checks may
        still run on the good keys, but no object is built. ``item`` is None when even that
        fails (a required key is missing or bad).
        """
        try:
            return model.model_validate(data), True
        except ValidationError as exc:
            errors = exc.errors()
        fields = list(model.model_fields)
        for err in errors:
            self.problem(prefix + tuple(err["loc"]), pydantic_message(err, fields, foreign or {}))
        bad = {err["loc"][0] for err in errors if err["loc"]}
        try:
            return model.model_validate({k: v for k, v in data.items() if k not in bad}), False
        except ValidationError:
            return None, False

    # -- sections -----------------------------------------------------------------------------

    def build(self, data: dict[str, Any], *, text: str, name: str,
              judge_size: bool = True) -> Case:
        try:
            top = TopSchema.model_validate(data)
            bad: set = set()
        except ValidationError as exc:  # report, then go on with the well-formed sections
            fields = list(TopSchema.model_fields)
            for err in exc.errors():
                self.problem(err["loc"], pydantic_message(err, fields, {}))
            bad = {err["loc"][0] for err in exc.errors()}
            top = TopSchema.model_validate({k: v for k, v in data.items() if k not in bad})
        self.gravity, self.gravity_direction = self.gravity_vector(top.gravity)
        self.material_names = set(top.materials)
        self.support_names = set(top.supports)
        if not top.supports and "supports" not in bad:
            self.problem(("supports",), "no support at all: the structure is free to drift; "
                         'fix at least one node, e.g. [supports] A = "pinned"')
        materials = self.materials(top.materials)
        nodes = self.nodes(top.nodes)
        supports = self.supports(top.supports, nodes)
        self.gravity_supports(supports)
        cables = self.cables(top.cables, materials, nodes)
        ends = connector_ends(top)
        self.cable_ends |= ends  # what a connector holds is held
        if any(e not in self.node_names and cable_of(e) not in self.cable_names for e in ends):
            # a connector's end misspelt (reported with its fix): the node it meant is not
            # "held by nothing", nor what is placed on it
            self.cable_ends |= self.node_names
        held = top.cables or top.springs or top.dampers or top.bars
        if not held and "cables" not in bad:
            self.problem(("cables",), "no cable at all: add at least one [[cables]] entry "
                         '(name, ends = ["A", "B"], material, length)')
        for key in sorted(self.node_names - self.cable_ends - self.support_names):
            if held:
                self.problem(("nodes", key), f"node {key!r} is not an end of any cable and "
                             "not supported: nothing holds it (remove it, or use it)")
        point_masses = self.located(top.point_masses, "point_masses", PointMassSchema, cables,
                                    nodes)
        loads = self.located(top.loads, "loads", LoadSchema, cables, nodes)
        distributed = self.distributed(top.distributed_loads, cables)
        connectors = self.connectors(top, cables, nodes)
        self.connector_items = connectors  # what a step's sweep may vary
        self.unique_names(top)
        motions = self.support_motions(top.support_motions, nodes, supports)
        self.reference_temperature = top.reference_temperature
        if top.reference_temperature is not None:
            self.below_absolute_zero(top.reference_temperature, ("reference_temperature",),
                                     "reference_temperature")
        ground = self.ground(top.ground)
        steps = self.steps(top.steps)
        water, air = self.water(top.water), self.air(top.air)
        self.fluid_lines(top.materials)
        seabed = self.seabed(top.seabed, nodes, supports, materials, steps,
                             water_floor=None if water is None or not math.isfinite(water.depth)
                             else water.surface - water.depth,
                             water_surface=None if water is None else water.surface)
        self.water_floor(water, nodes, supports, seabed)
        self.form_first_step(cables, steps, top.steps)
        self.slack(cables, materials, nodes, point_masses, loads, distributed)
        self.names(top)
        if self.problems:
            raise CaseError(self.path, self.problems)
        case = Case(
            title=top.title, source=top.source, gravity=self.gravity,
            gravity_direction=self.gravity_direction,
            materials=FrozenMap(materials), nodes=FrozenMap(nodes),
            supports=FrozenMap(supports), cables=tuple(c for _, c in cables.values()),
            point_masses=tuple(point_masses), loads=tuple(loads),
            distributed_loads=tuple(distributed), support_motions=tuple(motions),
            **connectors, steps=tuple(steps), water=water, air=air, seabed=seabed,
            path=self.path, text=text, name=name,
            reference_temperature=top.reference_temperature, ground=ground,
        )
        problems = size_problems(case) if judge_size else []  # counts and sizes, before work
        if problems:
            raise CaseError(self.path, problems)
        return case

    def names(self, top: TopSchema) -> None:
        """Names and texts end up in the results file, in messages and in ParaView: no control
        characters (netCDF cuts a string at NUL), no bidirectional controls (U+202E shows a
        name reversed), and names of at most MAX_NAME_LENGTH characters (every mesh node and
        element label repeats its cable's name)."""
        found: list[tuple[tuple, str]] = [(("title",), top.title), (("source",), top.source)]
        found += [(("materials", k), k) for k in top.materials]
        found += [(("nodes", k), k) for k in top.nodes]
        for section in ("cables", "point_masses", "loads", "distributed_loads", "springs",
                        "dampers", "bars", "steps"):
            # step names are also held to the stricter rule of group names (steps())
            found += [((section, i, "name"), item["name"]) for i, item in
                      enumerate(getattr(top, section))
                      if isinstance(item, dict) and isinstance(item.get("name"), str)]
        for where, text in found:
            text_field = where[0] in ("title", "source")
            allowed = "\n\t" if text_field else ""
            bad = [c for c in text if unicodedata.category(c) == "Cc" and c not in allowed]
            bidi = [c for c in text if c in (_BIDI_OVERRIDES if text_field else _BIDI)]
            if where[0] == "steps" and (bad or bidi):
                continue  # refused by the rule of group names (steps())
            if bad:
                self.problem(where, f"expected text without control characters, found "
                             f"{shorten(text)} (U+{ord(bad[0]):04X})")
            elif bidi:
                self.problem(where, "expected text without bidirectional control characters "
                             f"(they reorder what is shown), found U+{ord(bidi[0]):04X} in "
                             f"{shorten(text.encode('unicode_escape').decode('ascii'))}")
            elif not text_field and len(text) > MAX_NAME_LENGTH:
                self.problem(where, f"a name of {len(text)} characters, above the limit of "
                             f"{MAX_NAME_LENGTH}; found {shorten(text)}")

    def gravity_vector(self, raw: Any) -> tuple[float, tuple[float, float, float]]:
        """``gravity``: a number (m/s², along -z) or ``[gx, gy, gz]``; returns (|g|, unit)."""
        down = (0.0, 0.0, -1.0)
        if is_number(raw):
            if raw < 0:
                self.problem(("gravity",), f"expected a value >= 0 (m/s², along -z) or a vector "
                             f"[gx, gy, gz], found {found_text(raw)}")
                return 9.81, down
            return float(raw), down
        try:
            g = VEC3.validate_python(raw)
        except ValidationError:
            self.problem(("gravity",), "expected a number >= 0 (m/s², along -z) or a vector "
                         f"[gx, gy, gz] of 3 finite numbers (m/s²), found {found_text(raw)}")
            return 9.81, down
        norm = math.sqrt(sum(x * x for x in g))
        if norm == 0.0:
            return 0.0, down
        return norm, tuple(float(x) / norm for x in g)

    def gravity_supports(self, supports: dict) -> None:
        """The scene is solved with gravity along local -z (catdae.case.frame): every support must
        fix coordinate axes of that frame."""
        if self.gravity_direction == (0.0, 0.0, -1.0):
            return
        R = gravity_rotation(self.gravity_direction)
        for node, axes in supports.items():
            if local_axes(R, axes) is None:
                self.problem(("supports", node), (
                    f"fixes {list(axes)} only, and gravity {list(self.gravity_direction)} "
                    "(unit vector) is not perpendicular to those axes nor along them: the "
                    "constraint is not a coordinate constraint of the frame in which gravity is "
                    "vertical; pin the node, or fix axes that gravity is perpendicular to"))

    def materials(self, raw: dict[str, dict]) -> dict[str, Material]:
        out = {}
        for key, item in raw.items():
            m, complete = self.validate(MaterialSchema, item, ("materials", key))
            if complete:
                weight = m.mass * self.gravity if m.weight is None else m.weight
                out[key] = Material(key, m.EA, m.mass, weight, m.damping,
                                    float(m.thermal_expansion), **line_fluid(m),
                                    rated_strength=m.rated_strength)
        return out

    def nodes(self, raw: dict[str, Any]) -> dict[str, tuple[float, float, float]]:
        self.node_names = set(raw)
        out = {}
        for key, value in raw.items():
            where = ("nodes", key)
            ok = True
            if not key:
                self.problem(where, "a node name must not be empty")
                ok = False
            elif "." in key:
                self.problem(where, f"node names may not contain '.', found {key!r}: names with "
                             "a dot are reserved for mesh nodes such as 'main.7'")
                ok = False
            try:
                xyz = POSITION.validate_python(value)
            except ValidationError as exc:
                for err in exc.errors():
                    msg = pydantic_message(err, (), {})
                    if err["type"] == "list_type":
                        msg = f"expected coordinates [x, y, z] in m, found {found_text(value)}"
                    self.problem(where + tuple(err["loc"]), msg)
                continue
            if ok:
                out[key] = (float(xyz[0]), float(xyz[1]), float(xyz[2]))
        return out

    def supports(self, raw: dict[str, Any], nodes: dict) -> dict[str, tuple[str, ...]]:
        out = {}
        for key, value in raw.items():
            where = ("supports", key)
            known = key in self.node_names
            if not known:
                self.problem(where, unknown_word(key, "node", sorted(self.node_names)))
            if value == "pinned":
                axes: tuple[str, ...] = AXES
            elif isinstance(value, list) and value and all(isinstance(a, str) for a in value):
                bad = [i for i, a in enumerate(value) if a not in AXES]
                for i in bad:
                    self.problem(where + (i,), f"expected one of 'x', 'y', 'z', found "
                                 f"{found_text(value[i])}")
                dup = {a for a in value if value.count(a) > 1}
                if dup:
                    self.problem(where, f"axis {sorted(dup)[0]!r} is listed twice")
                if bad or dup:
                    continue
                axes = tuple(a for a in AXES if a in value)
            else:
                self.problem(where, 'expected "pinned" or a non-empty list of fixed axes such '
                             f'as ["y"], found {found_text(value)}')
                continue
            if known:
                out[key] = axes
        return out

    def unique_names(self, top: TopSchema) -> None:
        """Point masses, loads and distributed loads share one namespace.

        ``removable``: the names a step may ``add`` or ``remove`` (distributed loads only
        when named); ``inactive``: those absent at the start (``active = false``).
        """
        self.removable: dict[str, str] = {}
        self.distributed_names: set[str] = set()
        self.inactive: set[str] = set()
        seen: dict[str, str] = {}
        for section in ("point_masses", "loads", "distributed_loads"):
            for i, item in enumerate(getattr(top, section)):
                nm = item.get("name")
                if nm is None and section == "distributed_loads":
                    nm = f"distributed{i}"
                if not isinstance(nm, str):
                    continue
                here = fmt_path((section, i))
                if nm in seen:
                    self.problem((section, i, "name"), f"duplicate name {nm!r} (also "
                                 f"{seen[nm]}); point masses and loads share one namespace")
                    continue
                seen[nm] = here
                if section == "distributed_loads" and "name" not in item:
                    self.distributed_names.add(nm)
                else:
                    self.removable[nm] = here
                if item.get("active") is False:
                    self.inactive.add(nm)

    def slack(self, cables: dict, materials: dict, nodes: dict, point_masses: list,
              loads: list, distributed: list) -> None:
        """A weightless cable with no load on it and length >= chord has no defined shape."""
        loaded = {x.cable for x in (*point_masses, *loads) if x.cable is not None}
        loaded |= {cable_of(x.node) for x in (*point_masses, *loads)
                   if x.node is not None and "." in x.node}
        loaded |= {d.cable for d in distributed}
        for name, (i, c) in cables.items():
            if (materials[c.material].weight > 0 or name in loaded or c.length is None
                    or not all(e in nodes for e in c.ends)):  # bad ends: already reported
                continue
            if c.ends[0] not in nodes or c.ends[1] not in nodes:
                continue  # an end's coordinates are bad, and already reported
            chord = math.dist(nodes[c.ends[0]], nodes[c.ends[1]])
            if c.length >= chord:
                self.problem(("cables", i, "length"), (
                    f"slack: no defined shape: the cable is weightless (material "
                    f"{c.material!r} has weight 0) and its length {c.length:g} m is not shorter "
                    f"than its chord {chord:g} m, and nothing loads it; give the material a "
                    "weight, load the cable, or make it shorter than its chord"))
