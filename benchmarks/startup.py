"""The fixed cost of a whole ``catdae run`` process: interpreter, imports, loading the cached
kernels, the two eigensolves at the start of a transient step, the netCDF write.

Runs issue 11's cable (40 elements) over 0.05 s of simulated time as ``python -m catdae run``,
interleaved with the same run in a process that imports dask.array first (what xarray's own
probe of dask did in every run before catdae/_xr.py), and prints the CPU time (user + system)
of each process: median and spread over the repeats.

    python benchmarks/startup.py [--repeats 5] [--elements 40]
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
import speed_accuracy as sa  # noqa: E402

PROBE = ("import sys, dask.array; from catdae.cli import main; "
         "sys.exit(main(sys.argv[1:]))")


def one(argv: list[str]) -> tuple[float, float]:
    _, wall, cpu = sa.children_cost(subprocess.run, argv, check=True, capture_output=True)
    return cpu, wall


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--elements", type=int, default=40)
    args = ap.parse_args()
    print(f"Machine: {sa.ts.machine()}", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        case = Path(tmp) / "short.toml"
        case.write_text(sa.case_text(args.elements, 1e-4, duration=0.05))
        out = str(Path(tmp) / "out.nc")
        run = ["run", str(case), "-o", out, "--no-progress"]
        variants = {"catdae run": [sys.executable, "-m", "catdae", *run],
                    "with dask.array imported": [sys.executable, "-c", PROBE, *run]}
        one(variants["catdae run"])  # kernels compiled and cached, files in the page cache
        times = {k: [] for k in variants}
        for _ in range(args.repeats):
            for k, argv in variants.items():
                times[k].append(one(argv))
        for k, v in times.items():
            cpu = [c for c, _ in v]
            wall = [w for _, w in v]
            print(f"{k:26s}: CPU {statistics.median(cpu):.2f} s (min {min(cpu):.2f}, max "
                  f"{max(cpu):.2f}), wall {statistics.median(wall):.2f} s", flush=True)
    print(f"1-min load {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
