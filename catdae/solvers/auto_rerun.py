"""A transient whose ``mass_model = "auto"`` kept a catenary mass and that then pulled a
sagging line taut, or whose energy balance did not close, is run again with the lumped mass
(docs/theory.md §18.5).

``auto`` decides from the state a step starts in (catdae.model.snap): a start out of balance or
a support velocity jump on elements that can go slack. A smooth drive that makes a sagging line
go slack and snap taut in the middle of the step cannot be seen from its start, and the blended
mass does not carry the snaps' axial waves (an independent tester's sagging span driven into
snaps: peak tension +62 % at rtol 1e-4, +80 % and a 70 J energy gain at rtol 1e-6). Two signs
are read: an element whose tension rose from a sag-dominated state (λ² > 1 at the start) past
the tension where its λ² is 1 (λ² ∝ T⁻³ at a given load and length, so T ≥ T₀ (λ²₀)^⅓ =
(w⊥ l)^⅔ EA^⅓: its sag was pulled out and it took the chord change by stretch) and to at least
twice its start (an element just above λ² = 1 crosses it at a small rise), watched in the
tension envelope, which stops the run there; an element that went nearly slack (or into
compression) and snapped taut (``record.slack_where``: a taut line heaved into a snap, +47 % on
the peak with the blended mass), watched too; and, at the end, an energy gain
(``energy_check.energy_gain``). The envelope is looked at every ``WATCH_EVERY`` steps (it keeps
the extremes in between): a few µs per look. The step is then run again from the same start
with the lumped mass, which carries the waves, and its ``mass_model_choice`` says why. A step
whose mass was set by hand is never run twice."""

from __future__ import annotations

import numpy as np

from catdae.errors import SolverError
from catdae.model.assembly import Model
from catdae.solvers.energy_check import energy_gain
from catdae.solvers.record import slack_snapped, slack_where
from catdae.solvers.transient import run_transient

PULLED = "pulled taut"  # the status of a first run that the watch stopped
RISE = 2.0  # a tension that rose less than this many times its start is no snap (an element
#             just above λ² = 1 at the start passes λ² = 1 at a 1.2 times higher tension)
WATCH_EVERY = 8  # steps between two looks at the envelope (it keeps the extremes between)


def run_transient_auto(step, model: Model, state, writer, progress):
    """``run_transient``, and again with the lumped mass where ``auto`` kept a catenary mass
    and the run pulled sagging elements taut or gained energy (module docstring). The first run
    is stopped as soon as an element is pulled taut or snaps after slack (the envelope watched).
    ``state`` is left as the run that is kept leaves it."""
    mm = model.mass_model
    if not (mm.setting == "auto" and mm.catenary):
        return run_transient(step, model, state, writer, progress)
    start = (state.X.copy(), state.V.copy(), None if state.h is None else state.h.copy(),
             state.t)
    start_state = model.element_state(state.X, state.h)
    lam2 = model.element_lambda2(start_state, state.X)
    start_t = model.tensions(start_state)  # (n_elem, 2), as the record's first output
    t0 = start_t.min(axis=1)
    taut_at = np.maximum(t0 * np.cbrt(lam2), RISE * t0)  # where λ² = 1, and risen RISE times
    watched = np.flatnonzero((lam2 > 1.0) & np.isfinite(taut_at))
    calls = [0]

    def watch(envelope, t: float) -> str:
        """Why the run must stop at t ("" to go on); judged every WATCH_EVERY steps."""
        calls[0] += 1
        if calls[0] % WATCH_EVERY:
            return ""
        lo, hi = envelope.t_min, envelope.t_max
        if watched.size and (hi[watched].max(axis=1) >= taut_at[watched]).any():
            return f"{PULLED} at t = {t:.6g} s"
        snapped = slack_snapped(lo, hi, start_t).any()
        return f"{PULLED} after slack at t = {t:.6g} s" if snapped else ""
    try:
        rec = run_transient(step, model, state, writer, progress, watch)
    except SolverError as exc:
        if not (exc.termination or "").startswith(PULLED) or exc.partial is None:
            raise
        rec = exc.partial
    why = _why(model, rec, lam2, taut_at)
    if not why:
        return rec
    why = f"{why} (its {rec.attrs.get('n_steps', '?')} steps discarded)"
    first = {k: rec.attrs.get(k, 0) for k in ("n_steps", "wall_time")}
    state.X, state.V, state.h, state.t = start
    lumped = Model(model.case, model.mesh, model.absent, mass_model="auto", kind=step.kind,
                   snap=why, rerun=True)
    rec = run_transient(step, lumped, state, writer, progress)
    rec.attrs.update(n_steps_discarded=first["n_steps"], wall_time_discarded=first["wall_time"])
    state.snap = step.name  # a transient that continues it keeps the lumped mass
    return rec


def _why(model: Model, rec, lam2: np.ndarray, taut_at: np.ndarray) -> str:
    """Why a run with a catenary mass is not kept ("" if it is): elements pulled from sag to
    stretch (λ² > 1 at the start, tension past ``taut_at``), or an energy gain."""
    t_max = np.nan_to_num(np.nanmax(rec.envelope.t_max, axis=1), nan=0.0)
    pulled = (lam2 > 1.0) & np.isfinite(taut_at) & (t_max >= taut_at)
    mm = model.mass_model.name
    if pulled.any():
        e = int(np.argmax(np.where(pulled, t_max / np.maximum(taut_at, 1e-300), 0.0)))
        when = rec.envelope.time_max[e][np.nanargmax(rec.envelope.t_max[e])]
        return (f"a first run with the {mm} mass pulled sagging elements taut (element "
                f"{model.mesh.element_names[e]}: λ² {lam2[e]:.3g} at the start, tension "
                f"{t_max[e]:.4g} N at t = {when:.6g} s, past {taut_at[e]:.4g} N, where λ² is 1 "
                f"and at least {RISE:g} times its start): a sagging line pulled taut takes "
                "chord changes by stretch, whose axial waves the catenary mass does not "
                "carry")
    slack = slack_where(model, rec, rec.n_valid)
    if slack:  # a taut line that went slack (or into compression) and snapped taut
        return f"in a first run with the {mm} mass, {slack}"
    found = energy_gain(model, rec.prob, rec, rec.n_valid)
    if found is None:
        return ""
    gain, moved, first, _ = found
    return (f"a first run with the {mm} mass gained {gain:.3g} J that no force supplied "
            f"({gain / moved:.2g} of the energy moved, from t = {first:.6g} s): in the cases "
            "seen, a snap or an axial ringing that the catenary mass pumps up")
