"""``catdae study``: the command-line parser and :func:`main`."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from catdae.errors import CaseError
from catdae.study.core import _CHOICES, StudyError
from catdae.study.report import summary, write_study
from catdae.study.runner import run_study


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="catdae study", description="Work-precision study of one step of a case: runs the "
        "grid of settings (cartesian product), measures cost and error against a reference, "
        "writes a netCDF Dataset and PNG plots.")
    p.add_argument("case", help="case file (TOML)")
    p.add_argument("--step", help="step to study (default: the first transient, else modal, "
                   "else static)")
    p.add_argument("--rtol", type=float, nargs="+")
    p.add_argument("--atol", type=float, nargs="+", help="m")
    p.add_argument("--elements", type=int, nargs="+", help="elements per cable")
    p.add_argument("--gauss-points", type=int, nargs="+")
    p.add_argument("--mass-model", nargs="+", choices=_CHOICES["mass_model"])
    p.add_argument("--linear-solver", nargs="+", choices=_CHOICES["linear_solver"])
    p.add_argument("--max-order", type=int, nargs="+")
    p.add_argument("--response", help="transient: a case node, <cable>@<p/q> or <cable>.<k> of "
                   "the case file's mesh (default: the common node moving most); modal: how "
                   "many of the lowest frequencies are compared, or frequency:<k> for mode k; "
                   "static: <quantity>:<cable> (sag, sag_midspan, horizontal_tension, ..., "
                   "end_tension:<cable>:<i|j>; default sag of the first cable)")
    p.add_argument("--reference", nargs="+", metavar="KEY=VALUE|FILE.nc",
                   help="reference settings (e.g. elements=64 rtol=1e-10) or a catdae results "
                   "file holding the study step")
    p.add_argument("--duration", type=float, help="duration of the transient step, s")
    p.add_argument("--scheduler", help="address of a running Dask scheduler, or 'synchronous' "
                   "(default: a local cluster of --workers processes)")
    p.add_argument("--workers", type=int, default=2, help="local cluster size (default 2)")
    p.add_argument("--store", help="folder of finished runs (default: <case stem>-study/)")
    p.add_argument("--memory", choices=("rss", "tracemalloc"), default="rss",
                   help="peak memory probe (tracemalloc is exact but slows runs 3-4x)")
    p.add_argument("-o", "--output", help="output netCDF (default: <case stem>-study.nc)")
    p.add_argument("--plots", action=argparse.BooleanOptionalAction, default=True,
                   help="write the PNG plots beside the output (default: yes)")
    return p


def _reference_arg(items: list[str] | None):
    if not items:
        return None
    if len(items) == 1 and "=" not in items[0]:
        from catdae.output.results import read_tree

        try:
            return read_tree(items[0])
        except (OSError, ValueError) as exc:
            raise StudyError(f"reference: cannot read {items[0]!r}: {exc}") from None
    out: dict[str, Any] = {}
    for item in items:
        key, eq, value = item.partition("=")
        key = key.strip().replace("-", "_")
        if not eq:
            raise StudyError(f"reference: expected KEY=VALUE, found {item!r}")
        if key in _CHOICES:
            out[key] = value
        else:
            try:
                out[key] = int(value) if key in ("elements", "gauss_points", "max_order") \
                    else float(value)
            except ValueError:
                raise StudyError(f"reference {key}: expected a number, found {value!r}") from None
    return out


def main(argv: list[str] | None = None) -> int:
    """``catdae study CASE ...``: 0 all runs completed, 1 some failed (results still written),
    2 invalid case or settings, 130 interrupted."""
    args = _parser().parse_args(argv)
    from catdae.case import load_case

    try:
        case = load_case(args.case)
        stem = Path(args.case).stem
        out = Path(args.output) if args.output else Path(f"{stem}-study.nc")
        store = Path(args.store) if args.store else Path(f"{stem}-study")

        swept = {k for k, v in vars(args).items() if isinstance(v, list) and len(v) > 1}

        def report(settings, run_ds):
            what = ", ".join(f"{k}={v}" for k, v in settings.items()
                             if k in swept) or "run" if settings else "reference"
            print(f"  {what}: {run_ds.attrs['status']}, {run_ds.attrs['wall_time']:.3g} s",
                  flush=True)

        ds = run_study(
            case, step=args.step, rtol=args.rtol, atol=args.atol, elements=args.elements,
            gauss_points=args.gauss_points, mass_model=args.mass_model,
            linear_solver=args.linear_solver, max_order=args.max_order,
            response=args.response, reference=_reference_arg(args.reference),
            scheduler=args.scheduler, store=store, duration=args.duration,
            workers=args.workers, memory=args.memory, on_run=report)
        files = write_study(ds, out, plots=args.plots)
    except (CaseError, StudyError) as exc:
        print(f"catdae study: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"catdae study: interrupted; finished runs are kept in {store}", file=sys.stderr)
        return 130
    print(summary(ds))
    print("written: " + ", ".join(str(f) for f in files))
    failed = int((ds.status.values != "completed").sum())
    if failed or ds.attrs["reference_status"] != "completed":
        print(f"catdae study: {failed} run(s) failed; reference: {ds.attrs['reference_status']}",
              file=sys.stderr)
        return 1
    return 0
