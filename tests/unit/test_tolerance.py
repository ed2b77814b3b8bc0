"""catdae.solvers.tolerance: the error weights of a transient step and the ``resolve`` rule."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catdae.solvers.tolerance import FLOOR, error_weights, output_frequency, resolve_mode


def test_auto_follows_the_mass_model():
    assert resolve_mode("auto", True)[0] == "waves"  # lumped, linear: snaps asked for
    assert resolve_mode("auto", False)[0] == "output"  # blended, consistent
    assert resolve_mode("auto", False, True)[0] == "waves"  # a support velocity jump
    for mode in ("waves", "output"):
        for carries in (True, False):
            assert resolve_mode(mode, carries) == (mode, "set by the step")


def test_waves_weights_are_atol_and_atol_omega_1():
    w, omega = error_weights("waves", 1e-8, 0.3, 0.05, 4)
    assert omega == 0.3
    np.testing.assert_array_equal(w[0::2], 1e-8)
    np.testing.assert_array_equal(w[1::2], 1e-8 * 0.3)


@pytest.mark.parametrize("dt", [0.05, 0.01, 1.0])
def test_output_weights_hold_fast_content_to_the_floor_in_displacement(dt):
    """At the default atol the velocity atol is FLOOR ω_out: a component at ω >= ω_out whose
    displacement amplitude is FLOOR has velocity amplitude FLOOR ω >= the velocity atol, so
    the error test still sees it; below ω_out the displacement test governs."""
    atol, omega_1 = 1e-8, 0.31
    w, omega = error_weights("output", atol, omega_1, dt, 3)
    assert omega == pytest.approx(math.pi / dt) == output_frequency(dt, omega_1)
    np.testing.assert_array_equal(w[0::2], atol)
    for om in (omega, 2 * omega, 100 * omega):
        assert FLOOR * om >= w[1] * (1 - 1e-12)


def test_output_weights_never_looser_than_the_floor_nor_tighter_than_waves():
    """A loose atol keeps the former weight where it is the larger (nothing changes); a tight
    atol lowers the floor with it."""
    loose = error_weights("output", 1e-6, 3.8, 0.01, 2)[0][1]
    assert loose == max(1e-6 * 3.8, FLOOR * math.pi / 0.01) == 1e-6 * 3.8
    tight = error_weights("output", 1e-10, 0.31, 0.05, 2)[0][1]
    assert tight == pytest.approx(1e-10 * math.pi / 0.05)
    assert tight >= error_weights("waves", 1e-10, 0.31, 0.05, 2)[0][1]


def test_output_frequency_not_below_the_lowest_mode():
    assert output_frequency(10.0, 2.0) == 2.0  # π/10 < 2: never tighter than "waves"


def test_a_tighter_rtol_lowers_the_floor_in_proportion():
    """At rtol 1e-6 (the default) and looser the floor is as it was; below, it falls with rtol,
    so a study over rtol sees what the outputs' frequency hides (tester t73: a taut wire under
    a sudden load at 80 elements read its peak tension 0.6 % high, unmoved from rtol 1e-6 to
    1e-8; with this, -0.002 % at rtol 1e-7 against a reference at rtol 1e-8, atol 1e-10)."""
    base = error_weights("output", 1e-8, 0.31, 0.01, 2)[0][1]
    assert base == pytest.approx(FLOOR * math.pi / 0.01)
    for loose in (1e-6, 1e-4, 1e-2):
        assert error_weights("output", 1e-8, 0.31, 0.01, 2, rtol=loose)[0][1] == base
    for tight in (1e-7, 1e-8, 1e-9):
        v = error_weights("output", 1e-8, 0.31, 0.01, 2, rtol=tight)[0][1]
        assert v == pytest.approx(base * tight / 1e-6)
    # never below the former rule's atol ω₁ ("waves")
    v = error_weights("output", 1e-8, 0.31, 0.01, 2, rtol=1e-14)[0][1]
    assert v == pytest.approx(max(1e-8 * 0.31, FLOOR * 1e-8 * math.pi / 0.01))
