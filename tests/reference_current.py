"""An independent reference for a line on a rigid, frictionless seabed in a uniform current:
the continuous static line equations integrated from the anchor and shot onto the fairlead.

Written from the equilibrium of a line element, not from the ``catdae`` package (nothing here
imports it). SI units; z is up, gravity along -z, the seabed the plane z = z_anchor.

With s the unstrained arc length from the anchor and T(s) the tension vector along increasing
s, a line element is in equilibrium when dT/ds = -q, q the force per unstrained metre on it;
Hooke's law gives dx/ds = (1 + |T|/EA) T/|T|. The forces per unstrained metre (the
case-format's Morison convention): the submerged weight (0, 0, -w), and the drag of the current
u on the line at rest, u_t = (u·t)t along the tangent t = T/|T|, u_n = u - u_t across it,

    q_drag = ½ ρ Cd d |u_n| u_n + ½ ρ CdAx π d |u_t| u_t.

On the seabed (0 <= s <= L_B) the line lies in the plane z = z_anchor: the seabed's push takes
the weight (and any vertical drag), T stays horizontal and dT_h/ds = -q_drag,h: the resting
part bends in plan under the drag across it and its tension changes under the drag along it.
Off the seabed (L_B <= s <= L0) the suspended part leaves it tangentially (T_z = 0 at the
touchdown) under weight and drag. Unknowns: the horizontal tension (T_x, T_y) at the anchor and
the resting length L_B, found with ``scipy.optimize.root`` so that x(L0) is the fairlead.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import root


def grounded_line_in_current(anchor, fairlead, L0, EA, w, rho, d, cd, cda, u, guess):
    """The line from ``anchor`` (on the seabed) to ``fairlead`` in the current ``u`` (3,) m/s.
    ``guess`` = (H, L_B): the horizontal anchor tension and resting length without current.
    Returns the anchor and fairlead reactions (the supports' forces on the line), the resting
    length and the touchdown point."""
    u = np.asarray(u, float)
    anchor = np.asarray(anchor, float)
    fairlead = np.asarray(fairlead, float)

    def drag(T):
        t = T / np.linalg.norm(T)
        ut = (u @ t) * t
        un = u - ut
        return (0.5 * rho * cd * d * np.linalg.norm(un) * un
                + 0.5 * rho * cda * math.pi * d * np.linalg.norm(ut) * ut)

    def lying(_, y):
        T = np.array([y[3], y[4], 0.0])
        q = drag(T)
        dx = (1.0 + np.linalg.norm(T) / EA) * T / np.linalg.norm(T)
        return [dx[0], dx[1], 0.0, -q[0], -q[1], 0.0]

    def suspended(_, y):
        T = y[3:]
        q = drag(T) + np.array([0.0, 0.0, -w])
        dx = (1.0 + np.linalg.norm(T) / EA) * T / np.linalg.norm(T)
        return [*dx, *(-q)]

    def shoot(p):
        tx, ty, lb = p
        y0 = [*anchor, tx, ty, 0.0]
        a = solve_ivp(lying, (0.0, lb), y0, method="DOP853", rtol=1e-12, atol=1e-10)
        b = solve_ivp(suspended, (lb, L0), a.y[:, -1], method="DOP853", rtol=1e-12,
                      atol=1e-10)
        return a.y[:, -1], b.y[:, -1]

    chord = fairlead[:2] - anchor[:2]
    e = chord / np.linalg.norm(chord)
    H, lb0 = guess
    sol = root(lambda p: shoot(p)[1][:3] - fairlead, [H * e[0], H * e[1], lb0], method="hybr",
               options={"xtol": 1e-13})
    if not sol.success:
        raise RuntimeError(sol.message)
    td, end = shoot(sol.x)
    return {"anchor_reaction": np.array([-sol.x[0], -sol.x[1], 0.0]),
            "fairlead_reaction": end[3:], "lying_length": float(sol.x[2]),
            "touchdown": td[:3]}
