"""Does a transient step's energy balance close? (docs/theory.md §13.6)

Without damping the semi-discrete equations conserve the total energy plus the work done on
the line from outside (the fluid's, §13.5, and the moving supports'); damping, drag, seabed
friction and the BDF's own dissipation only take energy out. A run that *gains* energy beyond
that balance is not following its equations (in the cases seen: an axial ringing that the error
test resolves and nothing damps, fed by the integration error) and its tensions are not to be
trusted. ``energy_gain`` measures the gain at the output times; ``note`` of
catdae/solvers/record.py reports it.
"""

from __future__ import annotations

import numpy as np

GAIN_LIMIT = 1e-2  # of the energy moved, or 10 rtol if that is larger
LOSS_LIMIT = 0.1  # of the energy moved, lost where nothing dissipates: worth a word
JUMP_LIMIT = 1e-3  # m/s: a larger support velocity jump does impulsive work the outputs miss


def support_work(model, times: np.ndarray, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Work of the moving supports on the line, J, at the output times, and how far it may be
    off: the trapezoidal rule on R · v_s (R the supports' forces on the line at the outputs,
    v_s their prescribed velocity; zero where no support moves), and the cumulated half
    difference of the two rectangle rules (left, right), |ΔP| Δt / 2 per interval. The
    outputs sample the power only at their times: a snap's tension spike at a moving support
    between two outputs is work they cannot see (a rope heaved into a snap: a 15 J "gain" at
    outputs 5 ms apart, none at 0.5 ms)."""
    W = np.zeros(times.size)
    U = np.zeros(times.size)
    if not model.motions or times.size < 2:
        return W, U
    flat = R.reshape(times.size, -1)
    p = np.zeros(times.size)
    for dof, tf in model.motions:  # R · v_s, each moving axis with its own time function
        p += np.nan_to_num(flat[:, dof]) * np.asarray(tf.evaluate(times)[1], float)
    dt = np.diff(times)
    W[1:] = np.cumsum(0.5 * (p[1:] + p[:-1]) * dt)
    U[1:] = np.cumsum(0.5 * np.abs(np.diff(p)) * dt)
    return W, U


def _balance(model, prob, rec, n_valid: int):
    """(output times, the energy's change less the work done on the line, J, the allowance
    for the supports' work between outputs, J, the energy moved, J), or None when the balance
    cannot be closed at the outputs (loads that vary in time, support velocity jumps, fewer
    than two outputs)."""
    if n_valid < 2 or rec is None:
        return None
    ld = model.loading
    if ld.node_timed or ld.internal_timed:
        return None  # their work is not recorded
    if any(j[1] > JUMP_LIMIT for j in getattr(prob, "velocity_jumps", [])):
        return None
    t = rec.times[:n_valid]
    E = rec.E[:n_valid].sum(axis=1)
    if not np.all(np.isfinite(E)):
        return None
    dE = E - E[0]
    W = rec.W[:n_valid] if rec.work is not None else np.zeros(n_valid)
    W = np.nan_to_num(W)
    Ws, Us = support_work(model, t, rec.R[:n_valid])
    # the energy moved in or out, and the largest kinetic and strain energies: the scale of
    # the state's own energy, whose integration error is of order rtol of it
    moved = float(np.abs(dE).max() + np.abs(W).max() + np.abs(Ws).max()
                  + np.abs(rec.E[:n_valid, 0]).max() + np.abs(rec.E[:n_valid, 1]).max())
    return t, dE - W - Ws, Us, moved


def energy_gain(model, prob, rec, n_valid: int, found=False):
    """(gain J, energy moved J, first time s the gain passed the limit, its limit J), or None
    when the balance cannot be closed at the outputs (:func:`_balance`, or ``found``, its
    result when already computed) or no energy was gained beyond the limit."""
    if found is False:
        found = _balance(model, prob, rec, n_valid)
    if found is None:
        return None
    t, balance, Us, moved = found
    gap = balance - Us  # a gain the supports' work between outputs could explain is none
    limit = max(GAIN_LIMIT, 10.0 * float(prob.step.rtol)) * moved
    gain = float(gap.max())
    if not moved > 0.0 or gain <= limit:
        return None
    first = float(t[np.argmax(gap > limit)])
    return gain, moved, first, limit


def loss_note(model, prob, found) -> str:
    """A word when a scene with nothing to take energy out (no damping of any kind, no fluid,
    seabed or damper) lost more than LOSS_LIMIT of the energy moved: the BDF's own damping at
    the step's tolerances (an undamped pendulum at rtol 1e-2 lost 83 % of its energy and half
    its swing, reported "completed" with no word). ``found``: :func:`_balance`'s result."""
    cn = model.connectors
    if (prob.damping.damped or prob.axial is not None or model.fluid is not None
            or getattr(prob, "seabed", None) is not None
            or (cn is not None and np.any(cn.coefficient > 0))):
        return ""
    if found is None:
        return ""
    t, balance, Us, moved = found
    loss = -float((balance + Us).min())
    if not moved > 0.0 or loss <= LOSS_LIMIT * moved:
        return ""
    return (f"the run lost {loss:.3g} J ({loss / moved:.0%} of the {moved:.3g} J moved) with "
            "nothing in the scene to take energy out (no damping, fluid, seabed or damper): "
            "the integrator's own damping at these tolerances (rtol "
            f"{float(prob.step.rtol):g}); tighten rtol and atol where the motion's amplitude "
            "matters (docs/theory.md §13.6)")


def balance_notes(model, prob, rec, n_valid: int) -> str:
    """The notes on an energy gain and on a loss where nothing dissipates ("" when the
    balance closes or cannot be closed), from one computation of the balance."""
    found = _balance(model, prob, rec, n_valid)
    return "; ".join(n for n in (gain_note(model, prob, rec, n_valid, found),
                                 loss_note(model, prob, found)) if n)


def gain_note(model, prob, rec, n_valid: int, found=False) -> str:
    """The note on an energy gain ("" when the balance closes or cannot be closed)."""
    gained = energy_gain(model, prob, rec, n_valid, found)
    if gained is None:
        return ""
    gain, moved, first, _ = gained
    return (f"the energy balance does not close: the run gained {gain:.3g} J that no force "
            f"supplied ({gain / moved:.2g} of {moved:.3g} J, the energy that the supports "
            "and the fluid moved plus the line's largest kinetic and strain energies; past "
            f"{GAIN_LIMIT:g} of it from t = {first:.6g} s): the run is not following its "
            "equations there (in the cases seen, an element's undamped axial ringing grows) "
            "and its tensions are not reliable; add axial_damping (e.g. { ratio = 0.5 }) or "
            "tighten rtol (docs/theory.md §13.6)"
            + ("; where the line snaps taut, mass_model = \"lumped\", which carries the "
               "snap's axial wave, is the one that gets the peak tension right (an independent "
               "tester's sagging span driven into snaps: +80 % with the blended mass)"
               if model.mass_model.catenary else ""))
