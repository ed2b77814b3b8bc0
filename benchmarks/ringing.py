"""Issue 25: steps set by the motion asked for, not by undamped axial ringing.

Whole ``python -m catdae run`` processes (wall and CPU of the child), one after the other:

- ``pendulum``: a 1e5 kg mass on a 100.5 m line (EA 1e9, 7.854 kg/m, weightless: MoorDyn's
  pendulum test, tests/Mooring/pendulum.txt), 10 elements, held 10 m aside by a load, released,
  105 s. Period against 2π sqrt(l/g) (1 + θ²/16), amplitude after five periods against the
  start; default settings, then with ``axial_damping``.
- ``violent``: the paper's violent example 2 at 50 elements (lumped mass), 4 s: the peak of
  the tension envelope (``tension_max``) against 264 kN (time-converged; OpenSees 263.9 kN).
- ``snap``: a mass falling h onto a rope of vanishing mass: T_max = Mg + sqrt((Mg)² +
  2 Mg EA h / L) from the envelope.
- ``stay``: an inclined bridge stay (200 m chord at 30°, EA 1.6e9 N, 80 kg/m, pretension
  6.27 MN: first out-of-plane mode 0.703 Hz, λ² about 0.1), 20 elements, nudged out of plane by
  2 kN at midspan, then driven at its deck anchor along the chord, 0.05 sin(2π 1.4 t) m under a
  2 s smooth ramp (the tension varies by ±6 %: parametric 2:1 resonance of the out-of-plane
  mode), 60 s at rtol 1e-5: the growth rate of the out-of-plane midspan amplitude (log-linear
  fit of its peaks from 5 s on) against a run at rtol 1e-7.

``python benchmarks/ringing.py pendulum violent snap`` prints Markdown table rows (see
benchmarks/ringing.md); ``--duration`` shortens the violent scene, ``--rows`` picks variants.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import catdae

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))  # the one scene builder (tests/scene_toml.py)
from speed_accuracy import children_cost  # noqa: E402

from scene_toml import block, cable, load, point_mass, scene, step, support_motion  # noqa: E402

G = 9.81
PEND_M, PEND_L0, PEND_EA, PEND_LINE = 1e5, 100.5, 1e9, 7.85398


def pendulum_case(step_extra: str = "", elements: int = 10, duration: float = 105.0) -> str:
    """The pendulum as TOML: a static step held 10 m aside by a load, a transient without it."""
    th = math.asin(10.0 / PEND_L0)
    for _ in range(50):
        tension = PEND_M * G / math.cos(th)
        th = math.asin(10.0 / (PEND_L0 * (1 + tension / PEND_EA)))
    hold = PEND_M * G * math.tan(th)
    return scene(
        head={"title": "pendulum (MoorDyn's test): 1e5 kg on a 100.5 m line"},
        materials={"line": {"EA": PEND_EA, "mass": PEND_LINE, "weight": 0.0}},
        nodes={"A": [0.0, 0.0, 0.0], "B": [0.0, 0.0, -PEND_L0 * 1.001]}, supports=("A",),
        cables=cable("c", material="line", length=PEND_L0, elements=elements),
        extra=point_mass("bob", PEND_M, node="B") + load("hold", [hold, 0.0, 0.0], node="B"),
        steps=step("static", "held") + step("transient", "swing", remove=["hold"],
                                            duration=duration, output_interval=0.05)
        + block(step_extra))


def pendulum_figures(ds, periods: float = 5) -> dict:
    """Period (mean of the zero crossings of x) and amplitude over the ``periods``-th period
    (from periods - 0.5 to periods + 0.25 reference periods; the fifth by default), with
    their errors against 2π sqrt(l/g) (1 + θ²/16) and the release offset."""
    t = ds.time.values
    x = ds.position.sel(node="B", axis="x").values
    z = ds.position.sel(node="B", axis="z").values
    length = float(np.hypot(x[0], z[0]))
    th0 = math.asin(x[0] / length)
    ref = 2 * math.pi * math.sqrt(length / G) * (1 + th0**2 / 16)
    s = np.flatnonzero(np.sign(x[:-1]) != np.sign(x[1:]))
    tc = t[s] - x[s] * (t[s + 1] - t[s]) / (x[s + 1] - x[s])
    period = 2 * float(np.mean(np.diff(tc)))
    w = (t > (periods - 0.5) * ref) & (t <= (periods + 0.25) * ref)
    amp = float(np.max(np.abs(x[w])))
    return {"period": period, "period_ref": ref, "period_err": period / ref - 1,
            "amp_err": amp / x[0] - 1}


def violent_case(step_extra: str = "", duration: float = 4.0) -> str:
    text = (HERE.parent / "cases" / "example2_support_motion_violent.toml").read_text()
    text = text.replace("duration = 4.0", f"duration = {duration!r}")
    return text.replace('mass_model = "lumped"', 'mass_model = "lumped"\n' + step_extra)


def run_case(text: str, folder: Path, name: str, *extra_args: str):
    """One whole process: (dataset of the last step, wall s, CPU s)."""
    path = folder / f"{name}.toml"
    path.write_text(text)
    out = folder / f"{name}_{time.time_ns()}.nc"
    p, wall, cpu = children_cost(
        subprocess.run, [sys.executable, "-m", "catdae", "run", str(path), "-o", str(out),
                         "--no-progress", *extra_args], capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(p.stderr[-2000:])
    tree = catdae.read_results(out)
    ds = tree[list(tree.children)[-1]].ds.load()
    out.unlink(missing_ok=True)
    return ds, wall, cpu


PENDULUM_ROWS = {
    "default": "",
    'resolve = "waves" (the former default)': 'resolve = "waves"',
    "axial 50 % (element)": 'axial_damping = { ratio = 0.5, frequency = "element" }',
    "axial 5 % (element)": 'axial_damping = { ratio = 0.05, frequency = "element" }',
    "rtol 1e-4, atol 1e-6": "rtol = 1e-4\natol = 1e-6",
    "rtol 1e-4, atol 1e-6, axial 5 %": "rtol = 1e-4\natol = 1e-6\naxial_damping = { ratio = 0.05 }",
}
VIOLENT_ROWS = {
    "rtol 1e-3, atol 1e-6": ("", ["--rtol", "1e-3", "--atol", "1e-6"]),
    "rtol 1e-2, atol 1e-4": ("", ["--rtol", "1e-2", "--atol", "1e-4"]),
    "rtol 3e-3, atol 3e-5": ("", ["--rtol", "3e-3", "--atol", "3e-5"]),
    "rtol 5e-3, atol 1e-4": ("", ["--rtol", "5e-3", "--atol", "1e-4"]),
    "rtol 5e-3, atol 1e-4, max_order 2": ("max_order = 2", ["--rtol", "5e-3", "--atol", "1e-4"]),
    "case (rtol 1e-5, atol 1e-6)": ("", []),
    "case, resolve output": ('resolve = "output"', []),
    "rtol 1e-3, axial 0.5 % (element)": ('axial_damping = { ratio = 0.005 }',
                                          ["--rtol", "1e-3", "--atol", "1e-6"]),
    "rtol 1e-3, axial 5 % (element)": ('axial_damping = { ratio = 0.05 }',
                                        ["--rtol", "1e-3", "--atol", "1e-6"]),
}


STAY_L, STAY_INC, STAY_EA, STAY_M, STAY_T = 200.0, 30.0, 1.6e9, 80.0, 6.27e6


def stay_case(step_extra: str = "", duration: float = 60.0, elements: int = 20,
              amplitude: float = 0.05, frequency: float = 1.4) -> str:
    """The stay: a static step nudged out of plane, then the anchor A driven along the chord."""
    bx = STAY_L * math.cos(math.radians(STAY_INC))
    bz = STAY_L * math.sin(math.radians(STAY_INC))
    rtol = None if "rtol" in step_extra else 1e-5
    motion = {"kind": "product", "factors": [
        {"kind": "sine", "amplitude": amplitude, "frequency": frequency},
        {"kind": "ramp", "duration": 2.0, "smooth": True}]}
    return scene(
        head={"title": "bridge stay driven at its deck anchor (parametric 2:1)"},
        materials={"strand": {"EA": STAY_EA, "mass": STAY_M}},
        nodes={"A": [0.0, 0.0, 0.0], "B": [bx, 0.0, bz]},
        cables=cable("stay", material="strand", elements=elements,
                     form={"pretension": STAY_T}),
        extra=load("nudge", [0.0, 2000.0, 0.0], node=f"stay.{elements // 2}")
        + support_motion("A", direction=[bx, 0.0, bz], value=motion),
        steps=step("static", "nudged") + step("transient", "driven", remove=["nudge"],
                                              duration=duration, output_interval=0.02,
                                              rtol=rtol) + block(step_extra))


def stay_growth(ds, t_from: float = 5.0) -> float:
    """Growth rate (1/s) of the out-of-plane midspan amplitude: a log-linear fit of the peaks of
    |y| from ``t_from`` on."""
    t = ds.time.values
    a = np.abs(ds.position.sel(node="stay.10", axis="y").values)
    pk = np.flatnonzero((a[1:-1] > a[:-2]) & (a[1:-1] >= a[2:])) + 1
    w = t[pk] >= t_from
    return float(np.polyfit(t[pk][w], np.log(a[pk][w]), 1)[0])


STAY_ROWS = {
    "rtol 1e-7 (reference)": "rtol = 1e-7\natol = 1e-9",
    "default (rtol 1e-5)": "",
    'resolve = "waves" (the former default)': 'resolve = "waves"',
}


def stay(folder: Path, rows) -> None:
    print("| stay, 20 elements, 60 s | steps | CPU s | wall s | growth rate 1/s | vs reference |")
    print("|---|---:|---:|---:|---:|---:|")
    ref = None
    for label in rows:
        ds, wall, cpu = run_case(stay_case(STAY_ROWS[label]), folder, "stay")
        sigma = stay_growth(ds)
        ref = sigma if ref is None else ref
        print(f"| {label} | {ds.attrs['n_steps']} | {cpu:.1f} | {wall:.1f} | {sigma:.5f} | "
              f"{100 * (sigma / ref - 1):+.2f} % |", flush=True)


def pendulum(folder: Path, rows) -> None:
    print("| pendulum, 10 elements, 105 s | steps | CPU s | wall s | period error | "
          "amplitude error after 5 periods |")
    print("|---|---:|---:|---:|---:|---:|")
    for label in rows:
        ds, wall, cpu = run_case(pendulum_case(PENDULUM_ROWS[label]), folder, "pendulum")
        f = pendulum_figures(ds)
        print(f"| {label} | {ds.attrs['n_steps']} | {cpu:.1f} | {wall:.1f} | "
              f"{100 * f['period_err']:+.3f} % | {100 * f['amp_err']:+.3f} % |", flush=True)


def violent(folder: Path, rows, duration: float) -> None:
    print(f"| violent example 2, 50 elements, {duration:g} s | steps | CPU s | wall s | "
          "peak tension_max (kN) | vs 264 kN | peak of the outputs (kN) |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for label in rows:
        extra, args = VIOLENT_ROWS[label]
        ds, wall, cpu = run_case(violent_case(extra, duration), folder, "violent",
                                 "--elements", "50", *args)
        peak = float(ds.tension_max.max())
        print(f"| {label} | {ds.attrs['n_steps']} | {cpu:.1f} | {wall:.1f} | "
              f"{peak / 1e3:.1f} | {100 * (peak / 264.0e3 - 1):+.2f} % | "
              f"{float(ds.tension.max()) / 1e3:.1f} |", flush=True)


def snap_case(ratio: float, M=1000.0, L0=10.0, EA=1e7, fall=0.5, x_off=0.3) -> str:
    return f"""title = "a mass falling onto a rope"
[materials.rope]
EA = {EA!r}
mass = {ratio * M / L0!r}
[nodes]
A = [0.0, 0.0, 0.0]
B = [{x_off!r}, 0.0, {-(L0 - fall)!r}]
[supports]
A = "pinned"
[[cables]]
name = "c"
ends = ["A", "B"]
material = "rope"
length = {L0!r}
elements = 1
[[point_masses]]
name = "bob"
node = "B"
mass = {M!r}
[[steps]]
kind = "transient"
name = "drop"
mass_model = "lumped"
duration = 1.0
output_interval = 0.05
"""


def snap(folder: Path) -> None:
    M, L0, EA, fall, x_off = 1000.0, 10.0, 1e7, 0.5, 0.3
    h = math.sqrt(L0**2 - x_off**2) - (L0 - fall)
    exact = M * G + math.sqrt((M * G) ** 2 + 2 * M * G * EA * h / L0)
    print(f"| falling mass, rope mass / M | steps | CPU s | T_max envelope (kN) | closed form "
          f"{exact / 1e3:.2f} kN | max of the outputs (kN) |")
    print("|---:|---:|---:|---:|---:|---:|")
    for ratio in (1e-2, 1e-3, 1e-4):
        ds, wall, cpu = run_case(snap_case(ratio), folder, "snap")
        peak = float(ds.tension_max.max())
        print(f"| {ratio:g} | {ds.attrs['n_steps']} | {cpu:.1f} | {peak / 1e3:.2f} | "
              f"{100 * (peak / exact - 1):+.3f} % | {float(ds.tension.max()) / 1e3:.2f} |",
              flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", default=["pendulum", "stay", "violent", "snap"])
    ap.add_argument("--duration", type=float, default=4.0, help="of the violent scene, s")
    ap.add_argument("--rows", nargs="*", help="variants (labels of the tables) to run")
    args = ap.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        if "pendulum" in args.scenes:
            pendulum(folder, args.rows or list(PENDULUM_ROWS))
        if "stay" in args.scenes:
            stay(folder, args.rows or list(STAY_ROWS))
        if "violent" in args.scenes:
            violent(folder, args.rows or list(VIOLENT_ROWS), args.duration)
        if "snap" in args.scenes:
            snap(folder)
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
