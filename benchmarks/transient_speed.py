"""Transient (IDA) speed: work against accuracy, BDF order, linear solver, and mesh size.

Scenes
- Example 1 (``cases/example1_free_vibration.toml``): the 'release' transient step (14 elements,
  4 s, Rayleigh damping), after its static step.
- The 100 m cable: span 100 m, L0 = 102 m, EA = 1e8 N, weight 100 N/m (mass 100/9.81 kg/m),
  pinned ends; the end A moves vertically as z_A = 0.5 (1 - cos πt) m (a 0.5 m, 0.5 Hz
  oscillation about 0.5 m that starts from rest: displacement and velocity are zero at t = 0 and
  the motion is analytic on the whole integration interval). 16 elements, 10 s.

Each tolerance rtol is run with atol = rtol * 1e-2 m (displacements; catdae scales the velocity
atol by the lowest circular frequency). The error of a run is the largest distance, over the
output times (every 0.01 s), between the midspan node's position and that of a reference run at
rtol = 1e-10 (atol 1e-12 m) on the same mesh.

Run apart from the tests:

    python benchmarks/transient_speed.py [--part accuracy|scaling|profile|all] [--quick]
    python benchmarks/transient_speed.py --part scaling --sizes 10,50,100,200 --repeat 2

It prints markdown tables (copied into ``benchmarks/transient_speed.md``).
"""

from __future__ import annotations

import argparse
import cProfile
import io
import json
import os
import platform
import pstats
import sys
import time
import tomllib
from datetime import datetime
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import catdae  # noqa: E402
from catdae.case import case_from_dict  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_scene import hundred_metre_cable  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE1 = ROOT / "cases" / "example1_free_vibration.toml"
TOLS = (1e-4, 1e-6, 1e-8)
REF_RTOL = 1e-10
# simulated seconds per mesh size in the scaling part (the step count grows with the mesh:
# each run is kept under about a minute)
DURATIONS = {10: 2.0, 50: 1.0, 200: 0.1, 1000: 0.02, 2000: 0.01}

def cable_dict(elements: int = 16, duration: float = 10.0, output_interval: float = 0.01,
               **step) -> dict:
    text = hundred_metre_cable(title="Benchmark: 100 m cable, one end moving vertically",
                               elements=elements, node="A", axis="z", amplitude=0.5,
                               duration=duration, output_interval=output_interval, rtol=1e-6,
                               atol=1e-8)
    d = tomllib.loads(text)
    d["steps"][1].update(step)
    return d


def example1_dict(**step) -> dict:
    d = tomllib.loads(EXAMPLE1.read_text())
    # the paper's 14 elements and the automatic BDF order, as measured here (the case file has
    # 36 elements and max_order = 2 since, benchmarks/example1_default.md)
    d["cables"][0]["elements"] = 14
    d["steps"] = [s for s in d["steps"] if s["name"] in ("hanging", "release")]
    d["steps"][1]["max_order"] = "auto"
    d["steps"][1].update(step)
    return d


def run_dict(d: dict) -> tuple:
    """Run a case dict; return (transient dataset, its step name, whole-run wall time)."""
    case = case_from_dict(d)
    name = d["steps"][-1]["name"]
    t0 = time.perf_counter()
    c0 = time.process_time()
    tree = catdae.run(case, progress=False)
    wall = time.perf_counter() - t0
    tree[name].ds.attrs["bench_cpu_time"] = time.process_time() - c0  # whole run, this process
    return tree[name].ds, tree, wall


def tol(rtol: float) -> dict:
    return {"rtol": rtol, "atol": rtol * 1e-2}


def midspan(ds, node: str) -> np.ndarray:
    return ds.position.sel(node=node).values  # (time, 3)


def error(ds, ref, node: str) -> float:
    a, b = midspan(ds, node), midspan(ref, node)
    n = min(len(a), len(b))
    return float(np.max(np.linalg.norm(a[:n] - b[:n], axis=1)))


def row(ds, err=None, **extra) -> dict:
    a = ds.attrs
    out = {"wall": float(a["wall_time"]), "steps": int(a["n_steps"]),
           "nres": int(a["n_residual_evaluations"]), "njac": int(a["n_jacobian_evaluations"]),
           "solver": str(a["linear_solver"]), "bandwidth": int(a["bandwidth"]),
           "status": str(a["status"]), "duration": float(ds.time.values[-1])}
    out["us_per_res"] = 1e6 * out["wall"] / max(out["nres"], 1)
    out["cpu"] = float(a.get("bench_cpu_time", np.nan))
    if err is not None:
        out["err"] = err
    out.update(extra)
    return out


def machine() -> str:
    import numba
    import scipy
    import sksundae

    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return (f"{platform.platform()}, cpu `{cpu}`, {os.cpu_count()} logical CPUs, 1-min load "
            f"{load:.2f}; Python {platform.python_version()}, numpy {np.__version__}, scipy "
            f"{scipy.__version__}, numba {numba.__version__}, scikit-sundae "
            f"{sksundae.__version__}, catdae {catdae.__version__}; "
            f"{datetime.now():%Y-%m-%d %H:%M}; OMP_NUM_THREADS={os.environ['OMP_NUM_THREADS']}")


# --------------------------------------------------------------------------------- part 1
def accuracy(quick: bool = False) -> dict:
    out = {}
    scenes = {
        "example1": (example1_dict, "main.7", {}),
        "cable16": (cable_dict, "c.8", {}),
    }
    for scene, (make, node, base) in scenes.items():
        ref, _, _ = run_dict(make(**base, **tol(REF_RTOL)))
        rows = [dict(row(ref), rtol=REF_RTOL, order=5, requested="auto")]
        print(f"{scene}: reference {rows[0]['wall']:.2f} s, {rows[0]['steps']} steps",
              file=sys.stderr)
        variants = [("auto", 5), ("auto", 2)]
        if scene == "cable16":
            variants += [("band", 5), ("sparse", 5), ("dense", 5)]
        for rtol in TOLS[:2] if quick else TOLS:
            for solver, order in variants:
                ds, _, _ = run_dict(make(**base, **tol(rtol), max_order=order,
                                         linear_solver=solver))
                r = row(ds, error(ds, ref, node), rtol=rtol, order=order, requested=solver)
                rows.append(r)
                print(f"  rtol {rtol:g} order {order} {solver}: {r['wall']:.2f} s, "
                      f"{r['steps']} steps, err {r['err']:.2e}", file=sys.stderr)
        out[scene] = rows
    return out


# --------------------------------------------------------------------------------- part 2
def scaling(quick: bool = False, sizes=None, solvers=("auto", "band", "sparse"), repeat=1,
            duration_scale: float = 1.0) -> list:
    """Cost against mesh size. With ``repeat`` > 1 the solvers of one size are run in turn
    (band, sparse, band, sparse, ...) and every run is kept: take the fastest of each."""
    rows = []
    sizes = sizes or ((10, 50, 200) if quick else (10, 50, 200, 1000, 2000))
    for ne in sizes:
        duration = duration_scale * DURATIONS.get(ne) if ne in DURATIONS else \
            duration_scale * _duration_for(ne)
        used = None
        for k in range(repeat):
            for solver in solvers:
                if solver == "auto" and k > 0:
                    continue
                if solver == used and k == 0:  # 'auto' already ran it
                    continue
                d = cable_dict(ne, duration, min(0.01, duration / 10), **tol(1e-6),
                               linear_solver=solver)
                ds, _, _ = run_dict(d)
                if solver == "auto":
                    used = str(ds.attrs["linear_solver"])
                r = row(ds, ne=ne, requested=solver, repeat=k)
                r["per_sim_s"] = r["wall"] / r["duration"]
                rows.append(r)
                print(f"  {ne} elements {solver} ({r['solver']}) #{k}: {r['wall']:.2f} s for "
                      f"{r['duration']} s, {r['steps']} steps, {r['us_per_res']:.0f} us/res",
                      file=sys.stderr)
    return rows


def _duration_for(ne: int) -> float:
    """A duration for sizes not in DURATIONS: about the same number of steps as its neighbours
    (steps per simulated second grow about as the element count)."""
    return float(min(2.0, 20.0 / ne))


# --------------------------------------------------------------------------------- profile
def profile(scene: str = "cable16", n: int = 30) -> str:
    d = cable_dict(16, 10.0, **tol(1e-6)) if scene == "cable16" else \
        cable_dict(1000, 0.2, 0.01, **tol(1e-6))
    case = case_from_dict(d)
    catdae.run(case_from_dict(cable_dict(16, 0.05)), progress=False)  # warm the jit caches
    pr = cProfile.Profile()
    pr.enable()
    catdae.run(case, progress=False)
    pr.disable()
    s = io.StringIO()
    pstats.Stats(pr, stream=s).sort_stats("tottime").print_stats(n)
    return s.getvalue()


# --------------------------------------------------------------------------------- tables
def fmt_accuracy(res: dict) -> str:
    lines = []
    for scene, rows in res.items():
        lines += [f"\n{scene}\n",
                  "| rtol | max_order | solver (requested -> used) | wall s | steps | residuals "
                  "| Jacobians | µs/residual | midspan error m |",
                  "|---:|---:|---|---:|---:|---:|---:|---:|---:|"]
        for r in rows:
            err = f"{r['err']:.2e}" if "err" in r else "reference"
            lines.append(f"| {r['rtol']:.0e} | {r['order']} | {r['requested']} -> {r['solver']} "
                         f"| {r['wall']:.2f} | {r['steps']} | {r['nres']} | {r['njac']} | "
                         f"{r['us_per_res']:.0f} | {err} |")
    return "\n".join(lines)


def fmt_scaling(rows: list) -> str:
    lines = ["| elements | unknowns | simulated s | solver (requested -> used) | run | wall s | "
             "CPU s | CPU s per simulated s | steps | residuals | Jacobians | CPU ms/residual | "
             "CPU ms/residual per element |",
             "|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        n2 = 2 * 3 * (r["ne"] - 1)
        cpu_res = 1e3 * r["cpu"] / max(r["nres"], 1)
        lines.append(f"| {r['ne']} | {n2} | {r['duration']:g} | {r['requested']} -> "
                     f"{r['solver']} | {r.get('repeat', 0) + 1} | {r['wall']:.2f} | "
                     f"{r['cpu']:.2f} | {r['cpu'] / r['duration']:.2f} | {r['steps']} | "
                     f"{r['nres']} | {r['njac']} | {cpu_res:.2f} | {cpu_res / r['ne']:.4f} |")
    # band against sparse: the fastest run of each (explicit or picked by 'auto')
    lines += ["", "| elements | 'auto' picks | band: best CPU s | sparse: best CPU s | "
              "sparse / band (CPU) | band: best wall s | sparse: best wall s | "
              "sparse / band (wall) |", "|---:|---|---:|---:|---:|---:|---:|---:|"]
    for ne in sorted({r["ne"] for r in rows}):
        best = {}
        for r in rows:
            if r["ne"] == ne:
                for k in ("cpu", "wall"):
                    key = (r["solver"], k)
                    best[key] = min(best.get(key, np.inf), r[k])
        auto = next((r["solver"] for r in rows if r["ne"] == ne and r["requested"] == "auto"),
                    "-")
        bc, sc = best.get(("band", "cpu"), np.nan), best.get(("sparse", "cpu"), np.nan)
        bw, sw = best.get(("band", "wall"), np.nan), best.get(("sparse", "wall"), np.nan)
        lines.append(f"| {ne} | {auto} | {bc:.2f} | {sc:.2f} | {sc / bc:.2f} | {bw:.2f} | "
                     f"{sw:.2f} | {sw / bw:.2f} |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part", default="all",
                    choices=["accuracy", "scaling", "profile", "profile1000", "all"])
    ap.add_argument("--quick", action="store_true", help="fewer runs (a smoke test)")
    ap.add_argument("--json", help="also write the raw numbers here")
    ap.add_argument("--sizes", help="scaling: element counts, comma separated")
    ap.add_argument("--solvers", default="auto,band,sparse",
                    help="scaling: linear solvers, comma separated (default auto,band,sparse)")
    ap.add_argument("--repeat", type=int, default=1,
                    help="scaling: runs of each solver, interleaved (default 1)")
    ap.add_argument("--duration-scale", type=float, default=1.0,
                    help="scaling: multiply the simulated durations by this")
    args = ap.parse_args(argv)
    print(f"Machine: {machine()}\n")
    raw = {}
    # compile the kernels before timing anything
    catdae.run(case_from_dict(cable_dict(16, 0.05)), progress=False)
    if args.part in ("accuracy", "all"):
        raw["accuracy"] = accuracy(args.quick)
        print(fmt_accuracy(raw["accuracy"]))
    if args.part in ("scaling", "all"):
        sizes = tuple(int(x) for x in args.sizes.split(",")) if args.sizes else None
        raw["scaling"] = scaling(args.quick, sizes, tuple(args.solvers.split(",")),
                                 args.repeat, args.duration_scale)
        print("\n" + fmt_scaling(raw["scaling"]))
    if args.part in ("profile", "all"):
        print("\ncProfile, 16-element cable, 10 s, rtol 1e-6 (tottime):\n")
        print(profile("cable16"))
    if args.part == "profile1000":
        print("\ncProfile, 1000-element cable, 0.2 s, rtol 1e-6 (tottime):\n")
        print(profile("cable1000"))
    print(f"\nMachine after: 1-min load {os.getloadavg()[0]:.2f}")
    if args.json:
        Path(args.json).write_text(json.dumps(raw, indent=1))


if __name__ == "__main__":
    main()
