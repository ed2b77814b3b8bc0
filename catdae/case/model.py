"""The frozen model of a scene: what :func:`~catdae.case.load_case` returns and catdae reads.

Frozen dataclasses, tuples and read-only mappings, nothing mutable. Constructing these directly
skips validation.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

from catdae.case.build_connectors import Bar, Damper, Spring
from catdae.case.fluid import Air, Water
from catdae.case.sweep import Sweep
from catdae.case.timefunc import TimeFunction

AXES = ("x", "y", "z")
# docs/case-format.md, mass_model



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
    unstrained length, N s/m² (>= 0, used by ``damping = { kind = "material" }``);
    ``thermal_expansion`` α in 1/K: a temperature change ΔT adds the strain α ΔT.
    In water or air (docs/theory.md §13): ``diameter`` d, m (0: the line feels no fluid), the
    drag coefficients ``drag_normal`` and ``drag_axial`` and the added-mass coefficients
    ``added_mass_normal`` and ``added_mass_axial`` (MoorDyn's Cd, CdAx, Ca, CaAx).
    ``rated_strength`` N (optional): results quote tensions as a percentage of it.
    """

    name: str
    EA: float
    mass: float
    weight: float
    damping: float = 0.0
    thermal_expansion: float = 0.0
    diameter: float = 0.0
    drag_normal: float = 0.0
    drag_axial: float = 0.0
    added_mass_normal: float = 0.0
    added_mass_axial: float = 0.0
    rated_strength: float | None = None  # N: the tension quoted as 100 % (optional)


@dataclass(frozen=True)
class Form:
    """A form-finding target that replaces a cable's ``length``.

    ``kind`` is ``pretension`` (N: L0 = chord / (1 + T/EA), the member taken straight),
    ``horizontal_tension`` (N, at the cable's first end), ``tension`` (N, at end node ``at``) or
    ``sag`` (m, the largest vertical distance below the chord), all but ``pretension`` holding in
    the case's first static step.
    """

    kind: Literal["pretension", "horizontal_tension", "tension", "sag"]
    value: float
    at: str | None = None


@dataclass(frozen=True)
class Cable:
    """A cable between two named nodes, meshed into ``elements`` of equal unstrained length.

    ``length`` is the unstrained length L0 in m (at the reference temperature); ``gauss_points``
    per element integrate mass, damping and distributed loads. Mesh nodes are ``<name>.<k>``,
    k = 1 .. elements - 1. With a ``form`` other than ``pretension`` the length is found by the
    first static step and is ``None`` until then (see :mod:`catdae.model.formfind`).
    """

    name: str
    ends: tuple[str, str]
    material: str
    length: float | None
    elements: int = 1
    gauss_points: int = 3
    form: Form | None = None


@dataclass(frozen=True)
class PointMass:
    """A concentrated mass in kg, at ``node`` or on ``cable`` at unstrained arc length ``s`` (m).

    ``active = False``: absent until a step adds it.
    """

    name: str
    mass: float
    node: str | None = None
    cable: str | None = None
    s: float | None = None
    active: bool = True


@dataclass(frozen=True)
class Load:
    """A concentrated force (N, global x, y, z) at ``node`` or on ``cable`` at ``s``.

    ``time`` multiplies the force; ``None`` means a constant load (factor 1). ``active =
    False``: absent until a step adds it.
    """

    name: str
    force: tuple[float, float, float]
    node: str | None = None
    cable: str | None = None
    s: float | None = None
    time: TimeFunction | None = None
    active: bool = True


@dataclass(frozen=True)
class DistributedLoad:
    """A force per metre of unstrained cable (N/m, global axes) on ``from_s <= s <= to_s`` of
    ``cable`` (unstrained arc length, m; by default the whole cable). ``time`` multiplies the
    load; ``active = False``: absent until a step adds it.
    """

    name: str
    cable: str
    load: tuple[float, float, float]
    time: TimeFunction | None = None
    from_s: float = 0.0
    to_s: float = math.inf
    active: bool = True


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
class AxialDamping:
    """Strain-rate (Kelvin-Voigt) damping of a transient step: a share ``ratio`` of critical at
    ``frequency`` (Hz), or at each element's highest axial frequency (``"element"``); it acts
    on the axial strain rate only (docs/theory.md §18), or with ``rate = "chord"`` on the rate
    of change of the element's chord length (§18.6)."""

    ratio: float
    frequency: float | Literal["element"] = "element"
    rate: Literal["strain", "chord"] = "strain"


@dataclass(frozen=True)
class Step:
    """One analysis step. Fields that do not apply to ``kind`` keep their defaults.

    ``add`` names point masses or loads (``active = false``, or removed before) present from
    this step on; ``remove`` those taken away from this step on. ``temperature_change`` (K)
    from the reference temperature, from this step on: a number for every cable, a mapping
    cable name -> K (cables not named: 0), or ``None`` to keep that of the previous step (0 at
    the start). Static: ``load_steps``.
    Modal: ``modes``, ``mass_model``. Transient: ``duration`` and ``output_interval`` (s),
    ``rtol``, ``atol``, ``damping``, ``max_order`` (IDA's BDF order limit), ``linear_solver``,
    ``mass_model``, ``inertia`` ("lagrangian": M(q) v' plus the velocity terms of Lagrange's
    equations for T = ½ vᵀ M(q) v, which conserve energy; "paper": M(q) v' alone, the form of
    Chang, Park & Lee 2008, which does not), ``axial_damping`` (strain-rate damping, None:
    none), ``resolve`` (which motion IDA's error test follows: "output", "waves" or "auto";
    catdae.solvers.tolerance).
    """

    kind: Literal["static", "modal", "transient"]
    name: str
    remove: tuple[str, ...] = ()
    add: tuple[str, ...] = ()
    modes: int = 10
    duration: float | None = None
    output_interval: float | None = None
    rtol: float = 1e-6
    atol: float = 1e-8
    damping: Damping | None = None
    max_order: int | Literal["auto"] = "auto"
    linear_solver: Literal["auto", "band", "sparse", "dense"] = "auto"
    mass_model: Literal["auto", "blended", "consistent", "lumped", "linear"] = "auto"
    load_steps: int = 1
    inertia: Literal["lagrangian", "paper"] = "lagrangian"
    temperature_change: float | Mapping[str, float] | None = None
    jump_reference: str | None = None  # transient: an earlier static step (jump_height)
    sweep: Sweep | None = None
    axial_damping: AxialDamping | None = None
    resolve: Literal["auto", "output", "waves"] = "auto"

    def __post_init__(self):
        if isinstance(self.temperature_change, Mapping):
            object.__setattr__(self, "temperature_change", FrozenMap(self.temperature_change))


@dataclass(frozen=True)
class Seabed:
    """A flat seabed at height ``z`` (m, along "up" = -gravity). ``stiffness`` Pa/m (None:
    rigid, static steps only) and ``damping`` Pa s/m act per unit contact area (diameter ×
    unstrained length); Coulomb ``friction_axial``/``friction_lateral`` coefficients, smoothed
    below ``friction_velocity`` (m/s). docs/theory.md §17."""

    z: float
    stiffness: float | None = None
    damping: float = 0.0
    friction_axial: float = 0.0
    friction_lateral: float = 0.0
    friction_velocity: float = 0.01


@dataclass(frozen=True)
class Case:
    """A validated scene and its analysis steps. Build it with :func:`load_case`.

    ``nodes`` maps names to ``(x, y, z)`` in m; ``supports`` maps node names to their fixed axes
    (a subset of ``AXES`` in x, y, z order); ``gravity`` in m/s² acts along the unit vector
    ``gravity_direction`` (default -z); ``water`` and ``air`` the fluids around the cables
    (``None``: none). ``path`` is the
    case file (``None`` for text), ``text`` its TOML text, ``name`` its stem. Constructing a Case
    directly skips validation; mappings and sequences are frozen either way.
    """

    title: str = ""
    source: str = ""
    gravity: float = 9.81
    gravity_direction: tuple[float, float, float] = (0.0, 0.0, -1.0)
    materials: Mapping[str, Material] = field(default_factory=FrozenMap)
    nodes: Mapping[str, tuple[float, float, float]] = field(default_factory=FrozenMap)
    supports: Mapping[str, tuple[str, ...]] = field(default_factory=FrozenMap)
    cables: tuple[Cable, ...] = ()
    point_masses: tuple[PointMass, ...] = ()
    loads: tuple[Load, ...] = ()
    distributed_loads: tuple[DistributedLoad, ...] = ()
    support_motions: tuple[SupportMotion, ...] = ()
    springs: tuple[Spring, ...] = ()
    dampers: tuple[Damper, ...] = ()
    bars: tuple[Bar, ...] = ()
    steps: tuple[Step, ...] = ()
    reference_temperature: float | None = None  # °C: where lengths hold (steps' temperature)
    ground: Any = None  # catdae.case.ground.Ground: clearance results
    water: Water | None = None  # docs/case-format.md, "Water and air"
    air: Air | None = None
    seabed: Seabed | None = None
    path: str | None = None
    text: str = field(default="", repr=False)
    name: str = "case"
    # settings given over the case file's (with_overrides: --rtol, --elements, ...), in order
    overrides: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self):
        for key in ("materials", "nodes", "supports"):
            object.__setattr__(self, key, FrozenMap(getattr(self, key)))
        for key in ("cables", "point_masses", "loads", "distributed_loads", "support_motions",
                    "springs", "dampers", "bars", "steps"):
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
                       elements: int | None = None, mass_model: str | None = None,
                       max_order: int | str | None = None) -> Case:
        """A new Case with ``rtol``/``atol``/``max_order`` on every transient step,
        ``mass_model`` on every transient and modal step and ``elements`` on every cable
        (``None`` leaves a setting as it is); see :func:`catdae.case.overrides.with_overrides`."""
        from catdae.case.overrides import with_overrides

        return with_overrides(self, rtol=rtol, atol=atol, elements=elements,
                              mass_model=mass_model, max_order=max_order)
