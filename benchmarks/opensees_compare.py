"""catdae against OpenSees' CatenaryCable element on the 100 m cable with a moving support.

Scene (the one of ``transient_speed.py``): span 100 m, L0 = 102 m, EA = 1e8 N, weight 100 N/m,
mass 100/9.81 kg/m, 16 elements, end A moving vertically as z_A = 0.5 (1 - cos πt) m, 10 s,
no damping. Only the first 2 s are integrated here (DURATION).

OpenSees (openseespy) models it with ``element CatenaryCable`` (Abell & Ibanez; exact elastic
catenary flexibility, Newton on the misclosure each update) and integrates with Newmark's
average-acceleration rule (γ = 1/2, β = 1/4) at a fixed dt. CatenaryCable's mass is lumped
(massType 0: ρ L0 / 2 at each end; its other types are either truss-consistent or not
implemented), so the comparison uses catdae with ``mass_model = "lumped"`` too: the same
semi-discrete model, integrated by IDA (variable order/step BDF) or by Newmark. The OpenSees
nodes start at catdae's static equilibrium (the exact catenary); a static Newton step in
OpenSees confirms it is in equilibrium there too.

Errors: largest distance over the output times (every 0.01 s) between the midspan node's
position and that of catdae's reference run (rtol 1e-10, atol 1e-12 m, lumped mass; the
consistent-mass reference is reported as well). OpenSees' dt is halved until its error falls
below that of catdae at rtol 1e-6, then set from the dt² law to match it.

OpenSees runs in a subprocess (its import needs the wheel's own ``lib`` folder on
LD_LIBRARY_PATH); this script is both the driver and (``--worker``) that subprocess:

    python benchmarks/opensees_compare.py
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
DURATION = 4.0  # s (the catdae references at rtol 1e-10 are the slow part)
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
    ops.fix(a + 1, 1, 1, 0)  # z of A is imposed below
    ops.fix(b + 1, 1, 1, 1)
    for e, (i, j) in enumerate(conn):
        ops.element("CatenaryCable", e + 1, i + 1, j + 1, job["weight"], job["EA"], 1.0,
                    job["L0e"][e], 0.0, 0.0, job["rho"], job["error_tol"], job.get("nsub", 1), 0)
    # support motion: z_A(t) = 0.5 (1 - cos πt), sampled exactly at the steps
    nsteps = int(round(duration / dt))
    values = [0.5 * (1.0 - math.cos(math.pi * k * dt)) for k in range(nsteps + 2)]
    ops.timeSeries("Path", 1, "-dt", dt, "-values", *values)
    ops.pattern("Plain", 1, 1)
    ops.sp(a + 1, 3, 1.0)
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
    json.dump({"times": times, "mid": hist, "wall": wall, "build": t_build, "import": t_import,
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
def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--json", help="also write the raw numbers here")
    ap.add_argument("--consistent", action="store_true",
                    help="also measure errors against a consistent-mass reference")
    args = ap.parse_args(argv)
    if args.worker:
        worker()
        return

    import numpy as np

    sys.path.insert(0, str(HERE))
    import transient_speed as ts

    print(f"Machine: {ts.machine()}\n")
    env = opensees_env()
    ts.catdae.run(ts.case_from_dict(ts.cable_dict(16, 0.05)), progress=False)  # compile

    # catdae: references and runs, lumped mass (the OpenSees model) and consistent mass
    ref, tree, _ = ts.run_dict(ts.cable_dict(duration=DURATION, **ts.tol(ts.REF_RTOL),
                                            mass_model="lumped"))
    # the consistent-mass reference (rtol 1e-10) is optional: since commit 681680e it needs
    # ~100x more steps at that tolerance (see transient_speed.md)
    ref_c = ts.run_dict(ts.cable_dict(duration=DURATION, **ts.tol(ts.REF_RTOL)))[0] \
        if args.consistent else ref
    rows = []
    for rtol in ts.TOLS:
        ds, _, _ = ts.run_dict(ts.cable_dict(duration=DURATION, **ts.tol(rtol),
                                                mass_model="lumped"))
        r = ts.row(ds, ts.error(ds, ref, MID), rtol=rtol, code="catdae (IDA, lumped)")
        r["err_consistent"] = ts.error(ds, ref_c, MID)
        rows.append(r)
        print(f"catdae lumped rtol {rtol:g}: {r['wall']:.2f} s, {r['steps']} steps, "
              f"err {r['err']:.2e}", file=sys.stderr)
    target = next(r["err"] for r in rows if r["rtol"] == 1e-6)
    ref_err_lc = ts.error(ref, ref_c, MID)

    st = tree["initial"].ds
    nodes = [str(n) for n in st.node.values]
    X = st.position.values.tolist()
    order = {n: k for k, n in enumerate(nodes)}
    chain = ["A"] + [f"c.{k}" for k in range(1, 16)] + ["B"]
    conn = [[order[chain[k]], order[chain[k + 1]]] for k in range(16)]
    tref = ref.time.values
    pref = ref.position.sel(node=MID).values
    pref_c = ref_c.position.sel(node=MID).values
    job = {"X": X, "conn": conn, "supports": [order["A"], order["B"]], "mid": order[MID],
           "EA": 1.0e8, "weight": -100.0, "rho": 100.0 / 9.81, "L0e": [102.0 / 16] * 16,
           "error_tol": ERROR_TOL, "duration": DURATION, "newton_tol": 1e-10}

    def ops_run(dt):
        every = int(round(0.01 / dt))
        out = run_opensees(dict(job, dt=dt, every=every), env)
        t = np.asarray(out["times"])
        p = np.asarray(out["mid"])
        n = min(len(t), len(tref))
        assert np.allclose(t[:n], tref[:n], atol=1e-9), "output times differ"
        r = {"code": "OpenSees (Newmark, lumped)", "dt": dt, "wall": out["wall"],
             "steps": out["steps"], "status": out["status"], "build": out["build"],
             "static_disp": out["static_disp"], "version": out["version"],
             "err": float(np.max(np.linalg.norm(p[:n] - pref[:n], axis=1))),
             "err_consistent": float(np.max(np.linalg.norm(p[:n] - pref_c[:n], axis=1)))}
        print(f"OpenSees dt {dt:g}: {r['wall']:.2f} s, err {r['err']:.2e}, {r['status']}, "
              f"static disp {r['static_disp']:.1e}", file=sys.stderr)
        return r

    ops_rows = []
    dt = 0.01
    while True:
        r = ops_run(dt)
        ops_rows.append(r)
        if r["err"] <= target or dt < 1e-5 or r["wall"] > 200:
            break
        dt /= 2
    # dt for equal error (Newmark: error ∝ dt²), rounded so that 0.01 s is a whole number of
    # steps, from the two finest runs
    if len(ops_rows) >= 2:
        a, b = ops_rows[-2], ops_rows[-1]
        p_obs = np.log(a["err"] / b["err"]) / np.log(a["dt"] / b["dt"])
        dt_eq = b["dt"] * (target / b["err"]) ** (1.0 / p_obs)
        dt_eq = 0.01 / int(np.ceil(0.01 / dt_eq))
        if all(abs(dt_eq - r["dt"]) > 1e-12 for r in ops_rows):
            ops_rows.append(ops_run(dt_eq))
        print(f"observed order of Newmark here: {p_obs:.2f}", file=sys.stderr)

    if args.consistent:
        print(f"\nerror of the lumped reference against the consistent one: {ref_err_lc:.3e} m")
    print(f"catdae reference (rtol 1e-10): {ref.attrs['wall_time']:.2f} s, "
          f"{ref.attrs['n_steps']} steps\n")
    print("| code | rtol or dt | wall s | steps | residuals (catdae) | midspan error vs lumped "
          "reference m | vs consistent reference m (--consistent) |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['code']} | rtol {r['rtol']:.0e} | {r['wall']:.2f} | {r['steps']} | "
              f"{r['nres']} | {r['err']:.2e} | {r['err_consistent']:.2e} |")
    for r in ops_rows:
        print(f"| {r['code']} | dt {r['dt']:.3g} s | {r['wall']:.2f} | {r['steps']} | - | "
              f"{r['err']:.2e} | {r['err_consistent']:.2e} |")
    cat = next(r for r in rows if r["rtol"] == 1e-6)
    best = min((r for r in ops_rows if r["err"] <= 1.5 * target), key=lambda r: r["wall"],
               default=None)
    if best is not None:
        print(f"\nAt about equal error ({cat['err']:.2e} m catdae, {best['err']:.2e} m OpenSees "
              f"dt {best['dt']:.3g} s): wall time OpenSees / catdae = "
              f"{best['wall'] / cat['wall']:.2f}")
    print(f"OpenSees {ops_rows[0]['version']}; static check: largest displacement of the "
          f"static Newton step from catdae's equilibrium {ops_rows[0]['static_disp']:.1e} m")
    if args.json:
        Path(args.json).write_text(json.dumps({"catdae": rows, "opensees": ops_rows,
                                               "ref_lumped_vs_consistent": ref_err_lc},
                                              indent=1))


if __name__ == "__main__":
    main()
