"""The start of a fine mesh of issue 11's cable with IDA's ``first_step`` set for the run's first
IDA (speed_accuracy.md §8.2): steps in the first 0.02 / 0.1 / 0.3 s, in all, CPU, and the
midspan error against a reference (key "z", optional).

    OMP_NUM_THREADS=1 python benchmarks/first_step_start.py FIRST_STEP [N RTOL DURATION [REF]]

FIRST_STEP 0 leaves IDA's own estimate.
"""
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
import catdae.solvers.transient as tr  # noqa: E402
from catdae.case import case_from_dict  # noqa: E402

args = sys.argv[1:] + ["1000", "1e-4", "1.0"][len(sys.argv) - 2:]
fs, n, rtol, dur = float(args[0]), int(args[1]), float(args[2]), float(args[3])
ref = args[4] if len(args) > 4 else None
made = []
orig = tr.IDA


def ida(res, **kw):
    if not made and fs > 0:
        kw["first_step"] = fs
    made.append(kw.get("max_order"))
    return orig(res, **kw)


times = []


class Recorded(tr.OrderChoice):
    def observe(self, t):
        times.append(t)
        return super().observe(t)


tr.IDA, tr.OrderChoice = ida, Recorded
c0 = time.process_time()
tree = catdae.run(case_from_dict(tomllib.loads(sa.case_text(n, rtol, duration=dur))),
                  progress=False)
cpu = time.process_time() - c0
ds = tree["motion"].ds
z = ds.position.sel(node=f"c.{n // 2}", axis="z").values
t = np.array(times)
line = (f"first_step {fs:g}, {n} elements, rtol {rtol:g}: {ds.attrs['n_steps']} steps, "
        f"CPU {cpu:.2f} s; steps before 0.02 / 0.1 / 0.3 s: {(t < 0.02).sum()} / "
        f"{(t < 0.1).sum()} / {(t < 0.3).sum()}")
if ref:
    zr = np.load(ref)["z"]
    line += f"; error {sa.err(z, zr[:len(z)]) * 1e3:.4f} mm"
print(line)
