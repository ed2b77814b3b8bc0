"""Pass 2 and 3 for the connectors of a case: ``[[springs]]``, ``[[dampers]]`` and ``[[bars]]``
(docs/case-format.md, Connectors). A mixin of :class:`~catdae.case.build.Builder`, whose
``problem`` and ``validate`` collect what is wrong (see ``build``).

Each connector joins two nodes, ``ends = [node, node]``: named nodes of ``[nodes]`` (a
supported one is the ground) or cable mesh nodes ``<cable>.<k>``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated, Any

from pydantic import BaseModel, Field

from catdae.case.messages import unknown_word
from catdae.case.schema import STRICT

_Pos = Annotated[float, Field(gt=0)]
_NonNeg = Annotated[float, Field(ge=0)]
_Name = Annotated[str, Field(min_length=1)]
_Ends = Annotated[list[_Name], Field(min_length=2, max_length=2)]

SECTIONS = ("springs", "dampers", "bars")
COINCIDENT_TOL = 1e-9  # m: connector ends closer than this coincide


class _Spring(BaseModel):
    model_config = STRICT
    name: _Name
    ends: _Ends
    stiffness: _Pos  # N/m
    length: _Pos | None = None  # m at rest; default the initial distance


class _Damper(BaseModel):
    model_config = STRICT
    name: _Name
    ends: _Ends
    coefficient: _NonNeg  # N s/m


class _Bar(BaseModel):
    model_config = STRICT
    name: _Name
    ends: _Ends
    EA: _Pos  # N
    mass: _NonNeg = 0.0  # kg/m
    length: _Pos | None = None  # m unstrained; default the initial distance


_MODELS = {"springs": _Spring, "dampers": _Damper, "bars": _Bar}


@dataclass(frozen=True)
class Spring:
    """A linear spring along the line joining its ends: ``stiffness`` N/m, ``length`` at rest
    (m; None: the distance between the ends in the meshed reference configuration)."""

    name: str
    ends: tuple[str, str]
    stiffness: float
    length: float | None = None


@dataclass(frozen=True)
class Damper:
    """A linear viscous damper along the line joining its ends: ``coefficient`` N s/m."""

    name: str
    ends: tuple[str, str]
    coefficient: float


@dataclass(frozen=True)
class Bar:
    """A straight two-node member: axial stiffness ``EA`` N, ``mass`` kg per metre and
    unstrained ``length`` m (None: the distance between the ends in the reference)."""

    name: str
    ends: tuple[str, str]
    EA: float
    mass: float = 0.0
    length: float | None = None


_BUILD = {"springs": Spring, "dampers": Damper, "bars": Bar}


def connector_ends(top: Any) -> set[str]:
    """The node names the connectors of the parsed file name (before any validation)."""
    return {e for section in SECTIONS for item in getattr(top, section)
            if isinstance(item, dict) and isinstance(item.get("ends"), list)
            for e in item["ends"] if isinstance(e, str)}


class ConnectorsPass:
    """Springs, dampers and bars (methods of ``_Builder``)."""

    def connectors(self, top: Any, cables: dict, nodes: dict) -> dict[str, tuple]:
        """The valid connectors of each section: {section: tuple of Spring/Damper/Bar}."""
        out: dict[str, tuple] = {}
        seen: dict[str, str] = {}
        self.faulty_connectors: set[str] = set()  # not built: their problems are said
        for section in SECTIONS:
            items = []
            for i, item in enumerate(getattr(top, section)):
                where = (section, i)
                nm = item.get("name") if isinstance(item, dict) else None
                if isinstance(nm, str):
                    if nm in seen:
                        self.problem(where + ("name",), f"duplicate connector name {nm!r} (also "
                                     f"{seen[nm]}); springs, dampers and bars share one "
                                     "namespace")
                        continue
                    seen[nm] = f"{section}[{i}]"
                v, ok = self.validate(_MODELS[section], item, where)
                if isinstance(nm, str):
                    self.faulty_connectors.add(nm)  # until it is built (below)
                if v is None:
                    continue
                a, b = v.ends
                for k, ref in enumerate(v.ends):
                    ok = self.connector_end(ref, where + ("ends", k), cables) and ok
                if a == b:
                    self.problem(where + ("ends",), f"the two ends are the same node {a!r}: a "
                                 "connector joins two different nodes")
                    ok = False
                elif (ok and a in nodes and b in nodes
                      and math.dist(nodes[a], nodes[b]) <= COINCIDENT_TOL
                      and (section == "dampers" or v.length is None)):
                    what = ("a bar of zero length" if section == "bars" else
                            "a spring of zero length" if section == "springs" else
                            "a damper of zero length: its line of action is undefined")
                    self.problem(where + ("ends",), f"{what}: nodes {a!r} and {b!r} coincide"
                                 + ("" if section == "dampers" else "; give its length"))
                    ok = False
                if ok:
                    fields = v.model_dump()
                    fields["ends"] = (a, b)
                    items.append(_BUILD[section](**fields))
                    self.faulty_connectors.discard(v.name)
            out[section] = tuple(items)
        return out

    def connector_end(self, ref: str, where: tuple, cables: dict) -> bool:
        """A connector end: a [nodes] entry, or a mesh node ``<cable>.<k>``."""
        if ref in self.node_names:
            return True
        cable, dot, _k = ref.rpartition(".")
        if dot and cable in self.cable_names:
            return self.node_ref(ref, where, cables)
        on = next((c for c in self.cable_names if ref.startswith((f"{c}@", f"{c}."))), None)
        if on is not None:  # a place between mesh nodes ("c@s=3.5", "c.3.5")
            n = cables[on][1].elements if on in cables else None
            self.problem(where, (
                f"{ref!r} is not a node: a connector ends on a [nodes] entry or on a mesh node "
                f"'{on}.<k>' of cable {on!r} (k = 1 to "
                f"{'n - 1' if n is None else n - 1}, at unstrained arc length k L0 / n"
                f"{'' if n is None else f' with its {n} elements'}); to end one at another "
                "place, choose the cable's elements so that a mesh node falls there"))
            return False
        choices = sorted(self.node_names) + [
            f"{n}.{k}" for n, (_, c) in cables.items() for k in range(1, min(c.elements, 100))
        ]
        self.problem(where, unknown_word(ref, "node", choices))
        return False
