"""MoorDyn's published validation scenes, run by catdae and by MoorDyn side by side.

    python benchmarks/moordyn_validation.py [--quick] [--out benchmarks/moordyn_validation.md]

Scenes (tests/moordyn_scenes.py, data in tests/data/moordyn with MoorDyn's BSD-3 notice):
the studless chain against OrcaFlex at 200 and 600 m depth under the 2 m and 5 m fairlead heave
records (metric: max |ΔT - ΔT_ref| / (2 max |ΔT_ref|), tolerance 0.15), and the Lowe & Langley
(2006) jumper, cases 2-3 (top motion; largest |T - T_paper| over 80 s after the ramp) and
4-6 (Airy waves; over 30 s after two periods); tolerance 1 kN in MoorDyn's test, 1.5 kN for a
line without bending stiffness.

catdae: each scene on a small ladder of (elements, rtol), cheapest first; the cost is the CPU
time (time.process_time) and wall time of the whole ``catdae.run`` (static step, start-up of
the transient, kernels already compiled) per simulated second. MoorDyn (PyPI ``moordyn``): the
input file as published (fileIC dropped: the file is not in the data set), driven as its test
programs drive it, with its internal step dtM doubled from the input's value while the run
stays stable (no error, no NaN); each stable step is reported with its error and cost.
``--quick`` runs the 200 m chain (2 m heave) and jumper case 2 only; ``--jumper`` the jumper's
scenes only (each also by MoorDyn with EI = 0, the line catdae models). ``--long SECONDS`` runs each
scene that long instead (the chain's heave continued as the sine its record samples, the jumper's
motion or waves going on), catdae at the settings that passed and MoorDyn at its largest step
within tolerance, for the cost per simulated second once start-up no longer counts; the error is
still the published window's. For the chain the note also gives the marginal cost, (cost of the
long run - cost of the published 30 s) / (SECONDS - 30 s), each code's start-up taken out.
``--scenes chain`` or ``--scenes jumper`` runs only those scenes (default: both); ``--repeat N``
gives the long chain runs' median cost of N runs of each code (the machine's load varies).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from moordyn_scenes import (  # noqa: E402
    DATA,
    JUMPER_AMPLITUDE,
    JUMPER_PERIOD,
    RECORD,
    WAVE_CASES,
    WAVE_PERIOD,
    chain_metric,
    chain_toml,
    heave_record,
    jumper_error,
    jumper_toml,
)

import catdae  # noqa: E402
from catdae.case import load_case  # noqa: E402

CHAIN_TOL = 0.15
# the chain's (elements, rtol) ladders: short runs, and long runs (rungs that passed)
CHAIN_SHORT = ((10, 1e-3), (20, 1e-2), (20, 6e-3), (20, 3e-3), (20, 1e-3))
CHAIN_LONG = ((20, 1e-2), (20, 6e-3), (20, 3e-3))
JUMPER_TOL = 1.5e3  # N
# catdae's jumper settings: the short runs' ladder, and the long runs' (those that passed)
JUMPER_LADDER = ((20, 1e-4), (20, 3e-5), (40, 1e-4), (40, 3e-5))
JUMPER_LONG = ((20, 1e-4), (40, 3e-5))


# ---------------------------------------------------------------------------------- catdae
def catdae_chain(depth, motion, elements, rtol, duration=None):
    text = chain_toml(depth, motion=motion, elements=elements, rtol=rtol, duration=duration)
    c0, w0 = time.process_time(), time.perf_counter()
    tree = catdae.run(load_case(text), progress=False)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    static = np.linalg.norm(tree["static"].to_dataset().reaction.sel(node="fairlead").values)
    ds = tree["heave"].to_dataset()
    t = np.linalg.norm(ds.reaction.sel(node="fairlead").values, axis=-1)
    dur = float(ds.time.values[-1] - ds.time.values[0])
    return chain_metric(ds.time.values, t, depth, motion, static), cpu / dur, wall / dur, \
        int(ds.attrs["n_steps"])


def _marginal(cost_long, seconds, cost_short, short=RECORD):
    """CPU s per simulated s between the published window's end and the long run's."""
    return (cost_long * seconds - cost_short * short) / (seconds - short)


def catdae_jumper(case, elements, rtol, duration=None):
    text = jumper_toml(case=case, elements=elements, rtol=rtol, duration=duration)
    c0, w0 = time.process_time(), time.perf_counter()
    tree = catdae.run(load_case(text), progress=False)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    ds = tree[f"case{case}"].to_dataset()
    t = np.linalg.norm(ds.reaction.sel(node="top").values, axis=-1)
    dur = float(ds.time.values[-1] - ds.time.values[0])
    return jumper_error(ds.time.values, t, case), cpu / dur, wall / dur, \
        int(ds.attrs["n_steps"])


# ---------------------------------------------------------------------------------- MoorDyn
def _input(src: Path, folder: Path, dtm: float | None) -> Path:
    lines = [ln for ln in src.read_text().splitlines() if "fileIC" not in ln]
    if dtm is not None:
        lines = [ln for ln in lines if " dtM " not in f" {ln} " and "cfl" not in ln.split()[1:2]]
        at = next(i for i, ln in enumerate(lines) if "OPTIONS" in ln) + 1
        lines.insert(at, f"{dtm!r}    dtM    time step (s)")
    out = folder / src.name
    out.write_text("\n".join(lines) + "\n")
    return out


def moordyn_chain(md, depth, motion, dtm, folder, duration=None):
    src = DATA / "quasi_static_chain" / f"WD{depth:04d}_Chain.txt"
    t_rec, z_rec = heave_record(motion, duration)
    keep = t_rec <= (t_rec[-1] if duration is None else duration) + 1e-9
    rec = np.zeros((int(keep.sum()), 4))
    rec[:, 0], rec[:, 3] = t_rec[keep], z_rec[keep]
    c0, w0 = time.process_time(), time.perf_counter()
    s = md.Create(str(_input(src, folder, dtm)))
    try:
        md.Init(s, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
        tens = [math.hypot(*[x[0] for x in md.GetFASTtens(s, 1)[:2]])]
        times = [0.0]
        t, dt = 0.0, 0.1
        for i in range(rec.shape[0] - 1):
            x = list(rec[i, 1:4])
            v = list((rec[i + 1, 1:4] - rec[i, 1:4]) / dt)
            md.Step(s, x, v, t, dt)
            t += dt
            fh, fv = (x[0] for x in md.GetFASTtens(s, 1)[:2])
            tens.append(math.hypot(fh, fv))
            times.append(t)
    finally:
        md.Close(s)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    tens = np.array(tens)
    if not np.all(np.isfinite(tens)):
        raise FloatingPointError("NaN")
    dur = times[-1]
    return chain_metric(np.array(times), tens, depth, motion), cpu / dur, wall / dur


def _jumper_input(folder: Path, dtm: float | None, ei: float | None) -> Path:
    """The jumper's line.txt (``_input``), its EI replaced by ``ei`` when given."""
    path = _input(DATA / "lowe_and_langley_2006" / "line.txt", folder, dtm)
    if ei is not None:
        lines = path.read_text().splitlines()
        for k, ln in enumerate(lines):
            cols = ln.split()
            if cols and cols[0] == "main" and len(cols) == 10:
                cols[5] = repr(float(ei))
                lines[k] = "  ".join(cols)
        path.write_text("\n".join(lines) + "\n")
    return path


def moordyn_jumper(md, case, dtm, folder, duration=None, ei=None):
    c0, w0 = time.process_time(), time.perf_counter()
    s = md.Create(str(_jumper_input(folder, dtm, ei)))
    try:
        point = md.GetPoint(s, 2)
        line = md.GetLine(s, 1)
        r0 = list(md.GetPointPos(point))
        md.Init(s, r0, [0.0, 0.0, 0.0])
        n = md.GetLineN(line)
        k = case - 1
        t, dt = 0.0, 0.005
        times, tens = [], []
        while t < (80.0 + JUMPER_PERIOD if duration is None else duration) - 1e-9:
            f = min(t / JUMPER_PERIOD, 1.0)
            f = f**3 * (6 * f * f - 15 * f + 10)
            r = list(md.GetPointPos(point))
            x = r0[k] + f * JUMPER_AMPLITUDE * math.sin(2 * math.pi / JUMPER_PERIOD * (t + dt))
            u = [0.0, 0.0, 0.0]
            u[k] = (x - r[k]) / dt
            md.Step(s, r, u, t, dt)
            t += dt
            times.append(t)
            tens.append(float(np.linalg.norm(md.GetLineNodeForce(line, n))))
    finally:
        md.Close(s)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    tens = np.array(tens)
    if not np.all(np.isfinite(tens)):
        raise FloatingPointError("NaN")
    return jumper_error(np.array(times), tens, case), cpu / t, wall / t


def _wave(A, T, phi, d, t, r):
    """MoorDyn's test programme's Airy kinematics (deep-water k, finite-depth profile)."""
    omega = 2.0 * math.pi / T
    k = omega * omega / 9.81
    x = r[:, 0] * math.cos(d) + r[:, 1] * math.sin(d)
    cs, ss = np.cos(k * x - omega * t + phi), np.sin(k * x - omega * t + phi)
    ch = np.cosh(k * (r[:, 2] + 100.0)) / math.cosh(k * 100.0)
    sh = np.sinh(k * (r[:, 2] + 100.0)) / math.cosh(k * 100.0)
    ua, aa = omega * A, omega * omega * A
    u = np.stack([ua * cs * ch * math.cos(d), ua * cs * ch * math.sin(d), ua * ss * sh], 1)
    a = np.stack([aa * ss * ch * math.cos(d), aa * ss * ch * math.sin(d), -aa * cs * sh], 1)
    return u, a


def moordyn_jumper_waves(md, case, dtm, folder, duration=None, ei=None):
    phase, heading = WAVE_CASES[case]
    c0, w0 = time.process_time(), time.perf_counter()
    s = md.Create(str(_jumper_input(folder, dtm, ei)))
    try:
        point = md.GetPoint(s, 2)
        line = md.GetLine(s, 1)
        r = list(md.GetPointPos(point))
        md.Init(s, r, [0.0, 0.0, 0.0])
        md.ExternalWaveKinInit(s)
        n = md.GetLineN(line)
        t, dt = 0.0, 0.005
        times, tens = [], []
        while t < (30.0 + 2 * WAVE_PERIOD if duration is None else duration) - 1e-9:
            pts = np.array(md.ExternalWaveKinGetCoordinates(s)).reshape(-1, 3)
            u, a = _wave(5.0, WAVE_PERIOD, math.radians(phase), math.radians(heading),
                         t + 0.5 * dt, pts)
            md.ExternalWaveKinSet(s, u.tolist(), a.tolist(), t + 0.5 * dt)
            md.Step(s, r, [0.0, 0.0, 0.0], t, dt)
            t += dt
            times.append(t)
            tens.append(float(np.linalg.norm(md.GetLineNodeForce(line, n))))
    finally:
        md.Close(s)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    tens = np.array(tens)
    if not np.all(np.isfinite(tens)):
        raise FloatingPointError("NaN")
    return jumper_error(np.array(times), tens, case), cpu / t, wall / t


def moordyn_ladder(run, dtm0, n=4):
    """Runs at dtM, 2 dtM, 4 dtM, ... while stable: [(dtm, error, cpu/s, wall/s)]."""
    out = []
    for k in range(n):
        dtm = dtm0 * 2**k
        try:
            with tempfile.TemporaryDirectory() as d:
                err, cpu, wall = run(dtm, Path(d))
        except Exception as exc:  # MoorDyn's failures: RuntimeError, NaN
            out.append((dtm, f"unstable ({type(exc).__name__})", None, None))
            break
        out.append((dtm, err, cpu, wall))
    return out


# ---------------------------------------------------------------------------------- long runs
def long_runs(md, seconds, quick=False, scenes=("chain", "jumper"), repeat=1):
    """Each scene run for ``seconds`` of motion (the chain's heave continued as its sine, the
    jumper's top motion or waves going on): catdae at the settings that passed on the short
    runs, MoorDyn at its largest step within tolerance. Error on the published window."""
    rows = []
    chains = [(200, "ZZP1_A1")] if quick else [
        (200, "ZZP1_A1"), (200, "ZZP1_A2"), (600, "ZZP1_A1"), (600, "ZZP1_A2")]
    for depth, motion in (chains if "chain" in scenes else []):
        scene = f"chain {depth} m, {motion}, {seconds:g} s"
        for elements, rtol in CHAIN_LONG:
            runs = [catdae_chain(depth, motion, elements, rtol, seconds) for _ in range(repeat)]
            err, steps = runs[0][0], runs[0][3]
            cpu, wall = (float(np.median([r[k] for r in runs])) for k in (1, 2))
            short = np.median([catdae_chain(depth, motion, elements, rtol)[1]
                               for _ in range(repeat)])
            rows.append((scene, f"catdae {elements} el., rtol {rtol:g}", err, CHAIN_TOL, cpu,
                         wall, f"{steps} steps; marginal "
                         f"{_marginal(cpu, seconds, short):.4g}"))
        runs, shorts = [], []
        for _ in range(repeat):
            with tempfile.TemporaryDirectory() as d:
                runs.append(moordyn_chain(md, depth, motion, 0.003, Path(d), seconds))
            with tempfile.TemporaryDirectory() as d:
                shorts.append(moordyn_chain(md, depth, motion, 0.003, Path(d), RECORD)[1])
        err = runs[0][0]
        cpu, wall = (float(np.median([r[k] for r in runs])) for k in (1, 2))
        rows.append((scene, "MoorDyn 76 segs, dtM 0.003 s", err, CHAIN_TOL, cpu, wall,
                     f"RK2; marginal {_marginal(cpu, seconds, np.median(shorts)):.4g}"))
    for case in ([] if "jumper" not in scenes else [2] if quick else [2, 3, 4, 5, 6]):
        scene = f"jumper case {case}, {seconds:g} s"
        for elements, rtol in JUMPER_LONG:
            err, cpu, wall, steps = catdae_jumper(case, elements, rtol, seconds)
            rows.append((scene, f"catdae {elements} el., rtol {rtol:g}", err / 1e3,
                         JUMPER_TOL / 1e3, cpu, wall, f"{steps} steps"))
        run = moordyn_jumper_waves if case in WAVE_CASES else moordyn_jumper
        with tempfile.TemporaryDirectory() as d:
            err, cpu, wall = run(md, case, 0.002, Path(d), seconds)
        rows.append((scene, "MoorDyn 68 segs, EI, dtM 0.002 s", err / 1e3, JUMPER_TOL / 1e3,
                     cpu, wall, "midpoint5"))
    return rows


# ---------------------------------------------------------------------------------- report
def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default=None)
    ap.add_argument("--jumper", action="store_true",
                    help="the jumper's scenes only (as --scenes jumper)")
    ap.add_argument("--long", type=float, default=None,
                    help="seconds of motion: run each scene this long instead (cost of long runs)")
    ap.add_argument("--scenes", default="chain,jumper",
                    help="which scenes: chain, jumper or both (comma-separated)")
    ap.add_argument("--repeat", type=int, default=1,
                    help="long chain runs: median cost of this many runs of each code")
    args = ap.parse_args(argv)
    scenes = ("jumper",) if args.jumper else tuple(x.strip() for x in args.scenes.split(","))
    if not set(scenes) <= {"chain", "jumper"}:
        ap.error(f"--scenes: expected chain and/or jumper, got {args.scenes!r}")
    import moordyn as md
    from transient_speed import machine

    chains = [(200, "ZZP1_A1")] if args.quick else [
        (200, "ZZP1_A1"), (200, "ZZP1_A2"), (600, "ZZP1_A1"), (600, "ZZP1_A2")]
    jumpers = [2] if args.quick else [2, 3, 4, 5, 6]
    chains = chains if "chain" in scenes else []
    jumpers = jumpers if "jumper" in scenes else []
    rows = []
    # warm the kernels (compiled once per source change; not part of any cost)
    catdae.run(load_case(chain_toml(200, motion="ZZP1_A1", elements=4, rtol=1e-2,
                                    duration=0.5)), progress=False)
    if args.long is not None:
        chains, jumpers = [], []
        rows = long_runs(md, args.long, args.quick, scenes, args.repeat)
    for depth, motion in chains:
        scene = f"chain {depth} m, {motion}"
        for elements, rtol in CHAIN_SHORT:
            err, cpu, wall, steps = catdae_chain(depth, motion, elements, rtol)
            rows.append((scene, f"catdae {elements} el., rtol {rtol:g}", err, CHAIN_TOL,
                         cpu, wall, f"{steps} steps"))
        for dtm, err, cpu, wall in moordyn_ladder(
                lambda dtm, folder, d=depth, m=motion: moordyn_chain(md, d, m, dtm, folder),
                0.003):
            rows.append((scene, f"MoorDyn 76 segs, dtM {dtm:g} s", err, CHAIN_TOL, cpu, wall,
                         "RK2"))
    for case in jumpers:
        scene = f"jumper case {case}"
        for elements, rtol in JUMPER_LADDER:
            err, cpu, wall, steps = catdae_jumper(case, elements, rtol)
            rows.append((scene, f"catdae {elements} el., rtol {rtol:g}", err / 1e3,
                         JUMPER_TOL / 1e3, cpu, wall, f"{steps} steps"))
        run = moordyn_jumper_waves if case in WAVE_CASES else moordyn_jumper
        with tempfile.TemporaryDirectory() as d:  # the line without bending stiffness
            err, cpu, wall = run(md, case, 0.002, Path(d), ei=0.0)
        rows.append((scene, "MoorDyn 68 segs, EI = 0, dtM 0.002 s", err / 1e3,
                     JUMPER_TOL / 1e3, cpu, wall, "midpoint5"))
        for dtm, err, cpu, wall in moordyn_ladder(
                lambda dtm, folder, c=case, run=run: run(md, c, dtm, folder), 0.001):
            e = err if isinstance(err, str) else err / 1e3
            rows.append((scene, f"MoorDyn 68 segs, EI, dtM {dtm:g} s", e, JUMPER_TOL / 1e3,
                         cpu, wall, "midpoint5"))
    lines = ["| scene | run | error | tolerance | CPU s per simulated s | wall s per "
             "simulated s | note |", "|---|---|---|---|---|---|---|"]
    for scene, run, err, tol, cpu, wall, note in rows:
        e = err if isinstance(err, str) else f"{err:.3g}" + (" ✓" if err <= tol else " ✗")
        c = "" if cpu is None else f"{cpu:.4g}"
        w = "" if wall is None else f"{wall:.4g}"
        lines.append(f"| {scene} | {run} | {e} | {tol:g} | {c} | {w} | {note} |")
    text = (f"Machine: {machine()}\n\nChain error: MoorDyn's metric (dimensionless); jumper "
            "error: kN.\n\n" + "\n".join(lines) + "\n")
    print(text)
    if args.out:
        Path(args.out).write_text(text)


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    main()
