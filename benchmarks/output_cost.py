"""The cost of a transient's steps and outputs, trees compared one process after the other
(benchmarks/output_cost.md): the 100 m cable of speed_accuracy.md at its 1 cm candidate (blended,
48 elements, rtol 3e-4) and the stay of ringing.py (20 elements, 60 s, rtol 1e-5).

    python benchmarks/output_cost.py --tree /path/to/main --tree /path/to/branch [--rounds 3]

Per tree and round: the in-process CPU of ``catdae.run`` (warm: later runs of one process; three
runs of the cable, one of the stay) and whole ``python -m catdae run`` processes (CPU of the
child). Every process is started from an empty folder: ``python -m`` puts the working folder
first on ``sys.path``, ahead of ``PYTHONPATH``, so a process started inside a checkout would run
that checkout. Prints one line per process with the steps and residuals of its run.
"""
import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
import ringing  # noqa: E402
import speed_accuracy as sa  # noqa: E402

INPROC = """
import os, sys, time, catdae, netCDF4
case, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
catdae.run(case, output=out)
ts = []
for _ in range(n):
    c0 = time.process_time(); catdae.run(case, output=out); ts.append(time.process_time() - c0)
with netCDF4.Dataset(out) as d:
    g = d.groups[list(d.groups)[-1]]
    print(' '.join('%.3f' % t for t in ts), g.getncattr('n_steps'),
          g.getncattr('n_residual_evaluations'))
"""


def child(tree: str, argv: list[str], folder: Path):
    env = dict(os.environ, PYTHONPATH=tree, OMP_NUM_THREADS="1")
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run([sys.executable, *argv], env=env, cwd=folder, capture_output=True,
                       text=True)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise RuntimeError(p.stderr[-2000:])
    return p.stdout, r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--tree", action="append", required=True)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    folder = Path(tempfile.mkdtemp())
    cases = {"cable": folder / "cable.toml", "stay": folder / "stay.toml"}
    cases["cable"].write_text(sa.case_text(48, 3e-4))
    cases["stay"].write_text(ringing.stay_case(ringing.STAY_ROWS["default (rtol 1e-5)"]))
    script = folder / "inproc.py"
    script.write_text(INPROC)
    for _ in range(args.rounds):
        for name, case in cases.items():
            for tree in args.tree:
                n = "3" if name == "cable" else "1"
                out, _ = child(tree, [str(script), str(case), n, str(folder / "i.nc")], folder)
                print(f"{time.strftime('%H:%M:%S', time.gmtime())} load "
                      f"{os.getloadavg()[0]:.2f} {tree} {name} in-process CPU s, steps, "
                      f"residuals: {out.strip()}", flush=True)
            for tree in args.tree:
                out, cpu = child(tree, ["-m", "catdae", "run", str(case), "-o",
                                        str(folder / "w.nc"), "--no-progress"], folder)
                steps = [ln for ln in out.splitlines() if "steps" in ln][-1].split(",")[1]
                print(f"{time.strftime('%H:%M:%S', time.gmtime())} load "
                      f"{os.getloadavg()[0]:.2f} {tree} {name} whole process CPU "
                      f"{cpu:.2f} s,{steps}", flush=True)


if __name__ == "__main__":
    main()
