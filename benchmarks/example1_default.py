"""The default `catdae run` (example 1, issue 11): CPU time of its transient step and the error
of its midspan history against a converged reference.

Target (issue 11): the 'release' step under 3 s CPU warm, with the midspan vertical position
within 1 mm (max over the 4 s, output every 0.01 s) of a converged reference.

- Case: the bundled default case as shipped (``catdae/data/example1_free_vibration.toml``), with
  its static step 'hanging' and its transient step 'release' (the later static and modal steps
  do not take part in the transient and are left out).
- CPU: ``time.process_time`` around the 'release' step alone (from the end of 'hanging' to the
  end of 'release', by ``on_group``), after one warm-up run that loads the numba cache; best
  and median of ``--repeats`` runs. ``OMP_NUM_THREADS=1`` is set.
- Reference: the same case at ``--ref-elements`` (224) elements, blended mass, BDF order 5,
  rtol 1e-7, atol 1e-9 m. Its own accuracy is stated by the differences from the same
  tolerances at half the elements (mesh) and from rtol 1e-8 at half the elements (time).
  Reference arrays are cached in ``--cache`` (an .npz, keyed by elements and tolerances
  only: delete it when the case's scene or damping changes).
- ``--table``: the error and CPU of 14, 20, 28, 36 and 42 elements at the previous settings
  (rtol 1e-4, atol 1e-6, max_order "auto") and at the shipped ones.

    python benchmarks/example1_default.py --table --out benchmarks/example1_default.md
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import catdae  # noqa: E402
from catdae.cli import default_case_path  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from transient_speed import machine  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def release_case(elements=None, **release):
    """The shipped case with its 'hanging' and 'release' steps only; ``elements`` and the
    release step's fields (rtol, atol, max_order, mass_model) replaced where given."""
    case = catdae.load_case(default_case_path())
    cable = case.cables[0]
    if elements is not None:
        if elements % 2:
            raise ValueError("an even element count keeps the mass (at midspan) on a node")
        cable = dataclasses.replace(cable, elements=elements)
    hang = next(s for s in case.steps if s.name == "hanging")
    rel = dataclasses.replace(next(s for s in case.steps if s.name == "release"), **release)
    return dataclasses.replace(case, cables=(cable,), steps=(hang, rel))


def run_release(case):
    """(t, midspan z, CPU s of the release step, its dataset)."""
    marks = {}

    def on_group(name, ds):
        marks[name] = time.process_time()

    tree = catdae.run(case, progress=False, on_group=on_group)
    ds = tree["release"].ds
    n = case.cables[0].elements
    z = ds.position.sel(node=f"{case.cables[0].name}.{n // 2}", axis="z").values
    return ds.time.values, z, marks["release"] - marks["hanging"], ds


def reference(cache: Path, elements: int, rtol: float, atol: float):
    """Midspan z of a converged run (blended, order 5), cached in ``cache``."""
    key = f"ref_{elements}_{rtol:g}_{atol:g}"
    store = dict(np.load(cache)) if cache.exists() else {}
    if key not in store:
        case = release_case(elements, rtol=rtol, atol=atol, max_order=5, mass_model="blended")
        c0 = time.process_time()
        _, z, _, ds = run_release(case)
        print(f"  reference {key}: {ds.attrs['n_steps']} steps, "
              f"{time.process_time() - c0:.1f} s CPU", flush=True)
        store[key] = z
        cache.parent.mkdir(parents=True, exist_ok=True)
        np.savez(cache, **store)
    return store[key]


def measure(case, repeats: int):
    """Warm-up run, then ``repeats`` timed runs: (z, [CPU s], dataset)."""
    run_release(case)  # warm: the numba cache is loaded, the kernels are compiled if needed
    cpus = []
    for _ in range(repeats):
        _, z, cpu, ds = run_release(case)
        cpus.append(cpu)
    return z, cpus, ds


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--ref-elements", type=int, default=224)
    ap.add_argument("--cache", type=Path, default=ROOT / "scratch" / "example1_reference.npz")
    ap.add_argument("--table", action="store_true", help="also the table of meshes")
    ap.add_argument("--table-repeats", type=int, default=1, help="timed runs per table row")
    ap.add_argument("--out", type=Path, help="write the results as markdown here")
    args = ap.parse_args(argv)

    lines = [f"- machine: {machine()} (before the runs)"]
    ne = args.ref_elements
    print("references", flush=True)
    z_ref = reference(args.cache, ne, 1e-7, 1e-9)
    z_half = reference(args.cache, ne // 2, 1e-7, 1e-9)
    z_half_t = reference(args.cache, ne // 2, 1e-8, 1e-10)
    d_mesh = np.abs(z_half - z_ref).max()
    d_time = np.abs(z_half_t - z_half).max()
    lines.append(
        f"- reference: {ne} elements, blended mass, BDF order 5, rtol 1e-7, atol 1e-9 m. "
        f"{ne // 2} elements differ from it by {1e3 * d_mesh:.3f} mm (max over the 4 s), and "
        f"rtol 1e-8 at {ne // 2} elements from rtol 1e-7 by {1e3 * d_time:.2g} mm: the "
        "reference is good to about those (the mesh error falls by 2.5-6 per halving of the "
        "element length here)")

    shipped = release_case()
    rel = shipped.steps[1]
    z, cpus, ds = measure(shipped, args.repeats)
    err = np.abs(z - z_ref).max()
    t = ds.time.values
    lines.append(
        f"- shipped case: {shipped.cables[0].elements} elements, mass_model "
        f"{rel.mass_model!r}, rtol {rel.rtol:g}, atol {rel.atol:g}, max_order {rel.max_order!r}: "
        f"release step **{min(cpus):.2f} s CPU** (best of {len(cpus)}; median "
        f"{statistics.median(cpus):.2f} s; wall {ds.attrs['wall_time']:.2f} s last run), "
        f"{ds.attrs['n_steps']} IDA steps, {ds.attrs['n_residual_evaluations']} residuals; "
        f"midspan error **{1e3 * err:.3f} mm** at t = {t[np.argmax(np.abs(z - z_ref))]:.2f} s "
        f"(peak-to-peak of the history {1e3 * (z_ref.max() - z_ref.min()):.1f} mm)")
    print("\n".join(lines), flush=True)

    if args.table:
        rows = ["", f"| elements | settings | release CPU s (best of {args.table_repeats}) "
                "| IDA steps | midspan error mm | error in s 0-1 / 1-2 / 2-3 / 3-4 (mm) |",
                "|---:|---|---:|---:|---:|---|"]
        settings = {"rtol 1e-4, auto (before)": dict(rtol=1e-4, atol=1e-6, max_order="auto"),
                    f"rtol {rel.rtol:g}, order {rel.max_order} (shipped)":
                        dict(rtol=rel.rtol, atol=rel.atol, max_order=rel.max_order)}
        for n in (14, 20, 28, 36, 42):
            for label, kw in settings.items():
                case = release_case(n, mass_model="blended", **kw)
                zn, c, dsn = measure(case, args.table_repeats)
                e = np.abs(zn - z_ref)
                per = " / ".join(f"{1e3 * e[(t >= a) & (t < a + 1)].max():.2f}"
                                 for a in range(4))
                row = (f"| {n} | {label} | {min(c):.2f} | {dsn.attrs['n_steps']} | "
                       f"{1e3 * e.max():.3f} | {per} |")
                print(row, flush=True)
                rows.append(row)
        lines += rows
    up = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    lines.append(f"\n(uptime after the runs: {up})")
    if args.out:
        args.out.write_text("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
