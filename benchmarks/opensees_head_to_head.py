"""The 100 m cable against OpenSees' CatenaryCable, both of its mass types, whole processes
(issue 25, "Cheaper steps" and the 100 m cable's acceptance line). One run does it all and
writes the Markdown report (``--md``).

Scene (benchmarks/speed_accuracy.md, issue 11): span 100 m level, L0 = 102 m, EA = 1e8 N,
weight 100 N/m, pinned ends; end B moves along the span as 0.05 (1 - cos πt) m; 10 s, no
damping. Error of a run: the largest |Δz| of the midspan node over the 1 001 output times
against a converged reference (catdae, blended mass, 256 elements, rtol 1e-7; ``--ref-cache``
keeps it between runs). ``--ref-check`` states the reference's own error (the same run on 128
elements and at rtol 1e-6) and compares it with OpenSees' truss-consistent mass on 320 elements
at dt 0.0025 s, an independent code.

OpenSees (openseespy from PyPI, ``element CatenaryCable``, Newmark average acceleration, Newton
with a 1e-10 displacement test, the nodes at catdae's static equilibrium): ``massType`` 0
(lumped) and 3 (truss-consistent, ρ L0 / 6 [[2, 1], [1, 2]]). CatenaryCable's massType 1 ("by
integration") is not implemented in the element: it prints a warning and falls back to the lumped
mass (this script checks that its history equals massType 0's). 2 is a lumped mass split by the
end forces.

1. Search: catdae in-process (CPU of ``catdae.run``) over mesh × rtol × mass model × the step's
   ``resolve`` (``max_order = "auto"``); OpenSees as processes over mesh × dt for each mass type.
2. Head-to-head: for each target (1 cm, 2 mm) the cheapest runs of the search that reach it
   (two of catdae's, two of each OpenSees mass type) are run again as whole processes,
   ``python -m catdae run CASE -o OUT.nc`` (imports, kernels, static step, transient, netCDF) and
   the OpenSees worker process, one after the other, ``--repeats`` rounds; the median wall and
   CPU (user + system) of each; the ratio is catdae's best over OpenSees' best (either mass type).

    python benchmarks/opensees_head_to_head.py [--ref-cache ref256.npz] [--md FILE] [--quick]
"""

from __future__ import annotations

import argparse
import datetime
import os
import statistics
import sys
import tempfile
import time
import tomllib
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import speed_accuracy as sa  # noqa: E402

import catdae  # noqa: E402
from catdae.case import case_from_dict  # noqa: E402

TARGETS = (1e-2, 2e-3)  # m
OPS_TYPES = {0: "lumped", 3: "truss-consistent"}
LOADS: list[float] = []


def load() -> float:
    x = os.getloadavg()[0]
    LOADS.append(x)
    return x


# ---------------------------------------------------------------------------- runs
def case_text(n: int, rtol: float, mass: str, order="auto", resolve="auto") -> str:
    """speed_accuracy's case with the step's ``resolve`` (docs/case-format.md) when not auto."""
    text = sa.case_text(n, rtol, mass_model=mass, max_order=order)
    if resolve != "auto":
        text = text.replace(f'mass_model = "{mass}"',
                            f'mass_model = "{mass}"\nresolve = "{resolve}"')
    return text


def catdae_inproc(n: int, rtol: float, mass: str, order="auto", resolve="auto") -> dict:
    t0 = time.process_time()
    tree = catdae.run(case_from_dict(tomllib.loads(case_text(n, rtol, mass, order, resolve))),
                      progress=False)
    cpu = time.process_time() - t0
    ds = tree["motion"].ds
    return {"code": "catdae", "ne": n, "rtol": rtol, "mass": mass, "order": order,
            "resolve": resolve, "cpu": cpu,
            "z": ds.position.sel(node=f"c.{n // 2}", axis="z").values,
            "steps": int(ds.attrs["n_steps"]),
            "res": int(ds.attrs["n_residual_evaluations"]),
            "jac": int(ds.attrs["n_jacobian_evaluations"]),
            "final_order": ds.attrs["max_order"]}


def catdae_process(c: dict, folder: Path) -> dict:
    """``python -m catdae run`` in a new process: wall, CPU and the midspan history."""
    path = folder / f"case_{c['ne']}_{c['rtol']:g}_{c['mass']}_{c['resolve']}.toml"
    path.write_text(case_text(c["ne"], c["rtol"], c["mass"], c["order"], c["resolve"]))
    out = folder / f"out_{time.time_ns()}.nc"
    argv = [sys.executable, "-m", "catdae", "run", str(path), "-o", str(out), "--no-progress"]
    p, wall, cpu = sa.children_cost(sa.subprocess.run, argv, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(p.stderr[-2000:])
    ds = catdae.read_results(out)["motion"].ds
    z = ds.position.sel(node=f"c.{c['ne'] // 2}", axis="z").values
    out.unlink(missing_ok=True)
    return {"wall": wall, "cpu": cpu, "z": z}


_JOBS: dict[int, dict] = {}


def ops_run(n: int, dt: float, mass_type: int, env: dict) -> dict:
    """The OpenSees worker as a process: its wall and CPU, and the midspan history."""
    if n not in _JOBS:
        _JOBS[n] = sa.ops_job(n)
    job = dict(_JOBS[n], mass_type=mass_type)
    r = sa.run_ops(job, dt, env)
    return {"code": "OpenSees", "ne": n, "dt": dt, "mass_type": mass_type, "z": r["z"],
            "status": r["status"], "wall": r["process_wall"], "cpu": r["process_cpu"]}


# ---------------------------------------------------------------------------- reference
def reference(args) -> dict:
    cache = Path(args.ref_cache) if args.ref_cache else None
    if cache is not None and cache.exists():
        saved = np.load(cache)
        ref = {k: saved[k] for k in saved.files}
    else:
        t0 = time.process_time()
        r = sa.run_catdae(args.ref, args.ref_rtol)
        ref = {"n": args.ref, "rtol": args.ref_rtol, "z": r["z"], "steps": r["steps"],
               "cpu": time.process_time() - t0}
    if args.ref_check and "z_half" not in ref:
        ref["z_half"] = sa.run_catdae(int(ref["n"]) // 2, float(ref["rtol"]))["z"]
        ref["z_t"] = sa.run_catdae(int(ref["n"]), 10 * float(ref["rtol"]))["z"]
    if cache is not None:
        np.savez(cache, **ref)
    return ref


# ---------------------------------------------------------------------------- searches
def search_catdae(zref, args) -> list[dict]:
    masses = args.masses.split(",")
    meshes = [int(x) for x in args.meshes.split(",")]
    tols = [float(x) for x in args.tols.split(",")]
    rows = []
    orders = [o if o == "auto" else int(o) for o in args.orders.split(",")]
    for mass, resolve, order in ((m, v, o) for m in masses for v in args.resolve.split(",")
                                 for o in orders):
        for n in meshes:
            best = None
            for rtol in tols:  # loosest first
                r = catdae_inproc(n, rtol, mass, order, resolve=resolve)
                r["err"] = sa.err(r["z"], zref)
                rows.append(r)
                print(f"catdae {mass} {resolve:6s} order {order} {n:4d} el rtol {rtol:.0e}: err "
                      f"{r['err']:.2e} m, CPU {r['cpu']:.2f} s, {r['steps']} steps, "
                      f"{r['res']} residuals, order {r['final_order']}", flush=True)
                if best is not None and r["err"] > 0.8 * best:
                    break  # the mesh's own error: a tighter rtol buys nothing
                best = r["err"] if best is None else min(best, r["err"])
    return rows


def search_opensees(zref, env, args) -> list[dict]:
    rows = []
    for mt in OPS_TYPES:
        meshes = [int(x) for x in (args.ops_meshes_0 if mt == 0 else args.ops_meshes_3)
                  .split(",")]
        cheapest_fine = None  # CPU of the cheapest run of this type within the finest target
        for n in meshes:
            best = None
            for dt in (0.01, 0.005, 0.0025):
                if cheapest_fine is not None:
                    break
                r = ops_run(n, dt, mt, env)
                r["err"] = sa.err(r["z"], zref) if r["status"] == "completed" else float("inf")
                rows.append(r)
                print(f"OpenSees massType {mt} {n:4d} el dt {dt:g}: err {r['err']:.2e} m, "
                      f"wall {r['wall']:.2f} s, CPU {r['cpu']:.2f} s ({r['status']})",
                      flush=True)
                if r["err"] <= min(TARGETS):
                    cheapest_fine = r["cpu"]
                if best is not None and r["err"] > 0.8 * best:
                    break
                best = r["err"] if best is None else min(best, r["err"])
                if r["wall"] > args.max_ops_wall:
                    break
            if cheapest_fine is not None:
                break  # finer meshes of this mass type only cost more
    return rows


def check_mass_type_1(env) -> str:
    """massType 1 against 0 on 16 elements, 2 s: CatenaryCable falls back to the lumped mass."""
    a = ops_run(16, 0.01, 0, env)["z"]
    b = ops_run(16, 0.01, 1, env)["z"]
    c = ops_run(16, 0.01, 3, env)["z"]
    return (f"16 elements, dt 0.01 s, 10 s: massType 1 - massType 0 max |Δz| = "
            f"{np.max(np.abs(a - b)):.1e} m (identical: the element's 'integration' mass falls "
            f"back to lumped); massType 3 - massType 0: {np.max(np.abs(a - c)):.2e} m")


# ---------------------------------------------------------------------------- head-to-head
def head_to_head(crows, orows, env, args) -> list[dict]:
    lines = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for target in TARGETS:
            cands = sorted((r for r in crows if r["err"] <= target), key=lambda r: r["cpu"])
            cands = cands[:args.candidates]
            ocands = []
            for mt in OPS_TYPES:
                ocands += sorted((r for r in orows if r["err"] <= target
                                  and r["mass_type"] == mt), key=lambda r: r["cpu"])[:2]
            if not cands or not ocands:
                lines.append({"target": target, "catdae": cands, "opensees": ocands,
                              "missing": "catdae" if not cands else "OpenSees"})
                print(f"target {target:g}: not reached by "
                      f"{'catdae' if not cands else 'OpenSees'} in the search", flush=True)
                continue
            timing = {id(r): [] for r in cands + ocands}
            for k in range(args.repeats):
                for r in cands + ocands:
                    if r["code"] == "catdae":
                        w = catdae_process(r, folder)
                        w["err"] = sa.err(w["z"], ZREF)
                    else:
                        w = ops_run(r["ne"], r["dt"], r["mass_type"], env)
                        w["err"] = sa.err(w["z"], ZREF)
                    w["load"] = load()
                    timing[id(r)].append(w)
                    print(f"  round {k + 1} {label(r)}: wall {w['wall']:.2f} s, CPU "
                          f"{w['cpu']:.2f} s, err {w['err']:.2e} m, load {w['load']:.1f}",
                          flush=True)
            for r in cands + ocands:
                ts_ = timing[id(r)]
                r.setdefault("whole", {})[target] = {
                    "wall": statistics.median(w["wall"] for w in ts_),
                    "cpu": statistics.median(w["cpu"] for w in ts_),
                    "err_process": ts_[0]["err"],
                    "loads": [w["load"] for w in ts_]}
            bc = min(cands, key=lambda r: r["whole"][target]["wall"])
            bo = min(ocands, key=lambda r: r["whole"][target]["wall"])
            lines.append({"target": target, "catdae": cands, "opensees": ocands,
                          "best_c": bc, "best_o": bo})
    return lines


def label(r: dict) -> str:
    if r["code"] == "catdae":
        res = "" if r.get("resolve", "auto") == "auto" else f", resolve {r['resolve']}"
        order = "" if r.get("order", "auto") == "auto" else f", max_order {r['order']}"
        return f"catdae {r['mass']}{res}{order}, {r['ne']} el, rtol {r['rtol']:.0e}"
    return f"OpenSees massType {r['mass_type']} ({OPS_TYPES.get(r['mass_type'], '?')}), " \
           f"{r['ne']} el, dt {r['dt']:g} s"


# ---------------------------------------------------------------------------- report
def report(ref, crows, orows, lines, mt1, started, args) -> str:
    from transient_speed import machine

    out = ["# The 100 m cable: catdae against OpenSees, both mass types (issue 25)\n",
           f"`python benchmarks/opensees_head_to_head.py {' '.join(sys.argv[1:])}`, "
           f"{started:%Y-%m-%d %H:%M}-{datetime.datetime.now(datetime.UTC):%H:%M} "
           "UTC.\n",
           f"Machine: {machine()}. 1-min load average {min(LOADS):.1f}-{max(LOADS):.1f} "
           f"during the run (2 cores shared with other sessions' work: wall times are up to "
           f"several times the CPU times; each head-to-head row is the median of "
           f"{args.repeats} whole processes run one after the other, alternating).\n",
           "Scene: benchmarks/speed_accuracy.md (100 m span, L0 102 m, EA 1e8 N, 100 N/m, end B "
           "moved 0.05 (1 - cos πt) m along the span, 10 s). Error: max |Δz| of the midspan "
           "node over the 1 001 outputs against the reference.\n",
           f"Reference: catdae, blended, {int(ref['n'])} elements, rtol {float(ref['rtol']):g} "
           f"({int(ref['steps'])} steps)."]
    zref = ref["z"]
    if "z_half" in ref:
        out.append(f" Its own error: {int(ref['n']) // 2} elements differ from it by "
                   f"{sa.err(ref['z_half'], zref):.2e} m, rtol {10 * float(ref['rtol']):g} by "
                   f"{sa.err(ref['z_t'], zref):.2e} m.")
    if "z_ops" in ref:
        out.append(f" OpenSees (truss-consistent mass, {int(ref['ops_n'])} elements, dt "
                   f"{float(ref['ops_dt']):g} s) differs from it by "
                   f"{sa.err(ref['z_ops'], zref):.2e} m.")
    out.append(f"\n\nOpenSees' massType 1: {mt1}.\n")
    out.append("\n## Head-to-head, whole processes\n")
    out.append("| target | run | error m | wall s | CPU s |\n|---|---|---:|---:|---:|")
    summary = []
    for ln in lines:
        if "missing" in ln:
            out.append(f"| {ln['target'] * 1e3:g} mm | not reached by {ln['missing']} in the "
                       "search | | | |")
            continue
        t = ln["target"]
        for r in ln["catdae"] + ln["opensees"]:
            w = r["whole"][t]
            best = r is ln["best_c"] or r is ln["best_o"]
            b = "**" if best else ""
            out.append(f"| {t * 1e3:g} mm | {b}{label(r)}{b} | {r['err']:.2e} | {w['wall']:.2f} "
                       f"| {w['cpu']:.2f} |")
        c, o = ln["best_c"]["whole"][t], ln["best_o"]["whole"][t]
        summary.append(f"- within {t * 1e3:g} mm: catdae / OpenSees = {c['wall']:.2f} / "
                       f"{o['wall']:.2f} = **{c['wall'] / o['wall']:.2f}** (wall), "
                       f"{c['cpu']:.2f} / {o['cpu']:.2f} = **{c['cpu'] / o['cpu']:.2f}** (CPU); "
                       f"target ≤ 0.5: {'met' if c['wall'] / o['wall'] <= 0.5 else 'not met'}")
    out.append("\n" + "\n".join(summary) + "\n")
    out.append("\n## Search (catdae in-process CPU of `catdae.run`; OpenSees process)\n")
    out.append("| run | error m | CPU s | steps | residuals | Jacobians | final order |\n"
               "|---|---:|---:|---:|---:|---:|---:|")
    for r in crows:
        out.append(f"| {label(r)} | {r['err']:.2e} | {r['cpu']:.2f} | {r['steps']} | "
                   f"{r['res']} | {r['jac']} | {r['final_order']} |")
    for r in orows:
        out.append(f"| {label(r)} | {r['err']:.2e} | {r['cpu']:.2f} (wall {r['wall']:.2f}) | "
                   f"{int(round(10 / r['dt']))} | | | |")
    return "\n".join(out) + "\n"


ZREF = None


def main(argv=None) -> None:
    global ZREF
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", type=int, default=256)
    ap.add_argument("--ref-rtol", type=float, default=1e-7)
    ap.add_argument("--ref-cache", help=".npz: read the reference from it, else write it")
    ap.add_argument("--ref-check", action="store_true",
                    help="the reference's own error, and OpenSees (massType 3, 320 elements, "
                         "dt 0.0025 s) against it")
    ap.add_argument("--masses", default="blended,blended_linear")
    ap.add_argument("--meshes", default="24,32,40,48,56,64,80,96")
    ap.add_argument("--tols", default="1e-3,3e-4,1e-4,3e-5,1e-5,3e-6")
    ap.add_argument("--resolve", default="auto,waves",
                    help="the transient step's resolve settings to search (docs/case-format.md)")
    ap.add_argument("--orders", default="auto",
                    help="the transient step's max_order settings to search: auto, 1-5")
    ap.add_argument("--ops-meshes-0", default="96,128,160,192,256")
    ap.add_argument("--ops-meshes-3", default="48,64,80,96,128,160,192,256")
    ap.add_argument("--max-ops-wall", type=float, default=200.0)
    ap.add_argument("--candidates", type=int, default=2, help="catdae runs per target")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--md", help="write the report here")
    args = ap.parse_args(argv)
    started = datetime.datetime.now(datetime.UTC)
    load()
    env = sa.oc.opensees_env()
    sa.run_catdae(8, 1e-3, duration=0.05)  # the kernels compiled and cached
    ref = reference(args)
    ZREF = zref = ref["z"]
    if args.ref_check and "z_ops" not in ref:
        r = ops_run(320, 0.0025, 3, env)
        ref.update(z_ops=r["z"], ops_n=320, ops_dt=0.0025)
        if args.ref_cache:
            np.savez(args.ref_cache, **ref)
    print(f"reference: {int(ref['n'])} elements, rtol {float(ref['rtol']):g}", flush=True)
    mt1 = check_mass_type_1(env)
    print(mt1, flush=True)
    crows = search_catdae(zref, args)
    orows = search_opensees(zref, env, args)
    load()
    lines = head_to_head(crows, orows, env, args)
    load()
    text = report(ref, crows, orows, lines, mt1, started, args)
    print(text)
    if args.md:
        Path(args.md).write_text(text)


if __name__ == "__main__":
    main()
