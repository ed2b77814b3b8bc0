"""Issue 11, "nothing lost elsewhere": the bundled transient cases keep the accuracy the README
and the case files state, each checked against an independent reference (a closed form, or a
converged mesh computed here). The measurements behind every tolerance are in
benchmarks/nothing_lost.md (benchmarks/nothing_lost.py reproduces them).

- The gentle example 2 at its 10 elements against a fine mesh over the paper's 4 s (Fig. 9).
- The violent example 2 with a mass model that carries axial waves (the case's lumped mass, or
  the linear one): the velocity jump aπ of support A at t = 0 sends a water-hammer wave along
  the cable, a tension jump m c Δv_t (Δv_t the jump along the cable at A, c = sqrt(EA/m)), whose
  front reaches the far support B after L0 / c.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import catdae

from repo_paths import CASES  # noqa: E402

M, EA, L0, A = 5.0, 3.4e7, 15.0, 3.0  # example 2: kg/m, N, m (unstrained), support amplitude m
C = np.sqrt(EA / M)  # axial wave speed, 2 608 m/s


def _bundled(name: str, **step_changes):
    """A bundled case with its transient step changed (duration, output_interval, ...)."""
    case = catdae.load_case(CASES / name)
    steps = tuple(dataclasses.replace(s, **step_changes) if s.kind == "transient" else s
                  for s in case.steps)
    return dataclasses.replace(case, steps=steps)


# ------------------------------------------------------------------------------------------------
# The gentle example 2 (the paper's Fig. 9): 10 elements against a fine mesh over 4 s
# ------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def gentle():
    """Midspan y of the bundled case (the default mass model, rtol 1e-5) at 10 and 50 elements.

    50 elements are the converged mesh for y: 100 elements (at max_order 5, 200 s of CPU, too
    slow here) are 0.57 mm from them (0.8 % of the 68.7 mm peak) and their peaks agree to
    0.02 %. Not for z: there 50 and 100 elements at order 5 are 0.97 mm apart (6 % of the
    16.6 mm peak), the default max_order (a race of orders 2 and 5) now runs 50 elements at
    order 5 (benchmarks/speed_accuracy.md §8), and the lumped mass at 50 elements is 2 mm from
    them, so z is left to benchmarks/nothing_lost.md (10 elements' z peak: -4.55 % against 100
    at order 5)."""
    out = {}
    for n in (10, 50):
        ds = catdae.run(CASES / "example2_support_motion_gentle.toml", elements=n,
                        progress=False)["excitation"].ds
        assert ds.attrs["mass_model"] == "blended"  # the package's default (auto) picks it here
        out[n] = ds.displacement.sel(node=f"cable.{n // 2}", axis="y").values
    assert out[50].size == 401  # 4 s every 0.01 s
    return out


def test_gentle_example2_10_elements_peak_within_5_percent_of_a_fine_mesh(gentle):
    """Issue 11: the 10-element peak response within 5 % of a converged mesh's over the
    paper's 4 s (measured with the default blended mass: +1.0 % against 50 elements; with the
    consistent mass +0.64 %, and +0.65 % against 100 at order 5)."""
    peak10, peak50 = np.abs(gentle[10]).max(), np.abs(gentle[50]).max()
    assert peak10 == pytest.approx(peak50, rel=0.05)


def test_gentle_example2_10_elements_history_within_5_percent_of_the_peak(gentle):
    """The stricter reading, point by point over the 4 s: with the default (blended) mass 10
    elements are within 3.1 % of the 50-element peak (measured; the consistent mass misses it:
    6.4 mm of 68.7 mm, 9.3 %, benchmarks/nothing_lost.md)."""
    assert np.abs(gentle[10] - gentle[50]).max() < 0.05 * np.abs(gentle[50]).max()


# ------------------------------------------------------------------------------------------------
# The violent example 2: the water-hammer front and tension jump
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("mass_model", ["lumped", "linear"])
def test_violent_example2_water_hammer_jump_and_front_at_the_far_end(mass_model):
    """50 elements (the paper's fine mesh), the case's tolerances and max_order = "auto":

    - the tension at A jumps by m c Δv_t = 113.7 kN, to 2 % (measured: -0.9 % lumped, -0.0 %
      linear; the mean over 0.3-1.5 ms, behind the front, about which the discrete bar rings);
    - the front (tension at B up by half the jump) reaches B at L0 / c = 5.75 ms, to 2 element
      transits l_e / c (measured: +1.1 lumped, +0.1 linear: the discrete front spreads over a
      few elements), and B feels nothing (1 % of the jump) until 4 transits before it
      (causality; measured: 0 lumped, 0.4 % linear, whose consistent bar mass sends a small
      precursor ahead of the front: 3 % at 3 transits before).
    """
    n = 50
    case = _bundled("example2_support_motion_violent.toml", duration=0.0075,
                    output_interval=1e-5)
    tree = catdae.run(case, elements=n, mass_model=mass_model, progress=False)
    reaction = tree["initial"].ds.reaction.sel(node="A").values  # on the cable, outward at A
    dvt = A * np.pi * reaction[2] / np.linalg.norm(reaction)  # A_z = a sin πt starts at aπ
    jump = M * C * dvt
    assert jump == pytest.approx(113.7e3, rel=1e-3)
    ds = tree["excitation"].ds
    t = ds.time.values
    at_a = ds.tension.sel(end="i").values[:, 0]
    at_b = ds.tension.sel(end="j").values[:, -1]
    behind = (t >= 3e-4) & (t <= 1.5e-3)
    assert at_a[behind].mean() - at_a[0] == pytest.approx(jump, rel=0.02)
    rise = at_b - at_b[0]
    arrival = t[np.flatnonzero(rise > 0.5 * jump)[0]]
    transit = L0 / n / C
    assert arrival == pytest.approx(L0 / C, abs=2 * transit)
    before = t < L0 / C - 4 * transit
    assert np.abs(rise[before]).max() < 0.01 * jump
