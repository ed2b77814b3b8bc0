"""Settings a command line (or ``catdae.run``'s keywords) replaces in a case: ``rtol``,
``atol``, ``max_order``, ``mass_model`` and ``elements``, validated by the case file's own
schema types (``schema.OverridesSchema``), with what sits on mesh nodes kept in place on a new
mesh."""

from __future__ import annotations

import argparse
import math
import numbers
from dataclasses import replace

from pydantic import ValidationError

from catdae.case.limits import size_problems
from catdae.case.messages import pydantic_message
from catdae.case.model import Case
from catdae.case.names import mesh_node, split_mesh_node
from catdae.case.schema import OverridesSchema
from catdae.errors import CaseError


def with_overrides(self: Case, rtol: float | None = None, atol: float | None = None,
                   elements: int | None = None, mass_model: str | None = None,
                   max_order: int | str | None = None) -> Case:
    """A new Case with ``rtol``/``atol``/``max_order`` set on every transient step, ``mass_model``
    (one of ``schema.MASS_MODEL_NAMES``) on every transient and modal step, and ``elements`` on
    every cable (``None`` leaves a setting as it is).

    With a new ``elements``, a load or point mass placed on a mesh node ``<cable>.<k>`` is
    kept at the same place on the cable (its unstrained arc length in the case's mesh).
    Raises ``CaseError`` if a value is invalid.
    """
    given = {"rtol": rtol, "atol": atol, "mass_model": mass_model, "max_order": max_order,
             "elements": (int(elements) if isinstance(elements, numbers.Integral)
                          and not isinstance(elements, bool) else elements)}
    try:
        OverridesSchema.model_validate({k: v for k, v in given.items() if v is not None})
    except ValidationError as exc:
        fields = list(OverridesSchema.model_fields)
        raise CaseError(self.path, [(str(err["loc"][0]), pydantic_message(err, fields, {}))
                                    for err in exc.errors()]) from None
    steps = tuple(
        replace(s, rtol=float(rtol if rtol is not None else s.rtol),
                atol=float(atol if atol is not None else s.atol),
                max_order=max_order if max_order is not None else s.max_order)
        if s.kind == "transient" else s
        for s in self.steps
    )
    if mass_model is not None:
        steps = tuple(replace(s, mass_model=mass_model) if s.kind != "static" else s
                      for s in steps)
    cables = self.cables
    point_masses, loads = self.point_masses, self.loads
    if elements is not None:
        cables = tuple(replace(c, elements=int(elements)) for c in cables)
        # a mass or load placed on a mesh node <cable>.<k> stays where it is on the cable:
        # at the unstrained arc length k L0 / n of the case's own mesh, which the new mesh
        # carries exactly (at a node, or inside an element)
        by_name = {c.name: c for c in self.cables}

        def keep_place(item):
            if item.node is None or item.node in self.nodes:
                return item
            cable, k = split_mesh_node(item.node)
            c = by_name[cable]
            if c.length is None:  # form-found: the length is not known yet
                k_new = int(k) * int(elements) / c.elements
                if k_new != int(k_new):
                    raise CaseError(self.path, [("elements", (
                        f"{item.name!r} sits on mesh node {item.node!r} of cable {cable!r}, "
                        f"whose length is found by form-finding; with {elements} elements "
                        "it would fall between mesh nodes: use a multiple of "
                        f"{c.elements // math.gcd(int(k), c.elements)} elements"))])
                return replace(item, node=mesh_node(cable, k_new))
            return replace(item, node=None, cable=cable, s=int(k) * c.length / c.elements)

        point_masses = tuple(keep_place(p) for p in point_masses)
        loads = tuple(keep_place(p) for p in loads)

        def keep_end(ref: str, what: str) -> str:  # a connector's end on a mesh node
            if ref in self.nodes:
                return ref
            cable, k = split_mesh_node(ref)
            k_new = int(k) * int(elements) / by_name[cable].elements
            if k_new != int(k_new):
                raise CaseError(self.path, [("elements", (
                    f"{what} ends on mesh node {ref!r}, which with {elements} elements would "
                    f"fall between mesh nodes: use a multiple of "
                    f"{by_name[cable].elements // math.gcd(int(k), by_name[cable].elements)} "
                    "elements"))])
            return mesh_node(cable, k_new)

        connectors = {section: tuple(
            replace(x, ends=tuple(keep_end(e, f"{section}.{x.name}") for e in x.ends))
            for x in getattr(self, section)) for section in ("springs", "dampers", "bars")}
    else:
        connectors = {}
    done = dict(self.overrides) | {k: v for k, v in given.items() if v is not None}
    done = {k: done[k] for k in sorted(done, key=lambda k: list(given).index(k)
                                       if k in given else len(given))}  # one order, however given
    case = replace(self, steps=steps, cables=cables, point_masses=point_masses,
                   loads=loads, overrides=tuple(done.items()), **connectors)
    problems = size_problems(case)  # more elements: the limits are judged again
    if problems:
        raise CaseError(self.path, problems)
    return case


def max_order_arg(text: str) -> int | str:
    """``--max-order`` of ``catdae run`` and ``catdae study``: "auto" or an integer 1 to 5,
    refused by the command line itself otherwise (as a --mass-model that is none: an option
    given on the command line is not a field of the case file)."""
    if text == "auto":
        return text
    try:
        value = int(text)
    except ValueError:
        value = 0
    if not 1 <= value <= 5:
        raise argparse.ArgumentTypeError(f"expected auto or 1-5, found {text!r}")
    return value
