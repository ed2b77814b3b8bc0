"""MoorDyn's published validation scenes as catdae cases, and the comparisons its test programs
make (tests/data/moordyn, BSD-3-Clause; the programs ``*.cpp`` there say how each is driven).

Used by ``tests/scenes/test_moordyn_validation.py`` and ``benchmarks/moordyn_validation.py``.
Nothing here is fitted to the reference curves: the inputs are MoorDyn's line files, the
drive and the metrics its test programs.

- The quasi-static chain (``chain_toml``): d 0.252 m, 390 kg/m, EA 1.674e9 N, Cd 1.37, Ca 1,
  CdAx 0.64; seabed 1e5 Pa/m, 1e4 Pa s/m, friction 0.5 (rigid in the static tests); water
  1025 kg/m³, its still level at the fairlead as published (the 2 m and 5 m heave records
  lift the fairlead and the top of the chain out of the water and back: the water acts on the
  wet part of each element's chord, docs/theory.md §13.1); the seabed at the given
  depth. The fairlead at the origin heaves by the record ZZP1_A*; the case clock starts
  at the record's t = -10 s. Metric: max |ΔT - ΔT_ref| / (2 max |ΔT_ref|) over the record's
  t >= 0, ΔT the change of fairlead tension from each code's own static value (the reference's
  static value is the published 2065.4 or 5232.6 kN), at most 0.15. BDF order 2 (``max_order =
  2``): without axial damping the order race of ``"auto"`` picked order 5 on a window of the 2 m
  record, which then resolved the undamped axial ringing of the top element (the 200 m record
  at rtol 1e-3: 5539 steps and 0.25 against 1321 steps and 0.096 at order 2).
- Seabed friction: the inputs give MoorDyn's FrictionCoefficient 0.5 and leave its FricDamp
  at 200 N s/m: MoorDyn's friction on a node is min(μ 200 N s/m |u|, μ N), linear in the speed
  up to N / 200 N s/m, about 166 m/s for its 10 m segments (N ≈ 33 kN): in these scenes a
  100 N s/m damper per node, practically none. catdae's smoothed Coulomb law reaches μ N
  above ``friction_velocity``; the scenes set it to 0.1 m/s (``CHAIN_FRICTION_VELOCITY``),
  chosen by measurement: at 76 elements, rtol 1e-4, the 5 m records' fairlead tension
  differs from the near-Coulomb 0.001 m/s by at most 2.4 % (200 m) and 1.9 % (600 m) of the
  metric's scale (2 max |ΔT_ref|); 0.01 m/s, the default, 1.0 %; frictionless 5.2 %. At 20
  elements friction matters more (the 200 m, 5 m record frictionless is 0.206, outside the
  tolerance; with friction 0.10-0.11), and 0.1 m/s takes 40 % fewer steps than 0.01 m/s: the
  stick-slip turns of each lying node are spread over a 10 times wider band of speeds.
- MoorDyn's inputs damp the axial strain rate, BA/-zeta = -1.0 for the chain and -0.5 for the
  jumper: a viscous force c_d ė on each segment's elongation rate ė with c_d = ζ sqrt(EA m)
  (MoorDyn's log: "damping set to 8.08e6 N s based on input of -1" for the chain's BA =
  ζ l sqrt(EA m), l = 10 m). catdae's
  ``axial_damping = { ratio = ζ }`` (at each element's own axial frequency) has the same c_d =
  ζ sqrt(EA m), so the scenes carry MoorDyn's ζ as published. Without it the order race and
  the error of the jumper's case 3 depend on the run's step history (2-8.5 kN at 40 elements).
  With it the chain's transient starts with the viscous tension of the record's jump from rest
  to full speed (0.6-1.9 MN for an instant), so the metric takes ΔT from the static step.
- The Lowe & Langley (2006) jumper (``jumper_toml``): 170 m, d 0.396 m, 165 kg/m, EA 500 MN,
  Cd 1, Ca 1 (EI = 120.8 kN m² is not modelled), from (-100, 0, -55) to (0, 0, -5) in 100 m
  of fresh water, g = 9.807. Cases 2 and 3 move the top 10 m along y or z as
  A f sin(2π t / 27 s), f the quintic smoothstep of t/27 over the first period; the top
  tension magnitude is compared every 0.1 s over 80 s after the ramp with ``Case N.csv``.
  Cases 4-6 hold the top in Airy waves 10 m high, period 10 s, from t = 0 (no ramp), with
  phase and heading 230°/0°, 165°/45°, 0°/90°; compared over 30 s after two periods. (MoorDyn's
  test gives the wave number of deep water with the finite-depth profile; catdae uses the
  finite-depth dispersion: k differs by 0.07 % at this depth.) The jumper's BA/-zeta acts on
  the chord's rate (``axial_damping = { ratio = 0.5, rate = "chord" }``), as on MoorDyn's
  straight segments, whose elongation is all strain: each 4.25 m element of the 40-element
  jumper sags (its chord stiffness is about 1 % of EA/L), so on the strain rate the damping
  hardly acted, and the breathing of the elements' sags (lumped mass: no inertia inside the
  element) rang at about 1 Hz (0.5 Hz at 20 elements), driven by the drag when the top
  heaved down fast: case 3 missed by 1.74 kN (6.2 at 20 elements), with no wobble in
  MoorDyn at 20, 40 or 68 segments with EI = 0 (0.94, 0.81, 0.86 kN).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent / "data" / "moordyn"
CHAIN = {200: (700.0, 760.0, 2065.4, 1402.2), 600: (1500.0, 1700.0, 5232.6, 3244.2)}
# the chain's still-water level: at the fairlead, as published
SURFACE = 0.0
RECORD = 30.0  # s of heave compared (the records' t = -10 ... 20 s)
JUMPER_PERIOD = 27.0
JUMPER_AMPLITUDE = 10.0
WAVE_PERIOD = 10.0
CHAIN_ZETA = 1.0  # MoorDyn's BA/-zeta -1.0 (see the module docstring)
# m/s: the chain's friction velocity scale (see the module docstring): MoorDyn's own friction
# with these inputs is linear to far above any speed here; 0.1 m/s changes the fairlead tension
# by at most 2.4 % of the metric's scale against 0.001 m/s (76 elements, rtol 1e-4) and takes
# 40 % fewer steps than 0.01 m/s at 20 elements (benchmarks/moordyn_validation.md)
CHAIN_FRICTION_VELOCITY = 0.1
JUMPER_ZETA = 0.5  # MoorDyn's BA/-zeta -0.5
WAVE_CASES = {4: (230.0, 0.0), 5: (165.0, 45.0), 6: (0.0, 90.0)}  # phase, heading (deg)


def read_table(path: Path, sep: str | None = None) -> np.ndarray:
    rows = [line.replace(",", " ").split() for line in path.read_text().splitlines()
            if line.strip()]
    return np.array(rows, float)


def _damping(ratio: float | None, rate: str = "strain") -> str:
    """MoorDyn's BA/-zeta: ζ of critical at each segment's axial frequency, catdae's
    ``axial_damping`` stated at each element's own (docs/case-format.md), on the strain rate or
    (``rate = "chord"``, as MoorDyn's straight segments have it) on the chord's rate."""
    if not ratio:
        return ""
    on = "" if rate == "strain" else f', rate = "{rate}"'
    return f"axial_damping = {{ ratio = {ratio!r}{on} }}\n"


def _inline(t: np.ndarray, v: np.ndarray) -> str:
    ts = ", ".join(f"{x:.6g}" for x in t)
    vs = ", ".join(f"{x:.9g}" for x in v)
    return f'{{ kind = "table", t = [{ts}], value = [{vs}] }}'


def chain_toml(depth: int, *, elements: int = 20, motion: str | None = None,
               rigid: bool = False, duration: float | None = None, rtol: float = 1e-4,
               output_interval: float = 0.1, mass_model: str = "lumped",
               max_order: str | int = 2, axial_damping: float | None = CHAIN_ZETA,
               friction_velocity: float = CHAIN_FRICTION_VELOCITY) -> str:
    """The chain at ``depth`` (200 or 600 m). ``motion`` "ZZP1_A1" or "ZZP1_A2" adds the
    fairlead heave record and a transient step of ``duration`` (default: the record)."""
    x, length, _, _ = CHAIN[depth]
    seabed = ("" if rigid else
              "stiffness = 1.0e5\ndamping = 1.0e4\nfriction = 0.5\n"
              f"friction_velocity = {friction_velocity!r}\n")
    text = f"""
title = "MoorDyn/OrcaFlex quasi-static chain, {depth} m"
gravity = 9.81
[materials.chain]
EA = 1.674e9
mass = 390.0
diameter = 0.252
drag_normal = 1.37
drag_axial = 0.64
added_mass_normal = 1.0
added_mass_axial = 0.0
[water]
density = 1025.0
surface = {SURFACE!r}
depth = {float(depth) + SURFACE!r}
[seabed]
z = {-float(depth)!r}
{seabed}[nodes]
anchor = [{x!r}, 0.0, {-float(depth)!r}]
fairlead = [0.0, 0.0, 0.0]
[supports]
anchor = "pinned"
fairlead = "pinned"
[[cables]]
name = "chain"
ends = ["anchor", "fairlead"]
material = "chain"
length = {length!r}
elements = {elements}
[[steps]]
kind = "static"
name = "static"
"""
    if motion is not None:
        dur = RECORD if duration is None else duration
        t, z = heave_record(motion, dur)
        text += f"""[[support_motions]]
node = "fairlead"
z = {_inline(t, z)}
[[steps]]
kind = "transient"
name = "heave"
duration = {dur!r}
output_interval = {output_interval!r}
rtol = {rtol!r}
atol = {rtol!r}
mass_model = "{mass_model}"
max_order = {max_order if isinstance(max_order, int) else repr(max_order).replace("'", '"')}
{_damping(axial_damping)}"""
    return text


def heave_record(motion: str, duration: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(t on the case clock, fairlead heave z) of the record ZZP1_A*: 40 s at 0.1 s; longer runs
    (and any run to 1 s past its end, so that the step ends before the record's own end, where
    the fairlead would stop dead) continue it as the sine it samples, A sin(2π t / 10 s) with A
    2 m or 5 m (the record is that sine to its 1 mm)."""
    rec = read_table(DATA / "quasi_static_chain" / f"{motion}.txt")
    t = rec[:, 0] - rec[0, 0]
    z = rec[:, 3]
    if duration is not None and duration + 1.0 > t[-1]:
        amp = {"ZZP1_A1": 2.0, "ZZP1_A2": 5.0}[motion]
        extra = np.arange(t[-1] + 0.1, duration + 1.0 + 1e-9, 0.1)
        t = np.concatenate([t, extra])
        z = np.concatenate([z, amp * np.sin(2.0 * math.pi * extra / 10.0)])
    return t, z


def chain_metric(times: np.ndarray, fair_tension: np.ndarray, depth: int, motion: str,
                 static: float | None = None) -> float:
    """MoorDyn's dynamic metric for catdae's fairlead tension (N) sampled at ``times`` (case
    clock, s): max |ΔT - ΔT_ref| / (2 max |ΔT_ref|) over the reference's rows, ΔT from the
    static tension ``static`` (default: the first sample; with axial damping the first sample
    of the transient holds the viscous tension of the record's start from rest at full speed)."""
    ref = read_table(DATA / "quasi_static_chain" / f"WD{depth:04d}_Chain_{motion}.txt")
    ref = ref[ref[:, 0] + 10.0 <= times[-1] + 1e-9]  # rows the run reached
    t_ref = ref[:, 0] + 10.0  # the record starts at -10 s, the case clock at 0
    d_ref = 1e3 * ref[:, 3] - 1e3 * CHAIN[depth][2]
    d_own = np.interp(t_ref, times, fair_tension) - (fair_tension[0] if static is None
                                                     else static)
    return float(np.max(np.abs(d_own - d_ref)) / (2.0 * np.max(np.abs(d_ref))))


def jumper_motion(case: int, dt: float = 0.05, t_end: float | None = None):
    """(t, displacement) of the top along y (case 2) or z (case 3)."""
    T = JUMPER_PERIOD
    t_end = T + 80.0 if t_end is None else t_end
    t = np.arange(0.0, t_end + 1e-9, dt)
    f = np.clip(t / T, 0.0, 1.0)
    f = f**3 * (6 * f * f - 15 * f + 10)
    return t, JUMPER_AMPLITUDE * f * np.sin(2 * math.pi * t / T)


def jumper_toml(*, elements: int = 20, case: int | None = None, duration: float | None = None,
                rtol: float = 1e-4, output_interval: float = 0.1, mass_model: str = "lumped",
                max_order: str | int = "auto", axial_damping: float | None = JUMPER_ZETA,
                damping_rate: str = "chord") -> str:
    text = f"""
title = "Lowe & Langley (2006) flexible jumper"
gravity = 9.807
[materials.jumper]
EA = 500.0e6
mass = 165.0
diameter = 0.396
drag_normal = 1.0
drag_axial = 0.0
added_mass_normal = 1.0
added_mass_axial = 0.0
[water]
density = 1000.0
surface = 0.0
depth = 100.0
[nodes]
bottom = [-100.0, 0.0, -55.0]
top = [0.0, 0.0, -5.0]
[supports]
bottom = "pinned"
top = "pinned"
[[cables]]
name = "jumper"
ends = ["bottom", "top"]
material = "jumper"
length = 170.0
elements = {elements}
[[steps]]
kind = "static"
name = "static"
"""
    if case in WAVE_CASES:  # Airy waves 10 m high, 10 s, from t = 0; the top held
        phase, heading = WAVE_CASES[case]
        dur = 2 * WAVE_PERIOD + 30.0 if duration is None else duration
        text = text.replace("depth = 100.0\n", "depth = 100.0\nwaves = { kind = \"airy\", "
                            f"height = 10.0, period = {WAVE_PERIOD!r}, heading = {heading!r}, "
                            f"phase = {phase!r} }}\n")
        text += f"""[[steps]]
kind = "transient"
name = "case{case}"
duration = {dur!r}
output_interval = {output_interval!r}
rtol = {rtol!r}
atol = {rtol!r}
mass_model = "{mass_model}"
max_order = {max_order if isinstance(max_order, int) else repr(max_order).replace("'", '"')}
{_damping(axial_damping, damping_rate)}"""
    elif case is not None:
        dur = JUMPER_PERIOD + 80.0 if duration is None else duration
        t, u = jumper_motion(case, t_end=dur + 1.0)
        axis = {2: "y", 3: "z"}[case]
        text += f"""[[support_motions]]
node = "top"
{axis} = {_inline(t, u)}
[[steps]]
kind = "transient"
name = "case{case}"
duration = {dur!r}
output_interval = {output_interval!r}
rtol = {rtol!r}
atol = {rtol!r}
mass_model = "{mass_model}"
max_order = {max_order if isinstance(max_order, int) else repr(max_order).replace("'", '"')}
{_damping(axial_damping, damping_rate)}"""
    return text


def jumper_error(times: np.ndarray, top_tension: np.ndarray, case: int) -> float:
    """Largest |T - T_paper| (N) over the digitised curve (t after the one-period ramp, or
    after two wave periods in cases 4-6)."""
    ref = read_table(DATA / "lowe_and_langley_2006" / f"Case {case}.csv")
    t = ref[:, 0] + (2 * WAVE_PERIOD if case in WAVE_CASES else JUMPER_PERIOD)
    keep = t <= times[-1] + 1e-9
    own = np.interp(t[keep], times, top_tension)
    return float(np.max(np.abs(own - 1e3 * ref[keep, 1])))
