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
    elif which == "gentle-5":  # the displacement of fixed order 5 (for nothing_lost.md)
        for n in (10, 50):
            out.append(dict(kind="case", case="example2_support_motion_gentle.toml",
                            step="excitation", n=n, order=5))
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
    """Markdown tables: issue 11's cable (error in mm against the reference), then the cases."""
    recs, zs = load(args.out)
    before, zb = load(args.before) if args.before else ({}, {})
    zref = np.load(args.ref)["z"] if args.ref else None
    zall = {**zb, **zs}

    def cell(d, job, err=True):
        k = key(job)
        r = d.get(k)
        if r is None:
            return ""
        text = f"{r['cpu']:.2f} / {r['steps']}"
        zz = zb if d is before else zs if d is recs else zall
        if err and zref is not None and k in zz:
            z = zz[k]
            text += f" / {sa.err(z, zref[:len(z)]) * 1e3:.2f}"
        return text + (f" / {r['order']}" if job["order"] == "auto" else "")

    both = {**before, **recs}
    print("| n | rtol | T s | auto before | auto after | fixed 2 | fixed 5 | races after |")
    print("|---:|---:|---:|---|---|---|---|---|")
    cable = sorted({(r["job"]["n"], -r["job"]["rtol"], r["job"]["duration"])
                    for r in both.values() if r["job"]["kind"] == "issue11"})
    notes = []
    for n, mrtol, dur in cable:
        base = dict(kind="issue11", n=n, rtol=-mrtol, duration=dur)
        aa = recs.get(key(dict(base, order="auto")))
        races = aa["choice"].count("race(s), chosen") and aa["choice"].split(
            "race(s), chosen")[0].split(";")[-1].strip() if aa else ""
        print(f"| {n} | {-mrtol:g} | {dur:g} | {cell(before, dict(base, order='auto'))} | "
              f"{cell(recs, dict(base, order='auto'))} | {cell(both, dict(base, order=2))} | "
              f"{cell(both, dict(base, order=5))} | {races or 0} |")
        if aa:
            notes.append(f"{n} el, rtol {-mrtol:g}, {dur:g} s: {aa['choice']}")
    print()
    print("| case | elements | auto before | auto after | fixed 2 | fixed 5 |"
          " residuals per step at 2 / 5 |")
    print("|---|---:|---|---|---|---|---|")
    cases = sorted({(r["job"]["case"], r["job"]["step"], r["job"]["n"] or 0)
                    for r in both.values() if r["job"]["kind"] == "case"})
    for case, step, n in cases:
        base = dict(kind="case", case=case, step=step, n=n or None)
        per = []
        for order in (2, 5):
            r = both.get(key(dict(base, order=order)))
            per.append(f"{r['nres'] / r['steps']:.2f}" if r else "")
        print(f"| {case.removesuffix('.toml')} | {n or 'as bundled'} | "
              + " | ".join(cell(d, dict(base, order=o), err=False)
                           for d, o in ((before, "auto"), (recs, "auto"), (both, 2),
                                        (both, 5)))
              + f" | {' / '.join(per)} |")
        aa = recs.get(key(dict(base, order="auto")))
        if aa:
            notes.append(f"{case} {n or ''}: {aa['choice']}")
        ka, k5 = key(dict(base, order="auto")), key(dict(base, order=5))
        if ka in zs and k5 in zall:
            d = np.abs(zs[ka] - zall[k5]).max(axis=0)
            notes.append(f"  midspan |auto - fixed 5|, y, z: {d[1] * 1e3:.3f}, "
                         f"{d[2] * 1e3:.3f} mm")
    print()
    for line in notes:
        print("- " + line)


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
