"""The error weights of a transient step (docs/theory.md §8.3, §18.5): IDA's atol vector, the
displacement atol on the positions and a velocity atol that says which motion the error test
follows (the step's ``resolve``)."""

from __future__ import annotations

import numpy as np


def resolve_mode(setting: str, carries_axial_waves: bool) -> tuple[str, str]:
    """(mode, why) for a step's ``resolve``: ``"waves"`` or ``"output"`` as given; ``"auto"``
    follows the mass model: ``"waves"`` where the mass carries axial (snap) waves (lumped,
    linear: the masses chosen for snaps), ``"output"`` where it does not (blended,
    consistent)."""
    if setting != "auto":
        return setting, "set by the step"
    if carries_axial_waves:
        return "waves", "auto: waves (the mass model carries axial waves)"
    return "output", "auto: output (the mass model does not carry axial waves)"


def output_frequency(output_interval: float, omega_1: float) -> float:
    """ω_out (rad/s): the highest frequency the output times can show, π / output interval
    (their Nyquist frequency), and at least the lowest mode's ω₁."""
    return max(np.pi / output_interval, omega_1)


def error_weights(mode: str, atol: float, omega_1: float, output_interval: float,
                  n: int) -> tuple[np.ndarray, float]:
    """IDA's atol vector for y = (q₀, v₀, q₁, v₁, ...) of ``n`` free dofs, and the frequency ω
    that scales its velocity entries, atol ω: an absolute velocity error counts as the
    displacement error it makes at ω. ``"waves"``: ω = ω₁, the lowest mode's, so that every
    faster mode, the axial ones included, is followed to its velocity. ``"output"``: ω = ω_out,
    the highest frequency the output times can show; content faster than that (the axial
    ringing of a stiff cable after a release) is held to its velocity only relative to the
    motion (IDA's rtol |v|), and BDF's own dissipation removes what lies below it."""
    omega = omega_1 if mode == "waves" else output_frequency(output_interval, omega_1)
    weights = np.empty(2 * n)
    weights[0::2] = atol
    weights[1::2] = atol * omega
    return weights, omega
