"""Form-finding: unstrained lengths from the tension or sag an engineer knows.

A cable may give ``form = { ... }`` instead of ``length`` (case-format.md, "Form-finding"). A
``pretension`` is a closed form, L0 = chord / (1 + T/EA), applied when the case is read. The
other targets (``horizontal_tension``, ``tension`` at an end, ``sag``) hold in the first static
step, with everything present in it: the unknown lengths L (one per such cable) solve

    r_i(L) = (q_i(X(L), h(L)) - target_i) / target_i = 0,

where (X(L), h(L)) is the static equilibrium of the whole scene with those lengths and q_i the
measured quantity of cable i (as reported in the static results: ``horizontal_tension`` at the
first end, ``cable_end_tension`` at the named end, ``sag``). Cables that interact (a net, a
shared free node) are solved together.

Method: Newton on L around the static solve, with the Jacobian ∂r/∂L by forward differences
(one warm-started static solve per form-found cable, each a few Newton iterations from the
base equilibrium), kept up to date between them by Broyden's rank-one update from each step
taken (differences again when a step leads nowhere), and a backtracking line search on |r|.
This reuses the static solver as it is (load stepping, line search, slack elements) instead of
adding the lengths to its unknowns:
an augmented system would need ∂(element forces)/∂L0 and ∂(sag)/∂X from the kernel, which it
does not provide. The cost is n static solves per Jacobian for n form-found cables, and one
or a few per iteration.

Starting lengths, and bad targets: each cable alone, hanging between its end nodes under its
own weight (at the first static step's temperature), is one exact catenary element; its q(L0)
is scanned from 50 % strain to 100 times the chord and the first crossing of the target is
refined (brentq). This is the taut solution where two exist (the end tension first falls, then
rises again as a cable gets longer). For a cable pinned at both ends with nothing on it the
scan is the exact answer, and a target it never crosses cannot be reached: a ``CaseError``
naming the cable says why (also from ``catdae check``). For other cables the scan only gives
the start; if Newton cannot reduce |r| any further the targets are reported as not reachable
together, with the values reached.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from catdae.case import AXES, Case
from catdae.case.build import MAX_STRAIN
from catdae.case.frame import gravity_rotation
from catdae.case.names import cable_of
from catdae.element.elements import SLACK, Elements
from catdae.errors import CaseError, ConvergenceError

TOL = 1e-9  # relative: |q - target| <= TOL |target|
MAX_ITER = 100  # Broyden steps are one static solve each
_UNITS = {"horizontal_tension": "N", "tension": "N", "sag": "m"}


def pending(case: Case) -> list[int]:
    """Indices of the cables whose length the first static step finds."""
    return [i for i, c in enumerate(case.cables)
            if c.form is not None and c.form.kind != "pretension"]


def first_temperature(case: Case) -> float | Mapping[str, float]:
    """The temperature change of the first step (K), where form-finding holds."""
    steps = case.steps
    change = steps[0].temperature_change if steps else None
    return 0.0 if change is None else change


def initial_lengths(case: Case) -> Case:
    """``case`` with every unknown length set to its single-cable estimate (module docstring).

    Raises ``CaseError`` when a cable pinned at both ends with nothing on it cannot reach its
    target.
    """
    todo = pending(case)
    if not todo:
        return case
    R = gravity_rotation(case.gravity_direction)
    change = first_temperature(case)
    loaded = {x.cable for x in (*case.point_masses, *case.loads) if x.cable is not None}
    loaded |= {cable_of(x.node) for x in (*case.point_masses, *case.loads)
               if x.node is not None and "." in x.node}
    loaded |= {d.cable for d in case.distributed_loads}
    problems = []
    cables = list(case.cables)
    for i in todo:
        c = cables[i]
        mat = case.material_of(c)
        dt = change.get(c.name, 0.0) if isinstance(change, Mapping) else change
        f = 1.0 + mat.thermal_expansion * dt
        a, b = (R @ np.asarray(case.nodes[e], float) for e in c.ends)
        isolated = (c.name not in loaded
                    and all(case.supports.get(e) == AXES for e in c.ends))
        length, why = _single_cable(c.form, b - a, c.ends.index(c.form.at) if c.form.at else 0,
                                    mat.EA, mat.weight, f)
        if length is None and isolated:
            problems.append((f"cables[{i}].form.{c.form.kind}",
                             f"cable {c.name!r}: {why}"))
        cables[i] = replace(c, length=float(length if length is not None
                                            else np.linalg.norm(b - a)))
    if problems:
        raise CaseError(case.path, problems)
    return replace(case, cables=tuple(cables))


def _measure_one(el: Elements, h: np.ndarray, status: np.ndarray, chord: np.ndarray,
                 kind: str, end: int) -> np.ndarray:
    """q of every element of ``el`` (each a whole cable spanning ``chord``), (n,)."""
    slack = status == SLACK
    if kind == "horizontal_tension":
        q = np.hypot(h[:, 0], h[:, 1])
    elif kind == "tension":
        q = el.end_tensions(h)[:, end]
    else:
        s = np.linspace(0.0, 1.0, 257)[None, :] * el.L0[:, None]
        p = el.position(h, s)  # (n, 257, 3)
        ch = np.hypot(chord[0], chord[1])
        q = ((p[..., :2] @ chord[:2]) / ch**2 * chord[2] - p[..., 2]).max(axis=1)
        return np.where(slack, np.nan, q)  # a slack weightless element has no shape
    return np.where(slack, 0.0, q)


def _single_cable(form, chord, end, ea, w, f) -> tuple[float | None, str]:
    """(L0, "") from the scan of one catenary element, or (None, why the target is missed)."""
    lc = float(np.linalg.norm(chord))
    kind, target = form.kind, form.value
    if kind == "sag" and np.hypot(chord[0], chord[1]) <= 1e-9 * lc:
        return None, "its chord is vertical: a sag below the chord needs a chord with a " \
                     "horizontal extent"
    if kind == "horizontal_tension" and np.hypot(chord[0], chord[1]) <= 1e-9 * lc:
        return None, "its chord is vertical: it has no horizontal tension to set"
    lo = 1.0 / (1.0 + MAX_STRAIN) * (1.0 + 1e-9)
    ratios = np.concatenate([np.linspace(lo, 1.0, 60, endpoint=False),
                             1.0 + np.geomspace(1e-8, 100.0, 120)])

    def q_of(lengths):
        lengths = np.atleast_1d(lengths) * f  # heated (catdae.model.mesh.Mesh.heated)
        el = Elements(lengths, ea * f, w / f)
        st = el.solve(np.broadcast_to(chord, (lengths.size, 3)))
        q = _measure_one(el, st.h, st.status, chord, kind, end)
        return np.where(st.converged, q, np.nan)

    q = q_of(ratios * lc)
    d = q - target
    for k in range(len(d) - 1):
        if np.isfinite(d[k]) and np.isfinite(d[k + 1]) and d[k] * d[k + 1] <= 0.0:
            if d[k] == 0.0:
                return float(ratios[k] * lc), ""
            from scipy.optimize import brentq  # lazy: 0.5-1 s to import

            length = brentq(lambda x: float(q_of(x)[0]) - target, ratios[k] * lc,
                            ratios[k + 1] * lc, xtol=1e-14 * lc, rtol=1e-14)
            return float(length), ""
    unit = _UNITS[kind]
    ok = np.isfinite(q)
    if not ok.any():
        return None, "hanging alone between its ends it has no defined shape"
    qmin, qmax = float(np.nanmin(q)), float(np.nanmax(q))
    what = {"horizontal_tension": "a horizontal tension", "sag": "a sag",
            "tension": f"a tension at end {form.at!r}"}[kind]
    if target < qmin:
        if kind == "sag":
            return None, (f"{what} of {target:g} m needs a strain above "
                          f"{MAX_STRAIN:.0%}: hanging between its ends under its own weight "
                          f"its sag is at least {qmin:.6g} m")
        k = int(np.nanargmin(q))
        # the least q lies between the samples beside the least sample: refined there, a
        # target just above it may be reached after all (on either side of the dip)
        from scipy.optimize import brentq, minimize_scalar

        ka, kb = max(k - 1, 0), min(k + 1, len(ratios) - 1)
        a, b = ratios[ka] * lc, ratios[kb] * lc
        best = minimize_scalar(lambda x: float(q_of(x)[0]), bounds=(a, b), method="bounded",
                               options={"xatol": 1e-12 * lc})
        if np.isfinite(best.fun) and best.fun <= target:
            for side, q_side in ((a, q[ka]), (b, q[kb])):  # the scan's own values there
                if q_side >= target:
                    return float(brentq(lambda x: float(q_of(x)[0]) - target, side, best.x,
                                        xtol=1e-14 * lc, rtol=1e-14)), ""
        if np.isfinite(best.fun):
            qmin, at = float(best.fun), float(best.x)
        else:
            at = ratios[k] * lc
        return None, (f"{what} of {target:.9g} {unit} cannot be reached: hanging between its "
                      f"ends under its own weight it is at least {qmin:.9g} {unit} "
                      f"(at L0 = {at:.6g} m)")
    if kind == "sag":
        return None, (f"{what} of {target:g} m is beyond what the cable can hang: even at "
                      f"{ratios[-1]:.0f} times its chord its sag is {qmax:.6g} m")
    return None, (f"{what} of {target:g} {unit} needs a strain above {MAX_STRAIN:.0%} "
                  f"(at most {qmax:.6g} {unit})")


def summary_of(case: Case, model, sol) -> dict:
    """What :func:`measure` needs of a solved trial (Model.cable_summary): the sags only of the
    cables whose target is a sag (their search along the curve was 80 % of a net's
    form-finding)."""
    sags = frozenset(i for i in pending(case) if case.cables[i].form.kind == "sag")
    return model.cable_summary(sol.X, sol.state, sag=sags if sags else False)


def measure(case: Case, summary: dict) -> np.ndarray:
    """The quantity each pending cable's form sets, from Model.cable_summary, (n_pending,)."""
    out = []
    for i in pending(case):
        c = case.cables[i]
        kind = c.form.kind
        if kind == "horizontal_tension":
            out.append(summary["horizontal_tension"][i])
        elif kind == "tension":
            out.append(summary["end_tension"][i, c.ends.index(c.form.at)])
        else:
            out.append(summary["sag"][i])
    return np.array(out, float)


def solve(case: Case, evaluate) -> tuple[Case, object]:
    """Lengths of the pending cables such that their targets hold in the first static step.

    ``evaluate(case_trial, warm)`` solves that step for a case with trial lengths
    (``warm``: a previous result to start from, or None) and returns ``(result, summary)``;
    ``result`` is handed back with the final case. Raises ``CaseError`` when the targets cannot
    be reached together, ``ConvergenceError`` when a static solve of the start fails.
    """
    idx = pending(case)
    target = np.array([case.cables[i].form.value for i in idx])
    names = [case.cables[i].name for i in idx]

    def with_lengths(L):
        cables = list(case.cables)
        for i, length in zip(idx, L, strict=True):
            cables[i] = replace(cables[i], length=float(length))
        return replace(case, cables=tuple(cables))

    def resid(L, warm):
        trial = with_lengths(L)
        result, summary = evaluate(trial, warm)
        return (measure(trial, summary) - target) / target, result

    L = np.array([case.cables[i].length for i in idx], float)
    L_min = np.array([np.linalg.norm(np.subtract(*(case.nodes[e] for e in case.cables[i].ends)))
                      for i in idx]) / (1.0 + MAX_STRAIN)
    def jacobian(L, r, base):
        J = np.empty((len(L), len(L)))
        for k in range(len(L)):
            dL = 1e-7 * L[k]
            Lp = L.copy()
            Lp[k] += dL
            try:
                rp, _ = resid(Lp, base)
            except ConvergenceError:
                Lp[k] = L[k] - dL
                rp, _ = resid(Lp, base)
                dL = -dL
            J[:, k] = (rp - r) / dL
        return J

    r, base = resid(L, None)
    J, fresh = None, False
    for _ in range(MAX_ITER):
        if np.abs(r).max() <= TOL:
            return with_lengths(L), base
        if J is None:
            J, fresh = jacobian(L, r, base), True
        step_L = np.linalg.lstsq(J, -r, rcond=None)[0]
        # at most +-50 % of a length per iteration
        big = np.abs(step_L) / (0.5 * L)
        if big.max() > 1.0:
            step_L /= big.max()
        alpha = 1.0
        for _ in range(30):
            Ln = L + alpha * step_L
            if np.all(Ln > L_min):
                try:
                    rn, res = resid(Ln, base)
                except ConvergenceError:
                    rn = None
                if rn is not None and np.all(np.isfinite(rn)) and (
                        np.linalg.norm(rn) < (1.0 - 1e-4 * alpha) * np.linalg.norm(r)):
                    break
            alpha *= 0.5
        else:
            if fresh:
                break
            J = None  # the updated Jacobian led nowhere: differences again
            continue
        # Broyden's update of J with the step taken (no static solve), differences again
        # only where it leads nowhere: n static solves per Jacobian made a 60-cable net's
        # form-finding take a minute
        s_L = Ln - L
        J = J + np.outer(rn - r - J @ s_L, s_L) / (s_L @ s_L)
        L, r, base, fresh = Ln, rn, res, False
    if np.abs(r).max() <= TOL:
        return with_lengths(L), base
    worst = np.argsort(-np.abs(r))
    problems = []
    for k in worst:
        if abs(r[k]) <= TOL:
            continue
        c = case.cables[idx[k]]
        got = target[k] * (1.0 + r[k])
        unit = _UNITS[c.form.kind]
        problems.append((f"cables[{idx[k]}].form.{c.form.kind}", (
            f"cable {names[k]!r}: the target {target[k]:.6g} {unit} cannot be reached in "
            f"the first static step with everything in it (form-finding of "
            f"{', '.join(repr(n) for n in names)} together): the search stopped at "
            f"{got:.6g} {unit} at L0 = {L[k]:.6g} m, not necessarily the closest state; "
            "targets can contradict each other (cables in series through a free node with "
            "no load along them share one horizontal tension)")))
    raise CaseError(case.path, problems)
