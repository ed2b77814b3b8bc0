"""The water and air around the cables of a step (docs/theory.md §13): the line's fluid
properties per element, the current, waves and wind, and the compiled Morison pass
(``catdae.element.fluid_kernel``) that turns them into nodal forces, added mass and their
derivatives. A scene without ``[water]`` and ``[air]`` has no :class:`Fluid` at all
(``Model.fluid is None``) and pays nothing.

Buoyancy is exact in statics where it can be: a cable that lies wholly below the still-water
level (both ends below it) carries its submerged weight w - ρ g π d²/4 (of either sign) in
the element itself (:func:`line_weight`, used by the mesh), so its
static nodes are those of the elastic catenary of the submerged weight. Other cables get their
buoyancy on the part of each element's chord below the instantaneous surface, and parts of a
submerged cable that a wave trough leaves in air lose theirs there; drag, added mass and the
Froude-Krylov force act on that wet part too (docs/theory.md §13.1-13.2).
"""

from __future__ import annotations

import math

import numpy as np

from catdae.case import Case
from catdae.case.fluid import Waves
from catdae.case.timefunc import Ramp
from catdae.element.fluid_kernel import fluid_pass
from catdae.element.fluid_kinematics import (
    LOG,
    NONE,
    POWER,
    PROFILE,
    UNIFORM,
    point_kinematics,
)

_EMPTY = np.zeros(0)


def line_weight(case: Case, cable) -> float:
    """Weight per unstrained metre under which a cable is meshed (N/m): the material's, less the
    buoyancy ρ g π d²/4 when the cable lies wholly in still water (:func:`buoyancy_in_weight`)."""
    mat = case.material_of(cable)
    if not buoyancy_in_weight(case, cable):
        return mat.weight
    return mat.weight - case.water.density * case.gravity * _area(mat.diameter)


def buoyancy_in_weight(case: Case, cable) -> bool:
    """Whether a whole cable lies in still water: water, a diameter, both ends at or below the
    still-water level (a buoyant cable too: its catenary then bulges above its chord)."""
    water = case.water
    mat = case.material_of(cable)
    if water is None or mat.diameter <= 0.0:
        return False
    ends = [case.nodes[n][2] for n in cable.ends]
    return max(ends) <= water.surface


def element_weights(case: Case, cable, z_nodes) -> tuple[np.ndarray, np.ndarray]:
    """(weight per unstrained metre (n,) N/m, whether it holds the buoyancy (n,) bool) of the n
    elements of a cable whose nodes are at heights ``z_nodes`` (n + 1,): the submerged weight
    for an element with both nodes at or below the still-water level (of either sign), the
    weight in air otherwise (its buoyancy then comes from the Morison pass, docs/theory.md
    §13.1). A cable wholly in water holds its buoyancy in every element."""
    mat = case.material_of(cable)
    z = np.asarray(z_nodes, float)
    n = z.size - 1
    water = case.water
    if water is None or mat.diameter <= 0.0:
        return np.full(n, mat.weight), np.zeros(n, bool)
    wsub = mat.weight - water.density * case.gravity * _area(mat.diameter)
    if buoyancy_in_weight(case, cable):
        held = np.ones(n, bool)
    else:
        held = np.maximum(z[:-1], z[1:]) <= water.surface
    return np.where(held, wsub, mat.weight), held


def _area(d: float) -> float:
    return math.pi * d * d / 4.0


def dispersion(omega: float, g: float, depth: float) -> float:
    """Wave number k (1/m) of ω² = g k tanh(k depth) (deep water: k = ω²/g)."""
    k = omega * omega / g
    if math.isinf(depth):
        return k
    k = max(k, omega / math.sqrt(g * depth))  # shallow-water start, below the root
    for _ in range(100):
        th = math.tanh(k * depth)
        f = g * k * th - omega * omega
        df = g * th + g * k * depth * (1.0 - th * th)
        dk = f / df
        k -= dk
        if abs(dk) <= 1e-15 * k:
            break
    return k


MICHE = 0.142  # breaking: H / L <= 0.142 tanh(k depth) (Miche 1944; 1/7 in deep water)
FAST_CURRENT = 10.0  # m/s: no ocean or river current comes near it


def plausibility_note(case: Case, waves: bool = True) -> str:
    """A word where the water is outside what its theory describes ("" when it is not): a
    regular wave (or a sea's significant height) steeper than the breaking limit, where
    linear (Airy) kinematics have no meaning, and a current faster than FAST_CURRENT (both
    are usually a typing slip: H = 60 for 6.0, a current in cm/s). ``waves``: say it of the
    waves too (transient steps; static and modal steps see still water)."""
    water = case.water
    if water is None:
        return ""
    notes = []
    wv = water.waves
    if waves and wv is not None and case.gravity > 0:
        h, t, what = ((wv.height, wv.period, "wave height") if wv.kind == "airy"
                      else (wv.hs, wv.tp, "significant height hs"))
        k = dispersion(2 * math.pi / t, case.gravity, water.depth)
        limit = MICHE * 2 * math.pi / k * (1.0 if math.isinf(water.depth)
                                           else math.tanh(k * water.depth))
        if h > limit:
            notes.append(f"the {what} {h:.4g} m at period {t:.4g} s is above the breaking "
                         f"limit {limit:.4g} m (H/L <= 0.142 tanh(k depth), wavelength "
                         f"{2 * math.pi / k:.4g} m): linear (Airy) kinematics are far outside "
                         "their range there")
    cur = water.current
    if cur is not None:
        fast = float(np.linalg.norm(np.asarray(cur.velocity, float).reshape(-1, 3),
                                    axis=1).max()) * _largest_factor(cur.time, case)
        if fast > FAST_CURRENT:
            notes.append(f"the current reaches {fast:.4g} m/s, above any ocean or river "
                         f"current ({FAST_CURRENT:g} m/s): check its units (m/s)")
    return "; ".join(notes)


def _largest_factor(tf, case: Case) -> float:
    """The largest |factor| of a time function over the case's simulated time (1 without
    one): a current ramped to 0.4 of 20 m/s reaches 8 m/s, not 20."""
    if tf is None:
        return 1.0
    end = sum(float(st.duration) for st in case.steps if st.kind == "transient")
    times = np.linspace(0.0, end, 4001) if end > 0.0 else np.zeros(1)
    values = np.broadcast_to(np.asarray(tf.evaluate(times)[0], float), times.shape)
    return float(np.abs(values).max())


def wave_components(waves: Waves, g: float, depth: float) -> tuple[np.ndarray, ...]:
    """(amplitude m, ω rad/s, k 1/m, cos heading, sin heading, phase rad) of every component.

    JONSWAP: ``components`` frequencies, one drawn at random in each of equal bins of
    [ωp/2, 3 ωp] (so the record does not repeat), amplitudes sqrt(2 S(ω) Δω) scaled so that
    4 (Σ a²/2)^½ = hs exactly, phases uniform in [0, 2π); ``seed`` fixes both draws.
    """
    b = math.radians(waves.heading)
    if waves.kind == "airy":
        om = np.array([2.0 * math.pi / waves.period])
        amp = np.array([0.5 * waves.height])
        ph = np.array([math.radians(waves.phase)])
    else:
        rng = np.random.default_rng(waves.seed)
        wp = 2.0 * math.pi / waves.tp
        n = int(waves.components)
        edges = np.linspace(0.5 * wp, 3.0 * wp, n + 1)
        dw = edges[1] - edges[0]
        om = edges[:-1] + dw * rng.random(n)
        sigma = np.where(om <= wp, 0.07, 0.09)
        r = np.exp(-((om - wp) ** 2) / (2.0 * sigma**2 * wp**2))
        s = om**-5.0 * np.exp(-1.25 * (wp / om) ** 4) * waves.gamma**r
        amp = np.sqrt(2.0 * s * dw)
        amp *= waves.hs / (4.0 * math.sqrt(0.5 * float(amp @ amp)))
        ph = 2.0 * math.pi * rng.random(n)
    k = np.array([dispersion(float(w), g, depth) for w in om])
    n = om.size
    return amp, om, k, np.full(n, math.cos(b)), np.full(n, math.sin(b)), ph


def _wave_ramp(waves: Waves) -> Ramp | None:
    """The waves rise over ``ramp`` s as the quintic smoothstep (C2: no restart needed)."""
    return Ramp(waves.ramp, smooth=True) if waves.ramp > 0 else None


def elevation(waves: Waves, g: float, depth: float, xy, times) -> np.ndarray:
    """The wave elevation above the still-water level (m), (n_times, n_points), at the points
    ``xy`` (n_points, 2) of the gravity frame's horizontal plane, as the Morison pass sees it
    (ramp included): for the water surface in the ParaView export."""
    amp, omega, wk, cosb, sinb, phase = wave_components(waves, g, depth)
    ramp = _wave_ramp(waves)
    xy = np.asarray(xy, float).reshape(-1, 2)
    t = np.asarray(times, float).reshape(-1)
    # η = r(t) Σ_c a_c cos(k_c (x cos β_c + y sin β_c) - ω_c t + φ_c), every point of a time
    # at once (surface_elevation's sum, point by point in the Morison pass)
    space = np.outer(xy[:, 0], wk * cosb) + np.outer(xy[:, 1], wk * sinb) + phase  # (p, c)
    out = np.empty((t.size, xy.shape[0]))
    for k in range(t.size):
        out[k] = np.cos(space - omega * t[k]) @ amp
    if ramp is not None:
        out *= ramp.evaluate(t)[0][:, None]
    return out


class Fluid:
    """The fluids of one step and the per-element line properties the Morison pass reads."""

    def __init__(self, case: Case, mesh, lumped_fraction: float, gauss_s, gauss_w):
        ne = mesh.n_elements
        self.g = case.gravity
        self.mu = float(lumped_fraction)
        self.conn = np.ascontiguousarray(mesh.conn, np.int64)
        self.l0 = mesh.L0
        self.gs, self.gw = gauss_s, gauss_w
        mats = [case.material_of(c) for c in case.cables]
        ce = mesh.cable_of_element

        def per(f):
            return np.ascontiguousarray([f(mats[k]) for k in ce], float).reshape(ne)

        self.diam = per(lambda m: m.diameter)
        self.area = np.pi * self.diam**2 / 4.0
        self.cdn = per(lambda m: m.drag_normal)
        self.cda = per(lambda m: m.drag_axial)
        self.can = per(lambda m: m.added_mass_normal)
        self.caa = per(lambda m: m.added_mass_axial)
        # the elements whose weight holds their buoyancy (as the mesh decided, from X0)
        self.in_weight = np.zeros(ne)
        z0 = mesh.X0[:, 2]
        for k, cable in enumerate(case.cables):
            els = np.flatnonzero(ce == k)
            if els.size:
                zs = np.concatenate([z0[mesh.conn[els, 0]], z0[mesh.conn[els[-1:], 1]]])
                self.in_weight[els] = element_weights(case, cable, zs)[1]
        water, air = case.water, case.air
        self.water, self.air = water, air
        self.rho_w = water.density if water is not None else 0.0
        self.surface = water.surface if water is not None else 0.0
        self.depth = water.depth if water is not None else math.inf
        cur = water.current if water is not None else None
        self.c_time = cur.time if cur is not None else None
        if cur is None:
            self.c_kind, self.c_vec, self.c_z, self.c_v = NONE, np.zeros(3), _EMPTY, \
                np.zeros((0, 3))
        elif not cur.z:
            self.c_kind, self.c_vec = UNIFORM, np.array(cur.velocity[0], float)
            self.c_z, self.c_v = _EMPTY, np.zeros((0, 3))
        else:
            self.c_kind, self.c_vec = PROFILE, np.zeros(3)
            self.c_z = np.array(cur.z, float)
            self.c_v = np.ascontiguousarray(cur.velocity, float).reshape(-1, 3)
        waves = water.waves if water is not None else None
        self.waves = waves
        self.wave = (wave_components(waves, self.g, self.depth) if waves is not None
                     else (_EMPTY,) * 6)
        self._ramp = _wave_ramp(waves) if waves is not None else None
        self.rho_a = air.density if air is not None else 0.0
        wind = air.wind if air is not None else None
        self.a_time = wind.time if wind is not None else None
        self.a_vec = np.zeros(3)
        self.a_speed, self.a_dir = 0.0, np.zeros(3)
        self.a_expo, self.a_zref, self.a_ground = 0.0, 10.0, 0.0
        self.a_kind = NONE
        if wind is not None:
            vec = np.array(wind.vector, float)
            self.a_kind = {"uniform": UNIFORM, "power": POWER, "log": LOG}[wind.profile]
            self.a_vec = vec
            self.a_speed = float(np.linalg.norm(vec))
            self.a_dir = vec / self.a_speed if self.a_speed > 0 else np.zeros(3)
            self.a_expo, self.a_zref = wind.parameter, wind.reference_height
            self.a_ground = (wind.ground if wind.ground is not None else
                             self.surface if water is not None else 0.0)
        self.t = 0.0  # time of a static or modal step
        self.current_factor = 1.0  # times the current: a static step's ramp on a rigid seabed
        self._static_key = None
        self._static = None
        nd = 3 * mesh.n_nodes
        self.out = np.zeros(nd)
        self.ma = np.zeros((ne, 6, 6))
        self.kx = np.zeros((ne, 6, 6))
        self.kv = np.zeros((ne, 6, 6))

    @classmethod
    def of(cls, case: Case, mesh, lumped_fraction, gauss_s, gauss_w) -> Fluid | None:
        """The fluid of a scene, or None when it has neither water nor air."""
        if case.water is None and case.air is None:
            return None
        return cls(case, mesh, lumped_fraction, gauss_s, gauss_w)

    @property
    def has_current(self) -> bool:
        """A current is given (uniform or a profile; its time function aside)."""
        return self.c_kind != NONE

    @property
    def has_flow(self) -> bool:
        """A current or a wind is given (their time functions aside)."""
        return self.c_kind != NONE or self.a_kind != NONE

    # ---------------------------------------------------------------------------- time
    def _factors(self, t: float, waves: bool):
        cf = self.current_factor * (1.0 if self.c_time is None else
                                    float(self.c_time.evaluate(t)[0]))
        af = 1.0 if self.a_time is None else float(self.a_time.evaluate(t)[0])
        r, dr = 1.0, 0.0
        if waves and self._ramp is not None:
            r, dr = (float(x) for x in self._ramp.evaluate(t)[:2])
        return cf, af, r, dr

    def time_functions(self) -> list:
        """The time functions of the current and wind, whose kinks and jumps restart a
        transient (the wave ramp is C2 and has none)."""
        return [tf for tf in (self.c_time, self.a_time) if tf is not None]

    # ---------------------------------------------------------------------------- the pass
    def evaluate(self, t: float, X, V, A, want_jac: bool = False, waves: bool = True):
        """Run the pass: ``out`` (n_dof,) = M_a A - f_fluid, ``ma``, ``kx``, ``kv`` (n_elem,
        6, 6) (docs/theory.md §13); the arrays are the Fluid's own buffers."""
        cf, af, r, dr = self._factors(t, waves)
        wave = self.wave if waves else (_EMPTY,) * 6
        fluid_pass(np.ascontiguousarray(X, float).reshape(-1),
                   np.ascontiguousarray(V, float).reshape(-1),
                   np.ascontiguousarray(A, float).reshape(-1), self.conn, self.l0, self.gs,
                   self.gw, self.area, self.diam, self.cdn, self.cda, self.can, self.caa,
                   self.in_weight, self.mu, self.g, self.rho_w, self.surface, self.depth,
                   self.c_kind, self.c_vec, self.c_z, self.c_v, cf, *wave, r, dr,
                   self.rho_a, self.a_kind, self.a_vec, self.a_speed, self.a_dir, self.a_expo,
                   self.a_zref, self.a_ground, af, float(t), want_jac, self.out, self.ma,
                   self.kx, self.kv)
        return self.out, self.ma, self.kx, self.kv

    def static(self, X):
        """(-f (n_dof,), -∂f/∂X (n_elem, 6, 6)) of the fluid on the line at rest in still
        water at the static time ``self.t`` (buoyancy, steady current and wind drag; no
        waves). The last result is kept for the positions it was computed at."""
        X = np.asarray(X, float).reshape(-1)
        key = (self.t, self.current_factor, X.tobytes())
        if self._static_key != key:
            z = np.zeros(X.size)
            out, _, kx, _ = self.evaluate(self.t, X, z, z, want_jac=True, waves=False)
            self._static = (out.copy(), kx.copy())
            self._static_key = key
        return self._static

    def mass(self, X, t: float = 0.0) -> np.ndarray:
        """Element added-mass matrices (n_elem, 6, 6) about positions X (still water)."""
        z = np.zeros(np.size(X))
        return self.evaluate(t, X, z, z, waves=False)[1]

    def kinematics(self, points: np.ndarray, t: float, waves: bool = True):
        """Surface elevation above the still level at the points' (x, y), (n,) m, and the fluid
        velocity at the points (water below the surface, air above), (n, 3) m/s; without
        ``waves`` in still water (as static and modal steps see it)."""
        cf, af, r, dr = self._factors(t, waves)
        pts = np.ascontiguousarray(points, float).reshape(-1, 3)
        eta = np.zeros(pts.shape[0])
        vel = np.zeros((pts.shape[0], 3))
        point_kinematics(pts, float(t), self.rho_w, self.surface, self.depth, self.c_kind,
                         self.c_vec, self.c_z, self.c_v, cf,
                         *(self.wave if waves else (_EMPTY,) * 6), r, dr, self.rho_a,
                         self.a_kind, self.a_vec, self.a_speed, self.a_dir, self.a_expo,
                         self.a_zref, self.a_ground, af, eta, vel)
        return eta, vel
