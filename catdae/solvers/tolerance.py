"""The error weights of a transient step (docs/theory.md §8.3, §18.5): IDA's atol vector, the
displacement atol on the positions and a velocity atol that says which motion the error test
follows (the step's ``resolve``)."""

from __future__ import annotations

import numpy as np


def resolve_mode(setting: str, carries_axial_waves: bool,
                 velocity_jump: bool = False) -> tuple[str, str]:
    """(mode, why) for a step's ``resolve``: ``"waves"`` or ``"output"`` as given; ``"auto"``
    is ``"waves"`` where the mass carries axial (snap) waves (lumped, linear: the masses chosen
    for snaps) or a support velocity jumps in the step (the water-hammer wave it sends is asked
    for; a taut element carries it with any mass), ``"output"`` otherwise."""
    if setting != "auto":
        return setting, "set by the step"
    if carries_axial_waves:
        return "waves", "auto: waves (the mass model carries axial waves)"
    if velocity_jump:
        return "waves", "auto: waves (a support velocity jumps: its axial wave is followed)"
    return "output", "auto: output (the mass model does not carry axial waves)"


def output_frequency(output_interval: float, omega_1: float) -> float:
    """ω_out (rad/s): the highest frequency the output times can show, π / output interval
    (their Nyquist frequency), and at least the lowest mode's ω₁."""
    return max(np.pi / output_interval, omega_1)


FLOOR = 1e-8  # m: the displacement at ω_out below which velocity errors are not tested (the
#               default atol; a tighter atol lowers it, and so does an rtol below RTOL_REF)
RTOL_REF = 1e-6  # the default rtol: a tighter rtol lowers the floor in proportion


def error_weights(mode: str, atol: float, omega_1: float, output_interval: float,
                  n: int, rtol: float = RTOL_REF) -> tuple[np.ndarray, float]:
    """IDA's atol vector for y = (q₀, v₀, q₁, v₁, ...) of ``n`` free dofs, and the frequency ω
    with velocity atol = atol ω. ``"waves"``: ω = ω₁, the lowest mode's, the former rule: every
    faster mode, the axial ones included, is followed to its velocity. ``"output"``: the larger
    of atol ω₁ and min(atol, ``FLOOR``) ω_out, ω_out the highest frequency the output times can
    show: a velocity error smaller than that of a ``FLOOR`` displacement at ω_out (10 nm at the
    default atol) is not tested. Content faster than ω_out (the axial ringing of a stiff line
    after a release) is still held to that displacement, but its velocity is no longer followed
    to 1e-12 m, and BDF's own dissipation removes it; where atol ω₁ is the larger (a loose atol
    or a short output interval against a fast lowest mode) nothing changes. An ``rtol`` below
    the default lowers the floor in proportion (FLOOR rtol / RTOL_REF): a tighter rtol asks for
    more of what the outputs cannot show too, so a study over rtol sees the error that content
    leaves in a peak tension (an independent tester's taut wire under a sudden load, 80
    elements: its peak 0.6 % high at order 2 from rtol 1e-6 to 1e-8, unmoved, a study
    "converged" there); at the default rtol and looser nothing changes."""
    velocity = atol * omega_1
    if mode != "waves":
        floor = min(atol, FLOOR * min(1.0, rtol / RTOL_REF))
        velocity = max(velocity, floor * output_frequency(output_interval, omega_1))
    weights = np.empty(2 * n)
    weights[0::2] = atol
    weights[1::2] = velocity
    return weights, velocity / atol
