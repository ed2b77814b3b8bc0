"""catdae against MoorDyn on issue 25's scenes, whole processes on both sides, at equal accuracy.

The pendulum (MoorDyn's own test: 1e5 kg on a 100.5 m line, EA 1e9, held 10 m aside, about
5.3 periods) and the violent example 2 (50 elements, 4 s). Each run is a new Python process:
``python -m catdae run`` for catdae, and for MoorDyn (PyPI ``moordyn``) a process that imports
it and runs benchmarks/moordyn_compare.py's driver of the same scene (its test file, RK4). The
cost is the CPU time (user + system) of the child process, and its wall time; medians of
``--repeats``. Accuracy: the pendulum's period against 2π sqrt(l/g) (1 + θ²/16) and its
amplitude over the N-th period against the release offset (benchmarks/ringing.py; N is
``--periods``, 5 by default: catdae runs 105 s N / 5, MoorDyn N + 0.3 periods); the violent
scene's peak tension against the time-converged 264 kN.

The ratio compares the cheapest catdae run that is at least as accurate as MoorDyn's run on
both figures (pendulum) with that MoorDyn run; on the violent scene, the catdae run with the
cheapest MoorDyn run (a ladder of segments and coupling steps) at least as close to 264 kN.
264 kN is the 50-element catenary-element model's own converged peak, not the mesh limit (which
the first peak does not reach: benchmarks/moordyn_violent_convergence.md).

    python benchmarks/moordyn_parity.py [pendulum] [violent] [--repeats 3] [--periods 5]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import ringing  # noqa: E402
from speed_accuracy import children_cost  # noqa: E402
from static_speed import machine  # noqa: E402

PEAK_REF = 264.0e3  # N, time-converged peak of the violent scene (catdae and OpenSees agree)

CATDAE_PENDULUM = {
    "rtol 1e-3, atol 1e-5": "rtol = 1e-3\natol = 1e-5",
    "rtol 3e-4, atol 3e-6": "rtol = 3e-4\natol = 3e-6",
    "rtol 2e-4, atol 2e-6": "rtol = 2e-4\natol = 2e-6",
    "rtol 1e-4, atol 1e-6": "rtol = 1e-4\natol = 1e-6",
    # 0.1 mm: the bob's 10 m swing to 1e-5; the line's small vibrations are then not followed
    "rtol 1e-4, atol 1e-4": "rtol = 1e-4\natol = 1e-4",
    # session 18: looser rtol at the same atol, the ladder's cheap end
    "rtol 3e-4, atol 1e-4": "rtol = 3e-4\natol = 1e-4",
    "rtol 2e-4, atol 1e-4": "rtol = 2e-4\natol = 1e-4",
    # --periods 50: BDF's numerical damping of the swing adds up (rtol 1e-4, atol 1e-4: -1.7 %
    # over the 50th period, MoorDyn's RK4 -0.42 %); a tenth of the rtol keeps it below
    "rtol 1e-5, atol 1e-4": "rtol = 1e-5\natol = 1e-4",
    # session 15: half that rtol took fewer steps and lost -0.26 % over the 50th period
    "rtol 5e-6, atol 1e-4": "rtol = 5e-6\natol = 1e-4",
}
MOORDYN_PENDULUM = {  # label: (segments, BA/-zeta as a positive ratio, cfl)
    "10 segments, BA/-zeta -0.01 (its test file)": (10, 0.01, 0.1),
    "10 segments, no internal damping": (10, 0.0, 0.1),
    # its largest stable step (session 14: cfl 0.25, 0.3, 0.35, 0.4 and above fail to integrate)
    "10 segments, BA/-zeta -0.01, cfl 0.2 (largest stable)": (10, 0.01, 0.2),
}
CATDAE_VIOLENT = {
    "rtol 5e-3, atol 1e-4, max_order 2 (README snap settings)": (
        "max_order = 2", ["--rtol", "5e-3", "--atol", "1e-4"]),
}
# label: (segments, cfl, coupling step s, exact: end A's kinematics at the start of the step and
# the peak over nodes 0..N; benchmarks/moordyn_compare.py violent, moordyn_violent_convergence.md)
MOORDYN_VIOLENT = {
    "50 segments, cfl 0.5, coupling 1e-4 s": (50, 0.5, 1e-4, False),
    "50 segments, coupling 1e-4 s, exact": (50, 0.5, 1e-4, True),
    "100 segments, coupling 5e-5 s, exact": (100, 0.5, 5e-5, True),
    "200 segments, coupling 2.5e-5 s, exact": (200, 0.5, 2.5e-5, True),
    "200 segments, coupling 1e-5 s, exact": (200, 0.5, 1e-5, True),
    "300 segments, coupling 1.6e-5 s, exact": (300, 0.5, 1.6e-5, True),
}


def moordyn_process(call: str) -> tuple[dict, float, float]:
    """MoorDyn in a new process: (the driver's figures, wall s, CPU s of the process)."""
    code = (f"import sys, json; sys.path.insert(0, {str(HERE)!r}); import moordyn_compare as m; "
            f"print('@@' + json.dumps(m.{call}))")
    p, wall, cpu = children_cost(subprocess.run, [sys.executable, "-c", code],
                                 capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(p.stderr[-2000:])
    line = next(x for x in p.stdout.splitlines()[::-1] if x.startswith("@@"))
    return json.loads(line[2:]), wall, cpu


# What a catdae process cannot go below: the interpreter importing the dependencies the project
# is built on (scikit-sundae's IDA, which imports scipy.optimize and scipy.sparse; xarray with
# pandas for the labelled results; netCDF4 to write them) and nothing else.
CORE_IMPORTS = "import numpy, scipy.sparse, xarray, netCDF4, sksundae"


def floor_process() -> tuple[None, float, float]:
    """(None, wall s, CPU s) of a process that only imports CORE_IMPORTS."""
    p, wall, cpu = children_cost(subprocess.run, [sys.executable, "-c", CORE_IMPORTS],
                                 capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(p.stderr[-2000:])
    return None, wall, cpu


def floor_rows(folder: Path, repeats: int, md_wall: float, md_cpu: float) -> list[str]:
    """The fixed cost of a process: the core imports alone, and catdae on the pendulum run for
    0.05 s (every import, the cached kernels, the static step, results written), against the
    MoorDyn run of ``md_wall``/``md_cpu``."""
    _, fw, fc = median_runs(floor_process, repeats)
    text = ringing.pendulum_case("rtol = 1e-4\natol = 1e-4", duration=0.05)
    _, cw, cc = median_runs(lambda: ringing.run_case(text, folder, "pend_short"), repeats)
    return [f"- a process importing only the core dependencies ({CORE_IMPORTS[7:]}): "
            f"{fw:.2f} s wall, {fc:.2f} s CPU = **{fc / md_cpu:.2f}** of that MoorDyn run's CPU",
            f"- catdae's whole process on the pendulum run for 0.05 s: {cw:.2f} s wall, "
            f"{cc:.2f} s CPU = {cc / md_cpu:.2f} of it"]


def median_runs(fn, repeats: int):
    runs = [fn() for _ in range(repeats)]
    return (runs[0][0], statistics.median(r[1] for r in runs),
            statistics.median(r[2] for r in runs))


def pendulum(folder: Path, repeats: int, periods: float = 5) -> list[str]:
    """The rtol ladder of catdae and MoorDyn's runs; the ratio of whole processes, and of the
    integration alone (catdae: the transient step's ``wall_time``, single-threaded; MoorDyn:
    the CPU of its initial-condition solve and of its Step calls, timed inside its process).
    The amplitude over the ``periods``-th period; catdae runs 105 s per 5 periods (105 s at 5,
    about 5.2 periods of 20.1 s), MoorDyn to periods + 0.3."""
    duration = 105.0 * periods / 5
    cat, md = [], []
    for label, extra in CATDAE_PENDULUM.items():
        text = ringing.pendulum_case(extra, duration=duration)
        ds, wall, cpu = median_runs(lambda t=text: ringing.run_case(t, folder, "pend"), repeats)
        f = ringing.pendulum_figures(ds, periods)
        cat.append((label, f, wall, cpu, int(ds.attrs.get("n_steps", 0)),
                    float(ds.attrs["wall_time"])))
    for label, (seg, zeta, cfl) in MOORDYN_PENDULUM.items():
        f, wall, cpu = median_runs(
            lambda s=seg, z=zeta, c=cfl: moordyn_process(
                f"pendulum({s}, {z}, cfl={c!r}, periods={periods!r})"),
            repeats)
        md.append((label, f, wall, cpu, f["cpu_init"] + f["cpu_steps"]))
    rows = [f"| pendulum run ({periods:g} periods; catdae {duration:g} s) | period error | "
            "amplitude error | wall s | CPU s | integration s |",
            "|---|---|---|---|---|---|"]
    for label, f, wall, cpu, steps, integ in cat:
        rows.append(f"| catdae {label} ({steps} steps) | {100 * f['period_err']:+.3f} % | "
                    f"{100 * f['amp_err']:+.3f} % | {wall:.2f} | {cpu:.2f} | {integ:.2f} |")
    for label, f, wall, cpu, integ in md:
        rows.append(f"| MoorDyn {label} | {100 * f['period_err']:+.3f} % | "
                    f"{100 * f['amp_err']:+.3f} % | {wall:.2f} | {cpu:.2f} | {integ:.2f} |")
    rows.append("")
    for label, f, wall, cpu, integ in md:
        ok = [c for c in cat if abs(c[1]["period_err"]) <= abs(f["period_err"])
              and abs(c[1]["amp_err"]) <= abs(f["amp_err"])]
        if not ok:
            rows.append(f"- against MoorDyn {label}: no catdae run as accurate")
            continue
        best = min(ok, key=lambda c: c[3])
        rows.append(f"- against MoorDyn {label}: cheapest catdae run as accurate on both "
                    f"figures is {best[0]}: ratio catdae/MoorDyn **{best[2] / wall:.2f} wall, "
                    f"{best[3] / cpu:.2f} CPU** (whole processes); integration alone "
                    f"{best[5] / integ:.2f}")
    label, f, wall, cpu, integ = md[-1]  # the largest stable step
    rows.append(f"- the fixed cost of a process, against MoorDyn {label}:")
    rows += ["  " + r for r in floor_rows(folder, repeats, wall, cpu)]
    return rows


def violent_row(code: str, label: str, peak: float, wall: float, cpu: float) -> str:
    return (f"| {code} {label} | {peak / 1e3:.1f} kN | {100 * (peak / PEAK_REF - 1):+.2f} % | "
            f"{wall:.2f} | {cpu:.2f} |")


def violent_ratio(cat: list, md: list) -> list[str]:
    """Against each catdae run, the cheapest MoorDyn run at least as close to PEAK_REF."""
    rows = []
    for label, peak, wall, cpu in cat:
        ok = [m for m in md if abs(m[1] / PEAK_REF - 1) <= abs(peak / PEAK_REF - 1)]
        if not ok:
            rows.append(f"- against catdae {label}: no MoorDyn run as accurate")
            continue
        best = min(ok, key=lambda m: m[3])
        rows.append(f"- against catdae {label}: cheapest MoorDyn run as accurate is {best[0]}: "
                    f"ratio catdae/MoorDyn **{wall / best[2]:.2f} wall, {cpu / best[3]:.2f} CPU**")
    return rows


def violent(folder: Path, repeats: int) -> list[str]:
    cat, md = [], []
    for label, (extra, args) in CATDAE_VIOLENT.items():
        text = ringing.violent_case(extra)
        ds, wall, cpu = median_runs(
            lambda t=text, a=args: ringing.run_case(t, folder, "violent", "--elements", "50", *a),
            repeats)
        cat.append((label, float(ds.tension_max.max()), wall, cpu))
    for label, (seg, cfl, dt_c, exact) in MOORDYN_VIOLENT.items():
        f, wall, cpu = median_runs(
            lambda n=seg, c=cfl, d=dt_c, e=exact:
            moordyn_process(f"violent({n}, 4.0, {c}, {d}, {e})"), repeats)
        md.append((label, f["peak"], wall, cpu))
    rows = ["| violent run (4 s; catdae 50 elements) | peak tension | error | wall s | CPU s |",
            "|---|---|---|---|---|"]
    rows += [violent_row("catdae", *c) for c in cat] + [violent_row("MoorDyn", *m) for m in md]
    return rows + [""] + violent_ratio(cat, md)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", default=["pendulum", "violent"])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--periods", type=float, default=5.0,
                    help="pendulum: amplitude over this period; catdae runs 105 s per 5")
    args = ap.parse_args()
    print(f"Machine: {machine()}; load {os.getloadavg()[0]:.2f} at the start", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        if "pendulum" in args.scenes:
            print("\n".join(pendulum(Path(tmp), args.repeats, args.periods)), flush=True)
        if "violent" in args.scenes:
            print("\n".join(violent(Path(tmp), args.repeats)), flush=True)
    print(f"load {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()
