"""Passes 2 and 3: validate each item, check cross references and physics, build the model.

Every problem is collected (:meth:`_Builder.problem`) before anything is raised, so that one
:class:`~catdae.errors.CaseError` lists all of them with their field paths. An item that fails
pass 2 is left out of pass 3, but its name still counts as declared, so that one typo does not
cascade into a list of "unknown" errors elsewhere.
"""

from __future__ import annotations

import csv
import math
import re
import unicodedata
import warnings
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel, ValidationError

from ..errors import CaseError
from ..frame import gravity_rotation, local_axes
from ..records import AccelerationRecord, VelocityRecord
from ..timefunc import Constant, Cosine, Ramp, Sine, Table, TimeFunction
from .limits import FileProblem, confined, read_limited, size_problems
from .messages import _fmt_path, _found, _is_number, _message, _short, _suggest, _unknown
from .model import (
    AXES,
    Cable,
    Case,
    Damping,
    DistributedLoad,
    Form,
    FrozenMap,
    Load,
    Material,
    PointMass,
    Step,
    SupportMotion,
)
from .schema import (
    _DAMPING_MODELS,
    _STEP_MODELS,
    _TIME_MODELS,
    _VEC3,
    FORM_TARGETS,
    _Cable,
    _DistributedLoad,
    _Form,
    _Load,
    _Material,
    _PointMass,
    _SupportMotion,
    _TableTF,
    _Top,
)

COINCIDENT_TOL = 1e-9  # m: cable ends closer than this coincide
MAX_STRAIN = 0.5  # a chord longer than (1 + MAX_STRAIN) * length is rejected


class _Builder:
    """Collects problems while turning the parsed TOML into frozen objects."""

    def __init__(self, path: str | None, base_dir: Path):
        self.path = path
        self.base_dir = base_dir
        self.problems: list[tuple[str, str]] = []

    def problem(self, parts: Iterable[str | int], message: str) -> None:
        self.problems.append((_fmt_path(parts), message))

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
            self.problem(prefix + tuple(err["loc"]), _message(err, fields, foreign or {}))
        bad = {err["loc"][0] for err in errors if err["loc"]}
        try:
            return model.model_validate({k: v for k, v in data.items() if k not in bad}), False
        except ValidationError:
            return None, False

    # -- sections -----------------------------------------------------------------------------

    def build(self, data: dict[str, Any], *, text: str, name: str) -> Case:
        try:
            top = _Top.model_validate(data)
            bad: set = set()
        except ValidationError as exc:  # report, then go on with the well-formed sections
            fields = list(_Top.model_fields)
            for err in exc.errors():
                self.problem(err["loc"], _message(err, fields, {}))
            bad = {err["loc"][0] for err in exc.errors()}
            top = _Top.model_validate({k: v for k, v in data.items() if k not in bad})
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
        if not top.cables and "cables" not in bad:
            self.problem(("cables",), "no cable at all: add at least one [[cables]] entry "
                         '(name, ends = ["A", "B"], material, length)')
        for key in sorted(self.node_names - self.cable_ends - self.support_names):
            if top.cables:
                self.problem(("nodes", key), f"node {key!r} is not an end of any cable and "
                             "not supported: nothing holds it (remove it, or use it)")
        point_masses = self.located(top.point_masses, "point_masses", _PointMass, cables, nodes)
        loads = self.located(top.loads, "loads", _Load, cables, nodes)
        distributed = self.distributed(top.distributed_loads, cables)
        self.unique_names(top)
        motions = self.support_motions(top.support_motions, nodes, supports)
        steps = self.steps(top.steps)
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
            steps=tuple(steps), path=self.path, text=text, name=name,
        )
        problems = size_problems(case)  # counts and sizes, before any work
        if problems:
            raise CaseError(self.path, problems)
        return case

    def names(self, top: _Top) -> None:
        """Names and texts end up in the results file: no control characters (netCDF cuts a
        string at NUL)."""
        found: list[tuple[tuple, str]] = [(("title",), top.title), (("source",), top.source)]
        found += [(("materials", k), k) for k in top.materials]
        found += [(("nodes", k), k) for k in top.nodes]
        for section in ("cables", "point_masses", "loads", "distributed_loads"):  # steps:
            # their names are held to the stricter rule of group names (steps())
            found += [((section, i, "name"), item["name"]) for i, item in
                      enumerate(getattr(top, section)) if isinstance(item.get("name"), str)]
        for where, text in found:
            allowed = "\n\t" if where[0] in ("title", "source") else ""
            bad = [c for c in text if unicodedata.category(c) == "Cc" and c not in allowed]
            if bad:
                self.problem(where, f"expected text without control characters, found "
                             f"{_short(text)} (U+{ord(bad[0]):04X})")


    def gravity_vector(self, raw: Any) -> tuple[float, tuple[float, float, float]]:
        """``gravity``: a number (m/s², along -z) or ``[gx, gy, gz]``; returns (|g|, unit)."""
        down = (0.0, 0.0, -1.0)
        if _is_number(raw):
            if raw < 0:
                self.problem(("gravity",), f"expected a value >= 0 (m/s², along -z) or a vector "
                             f"[gx, gy, gz], found {_found(raw)}")
                return 9.81, down
            return float(raw), down
        try:
            g = _VEC3.validate_python(raw)
        except ValidationError:
            self.problem(("gravity",), "expected a number >= 0 (m/s², along -z) or a vector "
                         f"[gx, gy, gz] of 3 finite numbers (m/s²), found {_found(raw)}")
            return 9.81, down
        norm = math.sqrt(sum(x * x for x in g))
        if norm == 0.0:
            return 0.0, down
        return norm, tuple(float(x) / norm for x in g)

    def gravity_supports(self, supports: dict) -> None:
        """The scene is solved with gravity along local -z (catdae.frame): every support must
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
            m, complete = self.validate(_Material, item, ("materials", key))
            if complete:
                weight = m.mass * self.gravity if m.weight is None else m.weight
                out[key] = Material(key, m.EA, m.mass, weight, m.damping,
                                    float(m.thermal_expansion))
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
                xyz = _VEC3.validate_python(value)
            except ValidationError as exc:
                for err in exc.errors():
                    msg = _message(err, (), {})
                    if err["type"] == "list_type":
                        msg = f"expected coordinates [x, y, z] in m, found {_found(value)}"
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
                self.problem(where, _unknown(key, "node", sorted(self.node_names)))
            if value == "pinned":
                axes: tuple[str, ...] = AXES
            elif isinstance(value, list) and value and all(isinstance(a, str) for a in value):
                bad = [i for i, a in enumerate(value) if a not in AXES]
                for i in bad:
                    self.problem(where + (i,), f"expected one of 'x', 'y', 'z', found "
                                 f"{_found(value[i])}")
                dup = {a for a in value if value.count(a) > 1}
                if dup:
                    self.problem(where, f"axis {sorted(dup)[0]!r} is listed twice")
                if bad or dup:
                    continue
                axes = tuple(a for a in AXES if a in value)
            else:
                self.problem(where, 'expected "pinned" or a non-empty list of fixed axes such '
                             f'as ["y"], found {_found(value)}')
                continue
            if known:
                out[key] = axes
        return out

    def cables(self, raw: list[dict], materials: dict, nodes: dict) -> dict[str, tuple]:
        """Valid cables by name, each as ``(index, Cable)``."""
        self.cable_names = {c.get("name") for c in raw if isinstance(c.get("name"), str)}
        self.cable_ends = {e for c in raw if isinstance(c.get("ends"), list)
                           for e in c["ends"] if isinstance(e, str)}
        out: dict[str, tuple[int, Cable]] = {}
        seen: dict[str, int] = {}
        for i, item in enumerate(raw):
            where = ("cables", i)
            nm = item.get("name")
            if isinstance(nm, str) and nm in seen:
                self.problem(where + ("name",), f"duplicate cable name {nm!r} (also "
                             f"cables[{seen[nm]}])")
                continue
            if isinstance(nm, str):
                seen[nm] = i
            c, ok = self.validate(_Cable, item, where)
            if c is None:
                continue
            if "." in c.name:
                self.problem(where + ("name",), f"cable names may not contain '.', found "
                             f"{c.name!r}: mesh nodes are named <cable>.<k>")
                ok = False
            a, b = c.ends
            if a == b:
                self.problem(where + ("ends",), f"expected two different nodes, found {a!r} twice")
                ok = False
            for j, end in enumerate(c.ends):
                if end not in self.node_names:
                    self.problem(where + ("ends", j),
                                 _unknown(end, "node", sorted(self.node_names)))
                    ok = False
            if c.material not in materials:
                if c.material not in self.material_names:
                    self.problem(where + ("material",),
                                 _unknown(c.material, "material", sorted(self.material_names)))
                ok = False
            form = self.form(item, c, where)
            ok = ok and form is not False
            length = c.length
            if ok and a in nodes and b in nodes:
                chord = math.dist(nodes[a], nodes[b])
                if form and form.kind == "pretension":  # SAP2000 / Tibert: taken straight
                    length = chord / (1.0 + form.value / materials[c.material].EA)
                if chord < COINCIDENT_TOL:
                    self.problem(where + ("ends",), f"the ends {a!r} and {b!r} coincide "
                                 f"(distance {chord:.3g} m < {COINCIDENT_TOL:g} m)")
                    ok = False
                elif length is not None and chord > (1.0 + MAX_STRAIN) * length:
                    strain = chord / length - 1.0
                    self.problem(where + ("form" if form else "length",), (
                        f"the chord {a}-{b} is {chord:.6g} m but the unstrained length is "
                        f"{length:.6g} m: a strain of at least {strain:.0%}, above the "
                        f"{MAX_STRAIN:.0%} this model accepts; check the length and the node "
                        "coordinates"))
                    ok = False
            if ok:
                out[c.name] = (i, Cable(c.name, (a, b), c.material,
                                        None if length is None else float(length),
                                        c.elements, c.gauss_points, form or None))
        return out

    def form(self, item: dict, c: Any, where: tuple) -> Form | None | bool:
        """The cable's ``form`` (None without one); False after reporting a problem."""
        has_length, has_form = "length" in item, "form" in item
        if has_length and has_form:
            self.problem(where, "give either length or form, not both (form finds the length)")
            return False
        if not has_length and not has_form:
            self.problem(where + ("length",), "missing: this key is required: the unstrained "
                         "length L0 (m), or instead form = { pretension | horizontal_tension | "
                         "tension (with at) | sag }")
            return False
        if not has_form:
            return None
        if c.form is None:  # present but not a table: already reported
            return False
        v, complete = self.validate(_Form, c.form, where + ("form",))
        if not complete:
            return False
        given = [k for k in FORM_TARGETS if getattr(v, k) is not None]
        if len(given) != 1:
            self.problem(where + ("form",), "expected exactly one of pretension (N), "
                         "horizontal_tension (N), tension (N, with at = end node) or sag (m), "
                         f"found {', '.join(given) if given else 'none'}")
            return False
        kind = given[0]
        if kind == "tension":
            if v.at is None:
                self.problem(where + ("form", "at"), "missing: the end node where the tension "
                             f"holds, one of {list(c.ends)}")
                return False
            if v.at not in c.ends:
                self.problem(where + ("form", "at"), f"expected an end of the cable, one of "
                             f"{list(c.ends)}, found {_found(v.at)}")
                return False
        elif v.at is not None:
            self.problem(where + ("form", "at"), "at applies to form = { tension = ..., at = "
                         f"... }} only, not to {kind}")
            return False
        return Form(kind, float(getattr(v, kind)), v.at)

    def node_ref(self, ref: str, where: tuple, cables: dict) -> bool:
        """Check a ``node`` field: a [nodes] entry on some cable, or a mesh node ``<cable>.<k>``."""
        if ref in self.node_names:
            if ref not in self.cable_ends:
                self.problem(where, f"node {ref!r} is not an end of any cable, so nothing "
                             "carries what is placed on it")
                return False
            return True
        cable, dot, _k = ref.rpartition(".")
        if dot and cable in self.cable_names:
            if cable not in cables:
                return False  # the cable itself is invalid and already reported
            msg = _mesh_node_problem(ref, {n: c.elements for n, (_, c) in cables.items()})
            if msg:
                self.problem(where, msg)
                return False
            return True
        choices = sorted(self.node_names) + [
            f"{n}.{k}" for n, (_, c) in cables.items() for k in range(1, min(c.elements, 100))
        ]
        self.problem(where, _unknown(ref, "node", choices))
        return False

    def located(self, raw: list[dict], section: str, model: type[BaseModel], cables: dict,
                nodes: dict) -> list:
        """Point masses or loads: placed at a node, or on a cable at arc length s."""
        out = []
        for i, item in enumerate(raw):
            where = (section, i)
            v, complete = self.validate(model, item, where)
            if v is None:
                continue
            # a location key that was present but bad is already reported: don't guess
            placed = not any(k in item and getattr(v, k) is None for k in ("node", "cable", "s"))
            ok = placed and self.location(v, where, cables) and complete
            time = None
            if section == "loads" and v.time is not None:
                time = self.time_function(v.time, where + ("time",))
                ok = ok and time is not None
            if not ok:
                continue
            s = None if v.s is None else float(v.s)
            if section == "loads":
                out.append(Load(v.name, tuple(float(f) for f in v.force), v.node, v.cable, s, time,
                                active=v.active))
            else:
                out.append(PointMass(v.name, float(v.mass), v.node, v.cable, s,
                                     active=v.active))
        return out

    def location(self, v: Any, where: tuple, cables: dict) -> bool:
        on_cable = v.cable is not None or v.s is not None
        if v.node is not None and on_cable:
            self.problem(where, "give either node, or cable and s, not both")
            return False
        if v.node is not None:
            return self.node_ref(v.node, where + ("node",), cables)
        if not on_cable:
            self.problem(where, 'missing location: give node = "..." or cable = "..." with '
                         "s = arc length (m)")
            return False
        if v.cable is None:
            self.problem(where + ("cable",), "missing: s is given but not the cable it is "
                         "measured along")
            return False
        if v.cable not in self.cable_names:
            self.problem(where + ("cable",), _unknown(v.cable, "cable", sorted(self.cable_names)))
            return False
        if v.s is None:
            self.problem(where + ("s",), "missing: a point on a cable needs s, the unstrained "
                         "arc length (m) from the cable's first end")
            return False
        if v.cable not in cables:
            return False
        length = cables[v.cable][1].length
        if length is None:
            self.problem(where + ("s",), f"cable {v.cable!r} has its length found by "
                         "form-finding, so an arc length s is not known in advance; place it "
                         f"on a mesh node ({v.cable}.k) instead")
            return False
        if v.s > length:
            self.problem(where + ("s",), f"expected 0 <= s <= {length:g} (the length of cable "
                         f"{v.cable!r}), found {v.s:g}")
            return False
        return True

    def distributed(self, raw: list[dict], cables: dict) -> list[DistributedLoad]:
        out = []
        for i, item in enumerate(raw):
            where = ("distributed_loads", i)
            v, ok = self.validate(_DistributedLoad, item, where)
            if v is None:
                continue
            if v.cable not in self.cable_names:
                self.problem(where + ("cable",),
                             _unknown(v.cable, "cable", sorted(self.cable_names)))
                ok = False
            time = None if v.time is None else self.time_function(v.time, where + ("time",))
            if not v.active and v.name is None:
                self.problem(where + ("active",), "a distributed load with active = false "
                             'needs a name (name = "...") so that a step can add it')
                ok = False
            if not ok or v.cable not in cables or (v.time is not None and time is None):
                continue
            coverage = self.coverage(v, where, cables[v.cable][1])
            if coverage is None:
                continue
            out.append(DistributedLoad(v.name or f"distributed{i}", v.cable,
                                       tuple(float(f) for f in v.load), time, *coverage,
                                       active=v.active))
        return out

    def coverage(self, v: Any, where: tuple, cable: Cable) -> tuple[float, float] | None:
        """``(from_s, to_s)`` of a distributed load, within its cable and in order."""
        length = cable.length
        a = 0.0 if v.from_s is None else float(v.from_s)
        b = length if v.to_s is None else float(v.to_s)
        ok = True
        for key, value in (("from_s", v.from_s), ("to_s", v.to_s)):
            if value is not None and value > length:
                self.problem(where + (key,), f"expected 0 <= {key} <= {length:g} (the length "
                             f"of cable {cable.name!r}), found {value:g}")
                ok = False
        if ok and not a < b:
            self.problem(where + ("to_s",), f"expected from_s < to_s (the load covers "
                         f"from_s <= s <= to_s), found from_s = {a:g} and to_s = {b:g}")
            ok = False
        return (a, b) if ok else None

    def unique_names(self, top: _Top) -> None:
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
                here = _fmt_path((section, i))
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

    def support_motions(self, raw: list[dict], nodes: dict, supports: dict) -> list:
        out = []
        seen: dict[str, int] = {}
        for i, item in enumerate(raw):
            where = ("support_motions", i)
            v, ok = self.validate(_SupportMotion, item, where)
            if v is None:
                continue
            if v.node not in self.node_names:
                self.problem(where + ("node",), _unknown(v.node, "node", sorted(self.node_names)))
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
            if not any(axis in item for axis in AXES):
                self.problem(where, "a support motion needs at least one of x, y, z")
                ok = False
            funcs = {}
            fixed = supports.get(v.node)
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

    def steps(self, raw: list[dict]) -> list[Step]:
        out = []
        names: dict[str, int] = {}
        # what is present before each step, and why: the name -> (present, reason) of add/remove
        presence = {r: (r not in self.inactive, "active = false" if r in self.inactive else
                        "active from the start") for r in self.removable}
        for i, item in enumerate(raw):
            where = ("steps", i)
            kind = item.get("kind")
            if not isinstance(kind, str) or kind not in _STEP_MODELS:
                if "kind" not in item:
                    self.problem(where + ("kind",), "missing: this key is required (one of "
                                 "'static', 'modal', 'transient')")
                elif isinstance(kind, str):
                    self.problem(where + ("kind",), _unknown(kind, "step kind", _STEP_MODELS))
                else:
                    self.problem(where + ("kind",), "expected 'static', 'modal' or "
                                 f"'transient', found {_found(kind)}")
                continue
            model = _STEP_MODELS[kind]
            foreign = {
                key: f"does not apply to a {kind} step (it belongs to {other} steps)"
                for other, m in _STEP_MODELS.items() if other != kind
                for key in m.model_fields if key not in model.model_fields
            }
            v, complete = self.validate(model, item, where, foreign)
            nm = item.get("name") if isinstance(item.get("name"), str) else f"{kind}{i}"
            if nm in names:
                self.problem(where + ("name",), f"duplicate step name {nm!r} (also "
                             f"steps[{names[nm]}])")
            elif not _group_name(nm):
                self.problem(where + ("name",), "a step name names a group of the results "
                             "file: expected a letter, digit or '_' first, then also '.', '-', "
                             "'+', '@' or inner spaces (no '/'; netCDF group names), found "
                             f"{_short(nm)}")
            names.setdefault(nm, i)
            if v is None:
                continue
            self.add_remove(v, where, nm, presence)
            extra: dict[str, Any] = {}
            if kind == "static":
                extra = {"load_steps": v.load_steps}
            elif kind == "modal":
                extra = {"modes": v.modes, "mass_model": v.mass_model}
            else:
                if v.output_interval > v.duration:
                    self.problem(where + ("output_interval",), "expected at most the step "
                                 f"duration {v.duration:g} s, found {v.output_interval:g}")
                damping = None if v.damping is None else self.damping(v.damping, where)
                order = v.max_order
                if not (order == "auto" or (isinstance(order, int) and not isinstance(order, bool)
                                            and 1 <= order <= 5)):
                    self.problem(where + ("max_order",), 'expected "auto" or an integer from 1 '
                                 f"to 5 (IDA's largest BDF order), found {_found(order)}")
                extra = {"duration": float(v.duration), "output_interval": float(v.output_interval),
                         "rtol": float(v.rtol), "atol": float(v.atol), "damping": damping,
                         "max_order": v.max_order, "linear_solver": v.linear_solver,
                         "mass_model": v.mass_model, "inertia": v.inertia}
            temperature = self.temperature(v.temperature_change, where)
            if complete and temperature is not False:
                out.append(Step(kind=kind, name=nm, remove=tuple(v.remove),
                                add=tuple(v.add), temperature_change=temperature,
                                **extra))
        return out

    def temperature(self, raw: Any, where: tuple) -> float | FrozenMap | None | bool:
        """A step's ``temperature_change``: K for every cable, or a table cable name -> K."""
        where = where + ("temperature_change",)
        if raw is None:
            return None
        if _is_number(raw):
            return float(raw)
        if not isinstance(raw, dict):
            self.problem(where, "expected a temperature change in K (a number, for every "
                         f"cable) or a table cable name -> K, found {_found(raw)}")
            return False
        ok = True
        for key, value in raw.items():
            if key not in self.cable_names:
                self.problem(where + (key,), _unknown(key, "cable", sorted(self.cable_names)))
                ok = False
            elif not _is_number(value):
                self.problem(where + (key,), f"expected a temperature change in K (a finite "
                             f"number), found {_found(value)}")
                ok = False
        return FrozenMap({k: float(v) for k, v in raw.items()}) if ok else False

    def form_first_step(self, cables: dict, steps: list[Step], raw_steps: list) -> None:
        """Form-finding holds in the first static step, which must then come first."""
        found = [c.name for _, c in cables.values()
                 if c.form is not None and c.form.kind != "pretension"]
        if found and raw_steps and raw_steps[0].get("kind") != "static":
            self.problem(("steps", 0, "kind"), (
                f"cable {found[0]!r} has its length found by form-finding, which holds in the "
                "first step: expected a static step first, found "
                f"{_found(raw_steps[0].get('kind'))}"))

    def add_remove(self, v: Any, where: tuple, step: str, presence: dict) -> None:
        """A step's ``add`` names what is absent before it, its ``remove`` what is present."""
        here = f"step {step!r} ({_fmt_path(where)})"
        for key in ("add", "remove"):
            for j, r in enumerate(getattr(v, key)):
                at = where + (key, j)
                if r not in self.removable:
                    if r in self.distributed_names:
                        self.problem(at, f"{r!r} is the default name of an unnamed distributed "
                                     f'load; give it name = "..." to {key} it')
                    else:
                        self.problem(at, _unknown(r, "point mass, load or distributed load",
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

    def damping(self, raw: dict, step_where: tuple) -> Damping | None:
        where = step_where + ("damping",)
        kind = self.kind_of(raw, where, _DAMPING_MODELS, "damping kind")
        if kind is None:
            return None
        v, complete = self.validate(_DAMPING_MODELS[kind], raw, where)
        if not complete:
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

    def kind_of(self, raw: dict, where: tuple, models: Mapping, what: str) -> str | None:
        kind = raw.get("kind")
        if isinstance(kind, str) and kind in models:
            return kind
        if "kind" not in raw:
            self.problem(where + ("kind",), "missing: this key is required (one of "
                         f"{', '.join(repr(k) for k in models)})")
        elif isinstance(kind, str):
            self.problem(where + ("kind",), _unknown(kind, what, models))
        else:
            self.problem(where + ("kind",), f"expected a string, found {_found(kind)}")
        return None

    def time_function(self, raw: dict, where: tuple, motion: bool = False
                      ) -> TimeFunction | None:
        """A time function; ``motion``: it prescribes a support's displacement (a ``table``
        may then be a velocity or acceleration record)."""
        kind = self.kind_of(raw, where, _TIME_MODELS, "time function kind")
        if kind is None:
            return None
        v, complete = self.validate(_TIME_MODELS[kind], raw, where)
        if not complete:
            return None
        if kind == "constant":
            tf: TimeFunction | None = Constant(float(v.value))
        elif kind == "ramp":
            tf = Ramp(float(v.duration), float(v.start), v.smooth, float(v.amplitude))
        elif kind in ("sine", "cosine"):
            cls = Sine if kind == "sine" else Cosine
            tf = cls(float(v.amplitude), float(v.frequency), float(v.phase), float(v.offset))
        else:
            tf = self.table(v, where, motion)
        if tf is not None and not _finite(tf):
            self.problem(where, "its value, rate or second derivative overflows (not a "
                         "finite number): check the amplitude against the duration, the "
                         "frequency or the spacing of the points")
            return None
        return tf

    def table(self, v: _TableTF, where: tuple, motion: bool = False
              ) -> Table | AccelerationRecord | VelocityRecord | None:
        inline = v.t is not None or v.value is not None
        if v.file is not None and inline:
            self.problem(where, "give either file, or t and value, not both")
            return None
        if v.file is None and not inline:
            self.problem(where, 'a table needs file = "points.csv" or inline t = [...] and '
                         "value = [...]")
            return None
        if v.quantity != "displacement" and not motion:
            self.problem(where + ("quantity",), f"quantity = {v.quantity!r} applies to support "
                         "motions only; a load's time function is a factor that multiplies it")
            return None
        if v.column is not None and v.file is None:
            self.problem(where + ("column",), "column selects a column of a table file; an "
                         "inline table has one list of values")
            return None
        if v.file is not None:
            rows = self.read_csv(v.file, where + ("file",), v.column, where + ("column",))
            if rows is None:
                return None
            t, value, at = [r[0] for r in rows], [r[1] for r in rows], where + ("file",)
        else:
            for k in ("t", "value"):
                if getattr(v, k) is None:
                    self.problem(where + (k,), f"missing: needed together with "
                                 f"{'value' if k == 't' else 't'}")
            if v.t is None or v.value is None:
                return None
            t, value, at = v.t, v.value, where + ("t",)
            if len(t) != len(value):
                self.problem(where + ("value",), f"expected {len(t)} values, one per time in "
                             f"t, found {len(value)}")
                return None
        if len(t) < 2:
            self.problem(at, f"expected at least 2 points, found {len(t)}")
            return None
        for j in range(1, len(t)):
            if not t[j] > t[j - 1]:
                self.problem(at, "expected strictly increasing times, found "
                             f"{t[j - 1]:g} then {t[j]:g} (point {j})")
                return None
        t, value = tuple(float(x) for x in t), tuple(float(x) for x in value)
        if v.quantity == "acceleration":
            return AccelerationRecord(t, value, v.file, v.column)
        if v.quantity == "velocity":
            return VelocityRecord(t, value, v.file, v.column)
        with np.errstate(all="ignore"), warnings.catch_warnings():
            # points too close for their values overflow the spline: judged by _finite
            warnings.simplefilter("ignore", RuntimeWarning)
            return Table(t, value, v.file)

    def read_csv(self, name: str, where: tuple, column: str | None = None,
                 column_where: tuple = ()) -> list[tuple[float, float]] | None:
        """Rows ``time, value`` of a CSV file; blank and ``#`` lines skipped, one header allowed.

        With ``column``, the file has a header naming its columns (time first) and the value
        is taken from the column of that name. The file must be a regular file inside the case's
        folder (or a folder listed in CATDAE_TABLE_ROOTS) of at most MAX_FILE_BYTES; problems
        name the line, never quote a data row.
        """
        try:
            file = confined(name, self.base_dir)
            raw = read_limited(file, "table file")
        except FileProblem as exc:
            self.problem(where, f"cannot read table file {_short(name)}: {exc}")
            return None
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            self.problem(where, f"cannot read table file {_short(name)}: not UTF-8 text "
                         f"(byte {exc.start})")
            return None
        lines = [(n, [c.strip() for c in row])
                 for n, row in enumerate(csv.reader(text.splitlines()), start=1)]
        lines = [(n, c) for n, c in lines if any(c) and not c[0].startswith("#")]
        header: list[str] | None = None
        if lines and not all(_is_float(c) for c in lines[0][1]):
            header = lines[0][1]  # a header line such as "time,value" or "t,ax,ay,az"
            lines = lines[1:]
        width = len(header) if header is not None else len(lines[0][1]) if lines else 2
        if column is None and width != 2:
            names = f" ({', '.join(header)})" if header is not None else ""
            self.problem(where, f"{name} has {width} columns{names}: choose the value column "
                         'with column = "<name>" (time is the first column)')
            return None
        index = 1
        if column is not None:
            if header is None:
                self.problem(column_where, f"column = {column!r} needs a header line in {name} "
                             "naming its columns, time first (e.g. t,ax,ay,az); found none")
                return None
            if column not in header[1:]:
                hint = (f"{column!r} is the time column" if column == header[0] else
                        f"{name} has no column {column!r}{_suggest(column, header[1:])} (its "
                        f"columns: {', '.join(header)}; time is the first)")
                self.problem(column_where, hint)
                return None
            index = header.index(column)
        expect = "two numbers 'time,value'" if width == 2 else f"{width} numbers per row"
        rows = []
        for lineno, cells in lines:
            if len(cells) != width or not all(_is_float(c) for c in cells):
                found = (f"{len(cells)} field(s)" if len(cells) != width
                         else "a field that is not a number")
                self.problem(where, f"{_short(name)}, line {lineno}: expected {expect}, found "
                             f"{found}")
                return None
            pair = (float(cells[0]), float(cells[index]))
            if not all(math.isfinite(float(c)) for c in cells):
                self.problem(where, f"{_short(name)}, line {lineno}: expected finite numbers, "
                             "found inf or nan")
                return None
            rows.append(pair)
        return rows

    def slack(self, cables: dict, materials: dict, nodes: dict, point_masses: list,
              loads: list, distributed: list) -> None:
        """A weightless cable with no load on it and length >= chord has no defined shape."""
        loaded = {x.cable for x in (*point_masses, *loads) if x.cable is not None}
        loaded |= {x.node.rpartition(".")[0] for x in (*point_masses, *loads)
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


def _mesh_node_problem(ref: str, elements: Mapping[str, int]) -> str | None:
    """Why ``<cable>.<k>`` is not a mesh node of one of ``elements`` (cable -> count), or None."""
    cable, dot, k = ref.rpartition(".")
    if not dot or cable not in elements:
        return _unknown(ref, "node", sorted(elements))
    n = elements[cable]
    if k.isdigit() and k.isascii() and 1 <= int(k) <= n - 1:
        if k == str(int(k)):
            return None
        return (f"mesh node {ref!r} is written with a leading zero: its name is "
                f"'{cable}.{int(k)}'")
    if n == 1:
        return (f"mesh node {ref!r} does not exist: cable {cable!r} has 1 element and so no "
                "interior mesh nodes")
    return (f"mesh node {ref!r} does not exist: cable {cable!r} has {n} elements, so its mesh "
            f"nodes are {cable}.1 .. {cable}.{n - 1}")


_GROUP_NAME = re.compile(r"\w[\w.+\-@ ]*")


def _group_name(name: str) -> bool:
    """A netCDF-4 group name that reads back as written: a letter, digit or '_' first (not
    '$', '.', '-'), no '/', no trailing space, NFC, at most 255 bytes."""
    return (_GROUP_NAME.fullmatch(name) is not None and not name.endswith(" ")
            and unicodedata.is_normalized("NFC", name) and len(name.encode()) <= 255)


def _finite(tf: TimeFunction) -> bool:
    """f, f' and f'' finite, and with finite squares (below 1e150: energies and norms square
    them), where they are largest: at 0, the breakpoints, inside a ramp (f'' peaks at x = 0.21
    and 0.79), at a quarter period, at a table's points and between."""
    ts = [0.0, *tf.breakpoints()]
    if isinstance(tf, Ramp):
        ts += [tf.start + tf.duration * x for x in (0.2113, 0.5, 0.7887)]
    elif isinstance(tf, Sine | Cosine):
        ts += [0.25 / tf.frequency, 0.5 / tf.frequency]
    elif isinstance(tf, Table):
        t = np.asarray(tf.t)
        ts += [*t, *(0.5 * (t[1:] + t[:-1]))]
    with np.errstate(all="ignore"):
        values = tf.evaluate(np.asarray(ts, float))
    return all((np.isfinite(v) & (np.abs(v) < 1e150)).all() for v in values)


def _is_float(cell: str) -> bool:
    """Whether a CSV cell reads as a number (inf and nan included: reported as not finite)."""
    try:
        float(cell)
    except ValueError:
        return False
    return True
