"""The command line: ``catdae run``, ``check``, ``plot``, ``export``, ``study``. No physics.

Errors become one clear message on stderr and a non-zero exit code:
1 analysis failed or results cannot be written (what was computed is written if it can be, or
the loss is stated), 2 invalid case, usage or an unreadable results file (judged before any
work), 130 interrupted by Ctrl-C (SIGINT), 143 stopped by SIGTERM, 129 by SIGHUP; after an
interrupt the partial results are written and marked. A reader that closes standard output early
(a broken pipe) stops the printing, never the work.
"""

from __future__ import annotations

import argparse
import signal
import sys
import traceback
from importlib.resources import files
from pathlib import Path

from catdae._version import __version__
from catdae.case.overrides import max_order_arg
from catdae.case.schema import MASS_MODEL_NAMES
from catdae.errors import CaseError, CatdaeError, InternalError, OutputError, ResultsError
from catdae.interrupts import signals_as_interrupts
from catdae.output.files import check_folder
from catdae.output.summary import step_summary, summary  # noqa: F401 (catdae.cli.summary)
from catdae.progress import say

# catdae.output.plot.WHAT
WHAT = ("profile", "history", "spectrum", "tension", "modes", "spans", "reactions")

DEFAULT_CASE = "example1_free_vibration.toml"


def default_case_path() -> Path:
    """The bundled default case (the paper's example 1)."""
    return Path(str(files("catdae") / "data" / DEFAULT_CASE))


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="catdae", description="Exact elastic catenary cable "
                                "analysis: statics, modes and nonlinear dynamics.")
    p.add_argument("--version", action="version", version=f"catdae {__version__}")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run every step of a case and write netCDF results")
    r.add_argument("case", nargs="?", help="case file (TOML); default: the bundled example 1")
    r.add_argument("-o", "--output", help="output netCDF file (default: <case stem>.nc)")
    r.add_argument("--rtol", type=float, help="relative tolerance of transient steps")
    r.add_argument("--atol", type=float, help="absolute tolerance of transient steps, m")
    r.add_argument("--elements", type=int, help="elements per cable")
    r.add_argument("--max-order", type=max_order_arg, metavar="{auto,1,2,3,4,5}",
                   help="largest BDF order of transient steps (2: A-stable, damps what it does "
                        "not resolve)")
    r.add_argument("--mass-model", choices=MASS_MODEL_NAMES,
                   help="mass model of every transient and modal step")
    r.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress bar (default: on a terminal)")
    r.add_argument("--vtk", metavar="FOLDER",
                   help="also write VTK time series for ParaView into FOLDER (as catdae export)")
    pl = sub.add_parser("plot", help="PNG figures of a results file")
    pl.add_argument("results", help="results file (netCDF) written by catdae run")
    pl.add_argument("-o", "--output", required=True, metavar="FOLDER",
                    help="folder for the PNG files <step>-<what>.png")
    pl.add_argument("--step", nargs="+", metavar="NAME", help="steps to plot (default: all)")
    pl.add_argument("--what", nargs="+", choices=WHAT, metavar="WHAT",
                    help=f"figures: {', '.join(WHAT)} (default: all a step can make)")
    pl.add_argument("--node", help="node of history and spectrum: a node name, <cable>@<p/q> "
                    "(fraction of the cable's length, e.g. main@1/2) or <cable>@s=<m> (arc "
                    "length); default: the free node that moves most")
    pl.add_argument("--times", nargs="+", type=float, metavar="T",
                    help="times of profile and tension, s (nearest outputs; default: 5)")
    ex = sub.add_parser("export", help="export a results file for other tools")
    ex.add_argument("results", help="results file (netCDF) written by catdae run")
    ex.add_argument("--vtk", required=True, metavar="FOLDER",
                    help="VTK time series for ParaView: <step>.pvd and <step>/*.vtu")
    ex.add_argument("--step", nargs="+", metavar="NAME",
                    help="steps to export (default: every static and transient step)")
    c = sub.add_parser("check", help="validate a case file and report every problem")
    c.add_argument("case")
    c.add_argument("--elements", type=int, help="elements per cable, as catdae run takes it "
                   "(the checks that depend on the mesh, such as connectors on mesh nodes)")
    s = sub.add_parser("study", help="accuracy and cost studies (work-precision)",
                       add_help=False)  # `catdae study -h` is answered by catdae.study
    s.add_argument("rest", nargs=argparse.REMAINDER)
    return p


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] == ["study"]:  # its options (and -h) belong to catdae.study
        from catdae.study import main as study_main

        with signals_as_interrupts():  # the one signal policy: the study says what it keeps
            return study_main(argv[1:])
    args = _parser().parse_args(argv)
    try:
        with signals_as_interrupts():  # SIGTERM, SIGHUP stop a run like Ctrl-C: partial kept
            if args.command == "check":
                return _check(args)
            if args.command == "run":
                return _run(args)
            if args.command == "plot":
                return _plot(args)
            if args.command == "export":
                return _export(args)
            if args.command == "study":
                from catdae.study import main as study_main

                return study_main(list(args.rest))
    except CaseError as exc:
        sep = ": " if len(exc.problems) == 1 else "\n"
        print(f"catdae: invalid case{sep}{exc}", file=sys.stderr)
        return 2
    except ResultsError as exc:  # an unreadable or foreign results file: bad input
        print(f"catdae: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"catdae: cannot write the results: {exc}", file=sys.stderr)
        return 1
    except MemoryError:
        print("catdae: out of memory", file=sys.stderr)
        return 1
    except KeyboardInterrupt as exc:
        code = getattr(exc, "exit_code", 130)
        by = f" by {signal.Signals(code - 128).name}" if code > 128 else ""
        print(f"catdae: interrupted{by}", file=sys.stderr)
        _say_where(exc, "before the interrupt")
        return code
    return 2  # pragma: no cover - argparse requires a command


def _say_where(exc: BaseException, when: str) -> None:
    """Where the results computed before a failure or an interrupt went, or that they are
    lost (set on the exception by the pipeline's writer)."""
    where = getattr(exc, "output_path", None)
    lost = getattr(exc, "output_error", None)
    if where is not None:
        print(f"catdae: results computed {when} were written to {where}", file=sys.stderr)
    elif lost is not None:
        print(f"catdae: {lost}", file=sys.stderr)


def _check(args) -> int:
    from catdae.analysis import check_case
    from catdae.case import load_case

    # the command line always names a file; meshed as catdae run --elements would mesh it
    case = load_case(Path(args.case), elements=args.elements)
    mesh = check_case(case)
    say(f"{args.case}: valid: {len(case.cables)} cable(s), {mesh.n_elements} elements, "
        f"{mesh.n_nodes} nodes, {len(case.steps)} step(s)")
    from catdae.model.fluid import plausibility_note

    # what catdae run would note of the water (a slip of units shows here, before the run)
    if note := plausibility_note(case, waves=any(s.kind == "transient" for s in case.steps)):
        say(f"{args.case}: note: {note}")
    return 0


def _run(args) -> int:
    from catdae.analysis import run
    from catdae.case import load_case
    from catdae.output.files import check_output

    path = Path(args.case) if args.case else default_case_path()
    case = load_case(path, elements=args.elements)  # judged on the mesh asked for
    out = Path(args.output) if args.output is not None else Path(f"{path.stem}.nc")
    try:
        check_output(args.output if args.output is not None else out, case)
    except OutputError as exc:  # judged before any work: a usage error
        print(f"catdae: {exc}", file=sys.stderr)
        return 2
    from catdae.progress import announce_compiling

    titled = []

    def finished(name, ds):  # each step's summary as it ends: an interrupted run has them
        if not titled:
            titled.append(say(case.title or "catdae run"))
        try:
            text = step_summary(name, ds)
        except Exception as exc:  # noqa: BLE001 - MemoryError too: a summary never costs the run
            text = (f"[{name}] (no summary printed: {type(exc).__name__} while summarising; "
                    "the step's results are kept)")
        if text:
            say(text)

    try:
        with announce_compiling():  # whenever numba compiles, the first time is announced
            tree = run(case, output=out, progress=args.progress, rtol=args.rtol,
                       atol=args.atol, mass_model=args.mass_model,
                       max_order=args.max_order, on_group=finished)
    except CaseError:
        raise  # an invalid override (exit 2), reported by main
    except CatdaeError as exc:
        print(f"catdae: {path}: {exc}", file=sys.stderr)
        if isinstance(exc, InternalError) and exc.__cause__ is not None:  # for the report
            traceback.print_exception(exc.__cause__, file=sys.stderr)
        _say_where(exc, "before the failure")
        return 1
    say(f"results written to {out}")
    if args.vtk:
        from catdae.output.export import write_vtk

        for p in write_vtk(tree, args.vtk):
            say(f"ParaView time series written to {p}")
    return 0


def _plot(args) -> int:
    from catdae.output.plot import write_all
    from catdae.output.reading import read_results_file

    try:
        check_folder(args.output, "the figures")
    except OutputError as exc:  # judged before any work: a usage error
        print(f"catdae: {exc}", file=sys.stderr)
        return 2
    tree = read_results_file(args.results)
    try:
        files = write_all(tree, args.output, steps=args.step, what=args.what, node=args.node,
                          times=args.times)
    except CatdaeError as exc:
        print(f"catdae: {args.results}: {exc}", file=sys.stderr)
        return 2
    for f in files:
        say(str(f))
    _say_incomplete(tree, args.results, "the figures show")
    if not files:
        print(f"catdae: {args.results}: no figure to make: the steps chosen make none of "
              f"{', '.join(args.what or WHAT)}", file=sys.stderr)
        return 2
    return 0


def _say_incomplete(tree, path, what: str) -> None:
    """A run that failed or was interrupted: say so beside the files made from it."""
    status = str(tree.attrs.get("status", "completed"))
    if status != "completed":
        print(f"catdae: {path}: note: the run did not complete ({status}); {what} what it "
              "computed until then", file=sys.stderr)


def _export(args) -> int:
    from catdae.output.export import write_vtk
    from catdae.output.reading import read_results_file

    try:
        check_folder(args.vtk, "the VTK files")
    except OutputError as exc:  # judged before any work: a usage error
        print(f"catdae: {exc}", file=sys.stderr)
        return 2
    tree = read_results_file(args.results)
    try:
        files = write_vtk(tree, args.vtk, steps=args.step)
    except CatdaeError as exc:
        print(f"catdae: {args.results}: {exc}", file=sys.stderr)
        return 2
    for f in files:
        say(f"ParaView time series written to {f}")
    _say_incomplete(tree, args.results, "the series hold")
    if not files:
        print(f"catdae: {args.results}: nothing to export: no static or transient step",
              file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
