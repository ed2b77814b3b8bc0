"""A scene without [water] or [air] costs what it cost before the fluid was added (issue 21).

Runs the same bundled case with the code of two trees (this one and a base, e.g. main before
the fluid), interleaved, each in its own process with warm kernel caches: the step counts must
be identical and the node histories bitwise equal; the CPU time of the transient step is
compared. Usage::

    python benchmarks/fluid_off.py --base /work/main [--case CASE.toml] [--repeats N]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent

_CHILD = r"""
import hashlib, json, sys, time
import numpy as np
import catdae
case = catdae.load_case(sys.argv[1])
catdae.run(case, progress=False)  # warm: kernels compiled and cached, imports done
t0, c0 = time.perf_counter(), time.process_time()
tree = catdae.run(case, progress=False)
wall, cpu = time.perf_counter() - t0, time.process_time() - c0
out = {"wall": wall, "cpu": cpu, "steps": {}}
for name, node in tree.children.items():
    ds = node.to_dataset()
    if "n_steps" in ds.attrs:
        out["steps"][name] = [int(ds.attrs["n_steps"]), int(ds.attrs["n_residual_evaluations"]),
                              hashlib.sha256(np.ascontiguousarray(ds.position.values)).hexdigest()]
print(json.dumps(out))
"""


def run(tree: Path, case: str) -> dict:
    env = dict(os.environ, PYTHONPATH=str(tree), OMP_NUM_THREADS="1")
    res = subprocess.run([sys.executable, "-c", _CHILD, case], env=env, capture_output=True,
                         text=True, check=True, cwd=tree)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", required=True, help="a checkout without the fluid (e.g. main)")
    ap.add_argument("--case", default=str(HERE / "cases" / "example2_support_motion_gentle.toml"))
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args()
    rows = []
    for r in range(a.repeats):
        pair = (("base", Path(a.base)), ("fluid", HERE))
        for label, tree in (pair if r % 2 == 0 else pair[::-1]):  # alternate who goes first
            out = run(tree, a.case)
            rows.append((label, r, out))
            print(f"{label:6s} run {r}: cpu {out['cpu']:.3f} s, wall {out['wall']:.3f} s, "
                  f"steps {out['steps']}", flush=True)
    same = len({json.dumps(o["steps"], sort_keys=True) for _, _, o in rows}) == 1
    for label in ("base", "fluid"):
        cpus = sorted(o["cpu"] for lb, _, o in rows if lb == label)
        print(f"{label}: median cpu {cpus[len(cpus) // 2]:.3f} s (min {cpus[0]:.3f})")
    print("identical steps, residual counts and position histories:", same)
    print("load average:", os.getloadavg())


if __name__ == "__main__":
    main()
