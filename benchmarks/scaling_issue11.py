"""Cost per simulated second against the element count (issue 11's cable, blended mass,
automatic BDF order), at rtol 1e-4 and 1e-5: CPU time of the transient step per simulated
second, steps per simulated second, the order the run chose. Log-log slopes between 50 and
1000 elements are printed.

    python benchmarks/scaling_issue11.py [--duration 1.0] [--sizes 10,50,200,1000,2000]
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
args = ap.parse_args()
print(f"Machine: {sa.ts.machine()}", flush=True)
sa.run_catdae(8, 1e-3, duration=0.05)
cost = {}
for rtol in [float(x) for x in args.tols.split(",")]:
    for n in [int(x) for x in args.sizes.split(",")]:
        c0 = time.process_time()
        tree = catdae.run(case_from_dict(tomllib.loads(sa.case_text(n, rtol,
                          duration=args.duration))), progress=False)
        cpu = time.process_time() - c0
        ds = tree["motion"].ds
        cost[(rtol, n)] = cpu / args.duration
        print(f"rtol {rtol:.0e} n {n:5d}: CPU/simulated s {cpu / args.duration:8.2f}, steps/s "
              f"{ds.attrs['n_steps'] / args.duration:7.0f}, order {ds.attrs['max_order']} "
              f"({ds.attrs['order_choice']}), 1-min load {os.getloadavg()[0]:.1f}", flush=True)
    if (rtol, 50) in cost and (rtol, 1000) in cost:
        slope = np.log(cost[(rtol, 1000)] / cost[(rtol, 50)]) / np.log(1000 / 50)
        print(f"rtol {rtol:.0e}: log-log slope of CPU per simulated second, 50 -> 1000 "
              f"elements: {slope:.3f}", flush=True)
