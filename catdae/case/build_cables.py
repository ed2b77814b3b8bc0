"""Pass 3 for the scene along the cables: cables with their form-finding targets, the things
placed on them (point masses, loads, distributed loads and their coverage). A mixin of
:class:`~catdae.case.build.Builder`, whose ``problem`` and ``validate`` collect what is
wrong (see ``build``)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from pydantic import BaseModel

from catdae.case.messages import found_text, unknown_word
from catdae.case.model import (
    Cable,
    DistributedLoad,
    Form,
    Load,
    PointMass,
)
from catdae.case.names import cable_of, mesh_node, split_mesh_node
from catdae.case.schema import (
    FORM_TARGETS,
    CableSchema,
    DistributedLoadSchema,
    FormSchema,
)

COINCIDENT_TOL = 1e-9  # m: cable ends closer than this coincide
MAX_STRAIN = 0.5  # a chord longer than (1 + MAX_STRAIN) * length is rejected


class CablesPass:
    """Cables and what lies on them (methods of ``_Builder``)."""

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
            c, ok = self.validate(CableSchema, item, where)
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
                    mesh = split_mesh_node(end)
                    self.problem(where + ("ends", j), (
                        f"{end!r} is a mesh node of cable {mesh[0]!r}: a cable ends at a node "
                        f"of [nodes] (split cable {mesh[0]!r} at a node there, or join the two "
                        "with a spring or a bar, which may end at mesh nodes)")
                        if mesh is not None and mesh[0] in self.cable_names
                        else unknown_word(end, "node", sorted(self.node_names)))
                    ok = False
            if c.material not in materials:
                if c.material not in self.material_names:
                    self.problem(where + ("material",),
                                 unknown_word(c.material, "material", sorted(self.material_names)))
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
        v, complete = self.validate(FormSchema, c.form, where + ("form",))
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
                             f"{list(c.ends)}, found {found_text(v.at)}")
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
        cable = cable_of(ref)
        if cable and cable in self.cable_names:
            if cable not in cables:
                return False  # the cable itself is invalid and already reported
            msg = _mesh_node_problem(ref, {n: c.elements for n, (_, c) in cables.items()})
            if msg:
                self.problem(where, msg)
                return False
            return True
        choices = sorted(self.node_names) + [
            mesh_node(n, k) for n, (_, c) in cables.items() for k in range(1, min(c.elements, 100))
        ]
        self.problem(where, unknown_word(ref, "node", choices))
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
            self.problem(where + ("cable",),
                         unknown_word(v.cable, "cable", sorted(self.cable_names)))
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
            v, ok = self.validate(DistributedLoadSchema, item, where)
            if v is None:
                continue
            if v.cable not in self.cable_names:
                self.problem(where + ("cable",),
                             unknown_word(v.cable, "cable", sorted(self.cable_names)))
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
        if length is None:
            return self.found_length_coverage(v, where, cable)
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

    def found_length_coverage(self, v: Any, where: tuple,
                              cable: Cable) -> tuple[float, float] | None:
        """A cable whose length form-finding finds is covered whole: ``(0, inf)``, the mesh
        clips it to the length found. Arc lengths are not known in advance, so a part
        coverage (``from_s``, ``to_s``) is refused."""
        ok = True
        for key in ("from_s", "to_s"):
            if getattr(v, key) is not None:
                self.problem(where + (key,), f"cable {cable.name!r} has its length found by "
                             "form-finding, so an arc length is not known in advance: a "
                             "distributed load on it covers the whole cable (leave out from_s "
                             "and to_s)")
                ok = False
        return (0.0, math.inf) if ok else None


def _mesh_node_problem(ref: str, elements: Mapping[str, int]) -> str | None:
    """Why ``<cable>.<k>`` is not a mesh node of one of ``elements`` (cable -> count), or None."""
    cable, k = split_mesh_node(ref) or ("", "")
    if cable not in elements:
        return unknown_word(ref, "node", sorted(elements))
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
