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

import numpy as np

from catdae._version import __version__
from catdae.case.schema import MASS_MODEL_NAMES
from catdae.errors import CaseError, CatdaeError, InternalError, OutputError, ResultsError
from catdae.interrupts import signals_as_interrupts
from catdae.output.files import check_folder
from catdae.output.reading import step_values
from catdae.progress import say

# catdae.output.plot.WHAT
WHAT = ("profile", "history", "spectrum", "tension", "modes", "spans", "reactions")

DEFAULT_CASE = "example1_free_vibration.toml"


def default_case_path() -> Path:
    """The bundled default case (the paper's example 1)."""
    return Path(str(files("catdae") / "data" / DEFAULT_CASE))


def _order(text: str) -> int | str:
    """``--max-order``: "auto" or an integer (its range is judged with the case's own field)."""
    if text == "auto":
        return text
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'expected "auto" or an integer 1-5, got {text!r}') \
            from None


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
    r.add_argument("--max-order", type=_order, metavar="{auto,1,2,3,4,5}",
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

    case = load_case(Path(args.case))  # the command line always names a file
    mesh = check_case(case)
    say(f"{args.case}: valid: {len(case.cables)} cable(s), {mesh.n_elements} elements, "
        f"{mesh.n_nodes} nodes, {len(case.steps)} step(s)")
    return 0


def _run(args) -> int:
    from catdae.analysis import run
    from catdae.case import load_case
    from catdae.output.files import check_output

    path = Path(args.case) if args.case else default_case_path()
    case = load_case(path)
    out = Path(args.output) if args.output is not None else Path(f"{path.stem}.nc")
    try:
        check_output(args.output if args.output is not None else out, case)
    except OutputError as exc:  # judged before any work: a usage error
        print(f"catdae: {exc}", file=sys.stderr)
        return 2
    from catdae.progress import announce_compiling

    try:
        with announce_compiling():  # whenever numba compiles, the first time is announced
            tree = run(case, output=out, progress=args.progress, rtol=args.rtol,
                       atol=args.atol, elements=args.elements, mass_model=args.mass_model,
                       max_order=args.max_order)
    except CaseError:
        raise  # an invalid override (exit 2), reported by main
    except CatdaeError as exc:
        print(f"catdae: {path}: {exc}", file=sys.stderr)
        if isinstance(exc, InternalError) and exc.__cause__ is not None:  # for the report
            traceback.print_exception(exc.__cause__, file=sys.stderr)
        _say_where(exc, "before the failure")
        return 1
    say(summary(tree))
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
    if not files:
        print(f"catdae: {args.results}: no figure to make: the steps chosen make none of "
              f"{', '.join(args.what or WHAT)}", file=sys.stderr)
        return 2
    return 0


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
    if not files:
        print(f"catdae: {args.results}: nothing to export: no static or transient step",
              file=sys.stderr)
        return 2
    return 0


def summary(tree) -> str:
    """A short printed summary: per step, what a user looks at first (per value of a sweep)."""
    lines = [f"{tree.attrs.get('title') or 'catdae run'}"]
    for name, node in tree.children.items():
        ds = node.to_dataset()
        if "sweep" not in ds.dims:
            lines.extend(_step_lines(name, ds))
            continue
        field = ds.attrs.get("sweep_field", "sweep")
        lines.append(f"[{name}] swept over {field}: {ds.sizes['sweep']} values")
        for _, one in step_values(name, ds):
            lines.extend(_step_lines(f"{name} {one.attrs['sweep_value']}", one))
    return "\n".join(lines)


def _step_lines(name: str, ds) -> list[str]:
    """The summary of one step's dataset (of one value of a sweep)."""
    lines = []
    kind = ds.attrs.get("kind", "")
    if kind == "static":
        hot = (f" at {ds.attrs['temperature']:.6g} deg" if "temperature" in ds.attrs
               else "")
        lines.append(f"[{name}] static{hot}: {ds.attrs.get('iterations')} Newton "
                     f"iterations, residual {ds.attrs.get('residual_norm', 0):.2e} N")
        lines.extend(_cable_lines(ds))
        if ds.attrs.get("note"):
            lines.append(f"    note: {ds.attrs['note']}")
    elif kind == "modal":
        lines.extend(_mode_lines(name, ds))
        if ds.attrs.get("note"):
            lines.append(f"    note: {ds.attrs['note']}")
    elif kind == "transient":
        a = ds.attrs
        lines.append(f"[{name}] transient: {ds.time.size} outputs to t = "
                     f"{float(ds.time[-1]):.4g} s, {a.get('n_steps')} steps, "
                     f"{a.get('n_residual_evaluations')} residuals, "
                     f"{a.get('wall_time', 0):.2f} s wall, status {a.get('status')}")
        # supports (reaction defined on some axis) are prescribed: the free nodes' motion
        free = ds.reaction.isnull().all(("time", "axis"))
        d = ds.displacement.isel(node=np.flatnonzero(free.values)) if bool(free.any()) \
            else ds.displacement
        d = d - d.isel(time=0)  # during the step (displacement is from the case's geometry)
        mag = np.sqrt((d**2).sum("axis"))
        node = str(mag.max("time").idxmax("node").values)
        tmax = ds.tension_max if "tension_max" in ds else ds.get("tension")  # envelope
        top = (f"; max tension {float(tmax.max()):.6g} N" if ds.sizes.get("element")
               and tmax is not None else "")  # a scene of connectors alone has no element
        lines.append(f"    largest motion of a free node during the step at {node}: "
                     f"{float(mag.sel(node=node).max()):.4g} m{top}")
        lines.extend(_jump_lines(ds))
        if a.get("note"):
            lines.append(f"    note: {a['note']}")
    return lines


def _mode_lines(name: str, ds) -> list[str]:
    """Every mode of a modal step: its frequency and labels (plane, symmetry); with damping
    the damped frequency, the damped modes' labels and the damping ratio."""
    damped = "damping_ratio" in ds
    out = [f"[{name}] modal: {ds.mode.size} modes"
           + (" (damped: frequency Im s/2π, damping ratio -Re s/|s|)" if damped else "")]
    names = ("damped_plane", "damped_symmetry") if damped else ("plane", "symmetry")
    for k, mode in enumerate(ds.mode.values):
        labels = ", ".join(str(ds[v].values[k]) for v in names if v in ds)
        line = (f"    mode {int(mode)}: {float(ds.frequency.values[k]):.6g} Hz"
                + (f", {labels}" if labels else ""))
        if damped:
            line += f", damping ratio {float(ds.damping_ratio.values[k]):.4g}"
            like = int(ds.undamped_mode.values[k]) if "undamped_mode" in ds else k + 1
            if like >= 1:  # the undamped mode it is most like, not the k-th (sorted by |s|)
                f_u = float(ds.undamped_frequency.sel(mode=like))
                line += f" (like undamped mode {like}: {f_u:.6g} Hz)"
        out.append(line)
    return out


def _jump_lines(ds) -> list[str]:
    """Per cable of a transient: its largest rise above the jump_reference step, the largest
    tension as a percentage of the rated strength (catdae.output.engineering)."""
    out = []
    for k, cab in enumerate(ds.cable.values if "cable" in ds.coords else ()):
        parts = []
        if "jump_height" in ds:
            parts.append(f"jump {float(ds.jump_height.values[k]):.6g} m above step "
                         f"'{ds.attrs.get('jump_reference', '')}' at t = "
                         f"{float(ds.jump_time.values[k]):.6g} s, s = "
                         f"{float(ds.jump_s.values[k]):.6g} m")
        if "tension_percent_rated" in ds and np.isfinite(ds.tension_percent_rated.values[k]):
            parts.append(f"largest tension {float(ds.tension_percent_rated.values[k]):.4g} % "
                         "of rated strength")
        if "clearance_time" in ds:
            parts.append(f"least clearance {float(ds.clearance.values[k]):.6g} m at t = "
                         f"{float(ds.clearance_time.values[k]):.6g} s")
        if parts:
            out.append(f"    cable {cab}: " + "; ".join(parts))
    return out


def _span_lines(ds, k: int) -> list[str]:
    """The span quantities of cable k (catdae.output.engineering), when the group has them."""
    if "sag_midspan" not in ds:
        return []
    parts = [f"sag at midspan {float(ds.sag_midspan.values[k]):.6g} m",
             f"at the lowest point {float(ds.sag_lowest_point.values[k]):.6g} m below the lower "
             "end",
             f"swing angle {float(ds.swing_angle.values[k]):.4g} deg"]
    if "tension_percent_rated" in ds and np.isfinite(ds.tension_percent_rated.values[k]):
        parts.append(f"largest tension {float(ds.tension_percent_rated.values[k]):.4g} % of "
                     "rated strength")
    if "clearance" in ds:
        parts.append(f"clearance above the ground {float(ds.clearance.values[k]):.6g} m at "
                     f"s = {float(ds.clearance_s.values[k]):.6g} m")
    return ["      " + "; ".join(parts)]


def _cable_lines(ds) -> list[str]:
    """Per cable: end tensions, horizontal tension, sag (and unstrained length)."""
    if "cable" not in ds.coords:
        return []
    out = []
    for k, cab in enumerate(ds.cable.values):
        t_i, t_j = (float(v) for v in ds.cable_end_tension.values[k])
        first = str(ds.element_node.values[ds.element_cable.values == cab][0, 0])
        line = (f"    cable {cab}: end tensions {t_i:.6g} N, {t_j:.6g} N; horizontal tension "
                f"{float(ds.horizontal_tension.values[k]):.6g} N at {first} (includes the part "
                "across the chord)")
        if "horizontal_tension_along_chord" in ds:
            line += (f", along the chord "
                     f"{float(ds.horizontal_tension_along_chord.values[k]):.6g} N")
        line += f"; sag {float(ds.sag.values[k]):.6g} m"
        if "unstrained_length" in ds:
            line += f"; L0 {float(ds.unstrained_length.values[k]):.9g} m"
        out.append(line)
        out.extend(_span_lines(ds, k))
    return out


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
