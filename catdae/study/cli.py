"""``catdae study``: the command-line parser and :func:`main`."""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path
from typing import Any

from catdae.case.overrides import max_order_arg as _order
from catdae.errors import CaseError, OutputError
from catdae.study.core import CHOICES, StudyError
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
    p.add_argument("--mass-model", nargs="+", choices=CHOICES["mass_model"])
    p.add_argument("--linear-solver", nargs="+", choices=CHOICES["linear_solver"])
    p.add_argument("--max-order", type=_order, nargs="+", metavar="{auto,1-5}")
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
    p.add_argument("--workers", type=_positive, default=2,
                   help="local cluster size, at least 1 (default 2)")
    p.add_argument("--store", help="folder of finished runs (default: <case stem>-study/)")
    p.add_argument("--memory", choices=("rss", "tracemalloc"), default="rss",
                   help="peak memory probe (tracemalloc is exact but slows runs 3-4x)")
    p.add_argument("-o", "--output", help="output netCDF (default: <case stem>-study.nc)")
    p.add_argument("--plots", action=argparse.BooleanOptionalAction, default=True,
                   help="write the PNG plots beside the output (default: yes)")
    return p


def _positive(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, found {text!r}") from None
    if n < 1:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, found {n}")
    return n


def _reference_arg(items: list[str] | None):
    if not items:
        return None
    if len(items) == 1 and "=" not in items[0]:
        from catdae.output.results import read_tree

        try:
            tree = read_tree(items[0])
            tree.attrs["reference_file"] = str(items[0])  # named in the study's attrs
            return tree
        except (OSError, ValueError) as exc:
            raise StudyError(f"reference: cannot read {items[0]!r}: {exc}") from None
    out: dict[str, Any] = {}
    for item in items:
        key, eq, value = item.partition("=")
        key = key.strip().replace("-", "_")
        if not eq:
            raise StudyError(f"reference: expected KEY=VALUE, found {item!r}")
        if key in CHOICES:
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
    2 invalid case, settings or output, 128 + n stopped by signal n (130 Ctrl-C, 143 SIGTERM,
    129 SIGHUP: the finished runs are kept in the store and a partial report marked
    'interrupted' is written)."""
    args = _parser().parse_args(argv)
    from catdae.case import load_case
    from catdae.output.files import check_folder, check_output
    from catdae.progress import say

    store = None
    try:
        case = load_case(args.case)
        stem = Path(args.case).stem
        out = Path(args.output) if args.output else Path(f"{stem}-study.nc")
        store = Path(args.store) if args.store else Path(f"{stem}-study")
        # every output judged before any work: the report, its plots, the store
        check_output(out, case, derived=("-work-precision.png", "-convergence.png"))
        check_folder(store, "the finished runs")

        swept = {k for k, v in vars(args).items() if isinstance(v, list) and len(v) > 1}

        def report(settings, run_ds):
            what = ", ".join(f"{k}={v}" for k, v in settings.items()
                             if k in swept) or "run" if settings else "reference"
            say(f"  {what}: {run_ds.attrs['status']}, {run_ds.attrs['wall_time']:.3g} s")

        ds = run_study(
            case, step=args.step, rtol=args.rtol, atol=args.atol, elements=args.elements,
            gauss_points=args.gauss_points, mass_model=args.mass_model,
            linear_solver=args.linear_solver, max_order=args.max_order,
            response=args.response, reference=_reference_arg(args.reference),
            scheduler=args.scheduler, store=store, duration=args.duration,
            workers=args.workers, memory=args.memory, on_run=report)
        files = write_study(ds, out, plots=args.plots)
    except (CaseError, StudyError, OutputError) as exc:
        print(f"catdae study: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        return _interrupted(exc, out if store is not None else None, store)
    except OSError as exc:
        print(f"catdae study: cannot write the study to {out}: {exc.strerror or exc}; the "
              f"finished runs are kept in {store}", file=sys.stderr)
        return 1
    except MemoryError:
        print(f"catdae study: out of memory; the finished runs are kept in {store}",
              file=sys.stderr)
        return 1
    say(summary(ds))
    say("written: " + ", ".join(str(f) for f in files))
    failed = int((ds.status.values != "completed").sum())
    if failed or ds.attrs["reference_status"] != "completed":
        print(f"catdae study: {failed} run(s) failed; reference: {ds.attrs['reference_status']}",
              file=sys.stderr)
        return 1
    return 0


def _interrupted(exc: KeyboardInterrupt, out: Path | None, store: Path | None) -> int:
    """Say what an interrupted study kept: the finished runs (in the store) and, when the
    runs were under way, a partial report marked 'interrupted'."""
    from catdae.interrupts import deferred

    code = getattr(exc, "exit_code", 130)
    by = f" by {signal.Signals(code - 128).name}" if code > 128 else ""
    print(f"catdae study: interrupted{by}", file=sys.stderr)
    partial = getattr(exc, "partial", None)
    if partial is not None and out is not None:
        if out.exists():  # never over an earlier report
            out = out.with_name(f"{out.stem}.interrupted.nc")
        try:
            with deferred():
                write_study(partial, out, plots=False)
        except (OSError, ValueError) as err:
            print(f"catdae study: the partial report could not be written to {out}: "
                  f"{getattr(err, 'strerror', None) or err}", file=sys.stderr)
        else:
            print(f"catdae study: a partial report ({partial.attrs['status']}) was written "
                  f"to {out}", file=sys.stderr)
    if store is not None:
        print(f"catdae study: finished runs are kept in {store}", file=sys.stderr)
    return code
