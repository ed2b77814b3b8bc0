"""Static solution speed: one cable of 10, 100 and 1000 elements under a large point load.

The cable (span 100 m, L0 = 110 m, EA = 1e7 N, 5 kg/m) is meshed on its catenary under
self-weight; a point load of 20 times the cable's weight acts at 0.3 of its length (a mesh node).
Reported: wall time of the static step (solve_static alone, then the whole ``catdae.run`` with
results), Newton iterations, load increments, and the share of time in the sparse LU.
Run apart from the tests: ``python benchmarks/static_speed.py [--profile]``.
"""

from __future__ import annotations

import argparse
import cProfile
import platform
import pstats
import time
from datetime import date

import numba
import numpy as np
import scipy
import scipy.sparse.linalg as spla

import catdae
from catdae.case import case_from_dict
from catdae.model.assembly import Model
from catdae.model.mesh import build_mesh
from catdae.solvers.static import solve_static

L0, SPAN, EA, MASS, G = 110.0, 100.0, 1.0e7, 5.0, 9.81


def make_case(ne: int, slack: bool = False, load_steps: int = 1):
    """The benchmark cable; ``slack``: the hard scene of tests/scenes/test_static.py (span 10 m,
    L0 = 15 m, EA = 3.4e7 N, 100 times the weight at 0.4 L0)."""
    span, l0, ea, factor, at = (10.0, 15.0, 3.4e7, 100.0, 0.4) if slack else \
        (SPAN, L0, EA, 20.0, 0.3)
    P = factor * MASS * G * l0
    return case_from_dict({
        "materials": {"m": {"EA": ea, "mass": MASS}},
        "nodes": {"A": [0.0, 0.0, 0.0], "B": [span, 0.0, 0.0]},
        "supports": {"A": "pinned", "B": "pinned"},
        "cables": [{"name": "c", "ends": ["A", "B"], "material": "m", "length": l0,
                    "elements": ne}],
        "loads": [{"name": "p", "cable": "c", "s": at * l0, "force": [0.0, 0.0, -P]}],
        "steps": [{"kind": "static", "name": "st", "load_steps": load_steps}],
    })


def measure(ne: int, repeat: int = 3, slack: bool = False, load_steps: int = 1) -> dict:
    case = make_case(ne, slack, load_steps)
    mesh = build_mesh(case)
    lu_time = [0.0]
    real = spla.spsolve

    def timed_spsolve(*a, **k):
        t0 = time.perf_counter()
        out = real(*a, **k)
        lu_time[0] += time.perf_counter() - t0
        return out

    best = None
    for _ in range(repeat):
        model = Model(case, mesh, set())
        lu_time[0] = 0.0
        spla.spsolve = timed_spsolve
        try:
            t0 = time.perf_counter()
            sol = solve_static(model, mesh.X0, load_steps=load_steps)
            wall = time.perf_counter() - t0
        finally:
            spla.spsolve = real
        if best is None or wall < best["solve"]:
            best = {"ne": ne, "solve": wall, "lu": lu_time[0], "iterations": sol.iterations,
                    "increments": sol.load_steps, "residual": sol.residual_norm}
    t0 = time.perf_counter()
    catdae.run(case)
    best["run"] = time.perf_counter() - t0
    return best


def machine() -> str:
    import os

    return (f"{platform.platform()}, {platform.processor() or platform.machine()}, "
            f"{os.cpu_count()} CPUs; Python {platform.python_version()}, numpy {np.__version__}, "
            f"scipy {scipy.__version__}, numba {numba.__version__}, catdae {catdae.__version__}; "
            f"{date.today().isoformat()}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--profile", action="store_true", help="profile the 1000-element solve")
    args = ap.parse_args()
    measure(10, repeat=1)  # compile the element kernel
    print(machine())
    print("| elements | Newton iterations | load increments | solve_static (s) | of which "
          "sparse LU (s) | per iteration (ms) | catdae.run (s) | residual (N) |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|")
    for ne in (10, 100, 1000):
        r = measure(ne)
        per = 1e3 * r["solve"] / max(r["iterations"], 1)
        print(f"| {ne} | {r['iterations']} | {r['increments']} | {r['solve']:.3f} | "
              f"{r['lu']:.3f} | {per:.2f} | {r['run']:.3f} | {r['residual']:.1e} |")
    print()
    print("Slack cable, 100 times its weight (tests/scenes/test_static.py):")
    print("| elements | load_steps | Newton iterations | load increments | solve_static (s) |")
    print("|---:|---:|---:|---:|---:|")
    for ne in (10, 100, 1000):
        for ls in (1, 5):
            r = measure(ne, repeat=1, slack=True, load_steps=ls)
            print(f"| {ne} | {ls} | {r['iterations']} | {r['increments']} | {r['solve']:.3f} |")
    if args.profile:
        case = make_case(1000)
        mesh = build_mesh(case)
        model = Model(case, mesh, set())
        prof = cProfile.Profile()
        prof.runcall(solve_static, model, mesh.X0)
        pstats.Stats(prof).sort_stats("cumulative").print_stats(18)


if __name__ == "__main__":
    main()
