"""TOML case file -> validated, frozen model of the scene and its analysis steps.

``load_case`` reads a case file (the public format, case-format.md, names every key) and returns a
:class:`Case`: frozen dataclasses, tuples and read-only mappings, nothing mutable. Reading works
in three passes, and every problem of every pass is collected before anything is raised, so that a
single :class:`~catdae.errors.CaseError` lists all of them with their field paths
(``cables[0].length``, ``materials.strand.EA``):

1. TOML syntax (``tomllib``); a malformed file stops here, with line and column.
2. Shape and types of each item on its own (pydantic v2 models, strict, ``extra='forbid'``):
   unknown keys get a did-you-mean suggestion, wrong types say what was expected and found.
3. Cross references and physics: names that exist and are unique, mesh-node references, supports,
   removals, coinciding ends, excessive strain, slack weightless cables.

An item that fails pass 2 is left out of pass 3, but its name still counts as declared so that
one typo does not cascade into a list of "unknown" errors elsewhere.

A case is data: values are only ever read as numbers, strings and tables, never evaluated, and no
module is imported by a name taken from the file. The only side effect is reading the CSV file a
``table`` time function names, relative to the case file's folder.
"""

from __future__ import annotations

import csv
import difflib
import math
import numbers
import os
import re
import tomllib
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, TypeAdapter, ValidationError

from .errors import CaseError
from .timefunc import Constant, Cosine, Ramp, Sine, Table, TimeFunction

__all__ = [
    "AXES",
    "Cable",
    "Case",
    "Damping",
    "DistributedLoad",
    "FrozenMap",
    "Load",
    "Material",
    "PointMass",
    "Step",
    "SupportMotion",
    "case_from_dict",
    "load_case",
]

AXES = ("x", "y", "z")
COINCIDENT_TOL = 1e-9  # m: cable ends closer than this coincide
MAX_STRAIN = 0.5  # a chord longer than (1 + MAX_STRAIN) * length is rejected


# ---------------------------------------------------------------------------------------------
# The frozen model
# ---------------------------------------------------------------------------------------------


class FrozenMap(Mapping):
    """A read-only, hashable, picklable mapping that keeps insertion order.

    Used instead of ``types.MappingProxyType`` because a ``Case`` must pickle (it is shipped to
    dask workers by the studies) and a mapping proxy does not.
    """

    __slots__ = ("_data",)

    def __init__(self, items: Mapping | Iterable[tuple[Any, Any]] = ()):
        object.__setattr__(self, "_data", dict(items))

    def __getitem__(self, key):
        return self._data[key]

    def __iter__(self) -> Iterator:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __hash__(self) -> int:
        return hash(tuple(self._data.items()))

    def __setattr__(self, name, value):
        raise AttributeError("FrozenMap is read-only")

    def __reduce__(self):
        return (FrozenMap, (tuple(self._data.items()),))

    def __repr__(self) -> str:
        return f"FrozenMap({self._data!r})"


@dataclass(frozen=True)
class Material:
    """A cable material.

    ``EA`` axial stiffness, N (> 0); ``mass`` kg per metre of unstrained cable (>= 0); ``weight``
    N per metre of unstrained cable (default ``mass * gravity``); ``damping`` material damping per
    unstrained length, N s/m² (>= 0, used by ``damping = { kind = "material" }``).
    """

    name: str
    EA: float
    mass: float
    weight: float
    damping: float = 0.0


@dataclass(frozen=True)
class Cable:
    """A cable between two named nodes, meshed into ``elements`` of equal unstrained length.

    ``length`` is the unstrained length L0 in m; ``gauss_points`` per element integrate mass,
    damping and distributed loads. Mesh nodes are ``<name>.<k>``, k = 1 .. elements - 1.
    """

    name: str
    ends: tuple[str, str]
    material: str
    length: float
    elements: int = 1
    gauss_points: int = 3


@dataclass(frozen=True)
class PointMass:
    """A concentrated mass in kg, at ``node`` or on ``cable`` at unstrained arc length ``s`` (m)."""

    name: str
    mass: float
    node: str | None = None
    cable: str | None = None
    s: float | None = None


@dataclass(frozen=True)
class Load:
    """A concentrated force (N, global x, y, z) at ``node`` or on ``cable`` at ``s``.

    ``time`` multiplies the force; ``None`` means a constant load (factor 1).
    """

    name: str
    force: tuple[float, float, float]
    node: str | None = None
    cable: str | None = None
    s: float | None = None
    time: TimeFunction | None = None


@dataclass(frozen=True)
class DistributedLoad:
    """A force per metre of unstrained cable (N/m, global axes) on the whole of ``cable``."""

    name: str
    cable: str
    load: tuple[float, float, float]
    time: TimeFunction | None = None


@dataclass(frozen=True)
class SupportMotion:
    """Prescribed displacement (m) of a supported node along fixed axes; ``None``: no motion."""

    node: str
    x: TimeFunction | None = None
    y: TimeFunction | None = None
    z: TimeFunction | None = None

    def moved(self) -> tuple[tuple[str, TimeFunction], ...]:
        """The ``(axis, function)`` pairs of the axes that move, in x, y, z order."""
        return tuple((a, f) for a in AXES if (f := getattr(self, a)) is not None)


@dataclass(frozen=True)
class Damping:
    """Damping of a transient step: ``material`` or ``rayleigh``.

    Rayleigh damping ``C = alpha M + beta K`` is given either by ``alpha`` and ``beta`` or by a
    damping ``ratio`` reached at two ``frequencies`` (Hz).
    """

    kind: Literal["material", "rayleigh"]
    alpha: float | None = None
    beta: float | None = None
    ratio: float | None = None
    frequencies: tuple[float, float] | None = None

    def coefficients(self) -> tuple[float, float]:
        """Rayleigh ``(alpha, beta)`` in (1/s, s).

        From a ratio ζ at two frequencies, with ω = 2πf, the standard two-frequency formula
        (Chopra, *Dynamics of Structures*, §11.4) giving exactly ζ at both:
        ``alpha = 2 ζ ω1 ω2 / (ω1 + ω2)``, ``beta = 2 ζ / (ω1 + ω2)``.
        """
        if self.kind != "rayleigh":
            raise ValueError("material damping has no Rayleigh coefficients")
        if self.alpha is not None and self.beta is not None:
            return self.alpha, self.beta
        if self.ratio is None or self.frequencies is None:
            raise ValueError("Rayleigh damping needs alpha and beta, or ratio and frequencies")
        w1, w2 = (2.0 * math.pi * f for f in self.frequencies)
        return 2.0 * self.ratio * w1 * w2 / (w1 + w2), 2.0 * self.ratio / (w1 + w2)


@dataclass(frozen=True)
class Step:
    """One analysis step. Fields that do not apply to ``kind`` keep their defaults.

    ``remove`` names point masses or loads taken away from this step on. Static: ``load_steps``.
    Modal: ``modes``, ``mass_model``. Transient: ``duration`` and ``output_interval`` (s),
    ``rtol``, ``atol``, ``damping``, ``max_order`` (IDA's BDF order limit), ``linear_solver``,
    ``mass_model``, ``inertia`` ("lagrangian": M(q) v' plus the velocity terms of Lagrange's
    equations for T = ½ vᵀ M(q) v, which conserve energy; "paper": M(q) v' alone, the form of
    Chang, Park & Lee 2008, which does not).
    """

    kind: Literal["static", "modal", "transient"]
    name: str
    remove: tuple[str, ...] = ()
    modes: int = 10
    duration: float | None = None
    output_interval: float | None = None
    rtol: float = 1e-6
    atol: float = 1e-8
    damping: Damping | None = None
    max_order: int = 5
    linear_solver: Literal["auto", "band", "sparse", "dense"] = "auto"
    mass_model: Literal["consistent", "lumped", "linear"] = "consistent"
    load_steps: int = 1
    inertia: Literal["lagrangian", "paper"] = "lagrangian"


@dataclass(frozen=True)
class Case:
    """A validated scene and its analysis steps. Build it with :func:`load_case`.

    ``nodes`` maps names to ``(x, y, z)`` in m; ``supports`` maps node names to their fixed axes
    (a subset of ``AXES`` in x, y, z order); ``gravity`` in m/s² acts along -z. ``path`` is the
    case file (``None`` for text), ``text`` its TOML text, ``name`` its stem. Constructing a Case
    directly skips validation; mappings and sequences are frozen either way.
    """

    title: str = ""
    source: str = ""
    gravity: float = 9.81
    materials: Mapping[str, Material] = field(default_factory=FrozenMap)
    nodes: Mapping[str, tuple[float, float, float]] = field(default_factory=FrozenMap)
    supports: Mapping[str, tuple[str, ...]] = field(default_factory=FrozenMap)
    cables: tuple[Cable, ...] = ()
    point_masses: tuple[PointMass, ...] = ()
    loads: tuple[Load, ...] = ()
    distributed_loads: tuple[DistributedLoad, ...] = ()
    support_motions: tuple[SupportMotion, ...] = ()
    steps: tuple[Step, ...] = ()
    path: str | None = None
    text: str = field(default="", repr=False)
    name: str = "case"

    def __post_init__(self):
        for key in ("materials", "nodes", "supports"):
            object.__setattr__(self, key, FrozenMap(getattr(self, key)))
        for key in ("cables", "point_masses", "loads", "distributed_loads", "support_motions",
                    "steps"):
            object.__setattr__(self, key, tuple(getattr(self, key)))

    def cable(self, name: str) -> Cable:
        """The cable called ``name``; ``KeyError`` if there is none."""
        for c in self.cables:
            if c.name == name:
                return c
        raise KeyError(f"no cable named {name!r}")

    def material_of(self, cable: Cable | str) -> Material:
        """The material of a cable (given as a :class:`Cable` or by name)."""
        c = self.cable(cable) if isinstance(cable, str) else cable
        return self.materials[c.material]

    def with_overrides(self, rtol: float | None = None, atol: float | None = None,
                       elements: int | None = None, mass_model: str | None = None) -> Case:
        """A new Case with ``rtol``/``atol`` set on every transient step, ``mass_model``
        ("consistent" or "lumped") on every transient and modal step, and ``elements`` on
        every cable (``None`` leaves a setting as it is).

        With a new ``elements``, a load or point mass placed on a mesh node ``<cable>.<k>`` is
        kept at the same place on the cable (its unstrained arc length in the case's mesh).
        Raises ``CaseError`` if a value is invalid.
        """
        problems: list[tuple[str, str]] = []
        for key, value in (("rtol", rtol), ("atol", atol)):
            if value is not None and not (_is_number(value) and 0 < value < math.inf):
                problems.append((key, f"expected a finite number > 0, found {_found(value)}"))
        if elements is not None and not (
            isinstance(elements, numbers.Integral) and not isinstance(elements, bool)
            and elements >= 1
        ):
            problems.append(("elements", f"expected an integer >= 1, found {_found(elements)}"))
        if mass_model is not None and mass_model not in ("consistent", "lumped", "linear"):
            problems.append(("mass_model", 'expected "consistent", "lumped" or "linear", '
                             f"found {_found(mass_model)}"))
        if problems:
            raise CaseError(self.path, problems)
        steps = tuple(
            replace(s, rtol=float(rtol if rtol is not None else s.rtol),
                    atol=float(atol if atol is not None else s.atol))
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
                cable, _, k = item.node.rpartition(".")
                c = by_name[cable]
                return replace(item, node=None, cable=cable, s=int(k) * c.length / c.elements)

            point_masses = tuple(keep_place(p) for p in point_masses)
            loads = tuple(keep_place(p) for p in loads)
        return replace(self, steps=steps, cables=cables, point_masses=point_masses,
                       loads=loads)


# ---------------------------------------------------------------------------------------------
# Reading
# ---------------------------------------------------------------------------------------------


def load_case(path_or_text: str | os.PathLike, *, name: str | None = None) -> Case:
    """Read and validate a case.

    ``path_or_text`` is a path (a ``PathLike``, or a one-line string ending in ``.toml`` or naming
    an existing file) or the TOML text itself. ``name`` defaults to the file's stem, or ``"case"``
    for text. A ``table`` time function's ``file`` is relative to the case file's folder (to the
    current directory for text). Raises ``CaseError`` listing every problem found.
    """
    path: str | None = None
    if isinstance(path_or_text, os.PathLike) or _looks_like_path(path_or_text):
        path = os.fspath(path_or_text)
        try:
            raw = Path(path).read_bytes()
        except OSError as exc:
            reason = exc.strerror or str(exc)
            raise CaseError(path, [("", f"cannot read the case file: {reason}")]) from None
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise CaseError(path, [("", f"the case file is not UTF-8 text: {exc}")]) from None
    elif isinstance(path_or_text, bytes | bytearray):
        try:
            text = bytes(path_or_text).decode("utf-8")
        except UnicodeDecodeError as exc:
            raise CaseError(None, [("", f"the case text is not UTF-8: {exc}")]) from None
    elif isinstance(path_or_text, str):
        text = path_or_text
    else:
        raise CaseError(None, [("", "expected a path or TOML text, found "
                                    f"{type(path_or_text).__name__}")])
    text = text.removeprefix("\ufeff")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CaseError(path, [("", _toml_message(str(exc)))]) from None
    except RecursionError:
        msg = "malformed TOML: arrays or tables nested too deeply"
        raise CaseError(path, [("", msg)]) from None
    if name is None:
        name = Path(path).stem if path else "case"
    base_dir = Path(path).parent if path else Path.cwd()
    return case_from_dict(data, path=path, text=text, name=name, base_dir=base_dir)


def case_from_dict(data: Mapping[str, Any], *, path: str | None = None, text: str = "",
                   name: str = "case", base_dir: str | os.PathLike | None = None) -> Case:
    """Validate an already-parsed case (the dict ``tomllib`` returns) and build the Case.

    ``base_dir`` resolves ``table`` files (default: the current directory).
    """
    if not isinstance(data, Mapping):
        raise CaseError(path, [("", f"expected a table of keys, found {_found(data)}")])
    builder = _Builder(path, Path(base_dir) if base_dir is not None else Path.cwd())
    return builder.build(dict(data), text=text, name=name)


def _looks_like_path(obj: Any) -> bool:
    if not isinstance(obj, str) or "\n" in obj:
        return False
    try:
        if Path(obj).exists():  # a file, or a directory (reported as unreadable)
            return True
    except (OSError, ValueError):
        return False
    return obj.strip().endswith(".toml") and "=" not in obj


def _toml_message(msg: str) -> str:
    m = re.search(r"\s*\(at line (\d+), column (\d+)\)\s*$", msg)
    if m:
        return f"malformed TOML at line {m[1]}, column {m[2]}: {msg[: m.start()]}"
    m = re.search(r"\s*\(at end of document\)\s*$", msg)
    if m:
        return f"malformed TOML at the end of the document: {msg[: m.start()]}"
    return f"malformed TOML: {msg}"


# ---------------------------------------------------------------------------------------------
# Pass 2: the shape of each item (pydantic)
# ---------------------------------------------------------------------------------------------

_STRICT = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False)

Pos = Annotated[float, Field(gt=0)]
NonNeg = Annotated[float, Field(ge=0)]
Vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
Name = Annotated[str, Field(min_length=1)]
TomlTable = dict[str, Any]  # validated later on its own (time functions, damping)


class _Top(BaseModel):
    model_config = _STRICT
    title: str = ""
    source: str = ""
    gravity: NonNeg = 9.81
    materials: dict[str, TomlTable] = {}
    nodes: dict[str, Any] = {}
    supports: dict[str, Any] = {}
    cables: list[TomlTable] = []
    point_masses: list[TomlTable] = []
    loads: list[TomlTable] = []
    distributed_loads: list[TomlTable] = []
    support_motions: list[TomlTable] = []
    steps: list[TomlTable] = []


class _Material(BaseModel):
    model_config = _STRICT
    EA: Pos
    mass: NonNeg
    weight: NonNeg | None = None
    damping: NonNeg = 0.0


class _Cable(BaseModel):
    model_config = _STRICT
    name: Name
    ends: Annotated[list[Name], Field(min_length=2, max_length=2)]
    material: Name
    length: Pos
    elements: Annotated[int, Field(ge=1)] = 1
    gauss_points: Annotated[int, Field(ge=1, le=10)] = 3


class _PointMass(BaseModel):
    model_config = _STRICT
    name: Name
    mass: Pos
    node: Name | None = None
    cable: Name | None = None
    s: NonNeg | None = None


class _Load(BaseModel):
    model_config = _STRICT
    name: Name
    force: Vec3
    node: Name | None = None
    cable: Name | None = None
    s: NonNeg | None = None
    time: TomlTable | None = None


class _DistributedLoad(BaseModel):
    model_config = _STRICT
    name: Name | None = None
    cable: Name
    load: Vec3
    time: TomlTable | None = None


class _SupportMotion(BaseModel):
    model_config = _STRICT
    node: Name
    x: TomlTable | None = None
    y: TomlTable | None = None
    z: TomlTable | None = None


class _StaticStep(BaseModel):
    model_config = _STRICT
    kind: Literal["static"]
    name: Name | None = None
    remove: list[Name] = []
    load_steps: Annotated[int, Field(ge=1)] = 1


class _ModalStep(BaseModel):
    model_config = _STRICT
    kind: Literal["modal"]
    name: Name | None = None
    remove: list[Name] = []
    modes: Annotated[int, Field(ge=1)] = 10
    mass_model: Literal["consistent", "lumped", "linear"] = "consistent"


class _TransientStep(BaseModel):
    model_config = _STRICT
    kind: Literal["transient"]
    name: Name | None = None
    remove: list[Name] = []
    duration: Pos
    output_interval: Pos
    rtol: Pos = 1e-6
    atol: Pos = 1e-8
    damping: TomlTable | None = None
    max_order: Annotated[int, Field(ge=1, le=5)] = 5
    linear_solver: Literal["auto", "band", "sparse", "dense"] = "auto"
    mass_model: Literal["consistent", "lumped", "linear"] = "consistent"
    inertia: Literal["lagrangian", "paper"] = "lagrangian"


_STEP_MODELS: dict[str, type[BaseModel]] = {
    "static": _StaticStep, "modal": _ModalStep, "transient": _TransientStep,
}


class _MaterialDamping(BaseModel):
    model_config = _STRICT
    kind: Literal["material"]


class _RayleighDamping(BaseModel):
    model_config = _STRICT
    kind: Literal["rayleigh"]
    alpha: NonNeg | None = None
    beta: NonNeg | None = None
    ratio: Pos | None = None
    frequencies: Annotated[list[Pos], Field(min_length=2, max_length=2)] | None = None


_DAMPING_MODELS: dict[str, type[BaseModel]] = {
    "material": _MaterialDamping, "rayleigh": _RayleighDamping,
}


class _ConstantTF(BaseModel):
    model_config = _STRICT
    kind: Literal["constant"]
    value: float


class _RampTF(BaseModel):
    model_config = _STRICT
    kind: Literal["ramp"]
    duration: Pos
    start: float = 0.0
    smooth: bool = False
    amplitude: float = 1.0


class _SineTF(BaseModel):
    model_config = _STRICT
    kind: Literal["sine", "cosine"]
    amplitude: float
    frequency: Pos
    phase: float = 0.0
    offset: float = 0.0


class _TableTF(BaseModel):
    model_config = _STRICT
    kind: Literal["table"]
    file: Name | None = None
    t: list[float] | None = None
    value: list[float] | None = None


_TIME_MODELS: dict[str, type[BaseModel]] = {
    "constant": _ConstantTF, "ramp": _RampTF, "sine": _SineTF, "cosine": _SineTF,
    "table": _TableTF,
}

_VEC3 = TypeAdapter(Vec3, config=ConfigDict(strict=True, allow_inf_nan=False))


# ---------------------------------------------------------------------------------------------
# Messages
# ---------------------------------------------------------------------------------------------

_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def _fmt_path(parts: Iterable[str | int]) -> str:
    """``("cables", 0, "length")`` -> ``cables[0].length``; odd keys are quoted."""
    out = ""
    for p in parts:
        if isinstance(p, int):
            out += f"[{p}]"
        else:
            if not _BARE_KEY.fullmatch(p):
                p = '"' + p.replace("\\", "\\\\").replace('"', '\\"') + '"'
            out += f".{p}" if out else p
    return out


def _short(s: str, n: int = 40) -> str:
    return repr(s if len(s) <= n else s[: n - 3] + "...")


def _found(v: Any) -> str:
    """Describe a TOML value in a message: what was found."""
    if v is None:
        return "nothing"
    if isinstance(v, bool):
        return f"the boolean {str(v).lower()}"
    if isinstance(v, int):
        text = str(v) if abs(v) < 10**30 else f"{str(v)[:10]}... (too large)"
        return f"the integer {text}"
    if isinstance(v, float):
        return f"the number {v!r}"
    if isinstance(v, str):
        return f"the string {_short(v)}"
    if isinstance(v, list | tuple):
        return f"an array of {len(v)} item{'s' if len(v) != 1 else ''}"
    if isinstance(v, Mapping):
        keys = ", ".join(_short(str(k), 20) for k in list(v)[:5])
        return f"a table with keys {keys}" if v else "an empty table"
    return f"a {type(v).__name__} value ({_short(str(v))})"


def _suggest(word: str, choices: Iterable[str]) -> str:
    close = difflib.get_close_matches(word, list(choices), n=1)
    return f"; did you mean {close[0]!r}?" if close else ""


def _unknown(word: str, what: str, choices: Iterable[str]) -> str:
    choices = list(choices)
    hint = _suggest(word, choices)
    if not hint:
        hint = (f"; expected one of: {', '.join(repr(c) for c in choices)}" if choices
                else f"; there is no {what} at all")
    return f"unknown {what} {_short(word)}{hint}"


def _message(err: dict, fields: Iterable[str], foreign: Mapping[str, str]) -> str:
    """Turn one pydantic error into 'expected ..., found ...'."""
    typ, inp, ctx = err["type"], err.get("input"), err.get("ctx") or {}
    found = _found(inp)
    if typ == "missing":
        return "missing: this key is required"
    if typ == "extra_forbidden":
        key = str(err["loc"][-1])
        if key in foreign:
            return f"key {key!r} {foreign[key]}"
        close = difflib.get_close_matches(key, list(fields), n=1)
        hint = (f"; did you mean {close[0]!r}?" if close
                else f"; expected one of: {', '.join(fields)}")
        return f"unknown key {_short(key)}{hint}"
    simple = {
        "float_type": "a number", "int_type": "an integer", "string_type": "a string",
        "bool_type": "true or false", "list_type": "an array", "dict_type": "a table",
        "finite_number": "a finite number", "string_too_short": "a non-empty string",
    }
    if typ in simple:
        return f"expected {simple[typ]}, found {found}"
    bounds = {"greater_than": (">", "gt"), "greater_than_equal": (">=", "ge"),
              "less_than": ("<", "lt"), "less_than_equal": ("<=", "le")}
    if typ in bounds:
        op, key = bounds[typ]
        return f"expected a value {op} {ctx.get(key)}, found {found}"
    if typ in ("too_short", "too_long"):
        # every array with a length constraint has an exact length: [x, y, z], ends, frequencies
        want = ctx.get("min_length") if typ == "too_short" else ctx.get("max_length")
        return f"expected an array of exactly {want} items, found {found}"
    if typ == "literal_error":
        hint = ""
        if isinstance(inp, str):
            hint = _suggest(inp, re.findall(r"'([^']*)'", str(ctx.get("expected", ""))))
        return f"expected {ctx.get('expected')}, found {found}{hint}"
    return f"{err.get('msg', 'invalid value')}, found {found}"


# ---------------------------------------------------------------------------------------------
# Passes 2 and 3
# ---------------------------------------------------------------------------------------------


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


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
        self.gravity = top.gravity
        self.material_names = set(top.materials)
        self.support_names = set(top.supports)
        if not top.supports and "supports" not in bad:
            self.problem(("supports",), "no support at all: the structure is free to drift; "
                         'fix at least one node, e.g. [supports] A = "pinned"')
        materials = self.materials(top.materials)
        nodes = self.nodes(top.nodes)
        supports = self.supports(top.supports, nodes)
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
        self.slack(cables, materials, nodes, point_masses, loads, distributed)
        if self.problems:
            raise CaseError(self.path, self.problems)
        return Case(
            title=top.title, source=top.source, gravity=top.gravity,
            materials=FrozenMap(materials), nodes=FrozenMap(nodes),
            supports=FrozenMap(supports), cables=tuple(c for _, c in cables.values()),
            point_masses=tuple(point_masses), loads=tuple(loads),
            distributed_loads=tuple(distributed), support_motions=tuple(motions),
            steps=tuple(steps), path=self.path, text=text, name=name,
        )

    def materials(self, raw: dict[str, dict]) -> dict[str, Material]:
        out = {}
        for key, item in raw.items():
            m, complete = self.validate(_Material, item, ("materials", key))
            if complete:
                weight = m.mass * self.gravity if m.weight is None else m.weight
                out[key] = Material(key, m.EA, m.mass, weight, m.damping)
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
            if ok and a in nodes and b in nodes:
                chord = math.dist(nodes[a], nodes[b])
                if chord < COINCIDENT_TOL:
                    self.problem(where + ("ends",), f"the ends {a!r} and {b!r} coincide "
                                 f"(distance {chord:.3g} m < {COINCIDENT_TOL:g} m)")
                    ok = False
                elif chord > (1.0 + MAX_STRAIN) * c.length:
                    strain = chord / c.length - 1.0
                    self.problem(where + ("length",), (
                        f"the chord {a}-{b} is {chord:.6g} m but the unstrained length is "
                        f"{c.length:.6g} m: a strain of at least {strain:.0%}, above the "
                        f"{MAX_STRAIN:.0%} this model accepts; check the length and the node "
                        "coordinates"))
                    ok = False
            if ok:
                out[c.name] = (i, Cable(c.name, (a, b), c.material, float(c.length),
                                        c.elements, c.gauss_points))
        return out

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
                out.append(Load(v.name, tuple(float(f) for f in v.force), v.node, v.cable, s, time))
            else:
                out.append(PointMass(v.name, float(v.mass), v.node, v.cable, s))
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
            if not ok or v.cable not in cables or (v.time is not None and time is None):
                continue
            out.append(DistributedLoad(v.name or f"distributed{i}", v.cable,
                                       tuple(float(f) for f in v.load), time))
        return out

    def unique_names(self, top: _Top) -> None:
        """Point masses, loads and distributed loads share one namespace."""
        self.removable: dict[str, str] = {}
        self.distributed_names: set[str] = set()
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
                if section == "distributed_loads":
                    self.distributed_names.add(nm)
                else:
                    self.removable[nm] = here

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
                funcs[axis] = self.time_function(spec, where + (axis,))
                ok = ok and funcs[axis] is not None
            if ok and fixed is not None:
                out.append(SupportMotion(v.node, **funcs))
        return out

    def steps(self, raw: list[dict]) -> list[Step]:
        out = []
        names: dict[str, int] = {}
        removed: dict[str, str] = {}
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
            elif "/" in nm:
                self.problem(where + ("name",), f"step names may not contain '/' (they name "
                             f"result groups), found {nm!r}")
            names.setdefault(nm, i)
            if v is None:
                continue
            for j, r in enumerate(v.remove):
                if r in removed:
                    self.problem(where + ("remove", j), f"{r!r} is already removed by "
                                 f"{removed[r]}")
                elif r in self.removable:
                    removed[r] = f"step {nm!r} ({_fmt_path(where)})"
                elif r in self.distributed_names:
                    self.problem(where + ("remove", j), f"{r!r} is a distributed load; only "
                                 "point masses and loads can be removed")
                else:
                    self.problem(where + ("remove", j), _unknown(r, "point mass or load",
                                                                 sorted(self.removable)))
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
                extra = {"duration": float(v.duration), "output_interval": float(v.output_interval),
                         "rtol": float(v.rtol), "atol": float(v.atol), "damping": damping,
                         "max_order": v.max_order, "linear_solver": v.linear_solver,
                         "mass_model": v.mass_model, "inertia": v.inertia}
            if complete:
                out.append(Step(kind=kind, name=nm, remove=tuple(v.remove), **extra))
        return out

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

    def time_function(self, raw: dict, where: tuple) -> TimeFunction | None:
        kind = self.kind_of(raw, where, _TIME_MODELS, "time function kind")
        if kind is None:
            return None
        v, complete = self.validate(_TIME_MODELS[kind], raw, where)
        if not complete:
            return None
        if kind == "constant":
            return Constant(float(v.value))
        if kind == "ramp":
            return Ramp(float(v.duration), float(v.start), v.smooth, float(v.amplitude))
        if kind in ("sine", "cosine"):
            cls = Sine if kind == "sine" else Cosine
            return cls(float(v.amplitude), float(v.frequency), float(v.phase), float(v.offset))
        return self.table(v, where)

    def table(self, v: _TableTF, where: tuple) -> Table | None:
        inline = v.t is not None or v.value is not None
        if v.file is not None and inline:
            self.problem(where, "give either file, or t and value, not both")
            return None
        if v.file is None and not inline:
            self.problem(where, 'a table needs file = "points.csv" or inline t = [...] and '
                         "value = [...]")
            return None
        if v.file is not None:
            rows = self.read_csv(v.file, where + ("file",))
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
        return Table(tuple(float(x) for x in t), tuple(float(x) for x in value), v.file)

    def read_csv(self, name: str, where: tuple) -> list[tuple[float, float]] | None:
        """Rows ``time, value`` of a CSV file; blank and ``#`` lines skipped, one header allowed."""
        file = self.base_dir / name
        try:
            text = file.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            reason = getattr(exc, "strerror", None) or str(exc)
            self.problem(where, f"cannot read table file {name!r} (looked for {str(file)!r}): "
                         f"{reason}")
            return None
        rows = []
        for lineno, row in enumerate(csv.reader(text.splitlines()), start=1):
            cells = [c.strip() for c in row]
            if not any(cells) or cells[0].startswith("#"):
                continue
            try:
                pair = (float(cells[0]), float(cells[1])) if len(cells) == 2 else None
            except ValueError:
                pair = None
            if pair is None:
                if not rows and lineno == 1:
                    continue  # a header line such as "time,value"
                self.problem(where, f"{name}, line {lineno}: expected two numbers 'time,value', "
                             f"found {_short(','.join(row))}")
                return None
            if not all(math.isfinite(x) for x in pair):
                self.problem(where, f"{name}, line {lineno}: expected finite numbers, found "
                             f"{_short(','.join(row))}")
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
            if materials[c.material].weight > 0 or name in loaded:
                continue
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
        return None
    if n == 1:
        return (f"mesh node {ref!r} does not exist: cable {cable!r} has 1 element and so no "
                "interior mesh nodes")
    return (f"mesh node {ref!r} does not exist: cable {cable!r} has {n} elements, so its mesh "
            f"nodes are {cable}.1 .. {cable}.{n - 1}")
