"""Can a transient snap? What ``mass_model = "auto"`` asks before it keeps a catenary mass
(catdae.model.settings, docs/theory.md §18.5).

A snap is an axial (water-hammer) wave: a sudden change of what holds an element that takes a
change of chord by sag (Irvine's λ² > 1: slack, or sagging enough that it can go slack) sends
a tension front along it, and the consistent catenary mass (and so the blended one) does not
carry it there (docs/accuracy.md). The sudden changes are a start out of balance (a point mass
or load added or removed at the start of the step, a mass let go) and a jump of a support
velocity, at the start or at a breakpoint of the prescribed motion inside the step.
"""

from __future__ import annotations

import numpy as np

SAG_LAMBDA2 = 1.0  # elements with λ² above this take a chord change by sag (the note's rule)
SAG_AMPLIFICATION = 1.0  # elements whose midpoint moves sideways by more than this times a
#                          change of their chord: a taut but light, stiff element whose sag
#                          breathes with its stretch (docs/theory.md §7.1, §18.5)
SNAP_SHARE = 0.05  # a sudden change counts where the force it sends (m c Δv of a velocity
#                    jump, the force of an item added or removed) reaches this share of the
#                    largest tension at the start: a record's round-off steps or a small load
#                    released to start a vibration do not


def velocity_jumps(model, V: np.ndarray, t0: float, t1: float) -> list[tuple[float, float]]:
    """(t, largest |Δv| m/s) of each jump of a prescribed support velocity in [t0, t1]: at t0
    against the velocities ``V`` (n_nodes, 3) the step starts from, then at every breakpoint.
    Differences at round-off level (1e-12 of the velocity) are not jumps."""
    def jump(before: np.ndarray, after: np.ndarray) -> float:
        dv = np.abs(after - before)
        dv[dv <= 1e-12 * max(1.0, float(np.abs(after).max(initial=0.0)))] = 0.0
        return float(dv.max(initial=0.0))

    out = []
    first = jump(np.asarray(V, float).reshape(-1)[model.fixed], model.support_values(t0)[1])
    if first > 0.0:
        out.append((t0, first))
    for before, at in model.breakpoints(t0, t1):
        dv = jump(model.support_values(before)[1], model.support_values(at)[1])
        if dv > 0.0:
            out.append((at, dv))
    return out


def jump_floor(model, state) -> float:
    """m/s: the smallest support velocity jump whose axial (water-hammer) wave counts, from the
    element ``state`` a step starts in: m c Δv = ``SNAP_SHARE`` of the largest tension there
    (c = sqrt(EA/m); 0 when nothing is in tension: every jump counts). A record's spline that
    starts at a round-off velocity, or a velocity kink of a few µm/s, does not count."""
    t_max = float(model.tensions(state).max(initial=0.0))
    impedance = float(np.sqrt(model.mesh.EA * model.mesh.m).max(initial=0.0))  # m c, N s/m
    return SNAP_SHARE * t_max / impedance if impedance > 0.0 else np.inf


def unbalance_forces(model, state, X: np.ndarray, t0: float,
                     V: np.ndarray | None = None) -> np.ndarray:
    """The residual force on each node at t0 with no acceleration, (n_nodes, 3) N (0 at the
    supports, which take theirs as reactions): the elements, the loads, the water and air
    (buoyancy, drag on the velocities ``V``, the waves at t0) and the seabed's contact springs,
    so that a line resting on the seabed or held up by its buoyancy in the static state is in
    balance here too. The node is pushed along minus it."""
    r = model.internal_force(state, X) - model.nodal_load(t0)
    v = np.zeros(r.size) if V is None else np.asarray(V, float).reshape(-1)
    if model.fluid is not None:  # M_a A - f_fluid at A = 0: -f_fluid
        r = r + model.fluid.evaluate(t0, X, v, np.zeros(r.size))[0]
    if model.case.seabed is not None:
        from catdae.model.seabed import SeabedContact  # only scenes with a seabed

        contact = SeabedContact.of_step(model)  # the transient's springs (None when rigid)
        if contact is not None:
            r = r - contact.forces(np.reshape(X, (-1, 3)), v.reshape(-1, 3)).ravel()
    r = r.reshape(-1, 3)
    r[model.fixed_mask] = 0.0  # the supports take theirs as reactions
    return r


def release_slackens(model, X: np.ndarray, r: np.ndarray, t_end: np.ndarray) -> np.ndarray:
    """Elements whose tension a start out of balance can take to zero, (n_elem,) bool. The net
    force -r_k on a node k, let go at once, changes the tension of each element at k by its
    part along the element, drop = -r_k · ĉ (ĉ from k towards the element's other end) at the
    new balance, and the undamped axial ringing about it overshoots by as much again: the
    tension falls to about T - 2 drop, which is below zero when the drop is more than half the
    tension (a bob held 50° aside on a light line and let go: 152.6 N falls towards 63 N and
    rings through zero). Whatever the element's λ² (a weightless line has none) it then goes
    slack and snaps taut again. ``t_end`` (n_elem, 2): the tensions at ends i and j."""
    conn = model.mesh.conn
    c = model.unit_chords(X)
    drop_i = np.einsum("ej,ej->e", -r[conn[:, 0]], c)  # end i: towards j is +ĉ
    drop_j = np.einsum("ej,ej->e", -r[conn[:, 1]], -c)
    return (t_end[:, 0] < 2.0 * drop_i) | (t_end[:, 1] < 2.0 * drop_j)


def sag_amplification(model, state, X: np.ndarray) -> np.ndarray:
    """How far each element's midpoint moves sideways per metre of change of its chord,
    (n_elem,): |(I - ĉĉᵀ) B(L0/2) ĉ| from the interpolation N(s) = [I - B(s), B(s)] (a stretch
    moves end j by +ĉ/2 and end i by -ĉ/2; the straight line's share, ĉ/2 - ĉ/2 at the middle,
    is along ĉ). About P⊥ EA / (8 T²) for an element of transverse load P⊥ at tension T: the
    sag w L²/(8T) shrinks as the stretch raises T. 0 for a slack element (its λ² says it)."""
    el = model.elements
    u = model.unit_chords(X)
    b = el.interpolation(state, 0.5 * el.L0[:, None])[:, 0, :, 3:]  # (n, 3, 3)
    d = np.einsum("eij,ej->ei", b, u)
    d -= np.einsum("ei,ei->e", d, u)[:, None] * u
    return np.linalg.norm(d, axis=1)


def snap_reason(model, step, X: np.ndarray, V: np.ndarray, t0: float,
                h0: np.ndarray | None = None) -> str:
    """Why the transient ``step`` starting from positions ``X`` and velocities ``V`` (n_nodes, 3)
    at t0 can snap ("" if it cannot): a start out of balance (an item added or removed, a mass
    let go) or a support velocity jump, whose force (the largest out-of-balance force on a
    node; m c Δv of the jump's wave, c = sqrt(EA/m)) reaches ``SNAP_SHARE`` of the largest
    tension, while elements take a chord change by sag (λ² > 1 at the start) or their sag
    breathes with their stretch (``sag_amplification`` > 1: a taut, light, stiff line, whose
    catenary mass then makes the unresolved axial ringing pump itself up at BDF order 2), or,
    for a start out of balance, while it takes elements through zero tension
    (``release_slackens``)."""
    model.set_time(t0)
    state = model.element_state(X, h0)
    lam2 = model.element_lambda2(state, X)
    sag = lam2 > SAG_LAMBDA2
    amp = np.where(sag, 0.0, sag_amplification(model, state, X))
    breathes = amp > SAG_AMPLIFICATION
    t_end = model.tensions(state)
    t_max = float(t_end.max(initial=0.0))
    r = unbalance_forces(model, state, X, t0, V)
    norms = np.linalg.norm(r, axis=1)
    node = int(np.argmax(norms))
    force = float(norms[node])
    released = force >= SNAP_SHARE * t_max
    slackens = (release_slackens(model, X, r, t_end) & ~sag & ~breathes if released
                else np.zeros(lam2.size, bool))
    if not (sag.any() or breathes.any() or slackens.any()):
        return ""
    worst = float(lam2.max())
    where = " and ".join(
        ([f"{int(sag.sum())} of {lam2.size} elements take a chord change by sag (λ² up to "
          + ("inf, slack" if not np.isfinite(worst) else f"{worst:.3g}") + ", > 1)"]
         if sag.any() else [])
        + ([f"{int(breathes.sum())} of {lam2.size} elements move their middle sideways by up "
            f"to {float(amp.max()):.3g} times a change of their chord (> 1: their sag breathes "
            "with the stretch, an inertia the catenary mass gives a fast axial motion too)"]
           if breathes.any() else [])
        + ([f"{int(slackens.sum())} of {lam2.size} elements lose more than half their tension "
            "to it at the new balance (their axial ringing about it goes through zero: they "
            "go slack and snap taut)"] if slackens.any() else []))
    if released:
        changed = [*step.add, *step.remove]
        what = (f"{', '.join(repr(c) for c in changed)} added or removed" if changed else
                "a temperature change" if step.temperature_change is not None else
                "a release")
        return (f"the step starts out of balance by {force:.3g} N at node "
                f"{model.mesh.node_names[node]} ({what}; the largest tension is {t_max:.3g} N) "
                f"while {where}")
    floor = jump_floor(model, state)
    jumps = [j for j in velocity_jumps(model, V, t0, t0 + float(step.duration))
             if j[1] >= floor]
    if jumps:
        t, dv = jumps[0]
        return (f"a support velocity jumps by up to {dv:.3g} m/s at t = {t:.6g} s while "
                f"{where}")
    return ""
