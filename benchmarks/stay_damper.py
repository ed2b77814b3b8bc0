"""The stay designer's question (issue 22): the damping a viscous damper near the anchor adds
to a stay's first mode, against its coefficient; and how the cable's sag reduces it.

Run apart from the test suite:  python benchmarks/stay_damper.py

1. The universal damping curve. A taut level stay (span 100 m, m = 1 kg/m, EA = 1e7 N,
   H ≈ 1e5 N: λ² ≈ 0.01, 100 elements) with a transverse (out-of-plane) damper at a/L = 0.02
   and 0.05: the first mode's damping ratio ζ / (a/L) against c / c_opt, c_opt = √(Hm)/(π a/L),
   from catdae's damped modes, beside the exact taut string with a dashpot (the root of
   coth(γa) + coth(γ(L - a)) + c/√(Hm) = 0, tests/reference.py) and the asymptotic curve
   κ/(1 + κ²), κ = c/c_opt (docs/theory.md §16).
2. Sag. The same stay with EA = 1e9 N and lower tensions (λ² from 0.1 to 80), an in-plane
   (vertical) damper at a/L = 0.02 on the first symmetric in-plane mode: the largest damping
   ratio over c and the coefficient that gives it, against the estimate from the frequency
   shift when the damper point is locked, R = 1 - 3 (λ²/ω̄) dω̄/dλ² on Irvine's frequency
   equation (docs/theory.md §16).

Results go to benchmarks/stay_damper.md and the figure benchmarks/stay_damper.png.
"""

from __future__ import annotations

import dataclasses
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
from catdae.case import case_from_dict  # noqa: E402
from catdae.model.assembly import Model  # noqa: E402
from catdae.model.mesh import build_mesh  # noqa: E402
from catdae.solvers.damped_modes import solve_damped  # noqa: E402
from catdae.solvers.modal import classify  # noqa: E402
from catdae.solvers.static import solve_static  # noqa: E402

from reference import damper_sag_reduction, string_with_damper  # noqa: E402

SPAN, MASS, G = 100.0, 1.0, 9.81


def scene(length: float, EA: float, k: int, elements: int, ground=(0.0, 0.0, 0.0)) -> str:
    return f"""[materials]
m = {{ EA = {EA!r}, mass = {MASS!r} }}
[nodes]
A = [0.0, 0.0, 0.0]
B = [{SPAN!r}, 0.0, 0.0]
G = [{ground[0]!r}, {ground[1]!r}, {ground[2]!r}]
[supports]
A = "pinned"
B = "pinned"
G = "pinned"
[[cables]]
name = "c"
ends = ["A", "B"]
material = "m"
length = {length!r}
elements = {elements}
[[dampers]]
name = "d"
ends = ["c.{k}", "G"]
coefficient = 1.0
"""


def stay(length: float, EA: float, a_over_l: float, direction: str, elements: int = 100):
    """(model, static solution, H, m per metre of span, λ²) with the damper beside c.k."""
    k = int(round(a_over_l * elements))
    case = case_from_dict(tomllib.loads(scene(length, EA, k, elements)))
    mesh = build_mesh(case)
    x = mesh.X0[mesh.node_index(f"c.{k}")]
    offset = {"y": np.array([0.0, 2.0, 0.0]), "z": np.array([0.0, 0.0, -2.0])}[direction]
    case = dataclasses.replace(case, nodes={**case.nodes, "G": tuple(float(v) for v in
                                                                      x + offset)})
    mesh = build_mesh(case)
    model = Model(case, mesh, set(), kind="modal")
    sol = solve_static(model, mesh.X0)
    H = float(np.hypot(*sol.state.h[0, :2]))
    m = MASS * length / SPAN
    le = length  # shallow: the cable's length for the elastic term of λ²
    lam2 = (MASS * length * G / H) ** 2 * SPAN / (H * le / EA)
    return model, sol, H, m, lam2


def first_mode(model, sol, c: float, plane: str):
    model.connectors = dataclasses.replace(model.connectors, coefficient=np.array([c]))
    modes, shapes = solve_damped(model, sol.X, sol.state, 6, None)
    planes, sym = classify(model, sol.X, shapes.real)
    i = next(j for j in range(len(planes)) if planes[j] == plane and sym[j] == "symmetric")
    return float(modes.damping_ratio[i])


def length_for(H: float, EA: float) -> float:
    """Unstrained length of the level cable with horizontal tension H (parabolic, shallow)."""
    w = MASS * G
    d = w * SPAN**2 / (8 * H)
    arc = SPAN * (1 + 8 / 3 * (d / SPAN) ** 2)
    return arc / (1 + H / EA)


def main() -> None:
    wall0, cpu0 = time.perf_counter(), time.process_time()
    load = os.getloadavg()
    rows1 = []
    curves = {}
    ratios = np.geomspace(0.1, 10.0, 25)
    for a in (0.02, 0.05):
        model, sol, H, m, lam2 = stay(99.02, 1e7, a, "y")
        c_opt = np.sqrt(H * m) / (np.pi * a)
        z = np.array([first_mode(model, sol, r * c_opt, "out-of-plane") for r in ratios])
        exact = np.array([(lambda g: -g.real / abs(g))(string_with_damper(a, r / (np.pi * a)))
                          for r in ratios])
        curves[a] = (z, exact)
        for r, zc, ze in zip(ratios[::4], z[::4], exact[::4], strict=True):
            rows1.append(f"| {a} | {lam2:.3f} | {r:.3g} | {zc / a:.5f} | {ze / a:.5f} | "
                         f"{r / (1 + r * r):.5f} | {100 * (zc / ze - 1):+.3f} |")
    rows2 = []
    sag = {}
    a = 0.02
    fine = np.geomspace(0.1, 10.0, 41)
    for H in (2.0e5, 1.0e5, 6.0e4, 4.5e4, 3.5e4, 2.9e4, 2.5e4, 2.2e4):
        model, sol, H_, m, lam2 = stay(length_for(H, 1e9), 1e9, a, "z")
        c_opt = np.sqrt(H_ * m) / (np.pi * a)
        z = np.array([first_mode(model, sol, r * c_opt, "in-plane") for r in fine])
        k = int(np.argmax(z))
        R = damper_sag_reduction(lam2)
        sag[lam2] = z / a
        rows2.append(f"| {H_:.4g} | {lam2:.3g} | {z[k] / (0.5 * a):.4f} | {R:.4f} | "
                     f"{fine[k]:.3g} |")
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    k = np.geomspace(0.1, 10.0, 200)
    ax1.semilogx(k, k / (1 + k * k), "k-", lw=0.8, label="asymptotic κ/(1+κ²)")
    for a_, mark in ((0.02, "o"), (0.05, "s")):
        z, exact = curves[a_]
        ax1.semilogx(ratios, exact / a_, "-", lw=1.2, label=f"exact string, a/L = {a_}")
        ax1.semilogx(ratios, z / a_, mark, mfc="none", label=f"catdae, a/L = {a_}")
    ax1.set_xlabel("c / c_opt")
    ax1.set_ylabel("ζ₁ / (a/L)")
    ax1.set_title("Universal damping curve (taut stay, λ² = 0.01)")
    ax1.legend(fontsize=8)
    for lam2, zz in sag.items():
        ax2.semilogx(fine, zz, "-", label=f"λ² = {lam2:.3g}")
    ax2.set_xlabel("c / c_opt (taut-string c_opt)")
    ax2.set_ylabel("ζ₁ / (a/L), first symmetric in-plane mode")
    ax2.set_title("Sag reduces the damping (a/L = 0.02)")
    ax2.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(HERE / "stay_damper.png", dpi=110)

    machine = f"{platform.machine()} {platform.processor() or ''}, {os.cpu_count()} cores"
    text = f"""# Stay damper: the universal curve and the effect of sag

Made by `python benchmarks/stay_damper.py` on {_dt.date.today()} ({machine}, Python
{platform.python_version()}; load average at the start {load[0]:.2f}; {wall:.1f} s wall,
{cpu:.1f} s CPU). Figure: `benchmarks/stay_damper.png`.

## 1. The universal curve (out-of-plane damper, taut stay)

Span 100 m, m = 1 kg/m, EA = 1e7 N, unstrained length 99.02 m (H ≈ 9.9e4 N), 100
elements; the damper from mesh node c.2 or c.5 to a fixed node 2 m aside (along y). The first
(out-of-plane symmetric) mode's damping ratio from catdae's damped modes, beside the exact taut
string with a dashpot and the asymptotic κ/(1 + κ²) (κ = c/c_opt, c_opt = √(Hm)/(π a/L)).

| a/L | λ² | c/c_opt | catdae ζ/(a/L) | exact ζ/(a/L) | κ/(1+κ²) | catdae vs exact % |
|---|---|---|---|---|---|---|
""" + "\n".join(rows1) + """

## 2. Sag (in-plane damper at a/L = 0.02, EA = 1e9 N)

The largest damping ratio over c/c_opt (41 points from 0.1 to 10), as a fraction of the taut
string's ½ a/L, against R = 1 - 3 (λ²/ω̄) dω̄/dλ², the relative frequency shift of Irvine's
first symmetric in-plane mode when the damper point is locked, divided by that of a string
(docs/theory.md §16); and where the maximum lies.

| H (N) | λ² | catdae ζ_max / (½ a/L) | R (locked-point estimate) | c/c_opt at the maximum |
|---|---|---|---|---|
""" + "\n".join(rows2) + "\n"
    (HERE / "stay_damper.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
