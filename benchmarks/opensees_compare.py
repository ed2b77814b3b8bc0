"""catdae against OpenSees' CatenaryCable element on the 100 m cable with a moving support.

Scene (the one of ``transient_speed.py``): span 100 m, L0 = 102 m, EA = 1e8 N, weight 100 N/m,
mass 100/9.81 kg/m, 16 elements, end A moving vertically as z_A = 0.5 (1 - cos πt) m, 10 s,
no damping (``--duration`` sets the simulated time; default 10 s).

OpenSees (openseespy) models it with ``element CatenaryCable`` (Abell & Ibanez; exact elastic
catenary flexibility, Newton on the misclosure each update) and integrates with Newmark's
average-acceleration rule (γ = 1/2, β = 1/4) at a fixed dt. CatenaryCable's mass is lumped here
(massType 0: ρ L0 / 2 at each end; the worker takes ``mass_type`` 1, truss-consistent, from
its job, as ``opensees_head_to_head.py`` uses it), so the comparison uses catdae with
``mass_model = "lumped"`` too: the same
semi-discrete model, integrated by IDA (variable order/step BDF) or by Newmark. The OpenSees
nodes start at catdae's static equilibrium (the exact catenary); a static Newton step in
OpenSees confirms it is in equilibrium there too.

catdae runs with both mass models (lumped, the OpenSees model, and consistent, its default)
at several tolerances.

Errors: largest distance over the output times (every 0.01 s) between the midspan node's
position and that of a reference run: catdae at rtol 1e-10 (atol 1e-12 m) with the lumped mass
(time-integration error of the OpenSees model) and with the consistent mass, and optionally
(``--fine N``) catdae with the consistent mass on N elements (the total error, mesh included, of
every 16-element run). OpenSees' dt is halved from 0.01 s until its error against the lumped
reference falls below that of catdae lumped at rtol 1e-6 (or a run takes longer than
``--max-ops-wall``). OpenSees' time (CPU and wall) at each catdae lumped run's error is
interpolated (log-log) in that sweep; the ratio of the two is the speed-up at equal error on the
same model. With ``--fine``, a table of the cheapest runs' total errors follows, and
``--ops-mesh M`` adds OpenSees and catdae (rtol 1e-4) on M elements.

OpenSees runs in a subprocess (its import needs the wheel's own ``lib`` folder on
LD_LIBRARY_PATH); this script is both the driver and (``--worker``) that subprocess:

    python benchmarks/opensees_compare.py [--duration 10] [--fine 64 [--ops-mesh 32]]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

HERE = Path(__file__).resolve().parent
MID = "c.8"
DURATION = 10.0  # s (default; --duration)
ERROR_TOL = 1e-10  # CatenaryCable's relative misclosure tolerance (default examples use 1e-6)


# ------------------------------------------------------------------------------ OpenSees side
def worker() -> None:
    """Read the model from stdin (JSON), run OpenSees, write the midspan history (JSON)."""
    job = json.load(sys.stdin)
    t_import = time.perf_counter()
    import openseespy.opensees as ops

    t_import = time.perf_counter() - t_import
    import math

    X = job["X"]
    conn = job["conn"]
    dt = job["dt"]
    duration = job["duration"]
    every = job["every"]  # steps between outputs
    mid = job["mid"] + 1
    t0 = time.perf_counter()
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 3)
    for k, (x, y, z) in enumerate(X):
        ops.node(k + 1, x, y, z)
    a, b = job["supports"]
    # the moving support and axis (default: z of A) and the amplitude of a (1 - cos πt)
    moving, axis, amp = job.get("motion", (a, 3, 0.5))
    for node in (a, b):
        ops.fix(node + 1, *[0 if (node == moving and d == axis) else 1 for d in (1, 2, 3)])
    for e, (i, j) in enumerate(conn):
        ops.element("CatenaryCable", e + 1, i + 1, j + 1, job["weight"], job["EA"], 1.0,
                    job["L0e"][e], 0.0, 0.0, job["rho"], job["error_tol"], job.get("nsub", 1),
                    job.get("mass_type", 0))
    # support motion: z_A(t) = 0.5 (1 - cos πt), sampled exactly at the steps
    nsteps = int(round(duration / dt))
    values = [amp * (1.0 - math.cos(math.pi * k * dt)) for k in range(nsteps + 2)]
    ops.timeSeries("Path", 1, "-dt", dt, "-values", *values)
    ops.pattern("Plain", 1, 1)
    ops.sp(moving + 1, axis, 1.0)
    # static check (support motion at its t = 0 value, zero): the catenary positions must
    # already be in equilibrium
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-10, 50)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 0.0)
    ops.analysis("Static")
    ok_static = ops.analyze(1)
    static_disp = max(abs(ops.nodeDisp(n + 1, d + 1)) for n in range(len(X)) for d in range(3))
    ops.wipeAnalysis()
    ops.setTime(0.0)
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system(job.get("system", "BandGeneral"))
    ops.test("NormDispIncr", job["newton_tol"], 50)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    t_build = time.perf_counter() - t0

    def pos():
        return [ops.nodeCoord(mid, d + 1) + ops.nodeDisp(mid, d + 1) for d in range(3)]

    hist = [pos()]
    times = [0.0]
    status = "completed"
    t1 = time.perf_counter()
    c1 = time.process_time()
    done = 0
    while done < nsteps:
        n = min(every, nsteps - done)
        if ops.analyze(n, dt) != 0:
            status = f"analyze failed near t = {ops.getTime():.6g} s"
            break
        done += n
        times.append(ops.getTime())
        hist.append(pos())
    wall = time.perf_counter() - t1
    cpu = time.process_time() - c1
    json.dump({"times": times, "mid": hist, "wall": wall, "cpu": cpu, "build": t_build,
               "import": t_import,
               "status": status, "static_ok": ok_static, "static_disp": static_disp,
               "steps": done, "version": ops.version() if hasattr(ops, "version") else "?"},
              sys.stdout)


def opensees_env() -> dict:
    """The environment for the OpenSees subprocess: the wheel's lib folder on LD_LIBRARY_PATH."""
    import importlib.util

    spec = importlib.util.find_spec("openseespylinux")
    if spec is None or not spec.submodule_search_locations:
        raise RuntimeError("openseespy is not installed (pip install openseespy)")
    lib = Path(list(spec.submodule_search_locations)[0]) / "lib"
    env = dict(os.environ)
    env["LD_LIBRARY_PATH"] = f"{lib}:{env.get('LD_LIBRARY_PATH', '')}".rstrip(":")
    return env


def run_opensees(job: dict, env: dict) -> dict:
    p = subprocess.run([sys.executable, __file__, "--worker"], input=json.dumps(job),
                       capture_output=True, text=True, env=env, timeout=900)
    if p.returncode != 0 or not p.stdout.strip():
        raise RuntimeError(f"OpenSees worker failed (exit {p.returncode}):\n{p.stderr[-3000:]}")
    out = json.loads(p.stdout)
    out["stderr_tail"] = p.stderr[-500:]
    return out


# ------------------------------------------------------------------------------ driver
def equal_error_wall(ops_rows: list, err: float, key: str = "wall") -> tuple[float, str]:
    """OpenSees' time (``key``: wall or cpu) at error ``err``: log-log interpolation in
    (error, time) between the two runs that bracket it (error ∝ dt^p, time ∝ 1/dt);
    extrapolated from the two finest (or coarsest) otherwise. Returns (time, 'interpolated' |
    'extrapolated')."""
    import numpy as np

    pts = sorted((r["err"], r[key]) for r in ops_rows if r["status"] == "completed")
    e = np.log([p[0] for p in pts])
    w = np.log([p[1] for p in pts])
    x = np.log(err)
    if e[0] <= x <= e[-1]:
        k = int(np.clip(np.searchsorted(e, x), 1, len(e) - 1))
        how = "interpolated"
    else:
        k = 1 if x < e[0] else len(e) - 1
        how = "extrapolated"
    slope = (w[k] - w[k - 1]) / (e[k] - e[k - 1])
    return float(np.exp(w[k - 1] + slope * (x - e[k - 1]))), how


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--json", help="also write the raw numbers here")
    ap.add_argument("--duration", type=float, default=DURATION,
                    help=f"simulated seconds (default {DURATION:g})")
    ap.add_argument("--tols", default="1e-4,1e-5,1e-6,1e-7,1e-8",
                    help="catdae tolerances (rtol; atol = rtol * 1e-2 m)")
    ap.add_argument("--fine", type=int, default=0,
                    help="also measure total errors against a consistent-mass reference on a "
                         "mesh of this many elements (a multiple of 16; 0: none)")
    ap.add_argument("--fine-rtol", type=float, default=1e-9)
    ap.add_argument("--ops-mesh", type=int, default=0,
                    help="with --fine: also run OpenSees (and catdae, rtol 1e-4) on a mesh of "
                         "this many elements at dt 0.01, 0.005, 0.0025 s (total error)")
    ap.add_argument("--max-ops-wall", type=float, default=200.0,
                    help="stop halving OpenSees' dt once a run takes longer than this (s)")
    args = ap.parse_args(argv)
    if args.worker:
        worker()
        return

    import numpy as np

    sys.path.insert(0, str(HERE))
    import transient_speed as ts
    from bench_scene import opensees_job

    duration = args.duration
    tols = [float(x) for x in args.tols.split(",")]
    print(f"Machine: {ts.machine()}\n")
    env = opensees_env()
    ts.catdae.run(ts.case_from_dict(ts.cable_dict(16, 0.05)), progress=False)  # compile

    def cable(**kw):
        return ts.cable_dict(duration=duration, **kw)

    # references: lumped (the OpenSees model), consistent (catdae's default), both 16 elements
    # at rtol 1e-10; optionally a finer consistent mesh (total error of the 16-element models)
    ref, tree, _ = ts.run_dict(cable(**ts.tol(ts.REF_RTOL), mass_model="lumped"))
    ref_c = ts.run_dict(cable(**ts.tol(ts.REF_RTOL)))[0]
    refs = {"lumped": ref, "consistent": ref_c}
    for k, r in refs.items():
        print(f"reference {k}: {r.attrs['wall_time']:.2f} s, {r.attrs['n_steps']} steps",
              file=sys.stderr)
    ref_f = None
    if args.fine:
        ref_f = ts.run_dict(ts.cable_dict(args.fine, duration, **ts.tol(args.fine_rtol)))[0]
        print(f"reference fine ({args.fine} elements, rtol {args.fine_rtol:g}): "
              f"{ref_f.attrs['wall_time']:.2f} s, {ref_f.attrs['n_steps']} steps",
              file=sys.stderr)
    mid_f = f"c.{args.fine // 2}" if args.fine else None

    def errors(p_mid: np.ndarray) -> dict:
        out = {}
        for k, r in refs.items():
            q = r.position.sel(node=MID).values
            n = min(len(p_mid), len(q))
            out[k] = float(np.max(np.linalg.norm(p_mid[:n] - q[:n], axis=1)))
        if ref_f is not None:
            q = ref_f.position.sel(node=mid_f).values
            n = min(len(p_mid), len(q))
            out["fine"] = float(np.max(np.linalg.norm(p_mid[:n] - q[:n], axis=1)))
        return out

    ref_errs = {k: errors(r.position.sel(node=MID).values) for k, r in refs.items()}
    rows = []
    for mass in ("lumped", "consistent"):
        for rtol in tols:
            ds, _, _ = ts.run_dict(cable(**ts.tol(rtol), mass_model=mass))
            r = ts.row(ds, rtol=rtol, code=f"catdae (IDA, {mass})", mass=mass)
            r["errs"] = errors(ds.position.sel(node=MID).values)
            r["err"] = r["errs"][mass]  # against its own model's reference
            rows.append(r)
            print(f"catdae {mass} rtol {rtol:g}: {r['wall']:.2f} s, {r['steps']} steps, "
                  f"errs {r['errs']}", file=sys.stderr)
    target = min(r["err"] for r in rows if r["mass"] == "lumped" and r["rtol"] >= 1e-6)

    tref = ref.time.values

    def ops_job(ne: int, tree_ne) -> dict:
        """The OpenSees model of the ne-element cable, nodes at catdae's static equilibrium."""
        return opensees_job(tree_ne["initial"].ds, ne, error_tol=ERROR_TOL, duration=duration)

    job16 = ops_job(16, tree)

    def ops_run(dt, job=job16):
        every = int(round(0.01 / dt))
        out = run_opensees(dict(job, dt=dt, every=every), env)
        t = np.asarray(out["times"])
        p = np.asarray(out["mid"])
        n = min(len(t), len(tref))
        assert np.allclose(t[:n], tref[:n], atol=1e-9), "output times differ"
        r = {"code": f"OpenSees (Newmark, lumped), {job['ne']} elements", "dt": dt,
             "ne": job["ne"], "wall": out["wall"], "cpu": out["cpu"],
             "steps": out["steps"], "status": out["status"], "build": out["build"],
             "static_disp": out["static_disp"], "version": out["version"],
             "errs": errors(p)}
        r["err"] = r["errs"]["lumped"]
        print(f"OpenSees {job['ne']} elements dt {dt:g}: {r['wall']:.2f} s, errs {r['errs']}, "
              f"{r['status']}, static disp {r['static_disp']:.1e}", file=sys.stderr)
        return r

    ops_rows = []
    dt = 0.01
    while True:
        r = ops_run(dt)
        ops_rows.append(r)
        if r["err"] <= target or dt < 1e-5 or r["wall"] > args.max_ops_wall:
            break
        dt /= 2

    # a finer OpenSees mesh at coarse steps (total error against the fine reference), with
    # catdae's lumped mass on the same mesh beside it
    extra = []
    if args.ops_mesh and ref_f is not None:
        ne = args.ops_mesh
        for mass in ("lumped", "consistent"):
            ds, tree_ne, _ = ts.run_dict(ts.cable_dict(ne, duration, **ts.tol(1e-4),
                                                       mass_model=mass))
            r = ts.row(ds, rtol=1e-4, code=f"catdae (IDA, {mass}), {ne} elements", mass=mass,
                       ne=ne)
            r["errs"] = errors(ds.position.sel(node=f"c.{ne // 2}").values)
            extra.append(r)
            print(f"catdae {mass} {ne} elements rtol 1e-4: {r['cpu']:.2f} s CPU, "
                  f"errs {r['errs']}", file=sys.stderr)
        job_ne = ops_job(ne, tree_ne)
        for dt in (0.01, 0.005, 0.0025):
            extra.append(ops_run(dt, job_ne))

    # ------------------------------------------------------------------ tables
    refcols = ["lumped", "consistent"] + (["fine"] if ref_f is not None else [])
    names = {"lumped": "vs lumped ref m", "consistent": "vs consistent ref m",
             "fine": f"vs {args.fine}-element ref m"}
    print(f"\nSimulated {duration:g} s. References at rtol 1e-10 (16 elements): lumped "
          f"{ref.attrs['wall_time']:.2f} s, {ref.attrs['n_steps']} steps; consistent "
          f"{ref_c.attrs['wall_time']:.2f} s, {ref_c.attrs['n_steps']} steps.")
    print(f"Lumped reference against the consistent one: {ref_errs['lumped']['consistent']:.3e} m")
    if ref_f is not None:
        print(f"Fine reference ({args.fine} elements, consistent, rtol {args.fine_rtol:g}): "
              f"{ref_f.attrs['wall_time']:.2f} s, {ref_f.attrs['n_steps']} steps; against it "
              f"the 16-element lumped reference is off by {ref_errs['lumped']['fine']:.3e} m "
              f"and the consistent one by {ref_errs['consistent']['fine']:.3e} m.")
    print("\n| code | rtol or dt | wall s | CPU s | steps | residuals (catdae) | "
          + " | ".join(names[c] for c in refcols) + " |")
    print("|---|---:|---:|---:|---:|---:|" + "---:|" * len(refcols))
    for r in rows:
        print(f"| {r['code']} | rtol {r['rtol']:.0e} | {r['wall']:.2f} | {r['cpu']:.2f} | "
              f"{r['steps']} | {r['nres']} | "
              + " | ".join(f"{r['errs'][c]:.2e}" for c in refcols) + " |")
    for r in ops_rows:
        print(f"| {r['code']} | dt {r['dt']:.3g} s | {r['wall']:.2f} | {r['cpu']:.2f} | "
              f"{r['steps']} | - | " + " | ".join(f"{r['errs'][c]:.2e}" for c in refcols)
              + " |")

    # equal-error ratios on the same semi-discrete model (16 elements, lumped mass): OpenSees'
    # time at each catdae run's error, interpolated in the dt sweep
    print("\nSame model (16 elements, lumped mass), error against the lumped reference: time of "
          "OpenSees at catdae's error (log-log interpolation in the dt sweep, extrapolated "
          "beyond it; CPU times of the process, wall times of the integration):\n")
    print("| catdae run | catdae error m | catdae CPU s | OpenSees CPU s at that "
          "error | OpenSees / catdae (CPU) | catdae wall s | OpenSees wall s | OpenSees / catdae "
          "(wall) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    ratios = []
    for r in rows:
        if r["mass"] != "lumped":
            continue
        e = r["errs"]["lumped"]
        w, how = equal_error_wall(ops_rows, e, "wall")
        cp, _ = equal_error_wall(ops_rows, e, "cpu")
        ratios.append({"rtol": r["rtol"], "err": e, "catdae": r["wall"], "opensees": w,
                       "catdae_cpu": r["cpu"], "opensees_cpu": cp, "how": how})
        print(f"| {r['code']} rtol {r['rtol']:.0e} | {e:.2e} | {r['cpu']:.2f} "
              f"| {cp:.2f} ({how}) | {cp / r['cpu']:.1f} | {r['wall']:.2f} | {w:.2f} "
              f"| {w / r['wall']:.1f} |")
    if ref_f is not None:
        print(f"\nTotal error (mesh and time) against the {args.fine}-element consistent "
              f"reference, cheapest settings:\n")
        print("| run | elements | rtol or dt | CPU s | wall s | error vs fine ref m |")
        print("|---|---:|---:|---:|---:|---:|")
        sel = [r for r in rows if r["rtol"] in (max(tols), 1e-6)] + \
            [r for r in ops_rows if r["dt"] >= 0.0025] + extra
        for r in sel:
            setting = f"rtol {r['rtol']:.0e}" if "rtol" in r else f"dt {r['dt']:.3g} s"
            print(f"| {r['code']} | {r.get('ne', 16)} | {setting} | {r['cpu']:.2f} | "
                  f"{r['wall']:.2f} | {r['errs']['fine']:.3e} |")
    print(f"\nOpenSees {ops_rows[0]['version']}; static check: largest displacement of the "
          f"static Newton step from catdae's equilibrium {ops_rows[0]['static_disp']:.1e} m")
    if args.json:
        meta = {"duration": duration, "fine": args.fine, "fine_rtol": args.fine_rtol,
                "refs": {k: {"wall": float(r.attrs["wall_time"]), "steps": int(r.attrs["n_steps"])}
                         for k, r in dict(refs, **({"fine": ref_f} if ref_f is not None
                                                   else {})).items()}}
        Path(args.json).write_text(json.dumps({"catdae": rows, "opensees": ops_rows,
                                               "extra": extra, "ratios": ratios,
                                               "ref_errs": ref_errs, "meta": meta}, indent=1))


if __name__ == "__main__":
    main()
