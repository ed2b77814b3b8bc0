"""What a line engineer reads off a span, on the exact curve of its elements (docs/theory.md §14).

Per cable, in the gravity frame (z up), from the node positions ``X`` and the element states:
the horizontal tension along the chord, the sag at midspan and at the lowest point, the swing
angle at midspan, and the largest tension. Points are found on the exact catenary of each
element (``Elements.position``), sampled and then refined, not on the straight lines between
nodes, so the numbers do not depend on where the mesh put its nodes.
"""

from __future__ import annotations

import numpy as np

from catdae.model.scalar import minimize_bounded, root_bracketed

N_SAMPLE = 33  # points per element where the curve is sampled before refining


def _point(model, state, e: int, s: float) -> np.ndarray:
    """x(s) - x_i of element e at its arc length s (heated, m), (3,) m: that element alone
    (every element's point was computed for one: a 40x40 net's span quantities took 100 s of a
    101 s run, as cables times elements; tester t77)."""
    return model.elements.position_in(e, state.h[e], s)


def span_quantities(model, X: np.ndarray, state) -> dict[str, np.ndarray]:
    """Per cable (in ``mesh.cable_names`` order), arrays (n_cables,):

    ``horizontal_tension_along_chord`` N: the component of the tension at the first end along
    the chord's horizontal direction (constant along a cable loaded only across it: the
    horizontal tension of the catenary in its own, possibly swung, plane); ``sag_midspan`` m:
    the vertical distance from the chord down to the cable where the cable is horizontally
    halfway between its ends; ``swing_angle`` degrees: there, the angle from the vertical of
    the line from the chord to the cable (0 in still air, atan(p/w) under a uniform wind p
    across a level span of weight w); ``sag_lowest_point`` m: how far the lowest point of the
    cable lies below its lower end (0 when the lowest point is an end); ``lowest_point_s`` m:
    its unstrained arc length (reference temperature) from the first end;
    ``lowest_point_elevation`` m: its height; ``tension_max`` N: the largest tension along the
    cable. NaN where a quantity has no meaning (a vertical chord has no midspan).
    """
    mesh = model.mesh
    nc = len(mesh.cable_names)
    out = {k: np.full(nc, np.nan) for k in (
        "horizontal_tension_along_chord", "sag_midspan", "swing_angle", "sag_lowest_point",
        "lowest_point_s", "lowest_point_elevation", "tension_max")}
    frac = np.linspace(0.0, 1.0, N_SAMPLE)
    s = frac[None, :] * mesh.L0[:, None]  # (n_elem, N_SAMPLE) m, heated
    pts = X[mesh.conn[:, 0]][:, None, :] + model.elements.position(state.h, s)
    tens = model.tensions(state)  # (n_elem, 2) N
    for ci in range(nc):
        els = np.flatnonzero(mesh.cable_of_element == ci)
        for key, value in _one_cable(model, X, state, els, s, pts[els]).items():
            out[key][ci] = value
        out["tension_max"][ci] = float(tens[els].max())
    ground = getattr(model.case, "ground", None)
    if ground is not None:
        out.update(clearances(model, X, state, ground, s, pts))
    return out


def clearances(model, X, state, ground, s, pts) -> dict[str, np.ndarray]:
    """Per cable the least height of the cable above ``ground`` (a catdae.case.ground.Ground:
    heights are z, a profile's stations x of the gravity frame, where the model is solved:
    along up and e1), ``clearance`` m, and where, ``clearance_s`` m (unstrained arc length
    at the reference temperature): the lowest sample refined on its element's exact curve."""
    mesh = model.mesh
    nc = len(mesh.cable_names)
    out = {"clearance": np.full(nc, np.nan), "clearance_s": np.full(nc, np.nan)}
    gap = pts[..., 2] - ground.height(pts[..., 0])  # (n_elem, N_SAMPLE) m

    def above(e, v):
        p = X[mesh.conn[e, 0]] + _point(model, state, e, v)
        return float(p[2] - ground.height(p[0]))

    for ci in range(nc):
        els = np.flatnonzero(mesh.cable_of_element == ci)
        g, e, s_c = _least(above, els, s, gap[els], mesh)
        out["clearance"][ci] = g
        out["clearance_s"][ci] = (mesh.s_start[e] + s_c) / mesh.thermal[e]
    return out


def _least(f, els, s, values, mesh) -> tuple[float, int, float]:
    """(least value, element, arc length) of ``f(e, s)`` along a cable's elements ``els``: its
    least sample among ``values`` (len(els), N_SAMPLE) refined within a sample of it, and
    where that sample is a node, on both of the node's elements (a point load's kink just
    inside the other one is below the node: tester t74, 1-2.8 cm)."""
    m, j = np.unravel_index(int(np.argmin(values)), values.shape)
    n_s = values.shape[1]
    near = [(m, j)] + ([(m - 1, n_s - 1)] if j == 0 and m > 0 else []) + (
        [(m + 1, 0)] if j == n_s - 1 and m + 1 < len(els) else [])
    best = (float(values[m, j]), int(els[m]), float(s[els[m], j]))
    for mm, jj in near:
        e = int(els[mm])
        bx, bf = minimize_bounded(lambda v, e=e: f(e, v), s[e, max(jj - 1, 0)],
                                  s[e, min(jj + 1, n_s - 1)], xatol=1e-11 * mesh.L0[e])
        if bf < best[0]:
            best = (float(bf), e, float(bx))
    return best


def _crossing(u: np.ndarray, target: float) -> tuple[int | None, int]:
    """(element, sample j) with u between samples j and j + 1 crossing ``target``."""
    d = u - target
    hit = np.flatnonzero((d[:, :-1] <= 0.0) & (d[:, 1:] >= 0.0)
                         | (d[:, :-1] >= 0.0) & (d[:, 1:] <= 0.0))
    if hit.size == 0:
        return None, 0
    m, j = divmod(int(hit[0]), u.shape[1] - 1)
    return m, j


def _one_cable(model, X, state, els, s, p) -> dict[str, float]:
    """The span quantities of one cable: its elements ``els``, samples ``p`` (n, N, 3) at the
    arc lengths ``s`` (n_elem, N) of every element."""
    mesh = model.mesh
    out = {}
    a, b = X[mesh.conn[els[0], 0]], X[mesh.conn[els[-1], 1]]
    c = b - a
    ch = float(np.hypot(c[0], c[1]))
    if ch > 1e-9 * float(np.linalg.norm(c)):
        u_dir = c[:2] / ch
        out["horizontal_tension_along_chord"] = abs(float(state.h[els[0], :2] @ u_dir))
        u = (p[..., :2] - a[:2]) @ u_dir  # (n, N) m along the chord, in plan
        m, j = _crossing(u, 0.5 * ch)
        if m is not None:
            e = int(els[m])
            xi = X[mesh.conn[e, 0]]
            sv = root_bracketed(lambda v: float((xi[:2] + _point(model, state, e, v)[:2]
                                                 - a[:2]) @ u_dir) - 0.5 * ch,
                                s[e, j], s[e, j + 1], xtol=1e-12 * mesh.L0[e])
            d = a + 0.5 * c - (xi + _point(model, state, e, sv))  # chord point - cable, (3,)
            lateral = d[:2] - (d[:2] @ u_dir) * u_dir
            if float(np.linalg.norm(d)) <= 1e-12 * float(np.linalg.norm(c)):
                d = np.zeros(3)  # a straight line (weightless, unloaded): no sag, no swing
                lateral = d[:2]  # (round-off read as 180° of swing, "sag -2.2e-16 m")
            out["sag_midspan"] = float(d[2])
            out["swing_angle"] = float(np.degrees(np.arctan2(np.linalg.norm(lateral), d[2])))
    z_low, e, s_low = _least(
        lambda e, v: float(X[mesh.conn[e, 0], 2] + _point(model, state, e, v)[2]),
        els, s, p[..., 2], mesh)
    out["lowest_point_elevation"] = z_low
    out["lowest_point_s"] = (mesh.s_start[e] + s_low) / mesh.thermal[e]
    out["sag_lowest_point"] = max(min(a[2], b[2]) - z_low, 0.0)
    return out
