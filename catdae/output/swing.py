"""A cable's swing angle over a transient's outputs (docs/case-format.md, "Line engineering").

The static groups give ``swing_angle`` per cable on the exact curve (catdae.model.span): where
the cable is horizontally halfway between its ends, the angle from the vertical of the line
from the chord down to the cable. A transient stores the nodes only, so there the same point
is found on the line through the nodes (exact where a node sits at that point, as it does at
midspan of a level span meshed evenly; otherwise second order in the element length), at
every output time, with its envelope: a conductor's blowout in a gust is read off it.
"""

from __future__ import annotations

import numpy as np

from catdae._xr import xr
from catdae.output.reading import cable_paths

JUMP_ANGLE = 135.0  # degrees: past it the cable is above its chord more than beside it


def _swing(P: np.ndarray, up: np.ndarray) -> np.ndarray:
    """Swing angles (degrees) of one cable's node line P (time, n_along, 3); NaN where the
    chord is vertical, the line does not cross its horizontal middle, or the cable is above
    its chord more than beside it (past JUMP_ANGLE: a jump, no sag to swing; the static
    groups read a cable straight above its chord as 180°)."""
    a, c = P[:, 0], P[:, -1] - P[:, 0]
    c_h = c - np.outer(c @ up, up)  # the chord's horizontal part
    ch = np.linalg.norm(c_h, axis=1)
    ok = ch > 1e-9 * np.linalg.norm(c, axis=1)
    u_dir = c_h / np.where(ok, ch, 1.0)[:, None]
    u = np.einsum("tnk,tk->tn", P - a[:, None], u_dir) - 0.5 * ch[:, None]
    cross = (u[:, :-1] <= 0.0) & (u[:, 1:] >= 0.0) & (u[:, 1:] > u[:, :-1])
    ok &= cross.any(axis=1)
    k = np.argmax(cross, axis=1)
    t = np.arange(P.shape[0])
    u0, u1 = u[t, k], u[t, k + 1]
    f = np.where(u1 > u0, -u0 / np.where(u1 > u0, u1 - u0, 1.0), 0.0)
    point = P[t, k] + f[:, None] * (P[t, k + 1] - P[t, k])
    d = a + 0.5 * c - point  # from the cable up to the chord's middle
    down = d @ up
    lateral = d - np.outer(down, up) - np.einsum("tk,tk->t", d, u_dir)[:, None] * u_dir
    angle = np.degrees(np.arctan2(np.linalg.norm(lateral, axis=1), down))
    straight = np.linalg.norm(d, axis=1) <= 1e-12 * np.linalg.norm(c, axis=1)
    # above its chord more than beside it (angle past 135°): a jump (ice shedding), no swing;
    # a blow-out past horizontal (a gust's 110°) is a swing and is kept
    ok &= straight | (angle <= JUMP_ANGLE)
    return np.where(ok, np.where(straight, 0.0, angle), np.nan)


def swing_over_time(ds: xr.Dataset, cables: list[str],
                    up: np.ndarray | None = None) -> dict[str, xr.Variable]:
    """``swing_angle``(time, cable) degree, and ``swing_angle_max``(cable) with its
    ``swing_angle_max_time``, from the nodes of each cable (``up``: the unit vector against
    gravity, default +z)."""
    up = np.array([0.0, 0.0, 1.0]) if up is None else np.asarray(up, float)
    up = up / np.linalg.norm(up)
    X = np.asarray(ds.position.transpose("time", "node", "axis").values, float)
    index = {str(n): i for i, n in enumerate(ds.node.values)}
    paths = cable_paths(ds)
    angle = np.full((X.shape[0], len(cables)), np.nan)
    for ci, c in enumerate(cables):
        angle[:, ci] = _swing(X[:, [index[n] for n in paths[c]]], up)
    found = np.isfinite(angle).any(axis=0)
    k = np.argmax(np.where(np.isfinite(angle), angle, -np.inf), axis=0)
    top = np.where(found, angle[k, np.arange(len(cables))], np.nan)
    when = np.where(found, ds.time.values[k], np.nan)
    what = ("angle from the vertical of the line from the chord to the cable where it is "
            "horizontally halfway between its ends (swing under loads across the span), "
            "on the line through the nodes; NaN while the cable is above its chord more than "
            "beside it (past 135 degrees: a jump)")
    return {
        "swing_angle": xr.Variable(("time", "cable"), angle,
                                   {"units": "degree", "long_name": what}),
        "swing_angle_max": xr.Variable("cable", top, {
            "units": "degree", "long_name": "largest swing_angle over the output times"}),
        "swing_angle_max_time": xr.Variable("cable", when, {
            "units": "s", "long_name": "time of swing_angle_max"}),
    }
