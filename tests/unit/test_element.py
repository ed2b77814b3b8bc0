"""Physics checks of the exact 3-D elastic catenary element (``catdae.element.elements``).

Every assertion compares the element with something independent of its own earlier output:
finite differences of the chord and position maps, equilibrium of forces and moments on the solved
shape, Irvine's elastic catenary solved by a different method (``tests/reference.py``), closed forms
(straight bar, vertical bar, folded vertical cable, inextensible catenary, two straight bars) and
the exact identities of docs/theory.md §3-6.

Randomised 3-D elements (hypothesis) cover L0 in [0.5, 500] m, EA/(w L0) in [1e2, 1e8],
w in [0.1, 1000] N/m, chords of 0.3 L0 to 1.02 L0 in any direction (elevation within 89.9 degrees
of horizontal; exactly vertical chords have their own tests) and 0-4 point loads of up to three
times the cable weight in any direction at s inside (0, L0).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from catdae.element.elements import (
    CONVERGED,
    NOT_CONVERGED,
    SLACK,
    Elements,
    ElementState,
    PointLoads,
)

from reference import irvine_catenary, irvine_catenary_inclined_3d

EPS = np.finfo(float).eps
EZ = np.array([0.0, 0.0, 1.0])

# CATDAE_HYPOTHESIS_EXAMPLES=1000 runs a longer, randomised search (default: 60, derandomised)
_N_EXAMPLES = int(os.environ.get("CATDAE_HYPOTHESIS_EXAMPLES", "0"))
HYP = settings(max_examples=_N_EXAMPLES or 60, deadline=None, derandomize=not _N_EXAMPLES,
               suppress_health_check=[HealthCheck.too_slow])


# ----------------------------------------------------------------------------------------------
# cases and independent helpers
# ----------------------------------------------------------------------------------------------
@dataclass
class Case:
    L0: float
    EA: float
    w: float
    chord: np.ndarray
    loads: list[tuple[float, np.ndarray]] = field(default_factory=list)  # sorted by s

    def __repr__(self) -> str:  # full precision, so that a falsifying example can be replayed
        loads = [(float(sk), np.asarray(fk, float).tolist()) for sk, fk in self.loads]
        return (f"Case(L0={self.L0!r}, EA={self.EA!r}, w={self.w!r}, "
                f"chord=np.array({np.asarray(self.chord, float).tolist()!r}), "
                f"loads=[(s, np.array(f)) for s, f in {loads!r}])")

    def elements(self) -> Elements:
        return one(self.L0, self.EA, self.w, self.loads)

    @property
    def load_s(self) -> np.ndarray:
        return np.array([s for s, _ in self.loads])

    @property
    def load_f(self) -> np.ndarray:
        return np.array([f for _, f in self.loads]).reshape(-1, 3)


def one(L0, EA, w, loads=()) -> Elements:
    """A batch of one element."""
    return Elements([L0], [EA], [w], PointLoads.from_lists([list(loads)]))


def tension_vec(h, w, load_s, load_f, s) -> np.ndarray:
    """t(s) = h + w s e_z - sum_{s_k < s} f_k (docs/theory.md §1), written here independently."""
    t = np.asarray(h, float) + w * s * EZ
    for sk, fk in zip(load_s, load_f, strict=True):
        if sk < s:
            t = t - fk
    return t


def segments(case: Case) -> list[tuple[float, float]]:
    """The load-free stretches [a, b] of the element."""
    cuts = [0.0, *sorted(set(case.load_s.tolist())), case.L0]
    return [(a, b) for a, b in zip(cuts[:-1], cuts[1:], strict=True) if b > a]


def min_tension(case: Case, h) -> float:
    """Smallest tension along the element (T is convex in s on each load-free stretch)."""
    tmin = math.inf
    for a, b in segments(case):
        ta = tension_vec(h, case.w, case.load_s, case.load_f, 0.5 * (a + b)) - case.w * (
            0.5 * (a + b) - a) * EZ
        tb = ta + case.w * (b - a) * EZ
        tmin = min(tmin, np.linalg.norm(ta), np.linalg.norm(tb))
        if ta[2] * tb[2] < 0.0:
            tmin = min(tmin, math.hypot(ta[0], ta[1]))
    return tmin


def graded_edges(a, b, c, scale):
    """Edges on [a, b] refined geometrically towards c in [a, b], finest piece ~ scale."""
    edges = [c]
    d = scale
    while c + d < b:
        edges.append(c + d)
        d *= 2.0
    edges.append(b)
    d = scale
    while c - d > a:
        edges.insert(0, c - d)
        d *= 2.0
    edges.insert(0, a)
    return np.unique(edges)


def gauss_nodes(case: Case, h, order: int = 24):
    """Composite Gauss-Legendre nodes and weights over [0, L0] for integrating x(s).

    Split at the loads and graded towards the point of least tension of each stretch, where the
    cable bends over a length ~ H/w.
    """
    xg, wg = np.polynomial.legendre.leggauss(order)
    s_all, w_all = [], []
    for a, b in segments(case):
        t_a = tension_vec(h, case.w, case.load_s, case.load_f, 0.5 * (a + b)) - case.w * (
            0.5 * (a + b) - a) * EZ
        H = math.hypot(t_a[0], t_a[1])
        if case.w > 0.0:
            c = min(max(a - t_a[2] / case.w, a), b)  # u = 0, or the end nearest to it
            scale = max(H / case.w, 1e-9 * (b - a))
        else:
            c, scale = a, b - a
        edges = graded_edges(a, b, c, min(scale, b - a))
        for lo, hi in zip(edges[:-1], edges[1:], strict=True):
            s_all.append(0.5 * (lo + hi) + 0.5 * (hi - lo) * xg)
            w_all.append(0.5 * (hi - lo) * wg)
    return np.concatenate(s_all), np.concatenate(w_all)


def solve(case: Case, h0=None) -> tuple[Elements, ElementState]:
    el = case.elements()
    state = el.solve(case.chord[None, :], None if h0 is None else np.asarray(h0)[None, :])
    return el, state


def h_tol(state: ElementState, size, rtol=1e-10) -> float:
    """What h can be determined to when the chord is known to round-off of size: |K| eps size."""
    return rtol * np.linalg.norm(state.h[0]) + 64 * EPS * np.linalg.norm(state.K[0], 2) * size


# ----------------------------------------------------------------------------------------------
# hypothesis strategies
# ----------------------------------------------------------------------------------------------
def log_uniform(lo, hi):
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0**e)


def direction(max_elev_deg=90.0):
    def unit(az_el):
        az, el = az_el
        el = math.radians(el)
        return np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])

    return st.tuples(st.floats(0.0, 2 * math.pi), st.floats(-max_elev_deg, max_elev_deg)).map(unit)


@st.composite
def cases(draw, min_loads=0, max_loads=4, max_elev_deg=89.9):
    L0 = draw(log_uniform(0.5, 500.0))
    w = draw(log_uniform(0.1, 1000.0))
    EA = draw(log_uniform(1e2, 1e8)) * w * L0
    chord = draw(st.floats(0.3, 1.02)) * L0 * draw(direction(max_elev_deg))
    fracs = draw(st.lists(st.floats(0.01, 0.99), min_size=min_loads, max_size=max_loads,
                          unique=True))
    loads = []
    for frac in sorted(fracs):
        size = draw(st.floats(0.0, 3.0)) * w * L0
        loads.append((frac * L0, size * draw(direction())))
    return Case(L0, EA, w, chord, loads)


# ----------------------------------------------------------------------------------------------
# convergence, status, finiteness, iteration counts
# ----------------------------------------------------------------------------------------------
MAX_ITER = 100  # Elements.solve's default


def solved(el: Elements, state: ElementState, chord, L0) -> bool:
    """Every element converged, and its h reproduces the chord to round-off."""
    chord = np.asarray(chord, float).reshape(-1, 3)
    res = np.linalg.norm(el.chord(state.h) - chord, axis=1)
    ok = res <= 32 * EPS * np.maximum(L0, np.linalg.norm(chord, axis=1))
    return bool(((state.status == CONVERGED) & ok).all())


@HYP
@given(cases(), st.integers(0, 2**32 - 1))
def test_cold_and_warm_newton(case, seed):
    el, state = solve(case)
    assert solved(el, state, case.chord, case.L0)
    assert state.status[0] == CONVERGED or state.iterations[0] == MAX_ITER
    if state.status[0] == CONVERGED:
        assert state.iterations[0] <= 25
    for arr in (state.h, state.F, state.K):
        assert np.isfinite(arr).all()
    # the solved h reproduces the chord to round-off
    assert np.linalg.norm(el.chord(state.h)[0] - case.chord) <= 1e-12 * case.L0
    # every point of the cable is in tension (a catenary, not a folded chain)
    assert min_tension(case, state.h[0]) > 0.0
    # warm start after a small change of the chord: small against |F h|, the chord change
    # that alters the tension by its own size (a taut stiff element changes its tension by
    # 10 % when its chord changes by 1e-6 of its length)
    rng = np.random.default_rng(seed)
    scale = min(np.linalg.norm(state.F[0] @ state.h[0]), np.linalg.norm(case.chord))
    c2 = case.chord + 1e-6 * scale * rng.standard_normal(3) / math.sqrt(3)
    warm = el.solve(c2[None, :], state.h)
    assert solved(el, warm, c2, case.L0)
    if warm.status[0] == CONVERGED:
        assert warm.iterations[0] <= 3
    assert np.linalg.norm(el.chord(warm.h)[0] - c2) <= 1e-12 * case.L0


def random_batch(n, seed=20080212):
    """n random elements over the hypothesis domain with 0-4 loads each, and their chords."""
    rng = np.random.default_rng(seed)
    L0 = 10 ** rng.uniform(math.log10(0.5), math.log10(500.0), n)
    w = 10 ** rng.uniform(-1, 3, n)
    EA = 10 ** rng.uniform(2, 8, n) * w * L0
    az = rng.uniform(0, 2 * np.pi, n)
    el_ = np.radians(rng.uniform(-89.9, 89.9, n))
    d = np.stack([np.cos(el_) * np.cos(az), np.cos(el_) * np.sin(az), np.sin(el_)], axis=1)
    chord = rng.uniform(0.3, 1.02, n)[:, None] * L0[:, None] * d
    lists = []
    for e in range(n):
        k = rng.integers(0, 5)
        fd = rng.standard_normal((k, 3))
        fd /= np.linalg.norm(fd, axis=1, keepdims=True)
        lists.append([(rng.uniform(0.01, 0.99) * L0[e], rng.uniform(0, 3) * w[e] * L0[e] * fd[i])
                      for i in range(k)])
    return Elements(L0, EA, w, PointLoads.from_lists(lists)), chord


def test_random_mixed_batch_solves_everywhere():
    """2000 random elements with 0-4 loads each in one batch: solved, finite, exact chords."""
    el, chord = random_batch(2000)
    state = el.solve(chord)
    assert solved(el, state, chord, el.L0)
    assert state.iterations[state.status == CONVERGED].max() <= 25
    assert np.isfinite(state.h).all() and np.isfinite(state.K).all()
    err = np.linalg.norm(el.chord(state.h) - chord, axis=1)
    assert (err <= 1e-12 * el.L0).all()
    warm = el.solve(chord * (1 + 1e-6), state.h)
    assert solved(el, warm, chord * (1 + 1e-6), el.L0)
    assert warm.iterations[warm.status == CONVERGED].max() <= 3


def test_random_mixed_batch_has_no_not_converged():
    el, chord = random_batch(2000)
    state = el.solve(chord)
    assert (state.status != NOT_CONVERGED).all()


def test_roundoff_residual_floor_is_converged():
    L0, EA, w = 449.7494394642976, 154835769.59794074, 0.2097735306243669
    chord = np.array([26.576244458726244, 12.223669918466141, -180.39441002307086])
    loads = [(28.096565579817277, (-22.985509814208243, 170.0806829332745, -115.60665836714125))]
    el = one(L0, EA, w, loads)
    state = el.solve(chord[None, :])
    # h is right: the chord is reproduced to a few ulps of L0 and moments balance
    assert np.linalg.norm(el.chord(state.h)[0] - chord) <= 8 * EPS * L0
    case = Case(L0, EA, w, chord, [(s, np.array(f)) for s, f in loads])
    assert_equilibrium(el, state, case)
    assert state.status[0] == CONVERGED
    assert state.iterations[0] <= 25


@pytest.mark.parametrize(
    "ea_ratio, elev_deg, ratio",
    [
        pytest.param(1e4, 89.9, 1.0),
        pytest.param(1e4, -89.9, 1.00001),
        pytest.param(1e6, 89.9, 1.0),
        pytest.param(1e4, -89.99, 1.0),
        pytest.param(1e8, 89.99, 1.0),
        pytest.param(1e4, 89.9, 1.001, id="just-taut-ok"),
        pytest.param(1e4, -89.9, 0.999, id="just-slack-ok"),
    ],
)
def test_near_vertical_chord_near_L0_cold_start(ea_ratio, elev_deg, ratio):
    """Cold start at 89.9-89.99 degrees with |chord| ~ L0 converges fast (Irvine's answer)."""
    L0, w = 1.0, 10.0
    EA = ea_ratio * w * L0
    e = math.radians(elev_deg)
    B = ratio * L0 * np.array([math.cos(e), 0.0, math.sin(e)])
    state = one(L0, EA, w).solve(B[None, :])
    assert state.status[0] == CONVERGED
    # the hardest of these (89.99 degrees, EA/(w L0) = 1e8: the low end barely folds, its
    # tension ~1e-8 of the weight) needs ~55 iterations from the steep-chord start
    assert state.iterations[0] <= (25 if ea_ratio <= 1e4 else 60)
    compare_with_irvine((0, 0, 0), B, L0, EA, w, rtol=1e-8)


# ----------------------------------------------------------------------------------------------
# flexibility F, partial flexibility G(s), interpolation N(s) against finite differences
# ----------------------------------------------------------------------------------------------
def fd_jacobian(fun, h, step):
    """Central differences of fun (3,) -> (m, 3) with respect to h: (m, 3, 3)."""
    cols = []
    for m in range(3):
        dh = np.zeros(3)
        dh[m] = step
        cols.append((fun(h + dh) - fun(h - dh)) / (2 * step))
    return np.stack(cols, axis=-1)


@HYP
@given(cases())
def test_flexibility_is_jacobian_of_chord(case):
    el, state = solve(case)
    assert solved(el, state, case.chord, case.L0)
    h = state.h[0]
    step = 1e-6 * min_tension(case, h)
    F = el.flexibility(state.h)[0]
    F_fd = fd_jacobian(lambda hh: el.chord(hh[None, :])[0], h, step)
    scale = np.linalg.norm(F, 2)
    # FD error: truncation ~ (step/Tmin)^2 |F|, round-off ~ eps |chord| / step
    tol = 1e-7 * scale + 1e3 * EPS * case.L0 / step
    assert np.abs(F_fd - F).max() <= tol
    # F is what solve() returned, and is symmetric positive definite
    np.testing.assert_allclose(state.F[0], F, rtol=0, atol=1e-14 * scale)
    np.testing.assert_array_equal(F, F.T)
    assert np.linalg.eigvalsh(F).min() > 0.0


@HYP
@given(cases(), st.lists(st.floats(0.0, 1.0), min_size=1, max_size=4))
def test_partial_flexibility_is_jacobian_of_position(case, fracs):
    el, state = solve(case)
    h = state.h[0]
    s = np.array(fracs) * case.L0
    step = 1e-6 * min_tension(case, h)
    G = el.partial_flexibility(state.h, s)[0]
    G_fd = fd_jacobian(lambda hh: el.position(hh[None, :], s)[0], h, step)
    scale = np.linalg.norm(el.flexibility(state.h)[0], 2)
    tol = 1e-7 * scale + 1e3 * EPS * case.L0 / step
    assert np.abs(G_fd - G).max() <= tol
    np.testing.assert_array_equal(G, np.swapaxes(G, -1, -2))
    # G(0) = 0 and G(L0) = F
    ends = el.partial_flexibility(state.h, [0.0, case.L0])[0]
    np.testing.assert_array_equal(ends[0], 0.0)
    np.testing.assert_allclose(ends[1], state.F[0], rtol=0, atol=1e-13 * scale)


@HYP
@given(cases(), st.lists(st.floats(0.0, 1.0), min_size=1, max_size=4),
       st.integers(0, 2**32 - 1))
def test_interpolation_is_displacement_of_material_points(case, fracs, seed):
    """N(s) [du_i, du_j] = motion of the material point s when the nodes move (re-solved)."""
    el, state = solve(case)
    s = np.array(fracs) * case.L0
    x0 = el.position(state.h, s)[0]
    N = el.interpolation(state, s)[0]  # (q, 3, 6)
    rng = np.random.default_rng(seed)
    du = rng.standard_normal(6)
    du /= np.linalg.norm(du)
    delta = 1e-6 * np.linalg.norm(case.chord)

    def moved(sign):
        dui, duj = sign * delta * du[:3], sign * delta * du[3:]
        c_new = case.chord + duj - dui
        new = el.solve(c_new[None, :], state.h)
        assert solved(el, new, c_new, case.L0)
        return dui + el.position(new.h, s)[0] - x0

    dx_fd = (moved(1.0) - moved(-1.0)) / 2.0
    dx_n = delta * N @ du
    # FD error ~ (delta/L0)^2 plus the re-solve's round-off, amplified by K: eps |K| |c| |G| / delta
    G_scale = np.linalg.norm(state.F[0], 2)
    tol = delta * (1e-5 + 1e3 * EPS * np.linalg.norm(state.K[0], 2) * G_scale
                   * np.linalg.norm(case.chord) / delta)
    assert np.abs(dx_fd - dx_n).max() <= tol


# ----------------------------------------------------------------------------------------------
# exact identities of §3-6
# ----------------------------------------------------------------------------------------------
@HYP
@given(cases())
def test_matrix_identities(case):
    el, state = solve(case)
    F, K = state.F[0], state.K[0]
    np.testing.assert_array_equal(F, F.T)
    np.testing.assert_array_equal(K, K.T)
    cond = np.linalg.cond(F)
    assert np.abs(K @ F - np.eye(3)).max() <= 1e2 * EPS * cond
    # element stiffness [[K, -K], [-K, K]], symmetric, rigid translations are zero-energy
    k6 = state.stiffness6[0]
    np.testing.assert_array_equal(k6[:3, :3], K)
    np.testing.assert_array_equal(k6[:3, 3:], -K)
    np.testing.assert_array_equal(k6[3:, :3], -K)
    np.testing.assert_array_equal(k6[3:, 3:], K)
    np.testing.assert_array_equal(k6, k6.T)
    np.testing.assert_array_equal(k6 @ np.tile(np.eye(3), (2, 1)), 0.0)
    # interpolation: partition of unity and end values
    s = np.array([0.0, 0.25, 0.5, 0.75, 1.0]) * case.L0
    N = el.interpolation(state, s)[0]
    eye = np.eye(3)
    np.testing.assert_allclose(N[..., :3] + N[..., 3:], np.broadcast_to(eye, (5, 3, 3)),
                               rtol=0, atol=1e-15)
    np.testing.assert_allclose(N[0], np.hstack([eye, 0 * eye]), rtol=0, atol=0)
    np.testing.assert_allclose(N[-1], np.hstack([0 * eye, eye]), rtol=0, atol=1e2 * EPS * cond)


# ----------------------------------------------------------------------------------------------
# equilibrium of the solved shape
# ----------------------------------------------------------------------------------------------
def assert_equilibrium(el: Elements, state: ElementState, case: Case, rtol=1e-9):
    """Forces and moments (about node i) on the solved element vanish."""
    h = state.h[0]
    r = el.end_forces(state.h)[0]  # forces the nodes apply to the element
    weight = -case.w * case.L0 * EZ
    f = case.load_f
    force_scale = np.linalg.norm(h) + case.w * case.L0 + np.abs(f).sum()
    total = r[0] + r[1] + f.sum(axis=0) + weight
    assert np.linalg.norm(total) <= 1e-13 * force_scale
    # the node forces are the reactions to the cable's pull: -h at i, +t(L0) at j
    np.testing.assert_allclose(r[0], -h, rtol=0, atol=1e-14 * force_scale)
    t_end = tension_vec(h, case.w, case.load_s, case.load_f, case.L0)  # all s_k < L0
    np.testing.assert_allclose(r[1], t_end, rtol=0, atol=1e-12 * force_scale)
    # moments about node i on the solved geometry
    xj = el.position(state.h, [case.L0])[0, 0]
    moment = np.cross(xj, r[1])
    if len(case.loads):
        xk = el.position(state.h, case.load_s)[0]
        moment += np.cross(xk, f).sum(axis=0)
    sg, wg = gauss_nodes(case, h)
    xg = el.position(state.h, sg)[0]
    moment += np.cross((wg[:, None] * xg).sum(axis=0), -case.w * EZ)
    size = max(np.linalg.norm(case.chord), case.L0)
    assert np.linalg.norm(moment) <= rtol * force_scale * size


@HYP
@given(cases())
def test_equilibrium_of_forces_and_moments(case):
    el, state = solve(case)
    assert_equilibrium(el, state, case)


@HYP
@given(cases(), st.floats(0.02, 0.98))
def test_tangent_is_along_tension_with_hookes_stretch(case, frac):
    """dx/ds = t/T (1 + T/EA) on the solved shape (central difference in s)."""
    el, state = solve(case)
    s = frac * case.L0
    gap = min([s, case.L0 - s] + [abs(s - sk) for sk in case.load_s])
    if gap < 1e-3 * case.L0:  # stay off the kinks at the loads: middle of the stretch
        a, b = next((a, b) for a, b in segments(case) if a <= s <= b)
        s, gap = 0.5 * (a + b), 0.5 * (b - a)
    ds = min(1e-5 * case.L0, 0.1 * gap)
    x = el.position(state.h, [s - ds, s + ds])[0]
    tangent = (x[1] - x[0]) / (2 * ds)
    t = tension_vec(state.h[0], case.w, case.load_s, case.load_f, s)
    T = np.linalg.norm(t)
    expect = t / T * (1 + T / case.EA)
    # truncation ~ (ds w / Tmin)^2 (curvature w/T), round-off ~ eps L0 / ds
    tmin = min_tension(case, state.h[0])
    tol = 10 * (ds * case.w / tmin) ** 2 + 1e3 * EPS * case.L0 / ds + 1e-12
    assert np.abs(tangent - expect).max() <= tol
    # the tension vector reported by the element is the same t(s)
    np.testing.assert_allclose(el.tension_vector(state.h, [s])[0, 0], t, rtol=0,
                               atol=1e-13 * (T + case.w * case.L0))


# ----------------------------------------------------------------------------------------------
# a point load against two elements split at the load
# ----------------------------------------------------------------------------------------------
@HYP
@given(cases(min_loads=1), st.integers(0, 3))
def test_point_load_equals_two_elements_split_there(case, pick):
    el, state = solve(case)
    h = state.h[0]
    k = pick % len(case.loads)
    sk, fk = case.loads[k]
    x_load = el.position(state.h, [sk])[0, 0]
    left_loads = [(s, f) for s, f in case.loads if s < sk]
    right_loads = [(s - sk, f) for s, f in case.loads if s > sk]
    left = Case(sk, case.EA, case.w, x_load, left_loads)
    right = Case(case.L0 - sk, case.EA, case.w, case.chord - x_load, right_loads)
    el_left, st_left = solve(left)
    el_right, st_right = solve(right)
    assert solved(el_left, st_left, left.chord, left.L0)
    assert solved(el_right, st_right, right.chord, right.L0)
    # the sub-chords carry the round-off of x_load, of the size of the whole element
    size = max(case.L0, np.linalg.norm(case.chord))
    # left piece: same tension at s = 0
    assert np.linalg.norm(st_left.h[0] - h) <= h_tol(st_left, size, 1e-9)
    # right piece: tension just after the load
    t_after = tension_vec(h, case.w, case.load_s, case.load_f, sk) - fk
    assert np.linalg.norm(st_right.h[0] - t_after) <= h_tol(st_right, size, 1e-9)


# ----------------------------------------------------------------------------------------------
# one element against Irvine's elastic catenary (tests/reference.py)
# ----------------------------------------------------------------------------------------------
def compare_with_irvine(A, B, L0, EA, w, rtol=1e-10):
    A, B = np.asarray(A, float), np.asarray(B, float)
    chord = B - A
    ref = irvine_catenary_inclined_3d(A, B, L0, EA, w)
    el = one(L0, EA, w)
    state = el.solve(chord[None, :])
    assert state.status[0] == CONVERGED
    h = state.h[0]
    t_j = el.end_forces(state.h)[0, 1]
    T = el.end_tensions(state.h)[0]
    pl = ref["planar"]
    H = math.hypot(h[0], h[1])
    assert H == pytest.approx(pl["H"], rel=rtol)
    assert h[2] == pytest.approx(pl["V_i"], rel=rtol)
    assert t_j[2] == pytest.approx(pl["V_j"], rel=rtol)
    assert T[0] == pytest.approx(pl["T_i"], rel=rtol)
    assert T[1] == pytest.approx(pl["T_j"], rel=rtol)
    np.testing.assert_allclose(h[:2] / H, ref["e"][:2], rtol=0, atol=1e-13)
    # the solved h reproduces the chord
    assert np.linalg.norm(el.chord(state.h)[0] - chord) <= 1e-12 * np.linalg.norm(chord)
    # and the shape: positions of material points
    s = np.linspace(0.0, L0, 7)
    np.testing.assert_allclose(A + el.position(state.h, s)[0], ref["x"](s), rtol=0,
                               atol=1e-10 * max(L0, np.linalg.norm(chord)))
    return el, state


@pytest.mark.parametrize(
    "A, B, L0, EA, w",
    [
        pytest.param((0, 0, 0), (100, 0, 0), 102.0, 2e7, 20.0, id="level"),
        pytest.param((0, 0, 0), (80, 0, 45), 110.0, 5e6, 12.0, id="inclined-up"),
        pytest.param((0, 0, 0), (60, 0, -70), 100.0, 1e6, 5.0, id="inclined-down"),
        pytest.param((3, -2, 10), (-40, 55, 30), 80.0, 3e6, 8.0, id="3d-inclined"),
        pytest.param((0, 0, 0), (10, 0, 0), 9.99, 3.4e7, 50.0, id="taut-level"),
        pytest.param((1, 2, 3), (7, -5, 1), 9.0, 1e5, 2.0, id="3d-taut-ish"),
    ],
)
def test_one_element_matches_irvine(A, B, L0, EA, w):
    compare_with_irvine(A, B, L0, EA, w)


@pytest.mark.parametrize(
    "A, B, L0, EA, w",
    [
        pytest.param((0, 0, 0), (7e-4, 2e-4, 3e-4), 1e-3, 1e3, 0.5, id="1mm"),
        pytest.param((0, 0, 0), (9e3, 0, 1.5e3), 1e4, 1e9, 40.0, id="10km"),
        pytest.param((0, 0, 0), (30, 10, -5), 3 * math.sqrt(30**2 + 10**2 + 5**2), 1e6, 10.0,
                     id="very-slack"),
        pytest.param((0, 0, 0), (13, 0, 0), 10.0, 1e5, 10.0, id="very-taut-1.3"),
        pytest.param((0, 0, 0), (0.1 * math.cos(math.radians(89.9)), 0,
                                  0.1 * math.sin(math.radians(89.9))), 0.15, 1e4, 1.0,
                     id="89.9deg-sagging"),
        pytest.param((0, 0, 0), (1.001 * math.cos(math.radians(89.9)), 0,
                                 -1.001 * math.sin(math.radians(89.9))), 1.0, 1e5, 10.0,
                     id="89.9deg-hanging-down-taut"),
        pytest.param((0, 0, 0), (1e-6, 0, -0.6), 1.0, 1e5, 10.0, id="1e-6rad-folded-U"),
    ],
)
def test_extreme_elements_match_irvine(A, B, L0, EA, w):
    el, state = compare_with_irvine(A, B, L0, EA, w, rtol=1e-9)
    assert state.iterations[0] <= 25
    case = Case(L0, EA, w, np.subtract(B, A, dtype=float))
    assert_equilibrium(el, state, case)


@pytest.mark.parametrize("span, dz", [(100.0, 0.0), (100.0, -25.0)])
def test_sag_and_low_point_match_irvine(span, dz):
    """The 2-D reference's sag (at the tangent parallel to the chord) and lowest point."""
    L0, EA, w = 104.0, 4e6, 15.0
    ref = irvine_catenary(span, dz, L0, EA, w)
    el = one(L0, EA, w)
    state = el.solve(np.array([[span, 0.0, dz]]))
    assert state.status[0] == CONVERGED
    x_sag = el.position(state.h, [ref["s_sag"]])[0, 0]
    assert dz / span * x_sag[0] - x_sag[2] == pytest.approx(ref["sag"], rel=1e-10)
    x_low = el.position(state.h, [ref["s_low"]])[0, 0]
    assert x_low[2] == pytest.approx(ref["lowest_z"], rel=1e-10)
    # stretched length: integral of (1 + T/EA) over s
    sg, wg = gauss_nodes(Case(L0, EA, w, np.array([span, 0.0, dz])), state.h[0])
    stretched = wg @ (1.0 + el.tension(state.h, sg)[0] / EA)
    assert stretched == pytest.approx(ref["stretched_length"], rel=1e-12)


def test_very_taut_is_nearly_a_straight_bar():
    L0, EA, w = 10.0, 1e5, 10.0
    c = np.array([13.0, 0.0, 0.0])
    state = one(L0, EA, w).solve(c[None, :])
    T_bar = EA * (1.3 - 1.0)
    # weight 100 N against 3e4 N of tension: sag angle ~ w L0/(2 T)
    np.testing.assert_allclose(state.h[0, 0], T_bar, rtol=1e-4)
    assert state.h[0, 2] == pytest.approx(-w * L0 / 2, rel=1e-12)  # level: symmetric


# ----------------------------------------------------------------------------------------------
# vertical and nearly vertical elements
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("up", [True, False], ids=["going-up", "hanging-down"])
def test_exactly_vertical_taut(up):
    """Vertical bar under its own weight: t = (0, 0, V + w s), closed form."""
    L0, w, EA = 20.0, 50.0, 1e5
    length = L0 * 1.01
    dz = length if up else -length
    el = one(L0, EA, w)
    state = el.solve(np.array([[0.0, 0.0, dz]]))
    assert state.status[0] == CONVERGED
    # Δz = ±L0 + (V L0 + w L0²/2)/EA with the sign of u throughout
    sign = 1.0 if up else -1.0
    V = (dz - sign * L0) * EA / L0 - w * L0 / 2
    assert sign * V > 0 and sign * (V + w * L0) > 0  # taut everywhere
    np.testing.assert_allclose(state.h[0], [0.0, 0.0, V], rtol=1e-12, atol=1e-12 * abs(V))
    # axial flexibility L0/EA; lateral flexibility of a string L0/EA + ∫ ds/T
    Ta, Tb = abs(V), abs(V + w * L0)
    lateral = L0 / EA + math.log(Tb / Ta) / (sign * w)
    F = state.F[0]
    assert F[2, 2] == pytest.approx(L0 / EA, rel=1e-12)
    assert F[0, 0] == pytest.approx(lateral, rel=1e-12)
    assert F[1, 1] == pytest.approx(lateral, rel=1e-12)
    np.testing.assert_allclose(F[[0, 0, 1], [1, 2, 2]], 0.0, atol=1e-15 * lateral)
    assert np.isfinite(state.K).all()
    assert_equilibrium(el, state, Case(L0, EA, w, np.array([0, 0, dz])))


@pytest.mark.parametrize("up", [True, False], ids=["going-up", "hanging-down"])
@pytest.mark.parametrize("offset", [1e-6, 1e-3])
def test_nearly_vertical_taut_approaches_vertical_bar(up, offset):
    L0, w, EA = 20.0, 50.0, 1e5
    length = L0 * 1.01
    sign = 1.0 if up else -1.0
    c = length * np.array([math.sin(offset), 0.0, sign * math.cos(offset)])
    el = one(L0, EA, w)
    state = el.solve(c[None, :])
    assert state.status[0] == CONVERGED
    assert state.iterations[0] <= 25
    V = (sign * length - sign * L0) * EA / L0 - w * L0 / 2
    assert state.h[0, 2] == pytest.approx(V, rel=10 * offset)
    assert np.linalg.norm(el.chord(state.h)[0] - c) <= 1e-12 * length
    assert state.h[0, 0] > 0.0
    assert_equilibrium(el, state, Case(L0, EA, w, c))


def test_vertical_chord_shorter_than_L0_folds():
    """Exactly vertical, shorter than L0: the cable folds (SLACK) with the closed-form V."""
    L0, w, EA = 10.0, 20.0, 1e5
    dz = 4.0
    el = one(L0, EA, w)
    state = el.solve(np.array([[0.0, 0.0, dz]]))
    assert state.status[0] == SLACK
    # folded at s* = -V/w: Δz = (L0 - s*) - s* + (V L0 + w L0²/2)/EA
    V = (dz - L0 - w * L0**2 / (2 * EA)) / (2 / w + L0 / EA)
    s_star = -V / w
    assert 0 < s_star < L0
    np.testing.assert_allclose(state.h[0], [0.0, 0.0, V], rtol=1e-13, atol=1e-13 * abs(V))
    assert (L0 - 2 * s_star) + (V * L0 + w * L0**2 / 2) / EA == pytest.approx(dz, rel=1e-13)
    assert np.isfinite(state.K).all()
    assert state.K[0, 2, 2] == pytest.approx(1 / (2 / w + L0 / EA), rel=1e-13)
    # the limit of a near-vertical converged catenary with a tiny horizontal offset
    near = el.solve(np.array([[1e-6 * L0, 0.0, dz]]))
    assert near.status[0] == CONVERGED
    assert near.h[0, 2] == pytest.approx(V, rel=1e-4)
    assert 0 < near.h[0, 0] < 1e-3 * w * L0


def test_vertical_chord_folded_downwards():
    L0, w, EA = 10.0, 20.0, 1e5
    dz = -4.0
    state = one(L0, EA, w).solve(np.array([[0.0, 0.0, dz]]))
    assert state.status[0] == SLACK
    V = (dz - L0 - w * L0**2 / (2 * EA)) / (2 / w + L0 / EA)
    np.testing.assert_allclose(state.h[0], [0.0, 0.0, V], rtol=1e-13, atol=1e-13 * abs(V))
    assert (np.isfinite(state.h).all() and np.isfinite(state.K).all())


# ----------------------------------------------------------------------------------------------
# weightless and nearly weightless
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("c", [(12.0, 0.0, 0.0), (3.0, -4.0, 9.5), (0.0, 0.0, -10.5)])
def test_weightless_taut_is_a_straight_bar(c):
    L0, EA = 10.0, 1e6
    c = np.array(c)
    lc = np.linalg.norm(c)
    el = one(L0, EA, 0.0)
    state = el.solve(c[None, :])
    assert state.status[0] == CONVERGED
    h_bar = EA * (lc / L0 - 1) * c / lc
    np.testing.assert_allclose(state.h[0], h_bar, rtol=1e-13, atol=1e-13 * np.linalg.norm(h_bar))
    # bar stiffness: EA/L0 along the chord, T/|c| across it
    T = np.linalg.norm(h_bar)
    e = c / lc
    K_bar = EA / L0 * np.outer(e, e) + T / lc * (np.eye(3) - np.outer(e, e))
    np.testing.assert_allclose(state.K[0], K_bar, rtol=0, atol=1e-11 * EA / L0)


@pytest.mark.parametrize("c", [(8.0, 0.0, 0.0), (0.0, 0.0, 10.0), (1.0, 2.0, -3.0)])
def test_weightless_slack(c):
    el = one(10.0, 1e6, 0.0)
    state = el.solve(np.array([c]))
    assert state.status[0] == SLACK
    np.testing.assert_array_equal(state.h[0], 0.0)
    np.testing.assert_array_equal(state.K[0], 0.0)
    np.testing.assert_array_equal(state.stiffness6[0], 0.0)
    N = el.interpolation(state, [0.0, 5.0, 10.0])[0]
    np.testing.assert_allclose(N[1], np.hstack([0.5 * np.eye(3), 0.5 * np.eye(3)]))
    np.testing.assert_array_equal(el.end_forces(state.h)[0], 0.0)


def test_nearly_weightless_taut_matches_straight_bar():
    L0, EA, w = 10.0, 1e6, 1e-12
    c = np.array([7.0, 6.0, 5.5])
    lc = np.linalg.norm(c)
    state = one(L0, EA, w).solve(c[None, :])
    assert state.status[0] == CONVERGED
    h_bar = EA * (lc / L0 - 1) * c / lc
    # the weight (1e-11 N) shifts V by about w L0/2
    atol = 1e-10 + 1e-13 * np.linalg.norm(h_bar)
    np.testing.assert_allclose(state.h[0], h_bar, rtol=0, atol=atol)


def test_nearly_weightless_sagging_matches_irvine():
    """w = 1e-12 N/m, chord shorter than L0: a very light catenary, still exact."""
    compare_with_irvine((0, 0, 0), (8.0, 0.0, 1.0), 10.0, 1e6, 1e-12, rtol=1e-9)


def test_very_stiff_matches_inextensible_catenary():
    L0, w = 100.0, 10.0
    EA = 1e12 * w * L0
    l, dz = 80.0, 30.0
    # inextensible catenary: sqrt(L0² - dz²) = (l/λ) sinh λ with λ = w l/(2H),
    # V_i = (w/2)(dz coth λ - L0)
    target = math.sqrt(L0**2 - dz**2) / l
    lam = brentq(lambda x: math.sinh(x) / x - target, 1e-6, 50.0, xtol=1e-15, rtol=1e-15)
    H = w * l / (2 * lam)
    V = 0.5 * w * (dz / math.tanh(lam) - L0)
    state = one(L0, EA, w).solve(np.array([[0.6 * l, 0.8 * l, dz]]))
    assert state.status[0] == CONVERGED
    assert math.hypot(*state.h[0, :2]) == pytest.approx(H, rel=1e-9)
    assert state.h[0, 2] == pytest.approx(V, rel=1e-9)
    np.testing.assert_allclose(state.h[0, :2] / H, [0.6, 0.8], rtol=1e-9)


# ----------------------------------------------------------------------------------------------
# a point load that pulls the cable into a V
# ----------------------------------------------------------------------------------------------
def test_large_midspan_load_makes_two_straight_bars():
    L0, EA, w, l = 10.0, 1e7, 10.0, 8.0
    P = 100 * w * L0
    case = Case(L0, EA, w, np.array([l, 0.0, 0.0]), [(L0 / 2, np.array([0.0, 0.0, -P]))])
    el, state = solve(case)
    assert state.status[0] == CONVERGED
    h = state.h[0]
    # symmetry: each support carries half of the load and the weight, exactly
    assert h[2] == pytest.approx(-(P + w * L0) / 2, rel=1e-12)
    np.testing.assert_allclose(h[1], 0.0, atol=1e-12 * P)
    # two straight inextensible bars of length L0/2: depth d, H = (P/2)(l/2)/d
    d = math.sqrt((L0 / 2) ** 2 - (l / 2) ** 2)
    H_bars = (P + w * L0) / 2 * (l / 2) / d
    assert h[0] == pytest.approx(H_bars, rel=0.01)
    x_mid = el.position(state.h, [L0 / 2])[0, 0]
    np.testing.assert_allclose(x_mid, [l / 2, 0.0, -d], rtol=0, atol=0.01 * d)
    assert_equilibrium(el, state, case)


def test_mixed_batch_matches_single_elements():
    """Elements with 0, 1, 3, 0, 2 loads in one batch: CSR slicing keeps them apart."""
    rng = np.random.default_rng(7)
    lists = [[], [(4.0, (1.0, -2.0, -30.0))], [(1.0, (0, 0, -5.0)), (5.0, (3.0, 0, 0)),
                                               (9.0, (0, -4.0, 2.0))], [],
             [(7.0, (0, 0, -50.0)), (2.0, (10.0, 10.0, 10.0))]]
    n = len(lists)
    L0 = np.full(n, 10.0)
    EA = np.full(n, 1e6)
    w = np.linspace(5.0, 9.0, n)
    chord = rng.uniform(-1, 1, (n, 3))
    chord *= (rng.uniform(0.5, 0.95, n) * L0 / np.linalg.norm(chord, axis=1))[:, None]
    el = Elements(L0, EA, w, PointLoads.from_lists(lists))
    state = el.solve(chord)
    assert (state.status == CONVERGED).all()
    for e in range(n):
        loads = sorted((s, np.array(f, float)) for s, f in lists[e])
        case = Case(L0[e], EA[e], w[e], chord[e], loads)
        single_el, single = solve(case)
        np.testing.assert_allclose(state.h[e], single.h[0], rtol=1e-13, atol=0)
        sub = Elements(L0[e:e + 1], EA[e:e + 1], w[e:e + 1],
                       PointLoads.from_lists([lists[e]]))
        assert_equilibrium(sub, ElementState(state.h[e:e + 1], state.F[e:e + 1],
                                             state.K[e:e + 1], state.iterations[e:e + 1],
                                             state.status[e:e + 1]), case)
    np.testing.assert_allclose(el.chord(state.h), chord, rtol=0, atol=1e-12 * 10.0)


def test_status_codes_are_distinct():
    assert len({CONVERGED, SLACK, NOT_CONVERGED}) == 3


@pytest.mark.parametrize("stretch", [1e-9, 1e-6, 1e-3, 0.05])
def test_warm_start_from_a_folded_vertical_state_to_a_taut_one(stretch):
    """Newton warm-started from a folded (slack) vertical state reaches the taut hanging bar.

    Closed form for a vertical chord longer than the unstretched hanging length: the top
    tension T_top = EA (Δz - L0)/L0 + w L0/2 (the bar stretched by its mean tension)."""
    L0, EA, w = 5.0, 1e8, 0.00981
    el = Elements([L0], [EA], [w], PointLoads.from_lists([[]]))
    folded = el.solve(np.array([[0.0, 0.0, -0.9 * L0]]))  # folded by a tenth of its length
    assert folded.status[0] == SLACK
    dz = L0 * (1.0 + stretch) + 0.5 * w * L0**2 / EA
    taut = el.solve(np.array([[0.0, 0.0, -dz]]), folded.h)
    assert taut.status[0] == CONVERGED
    t_top = EA * (dz - L0) / L0 + 0.5 * w * L0
    # h is the force at end i (the top) on the element: pulling up-and-back along -chord
    assert -taut.h[0, 2] == pytest.approx(t_top, rel=1e-9)


def test_mass_gradient_against_re_solved_finite_differences():
    """∂M_e/∂c_k (complex step about the solved h) against central differences of M_e with the
    element re-solved by Newton at c ± δ e_k (Richardson-extrapolated): an independent path
    through the element solve. 40 random taut and sagging elements in 3-D."""
    rng = np.random.default_rng(1)
    n = 40
    L0 = rng.uniform(1, 30, n)
    EA = 10 ** rng.uniform(5, 9, n)
    w = rng.uniform(1, 200, n)
    dirs = rng.normal(size=(n, 3))
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    chord = dirs * (L0 * rng.uniform(0.6, 1.0, n))[:, None]
    el = Elements(L0, EA, w, PointLoads.from_lists([[] for _ in range(n)]))
    xi, wi = np.polynomial.legendre.leggauss(3)
    gs = 0.5 * (xi + 1)[None, :] * L0[:, None]
    gw = np.tile(0.5 * wi, (n, 1))
    m = w / 9.81
    state, _, _ = el.solve_dynamic(chord, None, gs, gw, m)
    assert np.all(state.status == CONVERGED)
    dm = el.mass_gradient(state)

    def mass_at(c):
        return el.solve_dynamic(c, None, gs, gw, m)[1]

    ref = np.zeros_like(dm)
    for k in range(3):
        def central(step, k=k):
            dc = np.zeros((n, 3))
            dc[:, k] = step * L0
            return (mass_at(chord + dc) - mass_at(chord - dc)) / (2 * step * L0)[:, None, None]
        ref[:, k] = (4 * central(1e-4) - central(2e-4)) / 3
    scale = np.abs(ref).reshape(n, -1).max(axis=1)
    err = np.abs(dm - ref).reshape(n, -1).max(axis=1) / scale
    assert np.median(err) < 1e-9 and err.max() < 1e-7, (np.median(err), err.max())


def test_energy_integrals_with_loads_inside_equal_adaptive_quadrature():
    """``Elements.energies``: ∫ T²/(2 EA) ds (in closed form, T² being quadratic in s between
    loads) and ∫ w (z(s) - z_i) ds (Gauss on each smooth piece) against scipy's adaptive
    quadrature of the element's own tension and position, breaking at the loads."""
    from scipy.integrate import quad

    from catdae.element.elements import Elements, PointLoads

    L0, EA, w = [10.0, 12.0, 8.0], [1e6, 2e6, 5e5], [50.0, 30.0, 0.0]
    loads = PointLoads.from_lists([[(7.0, (0.0, 20.0, -100.0)), (3.0, (10.0, -5.0, 200.0))], [],
                                   [(4.0, (1.0, 2.0, 3.0))]])
    el = Elements(L0, EA, w, loads)
    h = np.array([[1000.0, 50.0, -300.0], [2000.0, -10.0, -100.0], [500.0, 0.0, -10.0]])
    out = el.energies(h, *np.polynomial.legendre.leggauss(8))
    breaks = [[3.0, 7.0], [], [4.0]]
    for e in range(3):
        def at(s, e=e):
            return np.full((3, 1), s)

        strain = quad(lambda s, e=e: float(el.tension(h, at(s))[e, 0]) ** 2 / (2 * EA[e]), 0,
                      L0[e], points=breaks[e] or None, limit=200, epsabs=0, epsrel=1e-12)[0]
        grav = quad(lambda s, e=e: w[e] * float(el.position(h, at(s))[e, 0, 2]), 0, L0[e],
                    points=breaks[e] or None, limit=200, epsabs=1e-12, epsrel=1e-12)[0]
        assert out[e, 0] == pytest.approx(strain, rel=1e-12)
        assert out[e, 1] == pytest.approx(grav, rel=1e-11, abs=1e-9)
    assert out[1, 0] > 0 and out[0, 1] < 0  # not trivially zero
