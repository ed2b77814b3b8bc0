"""Pass 2: the shape and types of each item on its own (pydantic v2 models).

Strict, ``extra='forbid'``, no inf or nan: every key a case file may hold is declared here, with
its type, bounds and default. Sections whose content depends on a ``kind`` (steps, damping, time
functions) are validated later, against the model their kind selects.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal, get_args

from pydantic import BaseModel, ConfigDict, Field, TypeAdapter

from catdae.case.limits import (
    MAX_COORDINATE,
    MAX_DIAMETER,
    MAX_EA,
    MAX_ELEMENTS_PER_CABLE,
    MAX_FREQUENCY,
    MAX_LENGTH,
    MAX_LINE_MASS,
    MAX_POINT_MASS,
    MAX_THERMAL_EXPANSION,
    MAX_VECTOR,
    MIN_TIME,
)

# defer_build: a model's validator is built at its first use, not at import, so that a case
# pays only for the sections it has (about 40 ms of a process's start-up otherwise)
STRICT = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, defer_build=True)

Pos = Annotated[float, Field(gt=0)]
# a relative tolerance: above 0.1 an error test accepts errors as large as the motion (a tester's
# rtol = 5, a slip for 5e-3, reported 4.5e9 N for 12 kN with no word); below 1e-13 it asks for
# digits a double does not hold (a tester's rtol 1e-15: 1.8 million steps for 0.68 s, no word)
Rtol = Annotated[float, Field(ge=1e-13, le=0.1)]
NonNeg = Annotated[float, Field(ge=0)]
Time = Annotated[float, Field(ge=MIN_TIME)]  # s: shorter is degenerate (0/0 in a ramp)
Frequency = Annotated[float, Field(gt=0, le=MAX_FREQUENCY)]
Force = Annotated[float, Field(gt=0, le=MAX_VECTOR)]  # N, a tension target
Vec3 = Annotated[list[Annotated[float, Field(ge=-MAX_VECTOR, le=MAX_VECTOR)]],
                 Field(min_length=3, max_length=3)]
Name = Annotated[str, Field(min_length=1)]
# settings a command line may override too (``OverridesSchema``): one type for both
Elements = Annotated[int, Field(ge=1, le=MAX_ELEMENTS_PER_CABLE)]
MassModelName = Literal["auto", "blended", "consistent", "lumped", "linear"]
MaxOrder = Literal["auto"] | Annotated[int, Field(ge=1, le=5)]  # IDA's BDF order cap
MASS_MODEL_NAMES = get_args(MassModelName)
TomlTable = dict[str, Any]  # validated later on its own (time functions, damping)


class TopSchema(BaseModel):
    model_config = STRICT
    title: str = ""
    source: str = ""
    gravity: Any = 9.81  # a number (along -z) or [gx, gy, gz]: checked by the builder
    reference_temperature: float | None = None  # °C (or K): where lengths hold; steps' temperature
    materials: dict[str, TomlTable] = {}
    nodes: dict[str, Any] = {}
    supports: dict[str, Any] = {}
    cables: list[TomlTable] = []
    point_masses: list[TomlTable] = []
    loads: list[TomlTable] = []
    distributed_loads: list[TomlTable] = []
    support_motions: list[TomlTable] = []
    springs: list[TomlTable] = []  # connectors: validated by build_connectors
    dampers: list[TomlTable] = []
    bars: list[TomlTable] = []
    steps: list[TomlTable] = []
    seabed: TomlTable | None = None
    water: Any = None  # [water] and [air]: checked by build_fluid
    air: Any = None
    ground: TomlTable | None = None  # catdae.case.ground


class MaterialSchema(BaseModel):
    model_config = STRICT
    EA: Annotated[float, Field(gt=0, le=MAX_EA)]
    mass: Annotated[float, Field(ge=0, le=MAX_LINE_MASS)]
    weight: Annotated[float, Field(ge=0, le=MAX_LINE_MASS)] | None = None
    damping: Annotated[float, Field(ge=0, le=MAX_LINE_MASS)] = 0.0
    thermal_expansion: Annotated[float, Field(ge=-MAX_THERMAL_EXPANSION,
                                              le=MAX_THERMAL_EXPANSION)] = 0.0
    # fluid properties of the line (docs/case-format.md, "Water and air")
    diameter: Annotated[float, Field(gt=0, le=MAX_DIAMETER)] | None = None
    drag_normal: NonNeg | None = None
    drag_axial: NonNeg | None = None
    added_mass_normal: NonNeg | None = None
    added_mass_axial: NonNeg | None = None
    rated_strength: Pos | None = None  # N, optional


class CableSchema(BaseModel):
    model_config = STRICT
    name: Name
    ends: Annotated[list[Name], Field(min_length=2, max_length=2)]
    material: Name
    length: Annotated[float, Field(gt=0, le=MAX_LENGTH)] | None = None  # or form (builder)
    form: TomlTable | None = None
    elements: Elements = 1
    gauss_points: Annotated[int, Field(ge=1, le=10)] = 3


class PointMassSchema(BaseModel):
    model_config = STRICT
    name: Name
    mass: Annotated[float, Field(gt=0, le=MAX_POINT_MASS)]
    node: Name | None = None
    cable: Name | None = None
    s: NonNeg | None = None
    active: bool = True


class LoadSchema(BaseModel):
    model_config = STRICT
    name: Name
    force: Vec3
    node: Name | None = None
    cable: Name | None = None
    s: NonNeg | None = None
    time: TomlTable | None = None
    active: bool = True


class DistributedLoadSchema(BaseModel):
    model_config = STRICT
    name: Name | None = None
    cable: Name
    load: Vec3
    time: TomlTable | None = None
    from_s: NonNeg | None = None  # m, unstrained arc length; default 0
    to_s: Pos | None = None  # m; default the cable's length
    active: bool = True


class SupportMotionSchema(BaseModel):
    model_config = STRICT
    node: Name
    x: TomlTable | None = None
    y: TomlTable | None = None
    z: TomlTable | None = None
    direction: Vec3 | None = None  # with value: a motion along this direction
    value: TomlTable | None = None  # the displacement along ``direction`` (m)


class _StaticStep(BaseModel):
    model_config = STRICT
    kind: Literal["static"]
    name: Name | None = None
    remove: list[Name] = []
    temperature_change: Any = None
    temperature: Any = None  # with the case's reference_temperature
    add: list[Name] = []
    load_steps: Annotated[int, Field(ge=1)] = 1
    sweep: TomlTable | None = None


class _ModalStep(BaseModel):
    model_config = STRICT
    kind: Literal["modal"]
    name: Name | None = None
    remove: list[Name] = []
    temperature_change: Any = None
    temperature: Any = None  # with the case's reference_temperature
    add: list[Name] = []
    modes: Annotated[int, Field(ge=1)] = 10
    mass_model: MassModelName = "auto"
    damping: TomlTable | None = None
    sweep: TomlTable | None = None


class _TransientStep(BaseModel):
    model_config = STRICT
    kind: Literal["transient"]
    name: Name | None = None
    remove: list[Name] = []
    temperature_change: Any = None
    temperature: Any = None  # with the case's reference_temperature
    add: list[Name] = []
    duration: Time
    output_interval: Time
    rtol: Rtol = 1e-6
    atol: Pos = 1e-8
    damping: TomlTable | None = None
    max_order: Any = "auto"  # "auto" or an integer 1-5 (checked by the builder)
    linear_solver: Literal["auto", "band", "sparse", "dense"] = "auto"
    mass_model: MassModelName = "auto"
    inertia: Literal["lagrangian", "paper"] = "lagrangian"
    jump_reference: Name | None = None  # an earlier static step: jump_height results
    sweep: TomlTable | None = None
    axial_damping: TomlTable | None = None
    resolve: Literal["auto", "output", "waves"] = "auto"


class FormSchema(BaseModel):
    """``form = { ... }`` of a cable: exactly one target (the builder checks which)."""

    model_config = STRICT
    pretension: Force | None = None
    horizontal_tension: Force | None = None
    tension: Force | None = None
    at: Name | None = None
    sag: Annotated[float, Field(gt=0, le=MAX_COORDINATE)] | None = None


FORM_TARGETS = ("pretension", "horizontal_tension", "tension", "sag")

STEP_MODELS: dict[str, type[BaseModel]] = {
    "static": _StaticStep, "modal": _ModalStep, "transient": _TransientStep,
}


class _MaterialDamping(BaseModel):
    model_config = STRICT
    kind: Literal["material"]


class _RayleighDamping(BaseModel):
    model_config = STRICT
    kind: Literal["rayleigh"]
    alpha: NonNeg | None = None
    beta: NonNeg | None = None
    ratio: Pos | None = None
    frequencies: Annotated[list[Pos], Field(min_length=2, max_length=2)] | None = None


class AxialDampingSchema(BaseModel):
    """``axial_damping = { ratio = .., frequency = .., rate = .. }`` of a transient step."""

    model_config = STRICT
    ratio: Pos
    frequency: Pos | Literal["element"] = "element"
    rate: Literal["strain", "chord"] = "strain"


DAMPING_MODELS: dict[str, type[BaseModel]] = {
    "material": _MaterialDamping, "rayleigh": _RayleighDamping,
}


class _ConstantTF(BaseModel):
    model_config = STRICT
    kind: Literal["constant"]
    value: float


class _RampTF(BaseModel):
    model_config = STRICT
    kind: Literal["ramp"]
    duration: Time
    start: float = 0.0
    smooth: bool = False
    amplitude: float = 1.0


class _SineTF(BaseModel):
    model_config = STRICT
    kind: Literal["sine", "cosine"]
    amplitude: float
    frequency: Frequency
    phase: float = 0.0
    offset: float = 0.0


class TableSchema(BaseModel):
    model_config = STRICT
    kind: Literal["table"]
    file: Name | None = None
    t: list[float] | None = None
    value: list[float] | None = None
    column: Name | None = None  # a named column of a CSV file with several
    quantity: Literal["displacement", "velocity", "acceleration"] = "displacement"


class _ProductTF(BaseModel):
    model_config = STRICT
    kind: Literal["product"]
    factors: list[TomlTable]  # time functions, multiplied (at least 2: the builder)


class _TrapezoidTF(BaseModel):
    model_config = STRICT
    kind: Literal["trapezoid"]
    rise: Time
    hold: NonNeg = 0.0
    fall: Time
    start: float = 0.0
    amplitude: float = 1.0
    smooth: bool = False


TIME_MODELS: dict[str, type[BaseModel]] = {
    "constant": _ConstantTF, "ramp": _RampTF, "sine": _SineTF, "cosine": _SineTF,
    "table": TableSchema, "product": _ProductTF, "trapezoid": _TrapezoidTF,
}

VEC3 = TypeAdapter(Vec3, config=ConfigDict(strict=True, allow_inf_nan=False, defer_build=True))
Coordinate = Annotated[float, Field(ge=-MAX_COORDINATE, le=MAX_COORDINATE)]
POSITION = TypeAdapter(Annotated[list[Coordinate], Field(min_length=3, max_length=3)],
                       config=ConfigDict(strict=True, allow_inf_nan=False, defer_build=True))


class OverridesSchema(BaseModel):
    """What ``catdae run --rtol/--atol/--elements/--mass-model/--max-order`` (and the keywords
    of ``catdae.run``) may replace, typed as the case file's own fields."""

    model_config = STRICT
    rtol: Rtol | None = None  # as a transient step's rtol
    atol: Pos | None = None  # as a transient step's atol
    elements: Elements | None = None  # as a cable's elements
    mass_model: MassModelName | None = None  # as a modal or transient step's mass_model
    max_order: MaxOrder | None = None  # as a transient step's max_order
