"""The start of the rigid seabed statics for a mooring line of several cables in series
(docs/theory.md §17.4): chain, wire, chain joined at bare junction nodes, from an anchor on the
seabed to a support above it.

A line in one vertical plane under its own weight, with frictionless contact, has one horizontal
tension H all along, and its vertical tension falls by w per unstrained metre from the upper
support down to the touchdown point, below which it lies on the seabed: given (H, V) at the
upper end, each element's shape is the grounded element of §17.1 with its V continued from the
part above (catdae.element.grounded.chord_grounded), and the chords add up to the line's chord.
The two conditions (span and rise) fix H and V: for a given H, the rise grows with V (more of
the line is lifted), and for the V that gives the rise, the span grows with H, so both are
found by bisection. The elements' chords then place every node, the junctions included, on
the equilibrium, whatever the junctions' positions in the case were.

A line of unstrained length at least span + rise cannot be taut (H > 0): it hangs straight
down from the upper support with the rest lying slack (H = 0) on the seabed, where a
frictionless seabed leaves its spare length anywhere; :func:`check_not_slack` refuses it.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from catdae.element import grounded as g
from catdae.errors import ConvergenceError


def line_paths(model, on_support: np.ndarray, t: float = 0.0
               ) -> list[tuple[list[int], list[bool]]]:
    """The lines to start: (elements from the seabed end up, each element's orientation: True
    when it runs from the line's lower end towards its upper end). A line is a chain of cables
    joined end to end at junctions (nodes that end exactly two cables, with no support, load,
    point mass or connector), from a support resting on the seabed (``on_support``) to one
    fixed in x, y and z above it, without loads inside its elements and with positive weight."""
    mesh = model.mesh
    el = model.elements
    ends = [(int(mesh.conn[els[0], 0]), int(mesh.conn[els[-1], 1]), els) for els in
            (np.flatnonzero(mesh.cable_of_element == ci) for ci in range(len(mesh.cable_names)))]
    degree = np.bincount([n for a, b, _ in ends for n in (a, b)], minlength=mesh.n_nodes)
    # a junction may carry a vertical load (a clump weight, a buoy, a point mass's weight):
    # the horizontal tension stays one along the line, the vertical one jumps there
    bare = (degree == 2) & ~model.fixed_mask.any(axis=1)
    bare &= ~np.any(model.nodal_load(t).reshape(-1, 3)[:, :2] != 0.0, axis=1)
    if model.connectors is not None:
        bare[model.connectors.ends.ravel()] = False
    loaded = np.diff(el.loads.ptr) > 0
    anchored = model.fixed_mask.all(axis=1)
    out = []
    for start in np.flatnonzero(on_support & anchored):
        path, fwd, node, used = [], [], int(start), set()
        while True:
            nxt = [(k, a == node) for k, (a, b, _) in enumerate(ends)
                   if node in (a, b) and k not in used]
            if len(nxt) != 1:
                break
            k, forward = nxt[0]
            used.add(k)
            els = ends[k][2]
            path += list(els if forward else els[::-1])
            fwd += [forward] * len(els)
            node = ends[k][1] if forward else ends[k][0]
            if not bare[node]:
                break
        if (path and anchored[node] and not on_support[node] and not loaded[path].any()
                and (el.w[path] > 0.0).all()):
            out.append((path, fwd))
    return out


def _walk(h_top: float, v_top: float, el, path, e_h, jump) -> tuple[np.ndarray, list, bool]:
    """(span and rise, each element's chord from the top down, whether a junction lifts a line
    that touched down above it) of a path hanging from tension (H, V) at its upper end.
    ``jump``: the vertical force at each element's lower-end node (a buoy up, a clump down;
    0 at the path's lower end), added to V below it."""
    d = np.zeros(3)
    f = np.zeros(6)
    total = np.zeros(2)
    chords = []
    v, relifted = v_top, False
    for e, up in zip(reversed(path), reversed(jump), strict=True):
        w, l0 = float(el.w[e]), float(el.L0[e])
        v_low = v - w * l0  # V continued to the element's lower end
        g.chord_grounded(h_top * e_h[0], h_top * e_h[1], v_low, w, float(el.EA[e]), l0,
                         g.AT_I, d, f, False)
        chords.append(d.copy())
        total[0] += d[0] * e_h[0] + d[1] * e_h[1]
        total[1] += d[2]
        relifted |= v_low < 0.0 and up > 0.0  # an S-shape this walk does not describe
        v = max(max(v_low, 0.0) + up, 0.0)
    return total, chords, relifted


def _chord(h_top: float, v_top: float, el, path, e_h, jump) -> np.ndarray:
    """(span, rise) of a path hanging from tension (H, V) at its upper end (:func:`_walk`)."""
    return _walk(h_top, v_top, el, path, e_h, jump)[0]


def _solve(el, path, span: float, rise: float, e_h, jump) -> tuple[float, float]:
    """(H, V at the upper end) of the line through span and rise (both > 0), by bisection."""
    weight = float((el.w[path] * el.L0[path]).sum() + np.abs(jump).sum())

    def v_for(h):
        def f(v):
            return _chord(h, v, el, path, e_h, jump)[1] - rise
        hi = weight
        for _ in range(200):
            if f(hi) >= 0.0:
                break
            hi *= 2.0
        return brentq(f, 0.0, hi, xtol=1e-12 * weight, rtol=1e-14, maxiter=200)

    def fs(h):
        return _chord(h, v_for(h), el, path, e_h, jump)[0] - span

    lo = 1e-9 * weight
    hi = weight
    for _ in range(200):
        if fs(hi) >= 0.0:
            break
        lo, hi = hi, 2.0 * hi
    h = brentq(fs, lo, hi, xtol=1e-12 * weight, rtol=1e-14, maxiter=200)
    return h, v_for(h)


def place_line(model, X: np.ndarray, path, fwd, t: float = 0.0) -> bool:
    """Put the inner nodes of ``path`` (lower end first) on the line's equilibrium (in place);
    False when it is not found (the start is then left as it was)."""
    el = model.elements
    conn = model.mesh.conn
    a = int(conn[path[0], 0] if fwd[0] else conn[path[0], 1])
    b = int(conn[path[-1], 1] if fwd[-1] else conn[path[-1], 0])
    c = X[b] - X[a]
    span = float(np.hypot(c[0], c[1]))
    if span <= 0.0 or c[2] <= 0.0:
        return False
    e_h = c[:2] / span
    lower = [int(conn[e, 0] if forward else conn[e, 1]) for e, forward in zip(path, fwd,
                                                                             strict=True)]
    fz = model.nodal_load(t).reshape(-1, 3)[:, 2]
    jump = np.array([0.0] + [float(fz[n]) for n in lower[1:]])  # at each element's lower end
    try:
        h, v = _solve(el, path, span, float(c[2]), e_h, jump)
    except (ValueError, RuntimeError, OverflowError):
        return False
    _, chords, relifted = _walk(h, v, el, path, e_h, jump)
    if relifted:  # a buoy lifting a line that lies on the seabed above it: not this shape
        return False
    x = X[a].copy()
    for e, forward, ch in zip(path[:-1], fwd[:-1], chords[::-1][:-1], strict=True):
        x = x + ch
        X[conn[e, 1] if forward else conn[e, 0]] = x
    return True


def check_not_slack(model, X: np.ndarray, path, fwd) -> None:
    """Refuse a line whose unstrained length is at least its span plus its rise: it would lie
    slack (H = 0) with length to spare on the frictionless seabed, where nothing places it."""
    mesh = model.mesh
    conn = mesh.conn
    a = int(conn[path[0], 0] if fwd[0] else conn[path[0], 1])
    b = int(conn[path[-1], 1] if fwd[-1] else conn[path[-1], 0])
    c = X[b] - X[a]
    span, rise = float(np.hypot(c[0], c[1])), float(c[2])
    length = float(mesh.L0[path].sum())
    if length < span + rise:
        return
    cables = list(dict.fromkeys(mesh.cable_names[int(mesh.cable_of_element[e])] for e in path))
    which = (f"cable {cables[0]!r}" if len(cables) == 1
             else "the line of cables " + ", ".join(repr(n) for n in cables))
    raise ConvergenceError(
        f"{which}: its length ({length:.6g} m) is at least its horizontal span plus the height "
        f"of its upper end above the seabed ({span:.6g} m + {rise:.6g} m = {span + rise:.6g} m):"
        " it would hang straight down (H = 0) with the rest lying slack on the rigid, "
        "frictionless seabed, which holds the spare length nowhere in particular and has no "
        "unique equilibrium; give a length below span + height (cables.length), or move the "
        "anchor out")
