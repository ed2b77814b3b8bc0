"""The figures of issue 22's acceptance scenes, measured (the tests assert the bounds).

Run apart from the test suite:  python benchmarks/connectors_acceptance.py

1. MoorDyn's pendulum (1e5 kg on a 100.5 m bar, EA 1e9, released 10 m aside): periods against
   2π √(l/g)(1 + θ0²/16), amplitude of each swing, energy drift, steps and CPU.
2. The cable-and-strut system: the strut's axial force and the joint's position against the
   hand calculation (tests/scenes/test_connectors.py).
3. The bundled three-span section (cases/three_span_ice_shedding.toml) as bundled (8 s of
   shedding, rtol = atol = 1e-7): energy drift against the kinetic energy set free, the
   middle span's jump, the strings' forces, steps and CPU.

Results: benchmarks/connectors_acceptance.md.
"""

from __future__ import annotations

import datetime as _dt
import os
import platform
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE.parent / "tests" / "scenes"))
from test_connectors import STRUT, pendulum  # noqa: E402

import catdae  # noqa: E402
from catdae.case import case_from_dict  # noqa: E402


def timed(case):
    c0, w0 = time.process_time(), time.perf_counter()
    tree = catdae.run(case)
    return tree, time.process_time() - c0, time.perf_counter() - w0


def main() -> None:
    load = os.getloadavg()
    out = []
    text, theta0 = pendulum()
    tree, cpu, wall = timed(case_from_dict(tomllib.loads(text)))
    ds = tree["swing"].ds
    t, x = ds.time.values, ds.position.sel(node="bob", axis="x").values
    up = np.flatnonzero((x[:-1] < 0.0) & (x[1:] >= 0.0))
    cross = t[up] - x[up] * (t[up + 1] - t[up]) / (x[up + 1] - x[up])
    expected = 2 * np.pi * np.sqrt(100.5 / 9.81) * (1 + theta0**2 / 16)
    per = np.diff(cross) / expected - 1
    amp = [x[(t >= k * expected) & (t < (k + 1) * expected)].max() / 10 - 1 for k in range(5)]
    e = ds.energy_total.values
    out += ["## 1. Pendulum (MoorDyn's test)", "",
            f"Expected period {expected:.6f} s (θ0 = {theta0:.6f} rad). Periods measured between "
            f"upward zero crossings: relative errors {', '.join(f'{p:+.2e}' for p in per)}. "
            f"Largest swing in each of the five periods, relative to 10 m: "
            f"{', '.join(f'{a:+.2e}' for a in amp)}. Energy drift "
            f"{np.abs(e - e[0]).max():.3g} J of {e[0]:.6g} J. "
            f"{ds.attrs['n_steps']} steps, {ds.attrs['n_residual_evaluations']} residuals, "
            f"{cpu:.2f} s CPU ({wall:.2f} s wall) for 101 s.", ""]
    tree, cpu, wall = timed(case_from_dict(tomllib.loads(STRUT)))
    ds = tree["st"].ds
    out += ["## 2. Cable and strut", "",
            f"Strut force {float(ds.connector_force.sel(connector='strut')):.10g} N, joint "
            f"{ds.position.sel(node='J').values.tolist()} m (the test solves the hand formulas "
            "and asserts 1e-9).", ""]
    case = catdae.load_case(HERE.parent / "cases" / "three_span_ice_shedding.toml")
    tree, cpu, wall = timed(case)
    ds = tree["shedding"].ds
    e, k = ds.energy_total.values, ds.energy_kinetic.values
    z = ds.position.sel(node="span2.8", axis="z").values
    f = ds.connector_force.sel(connector="string1").values
    out += ["## 3. Three-span section, ice shed from the middle span", "",
            f"8 s at rtol = atol = 1e-7: energy drift {np.abs(e - e[0]).max():.3g} J, "
            f"{np.abs(e - e[0]).max() / k.max():.2e} of the largest kinetic energy "
            f"{k.max():.6g} J. Midspan of span2 rises {z.max() - z[0]:.3f} m; string1 force "
            f"{f[0]:.6g} N at the start, {f.min():.6g} to {f.max():.6g} N during the motion. "
            f"{ds.attrs['n_steps']} steps, {ds.attrs['n_residual_evaluations']} residuals, "
            f"{cpu:.1f} s CPU ({wall:.1f} s wall).", ""]
    head = ["# Connectors: acceptance figures (issue 22)", "",
            f"Made by `python benchmarks/connectors_acceptance.py` on {_dt.date.today()} "
            f"({platform.machine()}, {os.cpu_count()} cores, load average at the start "
            f"{load[0]:.2f}, shared with other runs: CPU times are indicative).", ""]
    text = "\n".join(head + out)
    (HERE / "connectors_acceptance.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
