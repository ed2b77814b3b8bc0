"""The settings of a step, decided once into typed objects (docs/theory.md §7, §8).

``MassModel``: which mass matrix a step uses and why (``mass_model`` of a step, with ``auto``
resolved for the scene); the solvers ask it questions (``catenary``, ``lumped_fraction``, ...)
instead of comparing names. ``DampingModel``: the damping of a step with Rayleigh coefficients
resolved. The names are parsed in ``catdae.case`` and written to results from ``name``/``kind``.
"""

from __future__ import annotations

from dataclasses import dataclass

# lumped fraction μ of mass_model = "blended": M = (1 - μ) M_consistent + μ M_lumped. μ = 1/2
# cancels the leading (second-order) frequency error of the two, which have opposite signs
# (docs/theory.md §7; measured in tests/scenes/test_modal.py and benchmarks/speed_accuracy.md)
BLEND_LUMPED = 0.5


@dataclass(frozen=True, eq=False)
class MassModel:
    """The mass model of a step: ``name`` (consistent, blended, lumped or linear), the
    ``setting`` the step gave (``auto`` or a name) and ``choice``, why (result attributes)."""

    name: str
    setting: str = "set by the step"
    choice: str = "set by the step"
    snap: str = ""  # why "auto" took a wave-carrying mass for a transient that can snap
    rerun: bool = False  # taken after a first run with a catenary mass (solvers/auto_rerun.py)

    @property
    def lumped_fraction(self) -> float:
        """μ: M = (1 - μ) M_catenary + μ M_lumped (1 lumped, 1/2 blended, 0 otherwise)."""
        return {"blended": BLEND_LUMPED, "lumped": 1.0}.get(self.name, 0.0)

    @property
    def catenary(self) -> bool:
        """Uses the catenary interpolation functions (consistent, blended): M depends on q,
        has ∂M/∂c and velocity terms."""
        return self.name in ("consistent", "blended")

    @property
    def linear(self) -> bool:
        """Straight-line interpolation: a constant matrix, the element a bar for inertia."""
        return self.name == "linear"

    @property
    def lumped(self) -> bool:
        """Only the lumped diagonal: a constant matrix."""
        return self.name == "lumped"

    @property
    def carries_axial_waves(self) -> bool:
        """Lumped and linear masses carry axial (snap) waves; the catenary ones, on slack
        elements, do not (docs/accuracy.md)."""
        return not self.catenary

    def __str__(self) -> str:
        return self.name

    def __eq__(self, other) -> bool:
        if isinstance(other, str):  # the settings are decided once: ask, do not compare names
            raise TypeError("compare a MassModel by its properties (.name, .catenary, .lumped, "
                            "...), not with a string")
        if not isinstance(other, MassModel):
            return NotImplemented
        return (self.name, self.setting, self.choice) == (other.name, other.setting,
                                                          other.choice)

    def __hash__(self) -> int:
        return hash((self.name, self.setting, self.choice))


def choose_mass_model(setting: str, kind: str, ends: list[str], snap: str = "",
                      rerun: bool = False) -> MassModel:
    """The mass model of a step: ``setting`` as given, or for ``"auto"`` (the default,
    docs/case-format.md, mass_model) "blended", except with a free-hanging end (``ends``, from
    ``catdae.model.loading.free_hanging_ends``): "consistent" for a modal step (the blend's
    lumped half puts mass on the tip, which has no lateral stiffness, and adds a spurious
    mode), "lumped" for a transient step (the consistent part breaks causality and the
    work-energy balance there; tests/scenes/test_extremes.py measures both). ``snap``: why a
    transient step can snap (``catdae.model.snap.snap_reason``; "" if it cannot): "lumped" then
    too, a mass that carries the axial wave of a snap (docs/theory.md §18.5); ``rerun``: found
    by a first run with a catenary mass (catdae.solvers.auto_rerun)."""
    if setting != "auto":
        return MassModel(setting, setting, "set by the step")
    if snap and kind == "transient":
        return MassModel("lumped", setting, f"auto: lumped (a transient that can snap: {snap})",
                         snap, rerun)
    if not ends:
        return MassModel("blended", setting, "auto: blended (no free-hanging end)")
    shown = ", ".join(ends[:3]) + (f" and {len(ends) - 3} more" if len(ends) > 3 else "")
    chosen = "consistent" if kind == "modal" else "lumped"
    return MassModel(chosen, setting, f"auto: {chosen} (free-hanging end at {shown})")


@dataclass(frozen=True)
class DampingModel:
    """The damping of a step, resolved: ``kind`` none, rayleigh (C = α M + β K) or material
    (c per metre on the absolute velocity, through the mass interpolation; docs/theory.md §7)."""

    kind: str = "none"
    alpha: float = 0.0
    beta: float = 0.0

    @classmethod
    def of_step(cls, damping) -> DampingModel:
        """From a case's ``Damping`` (or None)."""
        if damping is None:
            return cls()
        if damping.kind == "rayleigh":
            alpha, beta = damping.coefficients()
            return cls("rayleigh", alpha, beta)
        return cls(damping.kind)

    @property
    def damped(self) -> bool:
        return self.kind != "none"

    @property
    def material(self) -> bool:
        return self.kind == "material"
