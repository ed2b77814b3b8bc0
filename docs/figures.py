"""Render the paper's Table 2, Fig. 7 and Fig. 9 with catdae into docs/figures/.

    python docs/figures.py [OUTDIR]          (default: the folder figures/ beside this file)

Everything comes from the public interface, ``catdae.load_case`` and ``catdae.run`` on the case
files in ``cases/``; the paper's own numbers are typed in below from its Table 2. The test
``tests/scenes/test_figures.py`` runs :func:`render` and checks the numbers it returns against the
paper, so that ``python -m pytest`` rebuilds the figures every time the suite runs.

- ``table2.png``: natural frequencies of example 1 (in-plane symmetric modes 1-5): catdae at the
  paper's 14 elements and at 112 (converged), beside the experiment, the paper's element and
  ABAQUS beams.
- ``fig7.png``: example 1, midspan vertical displacement over the paper's 4 s after the 100 kg
  mass is released (the case file's mesh, 36 elements), and its spectrum with the frequencies
  of Table 2.
- ``fig9.png``: example 2, gentle scene (a = 0.03 m), midspan displacement in y and z over the
  paper's 4 s at 10 and 50 elements (consistent mass, the paper's formulation).

PNGs are written without a timestamp, so that rerunning on the same numbers leaves the files
unchanged.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import catdae  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"
OUT = Path(__file__).resolve().parent / "figures"

# the paper's Table 2 (Hz), in-plane symmetric modes 1-5
EXPERIMENT = (1.51, 4.41, 7.43, 10.61, 13.96)
PAPER = (1.51, 4.39, 7.37, 10.50, 13.72)
ABAQUS = (1.56, 4.30, 7.03, 9.96, 13.09)
FINE = 112  # elements of the converged mesh for Table 2
PAPER_ELEMENTS = 14  # the paper's mesh for Table 2 (the case file itself has a finer one)


def _save(fig, path: Path) -> None:
    fig.savefig(path, dpi=110, metadata={"Software": None})  # no version stamp: stable bytes
    plt.close(fig)


def _symmetric_in_plane(ds) -> np.ndarray:
    """Frequencies (Hz) of the in-plane symmetric modes of a modal result, lowest first."""
    sel = (ds.plane == "in-plane") & (ds.symmetry == "symmetric")
    return ds.frequency.values[sel.values]


def example1(out: Path) -> dict:
    """Table 2 and Fig. 7; returns the numbers drawn."""
    case = catdae.load_case(CASES / "example1_free_vibration.toml")
    # the paper's mass (consistent) for Table 2's modes; the release keeps the case's own
    rest, modes = case.steps[2], dataclasses.replace(case.steps[3], mass_model="consistent")
    case = dataclasses.replace(case, steps=(*case.steps[:3], modes))
    tree = catdae.run(case, progress=False)  # static with the mass, release (4 s), at rest, modes
    n_case = case.cables[0].elements
    f_case = _symmetric_in_plane(tree["modes"].ds)[:5]
    # the paper's 14 elements and the converged mesh: modes about the unloaded static state only
    # (no release); the case file's own mesh is finer than the paper's (for its transient)
    rest, modes = case.steps[2], case.steps[3]
    modal_case = dataclasses.replace(case, steps=(dataclasses.replace(rest, remove=("hung",)),
                                                  modes))
    f14 = _symmetric_in_plane(catdae.run(modal_case, elements=PAPER_ELEMENTS, progress=False)
                              ["modes"].ds)[:5]
    f_fine = _symmetric_in_plane(catdae.run(modal_case, elements=FINE, progress=False)
                                 ["modes"].ds)[:5]

    # --- Table 2
    k = np.arange(1, 6)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 3.8))
    rows = [("experiment (Koh 2007)", EXPERIMENT, "ks", "none"),
            ("paper's element, 14", PAPER, "o", "none"),
            ("ABAQUS B21H beams", ABAQUS, "^", "none"),
            ("catdae, 14 elements", f14, "x", None),
            (f"catdae, {FINE} elements", f_fine, "+", None)]
    for label, f, style, face in rows:
        kw = {"mfc": face} if face else {}
        a1.plot(k, f, style, label=label, ms=7, **kw)
        a2.plot(k, 100 * (np.asarray(f) / np.asarray(EXPERIMENT) - 1), style + "-", lw=0.8,
                label=label, ms=7, **kw)
    a1.set_xlabel("in-plane symmetric mode")
    a1.set_ylabel("frequency (Hz)")
    a1.set_xticks(k)
    a1.legend(fontsize=8)
    a2.axhline(0.0, color="k", lw=0.5)
    a2.set_xlabel("in-plane symmetric mode")
    a2.set_ylabel("difference from the experiment (%)")
    a2.set_xticks(k)
    fig.suptitle("Example 1, Table 2: natural frequencies (span 44.335 m)")
    fig.tight_layout()
    _save(fig, out / "table2.png")

    # --- Fig. 7
    rel = tree["release"].ds
    mid = f"main.{case.cables[0].elements // 2}"
    z = rel.displacement.sel(node=mid, axis="z")
    t = rel.time.values - rel.time.values[0]
    zz = z.values - z.values.mean()
    spec = np.abs(np.fft.rfft(zz * np.hanning(zz.size)))
    freq = np.fft.rfftfreq(zz.size, t[1] - t[0])
    peak = float(freq[np.argmax(spec * (freq > 0.5))])
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6.5))
    a1.plot(t, 1e3 * z.values, lw=0.9)
    a1.set_xlabel("time after the release (s)")
    a1.set_ylabel(f"midspan ({mid}) vertical\ndisplacement (mm)")
    a1.set_title("Example 1, Fig. 7: free vibration after the 100 kg mass is released "
                 f"({n_case} elements)")
    a2.semilogy(freq, spec / spec.max(), lw=0.9, label="spectrum of the record above")
    for j, f in enumerate(EXPERIMENT):
        a2.axvline(f, color="k", lw=0.6, ls=":", label="experiment, Table 2" if j == 0 else None)
    for j, f in enumerate(f_case):
        a2.axvline(f, color="C1", lw=0.6, ls="--",
                   label=f"catdae modes, {n_case} elements" if j == 0 else None)
    a2.set_xlim(0, 16)
    a2.set_ylim(1e-5, 2.0)
    a2.set_xlabel("frequency (Hz)")
    a2.set_ylabel("normalised amplitude")
    a2.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    _save(fig, out / "fig7.png")
    return {"f14": f14, "f_fine": f_fine, "f_case": f_case, "case_elements": n_case,
            "fig7_peak": peak, "fig7_resolution": 1.0 / t[-1],
            "fig7_range_mm": (1e3 * float(z.min()), 1e3 * float(z.max()))}


def _gentle(elements: int):
    case = catdae.load_case(CASES / "example2_support_motion_gentle.toml")
    ds = catdae.run(case, elements=elements, mass_model="consistent",
                    progress=False)["excitation"].ds
    return ds, ds.displacement.sel(node=f"cable.{elements // 2}")


def example2(out: Path) -> dict:
    """Fig. 9 (gentle scene, 10 and 50 elements, 4 s); returns the numbers drawn."""
    runs = {n: _gentle(n) for n in (10, 50)}
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), sharex=True)
    for ax, axis in zip(axes, ("y", "z"), strict=True):
        for (n, (ds, mid)), style in zip(runs.items(), ("-", "--"), strict=True):
            ax.plot(ds.time, 1e3 * mid.sel(axis=axis), style, label=f"{n} elements")
        ax.set_xlabel("time (s)")
        ax.set_ylabel(f"midspan {axis} displacement (mm)")
    axes[0].legend()
    fig.suptitle("Example 2, Fig. 9: support excitation, a = 0.03 m (consistent mass)")
    fig.tight_layout()
    _save(fig, out / "fig9.png")
    (d10, m10), (d50, m50) = runs[10], runs[50]
    y10, y50 = (m.sel(axis=["y", "z"]).values for m in (m10, m50))
    return {"fig9_duration": float(d50.time[-1] - d50.time[0]),
            "fig9_peak50": np.abs(y50).max(axis=0),
            "fig9_difference": np.abs(y10 - y50).max(axis=0),
            "fig9_steps": (int(d10.attrs["n_steps"]), int(d50.attrs["n_steps"]))}


def render(out: Path = OUT) -> dict:
    """Write table2.png, fig7.png and fig9.png into ``out``; return the numbers they show."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    return {**example1(out), **example2(out)}


def main(argv: list[str]) -> None:
    numbers = render(Path(argv[0]) if argv else OUT)
    print("Table 2 (Hz)   mode:    1       2       3       4       5")
    for label, f in (("experiment", EXPERIMENT), ("paper, 14", PAPER), ("ABAQUS", ABAQUS),
                     ("catdae, 14", numbers["f14"]), (f"catdae, {FINE}", numbers["f_fine"])):
        print(f"{label:>20s} " + " ".join(f"{x:7.3f}" for x in f))
    print(f"Fig. 7: spectral peak {numbers['fig7_peak']:.3f} Hz "
          f"(resolution {numbers['fig7_resolution']:.3f} Hz), midspan range "
          f"{numbers['fig7_range_mm'][0]:.2f} .. {numbers['fig7_range_mm'][1]:.2f} mm")
    print(f"Fig. 9 ({numbers['fig9_duration']:g} s): peak at 50 elements y, z = "
          f"{numbers['fig9_peak50'][0]:.4f}, {numbers['fig9_peak50'][1]:.4f} m; "
          f"|10 - 50 elements| = {numbers['fig9_difference'][0]:.4f}, "
          f"{numbers['fig9_difference'][1]:.4f} m; IDA steps {numbers['fig9_steps']}")


if __name__ == "__main__":
    main(sys.argv[1:])
