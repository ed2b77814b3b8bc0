"""Steps, CPU and error of the BDF order cap (``max_order`` auto against fixed 2 and 5) on issue
11's cable and the bundled transient cases: the measurements of benchmarks/speed_accuracy.md §8.

Each job is one in-process run of a transient step; its CPU (``time.process_time``), steps,
residual evaluations, chosen order and ``order_choice`` go to a JSON-lines file (a job already
in it is skipped, so the script resumes); the midspan z history of the issue 11 runs and
example 2's midspan displacement go to an .npz beside it. Errors are computed against a
reference (``--ref``, key "z": 160 elements, blended, rtol 1e-6, 1001 outputs over 10 s) with
``speed_accuracy.err`` when the table is printed.

    OMP_NUM_THREADS=1 python benchmarks/order_race.py run OUT.jsonl [--set issue11|cases|fine|...]
    python benchmarks/order_race.py table OUT.jsonl [--ref ref160.npz] [--before BEFORE.jsonl]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import tomllib
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import nothing_lost as nl  # noqa: E402
import speed_accuracy as sa  # noqa: E402

import catdae  # noqa: E402
from catdae.case import case_from_dict  # noqa: E402

ORDERS = ("auto", 2, 5)


def jobs(which: str) -> list[dict]:
    out = []
    if which == "issue11":
        for n in (16, 32, 40, 48, 64, 160):
            for rtol in (1e-3, 1e-4, 1e-5):
                for order in ORDERS:
                    out.append(dict(kind="issue11", n=n, rtol=rtol, duration=10.0, order=order))
    elif which == "issue11-auto":
        for n in (16, 32, 40, 48, 64, 160):
            for rtol in (1e-3, 1e-4, 1e-5):
                out.append(dict(kind="issue11", n=n, rtol=rtol, duration=10.0, order="auto"))
    elif which in ("fine", "fine-auto"):
        for rtol in (1e-4, 1e-5):
            for dur in (1.0, 2.0):
                for order in ("auto", 2) if which == "fine" else ("auto",):
                    out.append(dict(kind="issue11", n=1000, rtol=rtol, duration=dur, order=order))
    elif which in ("cases", "cases-auto"):
        orders = ("auto",) if which == "cases-auto" else ORDERS
        for n in (10, 50):
            for order in orders:
                out.append(dict(kind="case", case="example2_support_motion_gentle.toml",
                                step="excitation", n=n, order=order))
        for n in (14, 36):
            for order in orders:
                out.append(dict(kind="case", case="example1_free_vibration.toml",
                                step="release", n=n, order=order))
        for name, step in (("snow_gust_ground_record.toml", "shaking"),
                           ("example2_support_motion_violent.toml", "excitation")):
            for order in orders:
                out.append(dict(kind="case", case=name, step=step, n=None, order=order))
    elif which == "gentle100":
        for order in ("auto", 5):
            out.append(dict(kind="case", case="example2_support_motion_gentle.toml",
                            step="excitation", n=100, order=order))
    else:
        raise SystemExit(f"unknown set {which}")
    return out


def key(job: dict) -> str:
    return json.dumps(job, sort_keys=True)


def run_job(job: dict) -> tuple[dict, np.ndarray | None]:
    if job["kind"] == "issue11":
        text = sa.case_text(job["n"], job["rtol"], duration=job["duration"],
                            max_order=job["order"])
        case = case_from_dict(tomllib.loads(text))
        step, kw = "motion", {}
    else:
        changes = {} if job["order"] == "auto" else {"max_order": job["order"]}
        if job["case"].startswith("example1"):
            changes["max_order"] = job["order"]  # the case file sets 2
        case = nl._case(job["case"], **changes)
        step, kw = job["step"], {"elements": job["n"]}
    c0 = time.process_time()
    tree = catdae.run(case, progress=False, **kw)
    cpu = time.process_time() - c0
    ds = tree[step].ds
    if job["kind"] == "issue11":
        z = ds.position.sel(node=f"c.{job['n'] // 2}", axis="z").values
    elif job["n"] and f"cable.{job['n'] // 2}" in ds.node.values:  # example 2's midspan
        z = ds.displacement.sel(node=f"cable.{job['n'] // 2}").values  # (time, 3)
    else:
        z = None
    rec = dict(job=job, cpu=cpu, steps=int(ds.attrs["n_steps"]),
               nres=int(ds.attrs["n_residual_evaluations"]), order=int(ds.attrs["max_order"]),
               choice=str(ds.attrs["order_choice"]), step_wall=float(ds.attrs["wall_time"]),
               load=os.getloadavg()[0], date=time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime()))
    return rec, z


def cmd_run(args) -> None:
    out = Path(args.out)
    done = set()
    if out.exists():
        done = {key(json.loads(line)["job"]) for line in out.read_text().splitlines() if line}
    zfile = out.with_suffix(".npz")
    zs = dict(np.load(zfile)) if zfile.exists() else {}
    sa.run_catdae(8, 1e-3, duration=0.05)  # compile / load the kernels outside the timings
    for which in args.set.split(","):
        for job in jobs(which):
            if key(job) in done:
                continue
            rec, z = run_job(job)
            print(json.dumps(rec), flush=True)
            with out.open("a") as f:
                f.write(json.dumps(rec) + "\n")
            done.add(key(job))
            if z is not None:
                zs[key(job)] = z
                np.savez(zfile, **zs)


def load(path: str) -> tuple[dict, dict]:
    p = Path(path)
    recs = {key(r["job"]): r for r in map(json.loads, p.read_text().splitlines()) if r}
    zfile = p.with_suffix(".npz")
    zs = dict(np.load(zfile)) if zfile.exists() else {}
    return recs, zs


def cmd_table(args) -> None:
    recs, zs = load(args.out)
    before, zb = load(args.before) if args.before else ({}, {})
    zref = np.load(args.ref)["z"] if args.ref else None

    def error(k, zz):
        if zref is None or k not in zz:
            return ""
        z = zz[k]
        return f"{sa.err(z, zref[:len(z)]) * 1e3:.2f}"

    def cell(r, k, zz):
        if r is None:
            return "", "", "", ""
        return (f"{r['cpu']:.2f}", f"{r['steps']}", error(k, zz), f"{r['nres'] / r['steps']:.2f}")

    print("| n | rtol | T s | auto before: CPU s / steps / err mm | auto after: CPU s / steps / "
          "err mm / order | fixed 2: CPU / steps / err | fixed 5: CPU / steps / err | "
          "after's choice |")
    print("|---:|---:|---:|---|---|---|---|---|")
    rows = sorted({(r["job"]["kind"], str(r["job"].get("case", "")), r["job"]["n"] or 0,
                    -r["job"].get("rtol", 0), r["job"].get("duration", 0),
                    r["job"].get("step", "")) for r in list(recs.values()) + list(before.values())})
    for kind, case, n, mrtol, dur, step in rows:
        base = dict(kind=kind, n=n or None)
        if kind == "issue11":
            base.update(rtol=-mrtol, duration=dur)
            label = f"| {n} | {-mrtol:g} | {dur:g} "
        else:
            base.update(case=case, step=step)
            label = f"| {case.removesuffix('.toml')} {n or ''} | | "

        def get(d, order, base=base):
            k = key(dict(base, order=order))
            return d.get(k), k
        ab, kab = get(before, "auto")
        aa, kaa = get(recs, "auto")
        f2, k2 = get(recs, 2)
        if f2 is None:
            f2, k2 = get(before, 2)
        f5, k5 = get(recs, 5)
        if f5 is None:
            f5, k5 = get(before, 5)
        zall = {**zb, **zs}
        c_ab = " / ".join(cell(ab, kab, zb)[:3]) + (f" / {ab['order']}" if ab else "")
        c_aa = " / ".join(cell(aa, kaa, zs)[:3]) + (f" / {aa['order']}" if aa else "")
        c2 = " / ".join(cell(f2, k2, zall)[:3])
        c5 = " / ".join(cell(f5, k5, zall)[:3])
        print(f"{label}| {c_ab} | {c_aa} | {c2} | {c5} | {aa['choice'] if aa else ''} |")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("out")
    r.add_argument("--set", default="issue11,fine,cases")
    t = sub.add_parser("table")
    t.add_argument("out")
    t.add_argument("--ref")
    t.add_argument("--before")
    args = ap.parse_args(argv)
    {"run": cmd_run, "table": cmd_table}[args.cmd](args)


if __name__ == "__main__":
    main()
