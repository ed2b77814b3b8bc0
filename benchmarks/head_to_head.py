"""Whole processes one after the other on issue 11's cable: catdae runs (``python -m catdae
run CASE -o OUT.nc``) and one OpenSees run, each with its midspan error against a reference
made by ``speed_accuracy.py --ref-cache FILE`` (benchmarks/speed_accuracy.md §7).

    python benchmarks/head_to_head.py REF.npz [--catdae 40:1e-4:auto 48:1e-4:2 ...]
                                              [--opensees 160:0.01 ...]
"""
import argparse
import os
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import speed_accuracy as sa  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("ref", help="reference .npz written by speed_accuracy.py --ref-cache")
    ap.add_argument("--catdae", nargs="*", default=["40:1e-4:auto", "48:1e-4:2", "64:1e-4:auto"],
                    help="elements:rtol:max_order")
    ap.add_argument("--opensees", nargs="*", default=["160:0.01"], help="elements:dt")
    args = ap.parse_args()
    print(f"Machine: {sa.ts.machine()}", flush=True)
    zref = np.load(args.ref)["z"]
    sa.run_catdae(8, 1e-3, duration=0.05)  # the kernels compiled and cached
    with tempfile.TemporaryDirectory() as tmp:
        for spec in args.catdae:
            n, rtol, order = spec.split(":")
            r = sa.whole_catdae(int(n), float(rtol), Path(tmp), max_order=order)
            w, c, e, st = r["wall"], r["cpu"], sa.err(r["z"], zref), r["steps"]
            print(f"catdae {n} elements rtol {float(rtol):g} max_order {order}: err {e:.2e} m, "
                  f"{st} steps, wall {w:.2f} s, CPU {c:.2f} s, load {os.getloadavg()[0]:.1f}",
                  flush=True)
    env = sa.oc.opensees_env()
    for spec in args.opensees:
        n, dt = spec.split(":")
        r = sa.run_ops(sa.ops_job(int(n)), float(dt), env)
        print(f"OpenSees {n} elements dt {float(dt):g}: err {sa.err(r['z'], zref):.2e} m, wall "
              f"{r['process_wall']:.2f} s, CPU {r['process_cpu']:.2f} s, load "
              f"{os.getloadavg()[0]:.1f}", flush=True)


if __name__ == "__main__":
    main()
