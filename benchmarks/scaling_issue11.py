"""Cost per simulated second against the element count (issue 11's cable, blended mass,
automatic BDF order), at rtol 1e-4 and 1e-5: CPU time of the transient step per simulated
second, steps per simulated second, the order the run chose. Log-log slopes between 50 and
1000 elements are printed.

With ``--marginal`` each run is repeated over twice the duration and the cost per simulated
second is the difference, (CPU(2T) - CPU(T)) / T: the steady cost of the motion, without the
start-up that both runs share (imports are already loaded; the two eigensolves at the start,
IDA's first steps at order 1, and the response to what t = 0 excites, which a 1 s run weighs
heavily).

    python benchmarks/scaling_issue11.py [--duration 1.0] [--sizes 10,50,200,1000,2000]
                                         [--marginal]
"""
import argparse
import os
import sys
import time
import tomllib
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import speed_accuracy as sa  # noqa: E402

import catdae  # noqa: E402
from catdae.case import case_from_dict  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("--duration", type=float, default=1.0)
ap.add_argument("--sizes", default="10,50,200,1000,2000")
ap.add_argument("--tols", default="1e-4,1e-5")
ap.add_argument("--marginal", action="store_true",
                help="cost per simulated second from runs over T and 2T (their difference)")
args = ap.parse_args()
print(f"Machine: {sa.ts.machine()}", flush=True)
sa.run_catdae(8, 1e-3, duration=0.05)
cost = {}
marg = {}


def one(n, rtol, duration):
    c0 = time.process_time()
    tree = catdae.run(case_from_dict(tomllib.loads(sa.case_text(n, rtol, duration=duration))),
                      progress=False)
    return time.process_time() - c0, tree["motion"].ds


for rtol in [float(x) for x in args.tols.split(",")]:
    for n in [int(x) for x in args.sizes.split(",")]:
        T = args.duration
        cpu, ds = one(n, rtol, T)
        cost[(rtol, n)] = cpu / T
        line = (f"rtol {rtol:.0e} n {n:5d}: CPU/simulated s {cpu / T:8.2f}, steps/s "
                f"{ds.attrs['n_steps'] / T:7.0f}, order {ds.attrs['max_order']} "
                f"({ds.attrs['order_choice']})")
        if args.marginal:
            cpu2, ds2 = one(n, rtol, 2 * T)
            marg[(rtol, n)] = (cpu2 - cpu) / T
            line += (f"; marginal over ({T:g}, {2 * T:g}] s: CPU/simulated s "
                     f"{(cpu2 - cpu) / T:8.2f}, steps/s "
                     f"{(ds2.attrs['n_steps'] - ds.attrs['n_steps']) / T:7.0f}")
        print(line + f", 1-min load {os.getloadavg()[0]:.1f}", flush=True)
    for name, c in (("CPU per simulated second", cost), ("marginal CPU per simulated second",
                                                        marg)):
        if (rtol, 50) in c and (rtol, 1000) in c:
            slope = np.log(c[(rtol, 1000)] / c[(rtol, 50)]) / np.log(1000 / 50)
            print(f"rtol {rtol:.0e}: log-log slope of {name}, 50 -> 1000 elements: "
                  f"{slope:.3f}", flush=True)
