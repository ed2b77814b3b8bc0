"""Static equilibrium on a rigid, frictionless seabed (docs/theory.md §17.4).

The nodes resting on the seabed are an active set: they are held at z_b (a roller in z) and
the elements with an end on the seabed take their grounded relations (catdae.model.seabed,
catdae.element.grounded). Newton (catdae.solvers.static) solves each set; then free nodes that
went below z_b join the set and held nodes that the seabed would have to pull down leave it,
until the set settles. With exact grounded elements the seabed's point forces at held nodes are
zero at the solution (the seabed carries the lying weight along the elements), so the nodes
are on the continuous grounded catenary, whatever the mesh.

Start: each cable with exactly one end on the seabed, uniform properties and no loads inside
is solved first as one grounded element spanning the cable (the closed-form grounded catenary)
and its nodes are put on that curve; then Newton starts converged or nearly.
"""

from __future__ import annotations

import numpy as np

from catdae.element import grounded as g
from catdae.errors import ConvergenceError
from catdae.model.assembly import Model
from catdae.model.seabed import ContactModel, GroundedModel, SeabedContact
from catdae.solvers.line_start import check_not_slack, line_paths, place_line
from catdae.solvers.static import StaticSolution, solve_static


def solve_static_seabed(model: Model, zb: float, X, h0=None, t: float = 0.0,
                        load_steps: int = 1, max_rounds: int = 100
                        ) -> tuple[StaticSolution, GroundedModel]:
    """Equilibrium of ``model`` on a rigid frictionless seabed at height ``zb`` starting from
    ``X`` (n_nodes, 3). Returns the solution and the GroundedModel of the final contact set
    (whose tensions, reactions and positions are the grounded ones)."""
    X = np.array(X, float, copy=True)
    X.reshape(-1)[model.fixed] = model.support_positions(t)
    scale = max(float(np.ptp(X, axis=0).max()), float(model.mesh.L0.sum()), 1.0)
    ztol = 1e-9 * scale
    fscale = max(float((model.mesh.w * model.mesh.L0).sum()), 1e-300)
    fixed_z = model.fixed_mask[:, 2]
    support_on = fixed_z & (np.abs(X[:, 2] - zb) <= ztol)
    for path, fwd in line_paths(model, support_on, t):
        check_not_slack(model, X, path, fwd)
    start = grounded_start(model, X, support_on, t)
    try:
        return _active_set(model, zb, start.copy(), h0, t, load_steps, max_rounds, ztol, fscale,
                           support_on)
    except ConvergenceError:
        pass
    args = (t, load_steps, max_rounds, ztol, fscale, support_on)
    if model.fluid is not None and model.fluid.has_current:
        try:
            return _current_ramp(model, zb, start, args)
        except ConvergenceError:
            pass
    if np.any(model.loading.node_force) and not model.has_internal_loads:
        try:  # a large load at a free node (a moored body pushed far): raised in stages
            return _load_ramp(model, zb, start, args)
        except ConvergenceError:
            pass
    # a first approach on stiff penalty springs (no grounded elements, no active set), whose
    # equilibrium gives the active set nearly right: penetration w/k = 1e-4 element lengths
    mesh = model.mesh
    k = float(np.max(mesh.w / (1e-4 * mesh.L0)))
    penalty = ContactModel(model, SeabedContact.of_model(model, stiffness=k,
                                                         width=np.ones(mesh.n_elements)))
    try:
        pre = solve_static(penalty, X, None, t=t, load_steps=load_steps)
        # pre is the equilibrium at the full loads: the active set starts there, without a ramp
        return _active_set(model, zb, pre.X, None, t, 1, max_rounds, ztol, fscale, support_on)
    except ConvergenceError as exc:
        raise ConvergenceError(
            f"{exc} (on the rigid seabed, from its active-set start, a ramp of the loads and a "
            "penalty start; contact springs, [seabed] stiffness and damping, reach such scenes "
            "from any start: docs/case-format.md, \"Seabed\")") from exc


def _current_ramp(model, zb, X, args):
    """The equilibrium in a current reached from the one without it: the current times 0,
    then times factors growing to 1, each stage an active set started from the last. The drag
    moves the resting part in plan and the touchdown along the line; when a stage's touchdown
    leaves the touchdown element (Newton at a fixed set cannot follow it), the stage is tried
    again with the set grown or shrunk by the nodes next to the touchdown, then halved."""
    fl = model.fluid

    def factor(k):
        fl.current_factor = k

    return _ramp(model, zb, X, args, factor, "raising the current")


def _load_ramp(model, zb, X, args):
    """The equilibrium under the loads at the nodes reached as :func:`_current_ramp` reaches
    the current's: a body pushed far by a load moves the touchdowns of its lines across
    elements, which Newton at one contact set cannot follow (an independent tester's spread
    mooring converged at 0.8 and 1.3 MN but not at 1.0 MN; two steps, 0.8 then 1.0, did)."""
    ld = model.loading
    full = ld.node_force.copy()

    def factor(k):
        ld.node_force[...] = k * full

    return _ramp(model, zb, X, args, factor, "raising the loads")


def _ramp(model, zb, X, args, factor, what: str):
    """Stages of ``factor`` (a function setting what is raised to a share of it) from 0 to 1,
    each an active set started from the last (see :func:`_current_ramp`); the share is left at
    1 whatever happens."""
    lam, dlam = 0.0, 0.25
    try:
        factor(0.0)
        sol, gm = _active_set(model, zb, X.copy(), None, *args)
        while lam < 1.0:
            target = min(1.0, lam + dlam)
            factor(target)
            found = _stage(model, zb, sol, gm.contact, args)
            if found is None:
                dlam *= 0.5
                if dlam < 1.0 / 64.0:
                    raise ConvergenceError(f"static step on the seabed: no equilibrium found "
                                           f"by {what}")
                continue
            sol, gm = found
            lam = target
            dlam = min(2.0 * dlam, 0.5)
    finally:
        factor(1.0)
    return sol, gm


def _stage(model, zb, sol, contact, args):
    """One stage of :func:`_current_ramp` from ``sol`` with the nodes ``contact`` on the
    seabed, then with the free nodes next to them added, then with the touchdown-side nodes
    of the set removed; None when none converges."""
    fixed_z = model.fixed_mask[:, 2]
    conn = model.mesh.conn
    a, b = contact[conn[:, 0]], contact[conn[:, 1]]
    edge = np.zeros_like(contact)
    edge[conn[a & ~b, 1]] = True
    edge[conn[b & ~a, 0]] = True
    grow = contact | (edge & ~fixed_z)
    last = np.zeros_like(contact)
    last[conn[a & ~b, 0]] = True
    last[conn[b & ~a, 1]] = True
    args = (args[0], 1, *args[2:])  # from the last stage's equilibrium at the full loads
    for trial in (contact, grow, contact & ~last):
        try:
            return _active_set(model, zb, sol.X.copy(), sol.state.h, *args, contact=trial)
        except ConvergenceError:
            continue
    return None


def _active_set(model, zb, X, h0, t, load_steps, max_rounds, ztol, fscale, support_on,
                contact=None):
    fixed_z = model.fixed_mask[:, 2]
    if contact is None:
        contact = ~fixed_z & (X[:, 2] <= zb + ztol)
    h = h0
    seen: set[bytes] = set()
    for _ in range(max_rounds):
        X[contact, 2] = zb
        gm = GroundedModel(model, contact, contact | support_on, zb)
        sol = solve_static(gm, X, h, t=t, load_steps=load_steps)
        X, h = sol.X, sol.state.h
        # the next set starts from this one's equilibrium at the full loads: ramping the loads
        # again from a fraction would start a fixed set, chosen for the full loads, far from
        # its equilibrium at that fraction (where the set is not the right one)
        load_steps = 1
        rz = seabed_push(gm, sol.state, X, t)  # what the seabed must push up with
        below = ~fixed_z & ~contact & (X[:, 2] < zb - ztol)
        pulling = contact & (rz < -1e-9 * fscale)
        if not below.any() and not pulling.any():
            _check_dips(gm, sol, zb, ztol)
            _check_slack_resting(gm, sol, fscale)
            return sol, gm
        seen.add(contact.tobytes())
        contact = (contact | below) & ~pulling
        if contact.tobytes() in seen:
            break
    raise ConvergenceError("static step on the seabed: the set of nodes resting on the seabed "
                           "does not settle")


def seabed_push(gm: GroundedModel, state, X: np.ndarray, t: float) -> np.ndarray:
    """(n_nodes,) N: the vertical force the seabed must push up with at each node for the
    equilibrium of ``gm``: the elements' and the loads' vertical forces, and the fluid's static
    forces (buoyancy, drag), except at nodes whose elements all hold their buoyancy in their
    weight. There the fluid's force is drag alone, and its vertical part at a node on the
    seabed is that of the inclined chord of the touchdown element (the drag is lumped from the
    chords), where the resting line is horizontal: a horizontal current's drag on it has no
    vertical part. The seabed takes it either way; it vanishes as the element length does
    (docs/theory.md §17.4)."""
    r = gm.internal_force(state, X) - gm.nodal_load(t)
    fl = gm.fluid
    if fl is not None:  # the fluid's static forces, as in the static residual
        f = fl.static(X)[0].reshape(-1, 3).copy()
        conn = gm.mesh.conn
        drag_only = np.ones(gm.mesh.n_nodes, bool)
        held = np.asarray(fl.in_weight, bool)
        drag_only[conn[~held, 0]] = False
        drag_only[conn[~held, 1]] = False
        f[drag_only, 2] = 0.0
        r = r + f.reshape(-1)
    return r.reshape(-1, 3)[:, 2]


def grounded_start(model: Model, X: np.ndarray, on_support: np.ndarray, t: float = 0.0
                   ) -> np.ndarray:
    """Nodes of every cable with exactly one end supported on the seabed (uniform w and EA,
    no loads inside) placed on the grounded catenary of the whole cable, and those of every
    line of several cables in series from an anchor on the seabed to a support above it
    (catdae.solvers.line_start) on the line's equilibrium; others unchanged."""
    mesh = model.mesh
    el = model.elements
    X = X.copy()
    loaded = np.diff(el.loads.ptr) > 0
    interior = np.zeros(mesh.n_nodes, bool)
    for ci in range(len(mesh.cable_names)):
        els = np.flatnonzero(mesh.cable_of_element == ci)
        a, b = mesh.conn[els[0], 0], mesh.conn[els[-1], 1]
        inner = mesh.conn[els[1:], 0]
        interior[:] = False
        interior[inner] = True
        if (loaded[els].any() or on_support[a] == on_support[b] or np.ptp(el.w[els]) > 0
                or np.ptp(el.EA[els]) > 0 or el.w[els[0]] <= 0
                or model.fixed_mask[inner].any()):
            continue
        mode = g.AT_I if on_support[a] else g.AT_J
        l0 = float(el.L0[els].sum())
        w, ea = float(el.w[els[0]]), float(el.EA[els[0]])
        h = np.zeros(3)
        _, status = g.solve_grounded(X[b] - X[a], l0, ea, w, mode, h, False, 1e-13, 100,
                                     np.zeros(6), np.zeros((3, 3)))
        if status != g.CONVERGED:
            continue
        s = np.cumsum(el.L0[els])[None, :-1]
        out = np.zeros((1, s.shape[1], 3))
        g.position_batch(h[None], np.array([w]), np.array([ea]), np.array([l0]),
                         np.array([mode]), s, out)
        X[inner] = X[a] + out[0]
    for path, fwd in line_paths(model, on_support, t):
        if np.unique(mesh.cable_of_element[path]).size > 1:
            place_line(model, X, path, fwd, t)
    return X


def _check_dips(gm: GroundedModel, sol, zb: float, ztol: float) -> None:
    """A free element whose low point lies below the seabed between its nodes would need the
    seabed inside it with both ends off it: not modelled, say so."""
    free = np.flatnonzero(gm.mode == g.FREE)
    if free.size == 0:
        return
    h = sol.state.h[free]
    el = gm.base.elements
    s_low = -h[:, 2] / np.where(el.w[free] > 0, el.w[free], np.inf)
    inside = (s_low > 0) & (s_low < el.L0[free])
    if not inside.any():
        return
    s = np.zeros((gm.mesh.n_elements, 1))
    s[free[inside], 0] = s_low[inside]
    z = sol.X[gm.mesh.conn[:, 0], 2] + el.position(sol.state.h, s)[:, 0, 2]
    bad = free[inside][z[free[inside]] < zb - ztol]
    if bad.size:
        raise ConvergenceError(
            f"element {gm.mesh.element_names[int(bad[0])]} dips below the seabed between its "
            "nodes with both ends off it: use more elements on that cable, so that a node "
            "falls on the lying part")


def _check_slack_resting(gm: GroundedModel, sol, fscale: float) -> None:
    """In a current, a resting element without tension: the drag along the resting part has
    taken its tension to zero before the anchor, and on a frictionless seabed the rest of it
    has nothing to hold it (the line would pile up at the anchor): no equilibrium, say so."""
    if gm.fluid is None or not gm.fluid.has_current:
        return
    resting = np.flatnonzero(gm.mode != g.FREE)
    if resting.size == 0:
        return
    t = gm.tensions(sol.state)[resting].max(axis=1)
    slack = resting[t <= 1e-9 * fscale]
    if slack.size:
        raise ConvergenceError(
            f"element {gm.mesh.element_names[int(slack[0])]} rests slack on the rigid seabed: "
            "the current's drag along the resting part takes its tension to zero before the "
            "anchor, and a frictionless seabed holds nothing there (the line would pile up at "
            "the anchor): no static equilibrium")


def seabed_summary(gm: GroundedModel, X: np.ndarray, h: np.ndarray) -> dict[str, np.ndarray]:
    """Per cable: unstrained length resting on the seabed, and the touchdown point: where the
    suspended part that reaches the cable's upper end (the higher of its two ends, its second
    end when they are level) leaves the seabed, i.e. the last contact point seen from the upper
    end, whatever the cable's end order; NaN when the cable does not touch, or when its upper
    end itself rests on the seabed (it does not leave it)."""
    mesh = gm.mesh
    nc = len(mesh.cable_names)
    lying = gm.elements.lying_length(h)
    length = np.bincount(mesh.cable_of_element, weights=lying, minlength=nc)
    touchdown = np.full((nc, 3), np.nan)
    el = gm.base.elements
    for ci in range(nc):
        els = np.flatnonzero(mesh.cable_of_element == ci)
        if length[ci] <= 0.0:
            continue
        from_last = X[mesh.conn[els[-1], 1], 2] >= X[mesh.conn[els[0], 0], 2]
        walk = els[::-1] if from_last else els
        leaves = g.AT_I if from_last else g.AT_J  # the grounded mode whose free end faces up
        for e in walk:
            if gm.mode[e] == g.FREE:
                continue
            if gm.mode[e] == leaves:
                s = np.zeros((mesh.n_elements, 1))
                s[e, 0] = np.clip(-h[e, 2] / el.w[e], 0.0, el.L0[e])
                touchdown[ci] = X[mesh.conn[e, 0]] + gm.elements.position(h, s)[e, 0]
            break  # else the upper end rests on the seabed: the cable does not leave it
    return {"seabed_length": length, "touchdown": touchdown}


def solve_static_on_seabed(model: Model, X, h0=None, t: float = 0.0, load_steps: int = 1):
    """A static step of a scene with a seabed: on the rigid seabed (no ``stiffness``, §17.4)
    or on its contact springs (§17.5). Returns (solution, the model whose tensions and
    reactions are the solution's, per-cable seabed_length and touchdown)."""
    sb = model.case.seabed
    if sb.stiffness is None:
        sol, gm = solve_static_seabed(model, sb.z, X, h0, t=t, load_steps=load_steps)
        return sol, gm, seabed_summary(gm, sol.X, sol.state.h)
    contact = ContactModel(model, SeabedContact.of_model(model))
    sol = solve_static(contact, X, h0, t=t, load_steps=load_steps)
    return sol, contact, contact.summary(sol.X)
