"""Sweeps: one step repeated over a list of values of one field (docs/case-format.md, Sweeps).

``sweep = { field = "...", values = [...] }`` in a step. The fields that can be swept:

- ``dampers.<name>.coefficient``, ``springs.<name>.stiffness``, ``springs.<name>.length``,
  ``bars.<name>.EA``, ``bars.<name>.mass``, ``bars.<name>.length``: a connector's field;
- ``temperature_change``: the step's temperature change, K, for every cable;
- ``load_factor``: a factor on every point load and distributed load of the case (not on the
  self-weight nor on point masses).

``apply_sweep`` gives the case and step of one value; the pipeline runs them in turn from the
same starting state (catdae.analysis).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from catdae.case.messages import found_text, is_number, unknown_word

# field of a connector section -> (lowest value, whether the lowest is allowed)
_CONNECTOR_FIELDS = {
    "dampers": {"coefficient": (0.0, True)},
    "springs": {"stiffness": (0.0, False), "length": (0.0, False)},
    "bars": {"EA": (0.0, False), "mass": (0.0, True), "length": (0.0, False)},
}
_STEP_FIELDS = ("temperature_change", "load_factor")


@dataclass(frozen=True)
class Sweep:
    """A step's sweep: the ``field`` it varies and the ``values`` it takes, in order."""

    field: str
    values: tuple[float, ...]


class SweepPass:
    """A step's ``sweep`` (a method of ``_Builder``)."""

    def sweep(self, raw: Any, where: tuple, connectors: dict) -> Sweep | None | bool:
        """The validated sweep, None when absent, False when bad (reported)."""
        if raw is None:
            return None
        where = where + ("sweep",)
        if not isinstance(raw, dict):
            self.problem(where, 'expected a table { field = "...", values = [...] }, found '
                         f"{found_text(raw)}")
            return False
        extra = sorted(set(raw) - {"field", "values"})
        for key in extra:
            self.problem(where + (key,), unknown_word(key, "key", ["field", "values"]))
        field, values = raw.get("field"), raw.get("values")
        ok = not extra
        fields = list(_STEP_FIELDS) + [f"{s}.<name>.{f}" for s, fs in
                                        _CONNECTOR_FIELDS.items() for f in fs]
        low = None
        if not isinstance(field, str):
            self.problem(where + ("field",), f"expected one of {fields}, found {found_text(field)}")
            ok = False
        elif field not in _STEP_FIELDS:
            section, _, rest = field.partition(".")
            name, _, attr = rest.rpartition(".")
            names = {x.name for x in connectors.get(section, ())}
            if section not in _CONNECTOR_FIELDS or attr not in _CONNECTOR_FIELDS[section]:
                self.problem(where + ("field",), f"expected one of {fields}, found "
                             f"{found_text(field)}")
                ok = False
            elif name not in names:
                if name not in getattr(self, "faulty_connectors", ()):  # else said already
                    self.problem(where + ("field",),
                                 unknown_word(name, section[:-1], sorted(names)))
                ok = False
            else:
                low = _CONNECTOR_FIELDS[section][attr]
        if not (isinstance(values, list) and values and all(is_number(v) for v in values)):
            self.problem(where + ("values",), "expected a non-empty list of finite numbers, "
                         f"found {found_text(values)}")
            return False
        if low is not None:
            bound, inclusive = low
            for k, v in enumerate(values):
                if v < bound or (v == bound and not inclusive):
                    self.problem(where + ("values", k), f"expected a value "
                                 f"{'>=' if inclusive else '>'} {bound:g} for {field}, found "
                                 f"{found_text(v)}")
                    ok = False
        steps = [b - a for a, b in zip(values, values[1:], strict=False)]
        if not (all(d > 0 for d in steps) or all(d < 0 for d in steps)):
            self.problem(where + ("values",), "expected values in strictly increasing or "
                         f"decreasing order (they label the results' sweep coordinate, and "
                         f"sel(sweep=v) picks one), found {found_text(values)}")
            ok = False
        return Sweep(field, tuple(float(v) for v in values)) if ok else False


def apply_sweep(case, step, value: float):
    """(case, step) of one value of ``step.sweep``: the step without its sweep, the case or
    the step with the field set to ``value``."""
    field = step.sweep.field
    step = dataclasses.replace(step, sweep=None)
    if field == "temperature_change":
        return case, dataclasses.replace(step, temperature_change=value)
    if field == "load_factor":
        loads = tuple(dataclasses.replace(x, force=tuple(value * f for f in x.force))
                      for x in case.loads)
        distributed = tuple(dataclasses.replace(x, load=tuple(value * f for f in x.load))
                            for x in case.distributed_loads)
        return dataclasses.replace(case, loads=loads, distributed_loads=distributed), step
    section, _, rest = field.partition(".")
    name, _, attr = rest.rpartition(".")
    items = tuple(dataclasses.replace(x, **{attr: value}) if x.name == name else x
                  for x in getattr(case, section))
    return dataclasses.replace(case, **{section: items}), step


UNITS = {"coefficient": "N s/m", "stiffness": "N/m", "length": "m", "EA": "N", "mass": "kg/m",
         "temperature_change": "K", "load_factor": "1"}


def units(field: str) -> str:
    """The units of a swept field's values."""
    return UNITS[field.rpartition(".")[2]]
