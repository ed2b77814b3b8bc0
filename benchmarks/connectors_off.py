"""A scene without connectors runs as before (issue 22): the same integrator steps and the same
CPU time, within noise, with and without the connectors' hooks.

Run apart from the test suite:
    python benchmarks/connectors_off.py BEFORE_REPO AFTER_REPO [--repeats 3]

Runs each bundled case below in a fresh process per repeat, alternating the two checkouts
(BEFORE: a commit without connectors, e.g. main before the merge; AFTER: this branch), and
prints the steps, residual evaluations and CPU time of each run (time.process_time inside the
process, import and kernel loading excluded). With ``--calls``: the best CPU time of one
residual and one iteration matrix (example 1's transient start), which resolves differences
that whole runs on a loaded machine cannot. Results: benchmarks/connectors_off.md.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
CASES = ("example1_free_vibration.toml", "three_cables_shared_node.toml",
         "example2_support_motion_gentle.toml")

CHILD = r"""
import json, sys, time
import catdae
case = catdae.load_case(sys.argv[1])
catdae.run(case)  # warm-up: kernels loaded, caches filled
c0, w0 = time.process_time(), time.perf_counter()
tree = catdae.run(case)
cpu, wall = time.process_time() - c0, time.perf_counter() - w0
tr = [n.ds for n in tree.children.values() if n.ds.attrs.get("kind") == "transient"]
print(json.dumps({"cpu": cpu, "wall": wall,
                  "steps": sum(int(d.attrs["n_steps"]) for d in tr),
                  "residuals": sum(int(d.attrs["n_residual_evaluations"]) for d in tr)}))
"""


CALLS = r"""
import json, sys, time
import numpy as np
import catdae
from catdae.case.frame import to_gravity_frame
from catdae.model.assembly import Model
from catdae.model.mesh import build_mesh
from catdae.solvers.residual import TransientProblem
case = to_gravity_frame(catdae.load_case(sys.argv[1]))[0]
step = next(s for s in case.steps if s.kind == "transient")
mesh = build_mesh(case)
model = Model(case, mesh, set(), mass_model=step.mass_model, kind="transient")
prob = TransientProblem(model, step, mesh.X0, None)
y0, yp0 = prob.initial(0.0, mesh.X0, np.zeros_like(mesh.X0))
res = np.empty_like(y0)
J = np.zeros((y0.size, y0.size))
best = {}
for rep in range(5):
    c0 = time.process_time()
    for k in range(4000):
        prob.resfn(0.0, y0 * (1 + 1e-12 * (k % 7)), yp0, res)
    r = (time.process_time() - c0) / 4000
    c0 = time.process_time()
    for k in range(300):
        prob.jac_dense(0.0, y0 * (1 + 1e-12 * (k % 7)), yp0, res, 10.0, J)
    j = (time.process_time() - c0) / 300
    best["residual"] = min(best.get("residual", 1e9), r)
    best["jacobian"] = min(best.get("jacobian", 1e9), j)
print(json.dumps(best))
"""


def calls(repo: Path, case: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(repo))
    out = subprocess.run([sys.executable, "-c", CALLS, str(case)], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def run(repo: Path, case: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(repo))
    out = subprocess.run([sys.executable, "-c", CHILD, str(case)], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("before", type=Path)
    p.add_argument("after", type=Path)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--calls", action="store_true",
                   help="instead: the best CPU time of one residual and one iteration matrix "
                        "of example 1's transient start, over 5 x 4000 (300) calls")
    a = p.parse_args()
    if a.calls:
        case = "example1_free_vibration.toml"
        print(f"load average {os.getloadavg()}")
        print("| checkout | residual µs (best of 5 x 4000) | iteration matrix µs |")
        print("|---|---|---|")
        for _ in range(a.repeats):
            for label, repo in (("before", a.before), ("after", a.after)):
                r = calls(repo, repo / "cases" / case)
                print(f"| {label} | {1e6 * r['residual']:.2f} | {1e6 * r['jacobian']:.1f} |")
        print(f"load average {os.getloadavg()}")
        return
    print(f"load average {os.getloadavg()}")
    print("| case | checkout | steps | residuals | CPU s (each repeat) |")
    print("|---|---|---|---|---|")
    for name in CASES:
        rows = {"before": [], "after": []}
        for _ in range(a.repeats):
            for label, repo in (("before", a.before), ("after", a.after)):
                rows[label].append(run(repo, repo / "cases" / name))
        for label, rs in rows.items():
            cpu = ", ".join(f"{r['cpu']:.2f}" for r in rs)
            print(f"| {name} | {label} | {rs[0]['steps']} | {rs[0]['residuals']} | {cpu} |")
    print(f"load average {os.getloadavg()}")


if __name__ == "__main__":
    main()
