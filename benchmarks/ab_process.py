"""Whole ``python -m catdae run`` processes of two or more source trees, alternating.

    OMP_NUM_THREADS=1 python benchmarks/ab_process.py CASE.toml N TREE [TREE ...]

Each tree (a checkout or ``git archive`` of catdae, its kernels compiled once by a first run)
is put first on ``PYTHONPATH``; the processes run in an empty temporary folder one after the
other, the trees alternating, N rounds. Prints per tree the median and least CPU (user + system
of the child) and the median wall time. Used for benchmarks/startup.md.
"""

from __future__ import annotations

import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time


def main(argv=None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    case, n, trees = os.path.abspath(argv[0]), int(argv[1]), argv[2:]
    cpu = {t: [] for t in trees}
    wall = {t: [] for t in trees}
    with tempfile.TemporaryDirectory() as folder:
        for _ in range(n):
            for t in trees:
                env = dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=os.path.abspath(t))
                r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
                w0 = time.perf_counter()
                p = subprocess.run([sys.executable, "-m", "catdae", "run", case, "-o",
                                    os.path.join(folder, "out.nc"), "--no-progress"],
                                   env=env, cwd=folder, capture_output=True, text=True)
                w = time.perf_counter() - w0
                r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
                if p.returncode:
                    sys.exit(f"{t}: {p.stderr[-1500:]}")
                cpu[t].append(r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
                wall[t].append(w)
    for t in trees:
        print(f"{t}: CPU median {statistics.median(cpu[t]):.3f} s (least {min(cpu[t]):.3f}), "
              f"wall median {statistics.median(wall[t]):.3f} s, 1-min load "
              f"{os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
