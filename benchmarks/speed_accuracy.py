"""Cheapest run within an accuracy, catdae against OpenSees' CatenaryCable (issue 11's protocol).

Scene: span 100 m level, L0 = 102 m, EA = 1e8 N, weight 100 N/m, mass 100/9.81 kg/m, pinned
ends; end B moves along the span, u_x = 0.05 (1 - cos πt) m; 10 s, no damping. Quantity: the
vertical position of the midspan node (node c.{n/2}, the same material point for every even
mesh). Error of a run: the largest difference over the output times (every 0.01 s) from a
converged reference.

Reference: catdae, blended mass, 256 elements, rtol 1e-7 (atol 1e-9 m; ``--ref``,
``--ref-rtol``). Its accuracy is stated from the same run on half the elements (mesh) and at ten
times the rtol (time); optionally (``--crosscheck``)
OpenSees on 192 elements at dt 0.0025 s is compared with it too (an independent code).

Search: catdae (blended mass, the default automatic BDF order) over meshes and tolerances, and
OpenSees (CatenaryCable, lumped mass, Newmark average acceleration, Newton with a 1e-10
displacement test) over meshes and dt, each run in its own process. For each accuracy target
(1 cm and 2 mm) the cheapest run of each code that reaches it is re-run as a whole process
(``python -m catdae run CASE`` writing its netCDF; the OpenSees worker script) and its wall and
CPU times are compared, in the same session, one after the other.

    python benchmarks/speed_accuracy.py [--quick] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import opensees_compare as oc  # noqa: E402
import transient_speed as ts  # noqa: E402
from bench_scene import hundred_metre_cable, opensees_job  # noqa: E402

import catdae  # noqa: E402
from catdae.case import case_from_dict  # noqa: E402

DURATION = 10.0
TARGETS = (1e-2, 2e-3)  # m
def case_text(n: int, rtol: float, mass_model: str = "blended", duration: float = DURATION,
              max_order: str | int = "auto"):
    text = hundred_metre_cable(
        title="Issue 11 benchmark: 100 m cable, end B moving along the span", elements=n,
        node="B", axis="x", amplitude=0.05, duration=duration, output_interval=0.01, rtol=rtol,
        atol=rtol * 1e-2, mass_model=mass_model)
    if max_order != "auto":
        text = text.replace(f'mass_model = "{mass_model}"',
                            f'mass_model = "{mass_model}"\nmax_order = {int(max_order)}')
    return text


def run_catdae(n: int, rtol: float, **kw) -> dict:
    """In-process run: midspan z history, CPU and wall time of the transient step."""
    tree = catdae.run(case_from_dict(tomllib.loads(case_text(n, rtol, **kw))), progress=False)
    ds = tree["motion"].ds
    return {"code": "catdae", "ne": n, "rtol": rtol, "tree": tree,
            "z": ds.position.sel(node=f"c.{n // 2}", axis="z").values,
            "steps": int(ds.attrs["n_steps"]), "order": ds.attrs["max_order"],
            "step_wall": float(ds.attrs["wall_time"])}


def children_cost(fn, *args, **kw):
    """(fn's result, wall s, CPU s of the child processes fn ran: user + system)."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = fn(*args, **kw)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return out, wall, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def whole_catdae(n: int, rtol: float, folder: Path, max_order: str | int = "auto") -> dict:
    """``python -m catdae run`` in a new process: wall and CPU time of the whole process, and
    the run's midspan z history and step count (read back from its results file)."""
    path = folder / f"case_{n}_{rtol:g}_{max_order}.toml"
    path.write_text(case_text(n, rtol, max_order=max_order))
    out = folder / f"out_{n}_{rtol:g}_{time.time_ns()}.nc"
    p, wall, cpu = children_cost(
        subprocess.run, [sys.executable, "-m", "catdae", "run", str(path), "-o", str(out),
                         "--no-progress"], capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(p.stderr[-2000:])
    ds = catdae.read_results(out)["motion"].ds
    z = ds.position.sel(node=f"c.{n // 2}", axis="z").values
    steps = int(ds.attrs["n_steps"])
    out.unlink(missing_ok=True)
    return {"wall": wall, "cpu": cpu, "z": z, "steps": steps}


def ops_job(n: int) -> dict:
    """The OpenSees model on n elements, its nodes at catdae's static equilibrium."""
    tree = catdae.run(case_from_dict(tomllib.loads(case_text(n, 1e-4, duration=0.01))),
                      progress=False)
    return opensees_job(tree["initial"].ds, n, motion=("B", 1, 0.05), error_tol=oc.ERROR_TOL,
                        duration=DURATION)


def run_ops(job: dict, dt: float, env: dict) -> dict:
    every = int(round(0.01 / dt))
    out, wall, cpu = children_cost(oc.run_opensees, dict(job, dt=dt, every=every), env)
    z = np.asarray(out["mid"])[:, 2]
    return {"code": "OpenSees", "ne": job["ne"], "dt": dt, "z": z, "status": out["status"],
            "analysis_wall": out["wall"], "analysis_cpu": out["cpu"],
            "process_wall": wall,
            "process_cpu": cpu}


def err(z: np.ndarray, zref: np.ndarray) -> float:
    n = min(len(z), len(zref))
    if n < len(zref):
        return float("inf")
    return float(np.max(np.abs(z[:n] - zref[:n])))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer meshes and tolerances")
    ap.add_argument("--crosscheck", action="store_true",
                    help="also compare the reference with OpenSees on 192 elements, dt 0.0025")
    ap.add_argument("--json", help="write the numbers here")
    ap.add_argument("--ref", type=int, default=256, help="elements of the reference (256)")
    ap.add_argument("--ref-rtol", type=float, default=1e-7, help="its rtol (1e-7)")
    ap.add_argument("--ref-cache", help="an .npz file: the reference histories are read from it "
                    "if it exists, else computed and written to it")
    args = ap.parse_args(argv)
    print(f"Machine: {ts.machine()}\n", flush=True)
    env = oc.opensees_env()
    run_catdae(8, 1e-3, duration=0.05)  # compile / load the kernels

    # ---------------------------------------------------------------- reference
    nref, rref = args.ref, args.ref_rtol
    cache = Path(args.ref_cache) if args.ref_cache else None
    if cache is not None and cache.exists():
        saved = np.load(cache)
        assert int(saved["n"]) == nref and float(saved["rtol"]) == rref, "another reference"
        zref, z_half, z_t = saved["z"], saved["z_half"], saved["z_t"]
        ref = {"steps": int(saved["steps"]), "step_wall": float(saved["wall"])}
    else:
        ref = run_catdae(nref, rref)
        zref = ref["z"]
        z_half = run_catdae(nref // 2, rref)["z"]
        z_t = run_catdae(nref, 10.0 * rref)["z"]
        if cache is not None:
            np.savez(cache, n=nref, rtol=rref, z=zref, z_half=z_half, z_t=z_t,
                     steps=ref["steps"], wall=ref["step_wall"])
    mesh_diff = err(z_half, zref)
    time_diff = err(z_t, zref)
    print(f"reference: {nref} elements rtol {rref:g}, {ref['steps']} steps, "
          f"{ref['step_wall']:.1f} s; {nref // 2} elements differ by {mesh_diff:.2e} m, rtol "
          f"{10 * rref:g} by {time_diff:.2e} m", flush=True)
    cross = None
    if args.crosscheck:
        c = run_ops(ops_job(192), 0.0025, env)
        cross = err(c["z"], zref)
        print(f"OpenSees 192 elements dt 0.0025 s against the reference: {cross:.2e} m",
              flush=True)

    # ---------------------------------------------------------------- searches
    meshes = (16, 32, 48, 64) if args.quick else (16, 24, 32, 40, 48, 64, 80, 96)
    tols = (1e-3, 1e-4) if args.quick else (1e-3, 3e-4, 1e-4, 1e-5)
    rows = []
    for n in meshes:
        for rtol in tols:
            t0 = time.process_time()
            r = run_catdae(n, rtol)
            r["cpu_inproc"] = time.process_time() - t0
            r["err"] = err(r["z"], zref)
            r.pop("tree")
            rows.append(r)
            print(f"catdae {n:4d} elements rtol {rtol:.0e}: err {r['err']:.2e} m, CPU "
                  f"{r['cpu_inproc']:.2f} s, {r['steps']} steps, order {r['order']}", flush=True)
    ops_meshes = (32, 64, 96, 128) if args.quick else (32, 48, 64, 80, 96, 128, 160)
    ops_rows = []
    for n in ops_meshes:
        job = ops_job(n)
        best = None
        for dt in (0.01, 0.005, 0.0025, 0.00125):  # at most the output interval, 0.01 s
            r = run_ops(job, dt, env)
            r["err"] = err(r["z"], zref) if r["status"] == "completed" else float("inf")
            ops_rows.append(r)
            print(f"OpenSees {n:4d} elements dt {dt:g}: err {r['err']:.2e} m, process wall "
                  f"{r['process_wall']:.2f} s, CPU {r['process_cpu']:.2f} s ({r['status']})",
                  flush=True)
            if best is not None and r["err"] > 0.8 * best:
                break  # the mesh dominates: a smaller dt buys nothing
            best = r["err"] if best is None else min(best, r["err"])
            if r["process_wall"] > 300:
                break

    # ---------------------------------------------------------------- whole processes
    summary = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for target in TARGETS:
            cands = sorted((r for r in rows if r["err"] <= target), key=lambda r: r["cpu_inproc"])
            ocands = sorted((r for r in ops_rows if r["err"] <= target),
                            key=lambda r: r["process_wall"])
            if not cands or not ocands:
                summary.append({"target": target, "catdae": None, "opensees": None})
                print(f"target {target:g} m: not reached by "
                      f"{'catdae' if not cands else 'OpenSees'} in the search", flush=True)
                continue
            best_c = None
            for r in cands[:3]:
                w = whole_catdae(r["ne"], r["rtol"], folder)
                if best_c is None or w["wall"] < best_c[1]["wall"]:
                    best_c = (r, w)
            best_o = None
            for r in ocands[:2]:
                w = run_ops(ops_job(r["ne"]), r["dt"], env)
                if best_o is None or w["process_wall"] < best_o[1]["process_wall"]:
                    best_o = (r, w)
            (rc, wc), (ro, wo) = best_c, best_o
            line = {"target": target,
                    "catdae": {"ne": rc["ne"], "rtol": rc["rtol"], "err": rc["err"], **wc},
                    "opensees": {"ne": ro["ne"], "dt": ro["dt"], "err": ro["err"],
                                 "wall": wo["process_wall"], "cpu": wo["process_cpu"]}}
            summary.append(line)
            print(f"target {target:g} m: catdae {rc['ne']} elements rtol {rc['rtol']:.0e} "
                  f"(err {rc['err']:.2e}) {wc['wall']:.2f} s wall {wc['cpu']:.2f} s CPU; "
                  f"OpenSees {ro['ne']} elements dt {ro['dt']:g} (err {ro['err']:.2e}) "
                  f"{wo['process_wall']:.2f} s wall {wo['process_cpu']:.2f} s CPU; "
                  f"catdae/OpenSees wall {wc['wall'] / wo['process_wall']:.3f}, CPU "
                  f"{wc['cpu'] / wo['process_cpu']:.3f}", flush=True)

    print("\n| code | elements | rtol or dt | error m | CPU s (catdae in-process; OpenSees "
          "process) | steps |")
    print("|---|---:|---:|---:|---:|---:|")
    for r in rows:
        print(f"| catdae blended | {r['ne']} | rtol {r['rtol']:.0e} | {r['err']:.2e} | "
              f"{r['cpu_inproc']:.2f} | {r['steps']} |")
    for r in ops_rows:
        print(f"| OpenSees | {r['ne']} | dt {r['dt']:g} | {r['err']:.2e} | "
              f"{r['process_cpu']:.2f} | {int(round(DURATION / r['dt']))} |")
    load = os.getloadavg()[0]
    print(f"\n1-min load at the end: {load:.2f}")
    if args.json:
        Path(args.json).write_text(json.dumps({
            "reference": {"elements": nref, "rtol": rref, "mesh_diff_half": mesh_diff,
                          "time_diff_10rtol": time_diff,
                          "opensees_192_dt0.0025": cross},
            "catdae": [{k: v for k, v in r.items() if k != "z"} for r in rows],
            "opensees": [{k: v for k, v in r.items() if k != "z"} for r in ops_rows],
            "summary": summary, "load": load}, indent=1, default=str))


if __name__ == "__main__":
    main()
