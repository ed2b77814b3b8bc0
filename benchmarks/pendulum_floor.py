"""How low catdae's whole process could go on MoorDyn's pendulum without xarray (issue 25).

A measurement of a floor, not a product path. The child ``--child CASE OUT`` runs a case of one
static step and one transient step (the pendulum of benchmarks/ringing.py) through catdae's own
solvers, as ``catdae run`` does, but imports neither xarray nor pandas: it writes the
transient's positions, velocities, accelerations, reactions and tensions with netCDF4 directly
and builds no dataset, no envelope variables, no summary. The parent runs, one process after
the other and interleaved, that child, ``python -m catdae run`` on the same case, the imports
alone (with and without xarray) and MoorDyn's driver of the same scene
(benchmarks/moordyn_compare.py), and prints the median CPU of each (user + system of the
child).

    python benchmarks/pendulum_floor.py [--repeats 5] [--extra "rtol = 1e-4\\natol = 1e-4"]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from types import SimpleNamespace

os.environ.setdefault("OMP_NUM_THREADS", "1")
HERE = Path(__file__).resolve().parent


def child(case_path: str, out: str) -> None:
    import numpy as np

    from catdae.case import load_case
    from catdae.case.frame import to_gravity_frame
    from catdae.model import formfind
    from catdae.model.assembly import Model
    from catdae.model.mesh import build_mesh
    from catdae.solvers.static import solve_static
    from catdae.solvers.transient import run_transient

    case = load_case(Path(case_path))
    local = formfind.initial_lengths(to_gravity_frame(case)[0])
    mesh = build_mesh(local)
    static, transient = case.steps

    state = SimpleNamespace(X=mesh.X0.copy(), V=np.zeros_like(mesh.X0), h=None, snap="", t=0.0)
    absent = set(static.remove)
    model = Model(local, mesh, absent, mass_model=static.mass_model, kind="static")
    sol = solve_static(model, state.X, state.h, t=0.0, load_steps=static.load_steps)
    state.X, state.h = sol.X, sol.state.h
    absent |= set(transient.remove)
    model = Model(local, mesh, absent, mass_model=transient.mass_model, kind="transient")
    rec = run_transient(transient, model, state, None, False)
    import netCDF4

    with netCDF4.Dataset(out, "w") as f:
        g = f.createGroup(transient.name)
        for name, size in (("time", rec.X.shape[0]), ("node", rec.X.shape[1]), ("axis", 3),
                           ("element", rec.T.shape[1]), ("end", 2)):
            g.createDimension(name, size)
        d3, de = ("time", "node", "axis"), ("time", "element", "end")
        for name, arr, dims, units in (("position", rec.X, d3, "m"), ("velocity", rec.V, d3, "m/s"),
                                       ("acceleration", rec.A, d3, "m/s2"),
                                       ("reaction", rec.R, d3, "N"), ("tension", rec.T, de, "N")):
            v = g.createVariable(name, "f8", dims, fill_value=np.nan)
            v[:] = arr
            v.units = units


def cpu_of(cmd: list[str]) -> float:
    before = os.times()
    p = subprocess.run(cmd, capture_output=True, text=True)
    after = os.times()
    if p.returncode != 0:
        raise RuntimeError(p.stderr[-2000:])
    return (after.children_user - before.children_user) + (after.children_system
                                                           - before.children_system)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--extra", default="rtol = 1e-4\natol = 1e-4")
    ap.add_argument("--child", nargs=2, metavar=("CASE", "OUT"))
    a = ap.parse_args()
    if a.child:
        child(*a.child)
        return
    sys.path.insert(0, str(HERE))
    import ringing

    folder = Path(tempfile.mkdtemp(prefix="floor-"))
    case = folder / "pend.toml"
    case.write_text(ringing.pendulum_case(a.extra.replace("\\n", "\n")))
    py = sys.executable
    md = (f"import sys; sys.path.insert(0, {str(HERE)!r}); import moordyn_compare as m; "
          "m.pendulum(10, 0.01)")
    runs = {
        "catdae run (the product)": [py, "-m", "catdae", "run", str(case), "-o",
                                     str(folder / "cli.nc")],
        "catdae's solvers, no xarray (this script's child)": [
            py, __file__, "--child", str(case), str(folder / "floor.nc")],
        "imports of catdae run": [py, "-c", "import catdae.cli, catdae.analysis, "
                                  "catdae.solvers.transient"],
        "imports without xarray": [py, "-c", "import catdae.case, catdae.model.assembly, "
                                   "catdae.solvers.static, catdae.solvers.transient, netCDF4"],
        "numpy + numba imported": [py, "-c", "import numpy, numba"],
        "MoorDyn's driver, 10 segments (its test file)": [py, "-c", md],
    }
    cpu = {k: [] for k in runs}
    for _ in range(a.repeats):
        for k, cmd in runs.items():
            cpu[k].append(cpu_of(cmd))
    print(f"pendulum, {a.extra!r}; CPU s of whole processes, median of {a.repeats} "
          f"(min-max); load {os.getloadavg()[0]:.2f} at the end\n")
    print("| process | CPU s |\n|---|---|")
    for k, v in cpu.items():
        print(f"| {k} | {statistics.median(v):.2f} ({min(v):.2f}-{max(v):.2f}) |")


if __name__ == "__main__":
    main()
