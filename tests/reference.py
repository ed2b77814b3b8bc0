"""Independent reference solutions for suspended cables (Irvine 1981, *Cable Structures*).

Written from the textbook, not from the ``catdae`` package, so that the package's tests can compare
against something that shares no code with it. SI units throughout; z is up and gravity acts along
-z. Nothing here imports ``catdae``.

Contents
--------
``irvine_catenary``             2-D elastic catenary between two supports (exact, no point loads).
``irvine_catenary_inclined_3d`` the same for arbitrary support positions in 3-D.
``irvine_symmetric_roots``      roots of Irvine & Caughey's symmetric in-plane frequency equation.
``irvine_caughey_frequencies``  linear free-vibration frequencies of a shallow level cable (Hz).
``taut_string_frequencies``     frequencies of a weightless taut string (Hz).
``grounded_catenary``           elastic catenary from an anchor on a rigid frictionless seabed.
``string_with_damper``          exact eigenvalue of a taut string with a viscous damper.
``level_catenary_midspan``      midspan of a level elastic catenary with a thermal strain.

Formulation of the statics (chosen to differ from the package's: origin at support i, unknowns H and
the mid-length vertical tension c, two nested scalar root solves with ``brentq`` instead of a Newton
iteration on a 3-vector).  With s the unstrained arc length from support i and the tension vector
along increasing s written (H, u(s)), u(s) = V_i + w s, T = sqrt(H^2 + u^2), Hooke's law
ds_stretched/ds = 1 + T/EA and the tangent (H, u)/T give the ODE

    dx/ds = H/T + H/EA,        dz/ds = u/T + u/EA,

integrated from s = a to s = b = a + L (Irvine 1981, eqs. 2.xx, rearranged to avoid cancellation):

    x_b - x_a = H L/EA + (H/w) [asinh(u_b/H) - asinh(u_a/H)]
    z_b - z_a = (u_a L + w L^2/2)/EA + L (u_a + u_b)/(T_a + T_b)

where the second term of z uses T_b - T_a = w L (u_a + u_b)/(T_a + T_b), and the asinh difference is
evaluated as asinh(w L (u_a + u_b)/(u_b T_a + u_a T_b)) when u_a, u_b have the same sign.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

__all__ = [
    "irvine_catenary",
    "irvine_catenary_inclined_3d",
    "irvine_symmetric_roots",
    "irvine_caughey_frequencies",
    "taut_string_frequencies",
    "grounded_catenary",
    "level_catenary_midspan",
]

_EPS = np.finfo(float).eps
_RTOL = 4.0 * _EPS  # brentq's smallest allowed rtol


# --------------------------------------------------------------------------------------------------
# 2-D elastic catenary
# --------------------------------------------------------------------------------------------------
def _asinh_diff(ub, ua, H, wL):
    """asinh(ub/H) - asinh(ua/H) without cancellation (ub - ua = wL >= 0)."""
    ub = np.asarray(ub, dtype=float)
    ua = np.asarray(ua, dtype=float)
    Ta = np.hypot(H, ua)
    Tb = np.hypot(H, ub)
    same = ua * ub > 0.0
    den = np.where(same, ub * Ta + ua * Tb, 1.0)
    stable = np.arcsinh(np.where(same, wL * (ua + ub) / den, 0.0))
    direct = np.arcsinh(ub / H) - np.arcsinh(ua / H)
    return np.where(same, stable, direct)


def _segment(H, ua, L, w, EA):
    """Chord (dx, dz) of an unstrained length L starting with vertical tension ua."""
    L = np.asarray(L, dtype=float)
    ua = np.asarray(ua, dtype=float)
    ub = ua + w * L
    Ta = np.hypot(H, ua)
    Tb = np.hypot(H, ub)
    flex = 0.0 if math.isinf(EA) else 1.0 / EA
    dx = H * L * flex + (H / w) * _asinh_diff(ub, ua, H, w * L)
    dz = (ua * L + 0.5 * w * L * L) * flex + L * (ua + ub) / (Ta + Tb)
    return dx, dz


def _z_end(H, c, L0, w, EA):
    """Height of the end s = L0 when the vertical tension at mid-length (s = L0/2) is c."""
    return _segment(H, c - 0.5 * w * L0, L0, w, EA)[1]


def _solve_c(H, L0, w, EA, dz):
    """Mid-length vertical tension c for given H such that the end is at height dz.

    z_end is strictly increasing in c (d z_end/dc = L0/EA + (u_j/T_j - u_i/T_i)/w > 0).
    """
    if dz == 0.0:
        return 0.0  # z_end is odd in c
    C = max(w * L0, H)
    for _ in range(2000):
        if _z_end(H, C, L0, w, EA) > dz and _z_end(H, -C, L0, w, EA) < dz:
            break
        C *= 2.0
    else:  # pragma: no cover - only for impossible data
        raise ValueError("cannot bracket the vertical tension (is |dz| >= L0 with EA = inf?)")
    return brentq(lambda c: _z_end(H, c, L0, w, EA) - dz, -C, C, xtol=1e-300, rtol=_RTOL,
                  maxiter=500)


def irvine_catenary(span: float, dz: float, L0: float, EA: float, w: float) -> dict:
    """Elastic catenary between supports i = (0, 0) and j = (span, dz) (2-D, x horizontal, z up).

    Parameters
    ----------
    span : horizontal distance from i to j, > 0 [m].
    dz : height of j above i [m] (may be negative).
    L0 : unstrained length [m], > 0.
    EA : axial stiffness [N], > 0; ``math.inf`` gives the inextensible catenary.
    w : weight per unit UNSTRAINED length [N/m], > 0.

    Returns
    -------
    dict with
      ``H``       horizontal tension component (> 0) [N], constant along the cable;
      ``V_i``     vertical component of the tension vector at s = 0 taken along increasing s,
                  i.e. the cable pulls support i with the force (H, V_i) (level sagging span:
                  V_i = -w L0/2 < 0);
      ``V_j``     vertical component of the tension vector at s = L0 along increasing s
                  (V_j = V_i + w L0; the cable pulls support j with (-H, -V_j));
      ``T_i``, ``T_j``  tension magnitudes at the supports;
      ``sag``     max over the cable of (chord height - cable height), measured vertically.
                  Since w > 0 the cable curve z(x) is convex (dz/dx = u/H increases with s), so
                  the sag is > 0 and is attained where the tangent is parallel to the chord,
                  u(s_sag) = H dz/span;
      ``s_sag``   unstrained arc length at which ``sag`` is attained;
      ``x``       callable s -> (x(s), z(s)), vectorised over s in [0, L0] (position of the
                  material point s, stretched configuration);
      ``lowest_z`` lowest height of the cable (0 or dz if the low point is at a support);
      ``s_low``   arc length of the lowest point (clipped to [0, L0]);
      ``stretched_length``  L0 + int_0^L0 T/EA ds;
      ``residual``  max |end position - (span, dz)| of the solution [m] (self check).

    Tolerance: H and V are solved with brentq at rtol = 4 eps; the end residual is checked to be
    below 1e-13 * max(span, |dz|, L0) (a RuntimeError otherwise). H and V then agree with a
    40-digit solve to ~1e-15 relative for slack cables; for taut cables the problem itself is
    ill-conditioned (H ~ EA (chord - L0)/L0, condition number ~ EA/H) and the agreement is
    ~eps EA/H (measured 3e-13 at EA/H = 3e4). Compare with rtol >= 1e-12 (taut: 1e-10).
    """
    span = float(span)
    dz = float(dz)
    L0 = float(L0)
    EA = float(EA)
    w = float(w)
    if not (span > 0.0 and L0 > 0.0 and w > 0.0 and EA > 0.0):
        raise ValueError("need span > 0, L0 > 0, w > 0 and EA > 0")
    if math.isinf(EA) and math.hypot(span, dz) >= L0:
        raise ValueError("inextensible cable shorter than (or equal to) the chord")

    def x_end(H):
        c = _solve_c(H, L0, w, EA, dz)
        return float(_segment(H, c - 0.5 * w * L0, L0, w, EA)[0])

    # x_end increases with H from 0 (H -> 0) to infinity: bracket geometrically.
    lo = hi = w * L0
    for _ in range(3000):
        if x_end(lo) < span:
            break
        lo *= 0.5
    else:  # pragma: no cover
        raise RuntimeError("cannot bracket H from below")
    for _ in range(3000):
        if x_end(hi) > span:
            break
        hi *= 2.0
    else:  # pragma: no cover
        raise RuntimeError("cannot bracket H from above")
    H = brentq(lambda h: x_end(h) - span, lo, hi, xtol=1e-300, rtol=_RTOL, maxiter=500)
    c = _solve_c(H, L0, w, EA, dz)
    V_i = c - 0.5 * w * L0
    V_j = c + 0.5 * w * L0
    T_i = math.hypot(H, V_i)
    T_j = math.hypot(H, V_j)

    def position(s):
        s_arr = np.asarray(s, dtype=float)
        px, pz = _segment(H, V_i, s_arr, w, EA)
        if s_arr.ndim == 0:
            return float(px), float(pz)
        return px, pz

    xe, ze = position(L0)
    residual = max(abs(xe - span), abs(ze - dz))
    scale = max(span, abs(dz), L0)
    if residual > 1e-13 * scale:
        raise RuntimeError(f"elastic catenary residual {residual:.3e} m too large")

    slope = dz / span
    s_sag = min(max((H * slope - V_i) / w, 0.0), L0)  # tangent parallel to the chord
    xs, zs = position(s_sag)
    sag = max(slope * xs - zs, 0.0)
    s_low = min(max(-V_i / w, 0.0), L0)  # u(s) = 0
    lowest_z = min(position(s_low)[1], 0.0, dz)

    # int T ds = [u T + H^2 asinh(u/H)] / (2 w) between V_i and V_j
    int_T = (V_j * T_j - V_i * T_i + H * H * float(_asinh_diff(V_j, V_i, H, w * L0))) / (2.0 * w)
    stretched = L0 + (0.0 if math.isinf(EA) else int_T / EA)

    return dict(H=H, V_i=V_i, V_j=V_j, T_i=T_i, T_j=T_j, sag=sag, s_sag=s_sag, x=position,
                lowest_z=lowest_z, s_low=s_low, stretched_length=stretched, residual=residual)


def irvine_catenary_inclined_3d(A, B, L0: float, EA: float, w: float) -> dict:
    """Elastic catenary between arbitrary support points A (s = 0) and B (s = L0) in 3-D.

    The vertical plane through A and B is rotated onto the x-z plane, ``irvine_catenary`` is
    solved there and the result is rotated back. B must not lie vertically above/below A.

    Returns dict with
      ``h``    np.array (Hx, Hy, Vz): tension vector at A along increasing s = the force with which
               the cable pulls support A (Hx, Hy point horizontally from A towards B);
      ``t_B``  np.array: tension vector at B along increasing s (the cable pulls B with -t_B);
               t_B - h = (0, 0, w L0);
      ``T_A``, ``T_B``  tension magnitudes;
      ``e``    unit horizontal vector from A towards B;
      ``planar``  the full ``irvine_catenary`` dict of the rotated problem;
      ``x``    callable s -> array of shape s.shape + (3,), global position of material point s.
    """
    A = np.asarray(A, dtype=float).reshape(3)
    B = np.asarray(B, dtype=float).reshape(3)
    d = B - A
    span = math.hypot(d[0], d[1])
    if span <= 0.0:
        raise ValueError("vertical chord: not supported by the planar reference")
    e = np.array([d[0] / span, d[1] / span, 0.0])
    sol = irvine_catenary(span, d[2], L0, EA, w)
    h = np.array([sol["H"] * e[0], sol["H"] * e[1], sol["V_i"]])
    t_B = np.array([sol["H"] * e[0], sol["H"] * e[1], sol["V_j"]])

    def position(s):
        px, pz = sol["x"](np.asarray(s, dtype=float))
        px = np.asarray(px)
        pz = np.asarray(pz)
        return np.stack([A[0] + px * e[0], A[1] + px * e[1], A[2] + pz], axis=-1)

    return dict(h=h, t_B=t_B, T_A=sol["T_i"], T_B=sol["T_j"], e=e, planar=sol, x=position)


# --------------------------------------------------------------------------------------------------
# Linear free vibration (Irvine & Caughey 1974; Irvine 1981, ch. 3)
# --------------------------------------------------------------------------------------------------
def irvine_symmetric_roots(lambda2: float, n: int = 3) -> np.ndarray:
    """First n roots wb = omega l / sqrt(H/m) of tan(wb/2) = wb/2 - (4/lambda2) (wb/2)^3.

    With y = wb/2 and c = 4/lambda2 the equation is g(y) = tan y - y + c y^3 = 0. g > 0 on
    (0, pi/2) and g' = tan^2 y + 3 c y^2 > 0, so there is exactly one root on each branch
    ((k - 1/2) pi, (k + 1/2) pi), k = 1, 2, ... It is found as the root of the pole-free
    G(y) = cos(y) g(y) = sin y - (y - c y^3) cos y, which equals +-1 at the branch ends, so the
    closed bracket is valid for any lambda2 in (0, inf] (including lambda2 = 4 pi^2, where the
    first root is exactly wb = 2 pi, inside the first branch).

    lambda2 -> 0: wb -> pi, 3 pi, 5 pi (taut string); lambda2 = inf: roots of tan y = y.
    """
    if not lambda2 > 0.0:
        raise ValueError("lambda2 must be > 0")
    c = 0.0 if math.isinf(lambda2) else 4.0 / lambda2

    def G(y):
        return (math.sin(y) - (y - c * y**3) * math.cos(y)) / (1.0 + c * y**3)

    roots = []
    for k in range(1, n + 1):
        a = (k - 0.5) * math.pi
        b = (k + 0.5) * math.pi
        Ga, Gb = G(a), G(b)
        if Ga == 0.0:  # pragma: no cover - cos(a) is never exactly 0 in floating point
            y = a
        elif Gb == 0.0:  # pragma: no cover
            y = b
        else:
            y = brentq(G, a, b, xtol=1e-300, rtol=_RTOL, maxiter=500)
        roots.append(2.0 * y)
    return np.array(roots)


def irvine_caughey_frequencies(span: float, H: float, m: float, w: float, EA: float,
                               L0: float | None = None, n: int = 3) -> dict:
    """Linear natural frequencies [Hz] of a shallow, level, sagging cable (Irvine & Caughey 1974).

    Parameters
    ----------
    span : l [m]; H : static horizontal tension [N]; EA [N] (``math.inf`` allowed);
    m : mass per unit length [kg/m]; w : weight per unit length [N/m];
    L0 : optional unstrained length. If given, m and w are taken per unit UNSTRAINED length and
         converted to the per-unit-span values the shallow theory uses (total mass m L0 and
         weight w L0 spread evenly over the span, i.e. both multiplied by L0/l). If None
         (default) m and w are already per unit span.
    n : number of frequencies of each family.

    Theory: d = w l^2 / (8 H), L_e = l (1 + 8 (d/l)^2), lambda2 = (w l/H)^2 l / (H L_e / EA).
      out-of-plane:          omega_n = n pi / l sqrt(H/m),  n = 1, 2, ...
      in-plane antisymmetric: omega_n = 2 n pi / l sqrt(H/m)
      in-plane symmetric:    omega = wb sqrt(H/m) / l, wb from ``irvine_symmetric_roots``.

    Returns dict(out_of_plane=, antisymmetric=, symmetric= (np.arrays of n values in Hz),
    lambda2=, sag=d, Le=L_e, wb_symmetric= (the dimensionless roots)).
    """
    l = float(span)
    m_eff = float(m)
    w_eff = float(w)
    if L0 is not None:
        m_eff *= L0 / l
        w_eff *= L0 / l
    d = w_eff * l * l / (8.0 * H)
    Le = l * (1.0 + 8.0 * (d / l) ** 2)
    lambda2 = math.inf if math.isinf(EA) else (w_eff * l / H) ** 2 * l * EA / (H * Le)
    c0 = math.sqrt(H / m_eff)  # wave speed
    k = np.arange(1, n + 1)
    to_hz = c0 / (2.0 * math.pi * l)
    wb = irvine_symmetric_roots(lambda2, n)
    return dict(
        out_of_plane=k * math.pi * to_hz,
        antisymmetric=2.0 * k * math.pi * to_hz,
        symmetric=wb * to_hz,
        lambda2=lambda2,
        sag=d,
        Le=Le,
        wb_symmetric=wb,
    )


def taut_string_frequencies(span: float, T: float, m: float, n: int = 3) -> np.ndarray:
    """Frequencies [Hz] of a weightless taut string: f_k = k / (2 l) sqrt(T/m), k = 1..n."""
    return np.arange(1, n + 1) * math.sqrt(T / m) / (2.0 * span)


# --------------------------------------------------------------------------------------------------
# 2-D elastic catenary with a weight per length that changes along the cable
# --------------------------------------------------------------------------------------------------
def piecewise_catenary(span: float, dz: float, EA: float, pieces) -> dict:
    """Elastic catenary from i = (0, 0) to j = (span, dz) whose weight per unstrained length is
    constant on each of ``pieces`` = [(L_k, w_k), ...] (in order from i, w_k > 0): self-weight
    plus a vertical load over part of the cable, for instance.

    Each piece is the closed form ``_segment`` started with the vertical tension at its start,
    u continuing from piece to piece (u_b = u_a + w_k L_k); H is constant. (H, V_i) solve the two
    end conditions by ``scipy.optimize.root`` from the uniform catenary of the mean weight.
    Returns ``H``, ``V_i``, ``V_j`` (tension vector along increasing s, as in
    ``irvine_catenary``), ``position`` (s -> (x, z)) and ``residual`` (m).
    """
    from scipy.optimize import root

    L = np.array([p[0] for p in pieces], float)
    w = np.array([p[1] for p in pieces], float)
    starts = np.concatenate([[0.0], np.cumsum(L)])

    def position(s, H, V):
        s = float(s)
        x = z = 0.0
        u = V
        for k in range(L.size):
            part = min(max(s - starts[k], 0.0), L[k])
            dx, dzk = _segment(H, u, part, w[k], EA)
            x, z, u = x + float(dx), z + float(dzk), u + w[k] * L[k]
        return x, z

    total = float(L.sum())
    mean = irvine_catenary(span, dz, total, EA, float((w * L).sum() / total))
    scale = (mean["H"], abs(mean["V_i"]) + mean["H"])

    def ends(y):
        H, V = y[0] * scale[0], y[1] * scale[1]
        xe, ze = position(total, H, V)
        return [(xe - span) / span, (ze - dz) / span]

    sol = root(ends, [1.0, mean["V_i"] / scale[1]], method="hybr", tol=1e-15)
    H, V = sol.x[0] * scale[0], sol.x[1] * scale[1]
    residual = float(np.max(np.abs(ends(sol.x)))) * span
    if residual > 1e-11 * span:
        raise RuntimeError(f"piecewise catenary residual {residual:.3e} m too large")
    return {"H": H, "V_i": V, "V_j": V + float((w * L).sum()),
            "position": lambda s: position(s, H, V), "residual": residual}


# --------------------------------------------------------------------------------------------------
# grounded elastic catenary (an anchor on a rigid, frictionless, flat seabed)
# --------------------------------------------------------------------------------------------------
def grounded_catenary(span: float, height: float, L0: float, EA: float, w: float) -> dict:
    """A line from an anchor on the seabed to a fairlead ``span`` away horizontally and
    ``height`` above it, part of it lying on the seabed (the closed form of MoorPy's and FAST's
    quasi-static line, with no friction).

    The lying length L_B carries the horizontal tension H alone (stretched by H/EA); the
    suspended length l_s = L0 - L_B rises as a catenary with zero slope at the touchdown point.
    Unknowns H and l_s, by two nested ``brentq`` solves: for given H, l_s from the height

        height = (H/w) (sqrt(1 + (w l_s/H)^2) - 1) + w l_s^2/(2 EA),

    then H from the span, span = L_B + (H/w) asinh(w l_s/H) + H L0/EA.
    Returns H, fairlead vertical force V = w l_s, lying length L_B and the touchdown distance
    x_td = L_B (1 + H/EA) from the anchor, and the fairlead and anchor tension magnitudes.
    """

    def rise(H, ls):
        a = w * ls / H
        return (H / w) * a * a / (math.sqrt(1.0 + a * a) + 1.0) + w * ls * ls / (2.0 * EA)

    def suspended(H):
        if rise(H, L0) < height:
            raise ValueError("the line cannot reach the fairlead with a part on the seabed")
        return brentq(lambda ls: rise(H, ls) - height, 0.0, L0, xtol=1e-300, rtol=_RTOL,
                      maxiter=500)

    def span_of(H):
        ls = suspended(H)
        return (L0 - ls) + (H / w) * math.asinh(w * ls / H) + H * L0 / EA - span

    lo = 1e-9 * w * L0
    hi = w * L0
    while span_of(hi) < 0.0:
        hi *= 2.0
    H = brentq(span_of, lo, hi, xtol=1e-300, rtol=_RTOL, maxiter=500)
    ls = suspended(H)
    LB = L0 - ls
    V = w * ls
    return {"H": H, "V": V, "lying_length": LB, "touchdown_x": LB * (1.0 + H / EA),
            "fairlead_tension": math.hypot(H, V), "anchor_tension": H}


def grounded_line(span: float, height: float, segments) -> dict:
    """A mooring line of several uniform segments in series, ``segments`` = [(L0, EA, w), ...]
    from the fairlead down to the anchor on a frictionless seabed ``span`` away horizontally
    and ``height`` below the fairlead; shot down from the fairlead. A fourth entry is a
    vertical force at the segment's lower joint (up positive: a buoy; a clump weight is
    negative), which V takes on below it (a joint that rests on the seabed passes it on).

    With the fairlead's forces (H, V), a segment hanging from the vertical tension V_top has
    V_bot = V_top - w L0 at its lower end; while V_bot >= 0 it is an elastic catenary
    (Irvine: dx = (H/w)(asinh(V_top/H) - asinh(V_bot/H)) + H L0/EA, dz = (H/w)(sqrt(1 +
    (V_top/H)^2) - sqrt(1 + (V_bot/H)^2)) + (V_top^2 - V_bot^2)/(2 EA w)); otherwise it
    touches down after l_s = V_top/w and the rest lies flat, stretched by H/EA, as does every
    segment below. Unknowns H and V by nested ``brentq``: V from the height at given H, H from
    the span. Returns H, V, the lying length and the joints' (dx, dz) from the fairlead
    (positive away from it and downwards), the anchor last.
    """

    def shoot(H, V):
        x = z = lying = 0.0
        joints = []
        for L0, EA, w, *up in segments:
            lo = V - w * L0
            if lo >= 0.0:
                x += (H / w) * (math.asinh(V / H) - math.asinh(lo / H)) + H * L0 / EA
                z += ((H / w) * (math.hypot(1.0, V / H) - math.hypot(1.0, lo / H))
                      + (V * V - lo * lo) / (2.0 * EA * w))
                V = lo
            else:
                ls = V / w
                x += ((H / w) * math.asinh(V / H) + H * ls / EA
                      + (L0 - ls) * (1.0 + H / EA))
                z += (H / w) * (math.hypot(1.0, V / H) - 1.0) + V * V / (2.0 * EA * w)
                lying += L0 - ls
                V = 0.0
            V = max(V + (up[0] if up else 0.0), 0.0)  # a buoy (+) or clump (-) at the joint
            joints.append((x, z))
        return x, z, lying, joints

    weight = sum(seg[0] * seg[2] + abs(seg[3] if len(seg) > 3 else 0.0) for seg in segments)

    def v_of(H):
        return brentq(lambda V: shoot(H, V)[1] - height, 0.0, 4.0 * weight, xtol=1e-300,
                      rtol=_RTOL, maxiter=500)

    H = brentq(lambda H: shoot(H, v_of(H))[0] - span, 1e-6 * weight, 10.0 * weight,
               xtol=1e-300, rtol=_RTOL, maxiter=500)
    V = v_of(H)
    _, _, lying, joints = shoot(H, V)
    return {"H": H, "V": V, "lying_length": lying, "joints": joints}


def string_with_damper(a_over_l: float, eta: float, mode: int = 1) -> complex:
    """The exact eigenvalue γ L (γ = s / c_w, s the Laplace variable) of a taut string of
    length L with a viscous damper at distance a from one end (Krenk 2000, J. Appl. Mech.
    67, 772-776):

        coth(γ a) + coth(γ (L - a)) + η = 0,     η = c / √(T m),

    followed by continuation in η from the undamped root γ L = i n π. The damping ratio is
    -Re γ / |γ|, the damped frequency Im γ c_w / 2π."""
    x1, x2 = a_over_l, 1.0 - a_over_l

    def f(g):
        return 1.0 / np.tanh(g * x1) + 1.0 / np.tanh(g * x2)

    def df(g):
        return -x1 / np.sinh(g * x1) ** 2 - x2 / np.sinh(g * x2) ** 2

    g = 1j * mode * np.pi
    if eta == 0.0:
        return complex(g)
    etas = np.concatenate([np.geomspace(1e-4 * min(eta, 1.0), eta, 400)])
    for e in etas:
        for _ in range(50):
            step = (f(g) + e) / df(g)
            g = g - step
            if abs(step) < 1e-14 * abs(g):
                break
    return complex(g)


def damper_sag_reduction(lambda2: float) -> float:
    """R = 1 - 3 (λ²/ω̄) dω̄/dλ² for the first symmetric in-plane mode (Irvine's root): the
    relative frequency shift when a point at a ≪ L is locked, over that of a taut string, to
    first order in a/L. The largest damping ratio a damper there can give is about ½ (a/L) R
    (docs/theory.md §16; the argument is the document's own, the roots Irvine's)."""
    h = 1e-4 * lambda2
    w = irvine_symmetric_roots(lambda2, 1)[0]
    dw = (irvine_symmetric_roots(lambda2 + h, 1)[0]
          - irvine_symmetric_roots(lambda2 - h, 1)[0]) / (2 * h)
    return 1.0 - 3.0 * lambda2 / w * dw


def level_catenary_midspan(L0, EA, w, eps_t, span=None):
    """(midspan height below the supports (< 0), H) of an elastic catenary of unstrained length
    L0 between level supports ``span`` apart (default L0) with stretch 1 + eps_t + T/EA
    (Irvine 1981, §2.2 with a thermal strain): span = H L0/EA + (1 + eps_t) (2H/w)
    asinh(w L0/(2H)), z_mid = (1 + eps_t) (H - sqrt(H² + (w L0/2)²))/w - w L0²/(8 EA)."""
    span = L0 if span is None else span

    def gap(H):
        return H * L0 / EA + (1.0 + eps_t) * 2.0 * H / w * math.asinh(w * L0 / (2.0 * H)) - span
    H = brentq(gap, 1e-6 * w * L0, 1e3 * w * L0, xtol=1e-13, rtol=1e-15)
    return ((1.0 + eps_t) * (H - math.hypot(H, 0.5 * w * L0)) / w
            - w * L0**2 / (8.0 * EA)), H
