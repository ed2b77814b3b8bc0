"""The fixed cost of a whole ``catdae run`` process: interpreter, imports, loading the cached
kernels, the static step, the start of a transient step, the netCDF write.

Runs issue 11's cable (40 elements) over 0.05 s of simulated time as ``python -m catdae run``
and prints the CPU time (user + system) of each process: median and spread over the repeats.
The variants are run interleaved, one process after the other, so that they see the same load:

- ``catdae run``: this tree (the catdae beside this benchmarks folder, by PYTHONPATH);
- ``--tree DIR`` (any number of times): the same command with ``PYTHONPATH=DIR``, another
  checkout of catdae (for a before/after in one run: ``git archive <commit> | tar -x -C DIR``;
  its kernels are compiled by a first run, not timed);
- ``--dask``: this tree in a process that imports dask.array first (what xarray's own probe of
  dask did in every run before catdae/_xr.py);
- ``--phases``: one more process of this tree that times the pieces of a run from inside
  (``time.process_time`` around the imports, the cached kernels' loading, the steps, the
  netCDF write): where the part after the imports goes;
- ``--breakdown``: processes that stop after each stage of a run's imports (the interpreter
  alone, + numpy, + the case reader (pydantic), + xarray/pandas, + numba, + catdae.analysis
  (scipy.sparse, scipy.linalg), + the transient solver (scikit-sundae, scipy.optimize)), so that
  the differences of their medians are what each stage adds; the rest of a run (kernels,
  steps, netCDF) is the whole run minus the last stage.

    python benchmarks/startup.py [--repeats 5] [--elements 40] [--tree DIR ...] [--dask]
                                 [--breakdown] [--phases]
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parent))
if sys.argv[1:2] != ["--in-process-phases"]:  # that process times its own imports
    import speed_accuracy as sa  # noqa: E402

PROBE = ("import sys, dask.array; from catdae.cli import main; "
         "sys.exit(main(sys.argv[1:]))")
STAGES = {  # cumulative: each stage imports what the one before did, and more
    "interpreter (python -c pass)": "",
    "+ numpy": "import numpy",
    "+ case reader (pydantic)": "import numpy, catdae.case",
    "+ xarray, pandas (catdae.output.files)": "import numpy, catdae.case, catdae.output.files",
    "+ numba (catdae.cli)": "import catdae.cli",
    "+ catdae.analysis (scipy.sparse, .linalg)": "import catdae.cli, catdae.analysis",
    "+ transient solver (scikit-sundae)": "import catdae.cli, catdae.analysis, "
                                          "catdae.solvers.transient",
}
# a stage ends as a finished run does (catdae/__main__.py): without the interpreter's teardown
EXIT = "; import os; os._exit(0)"


def one(argv: list[str], env: dict | None, cwd: str) -> tuple[float, float]:
    """CPU and wall s of one process, run in ``cwd`` (not in a catdae checkout, whose catdae
    would come before PYTHONPATH's)."""
    _, wall, cpu = sa.children_cost(subprocess.run, argv, check=True, capture_output=True,
                                    env=env, cwd=cwd)
    return cpu, wall


def phases(run_args: list[str]) -> None:
    """In this process: CPU of the pieces of one ``catdae run`` (nested pieces marked)."""
    import time
    from collections import defaultdict

    t0 = time.process_time()
    import catdae.cli as cli
    t1 = time.process_time()
    import numba.core.dispatcher as nd

    import catdae.analysis as an
    import catdae.output.writer as writer
    t2 = time.process_time()
    acc: dict[str, float] = defaultdict(float)

    def wrap(owner, name, label):
        f = getattr(owner, name)

        def timed(*a, **k):
            t = time.process_time()
            try:
                return f(*a, **k)
            finally:
                acc[label] += time.process_time() - t
        setattr(owner, name, timed)

    wrap(an, "build_mesh", "mesh (the first kernel's load in it)")
    wrap(an, "_run_step", "steps (transient solver's imports in it)")
    wrap(an, "engineering_results", "engineering results")
    wrap(writer.ResultWriter, "__init__", "writer set-up")
    wrap(writer.ResultWriter, "write_final", "netCDF write")
    wrap(nd.Dispatcher, "_compile_for_args", "  in these: cached kernels' loading")
    wrap(cli, "summary", "printed summary")
    import contextlib
    import io

    with contextlib.redirect_stdout(io.StringIO()):
        cli.main(["run", *run_args])
    t3 = time.process_time()
    print(f"  import catdae.cli {t1 - t0:.3f} s, + catdae.analysis {t2 - t1:.3f} s, "
          f"the run after them {t3 - t2:.3f} s (this process: {t3:.3f} s)")
    for k, v in acc.items():
        print(f"    {k:42s} {v:.3f} s")


def main() -> None:
    if sys.argv[1:2] == ["--in-process-phases"]:
        phases(sys.argv[2:])
        return
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--elements", type=int, default=40)
    ap.add_argument("--tree", metavar="DIR", action="append", default=[],
                    help="another catdae tree, run interleaved (repeatable)")
    ap.add_argument("--dask", action="store_true", help="also a run with dask.array imported")
    ap.add_argument("--breakdown", action="store_true", help="also the import stages")
    ap.add_argument("--phases", action="store_true", help="also the pieces of one run")
    args = ap.parse_args()
    print(f"Machine: {sa.ts.machine()}", flush=True)
    print(f"1-min load at the start {os.getloadavg()[0]:.1f}", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        case = Path(tmp) / "short.toml"
        case.write_text(sa.case_text(args.elements, 1e-4, duration=0.05))
        out = str(Path(tmp) / "out.nc")
        run = ["run", str(case), "-o", out, "--no-progress"]
        variants = {"catdae run": ([sys.executable, "-m", "catdae", *run], None)}
        here = str(Path(__file__).resolve().parent.parent)  # this tree, wherever it is run from
        mine = {**os.environ, "PYTHONPATH": here}
        variants = {k: (argv, mine) for k, (argv, _) in variants.items()}
        for tree in args.tree:
            env = {**os.environ, "PYTHONPATH": str(Path(tree).resolve())}
            variants[f"catdae run, {tree}"] = ([sys.executable, "-m", "catdae", *run], env)
        if args.dask:
            variants["with dask.array imported"] = ([sys.executable, "-c", PROBE, *run], mine)
        if args.breakdown:
            for name, code in STAGES.items():
                variants[name] = ([sys.executable, "-c", (code or "pass") + EXIT], mine)
        for argv, env in variants.values():  # kernels compiled and cached, files in page cache
            one(argv, env, tmp)
        times = {k: [] for k in variants}
        for _ in range(args.repeats):
            for k, (argv, env) in variants.items():
                times[k].append(one(argv, env, tmp))
        med = {}
        for k, v in times.items():
            cpu = [c for c, _ in v]
            wall = [w for _, w in v]
            med[k] = statistics.median(cpu)
            print(f"{k:42s}: CPU {med[k]:.3f} s (min {min(cpu):.3f}, max "
                  f"{max(cpu):.3f}), wall {statistics.median(wall):.3f} s", flush=True)
        if args.breakdown:
            print("\nWhat each stage adds (differences of the CPU medians):")
            last = 0.0
            for name in STAGES:
                print(f"  {name:42s} {med[name] - last:+.3f} s")
                last = med[name]
            print(f"  {'kernels, steps, netCDF write (the rest)':42s} "
                  f"{med['catdae run'] - last:+.3f} s")
        if args.phases:
            print("\nThe pieces of one run of this tree, CPU from inside the process:")
            print(subprocess.run([sys.executable, __file__, "--in-process-phases", *run[1:]],
                                 env=mine, cwd=tmp, check=True, capture_output=True,
                                 text=True).stdout, end="")
    print(f"1-min load at the end {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
