"""An elastic cable with point loads solved by adaptive quadrature, and the equilibrium check of a
reported static state built on it (shared by tests/scenes/test_static.py and test_cases.py).

Independent of catdae's element: the tangent dx/ds = t/T + t/EA with t(s) = h + w s e_z - the
loads before s is integrated by ``scipy.integrate.quad``, and the tension vector h at the first
end that meets a chord is found by a scipy root solve (:func:`solve_cable`). The flexibility of
an elastic cable is positive definite, so the h that meets a chord is unique and any root found
is the root. :func:`check_equilibrium` re-solves every element of a scene from the reported node
positions that way and checks node equilibrium, the reported tensions and reactions, and global
force and moment balance. Nothing here imports catdae.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import quad
from scipy.optimize import root

EZ = np.array([0.0, 0.0, 1.0])


def _tension_vector(h, s, w, loads):
    """t(s) just after s: h + w s e_z - sum of the loads at arc lengths < s."""
    t = np.asarray(h, float) + w * s * EZ
    for sk, f in loads:
        if sk < s:
            t = t - np.asarray(f, float)
    return t


def _pieces(s_end, loads):
    cuts = sorted({0.0, float(s_end), *(float(sk) for sk, _ in loads if 0.0 < sk < s_end)})
    return list(zip(cuts[:-1], cuts[1:], strict=False))


def cable_position(h, s_end, EA, w, loads=()):
    """x(s_end) - x(0) of a cable whose tension vector at s = 0 is h (adaptive quadrature)."""
    out = np.zeros(3)
    for a, b in _pieces(s_end, loads):
        t0 = _tension_vector(h, 0.5 * (a + b), w, loads) - w * 0.5 * (a + b) * EZ
        for k in range(3):
            def f(s, k=k, t0=t0):
                t = t0 + w * s * EZ
                return t[k] / math.sqrt(t @ t) + t[k] / EA
            out[k] += quad(f, a, b, epsabs=0.0, epsrel=1e-13, limit=200)[0]
    return out


def cable_first_moment(h, L0, EA, w, loads=()):
    """∫_0^L0 (x(s) - x(0)) ds = ∫_0^L0 (L0 - s) x'(s) ds, for the moment of the weight."""
    out = np.zeros(3)
    for a, b in _pieces(L0, loads):
        t0 = _tension_vector(h, 0.5 * (a + b), w, loads) - w * 0.5 * (a + b) * EZ
        for k in range(3):
            def f(s, k=k, t0=t0):
                t = t0 + w * s * EZ
                return (L0 - s) * (t[k] / math.sqrt(t @ t) + t[k] / EA)
            out[k] += quad(f, a, b, epsabs=0.0, epsrel=1e-13, limit=200)[0]
    return out


def solve_cable(chord, L0, EA, w, loads=(), h0=None):
    """Tension vector h at s = 0 of the cable whose ends are ``chord`` apart (root of the chord
    equation). ``h0`` is only a starting point; the answer is checked by its chord residual."""
    chord = np.asarray(chord, float)
    if h0 is None:
        span = math.hypot(chord[0], chord[1])
        lam = math.sqrt(max(3.0 * (L0**2 - chord[2] ** 2) / span**2 - 1.0, 0.04))
        hh = abs(w * span / (2.0 * lam))
        h0 = np.array([hh * chord[0] / span, hh * chord[1] / span,
                       0.5 * w * (chord[2] / math.tanh(lam) - L0)])
    scale = float(np.linalg.norm(chord))

    def fun(h):
        return (cable_position(h, L0, EA, w, loads) - chord) / scale

    sol = root(fun, np.asarray(h0, float), method="hybr", options={"xtol": 1e-14})
    res = np.abs(fun(sol.x)).max()
    assert res < 1e-12, f"reference cable not solved: chord residual {res:.2e} (relative)"
    return sol.x


def cable_end_pull(h, L0, w, loads=()):
    """t(L0): the cable pulls its last end with -t(L0)."""
    return _tension_vector(h, L0 + 1.0, w, loads) - w * (L0 + 1.0) * EZ + w * L0 * EZ


def node_names(cable, ends, ne):
    return [ends[0], *(f"{cable}.{k}" for k in range(1, ne)), ends[1]]


def _on_cables(case):
    """Loads and point-mass weights placed on cables: (cable, s, force)."""
    out = [(ld.cable, ld.s, np.asarray(ld.force, float)) for ld in case.loads
           if ld.cable is not None]
    out += [(pm.cable, pm.s, np.array([0.0, 0.0, -pm.mass * case.gravity]))
            for pm in case.point_masses if pm.cable is not None]
    return out


def _element_loads(case, cable, k, le):
    """Loads (local s, force) acting strictly inside element k (1-based) of a cable."""
    out = []
    for cab, s_cable, f in _on_cables(case):
        s = s_cable - (k - 1) * le
        if cab == cable and 1e-9 * le < s < le * (1 - 1e-9):
            out.append((s, f))
    return out


def check_equilibrium(case, ds):
    """Re-solve every element from the reported node positions by quadrature, then check node
    equilibrium at free nodes, the reported tensions and reactions, and global force and
    moment balance. Returns the largest tension."""
    X = {n: ds.position.sel(node=n).values for n in ds.node.values}
    pull = {n: np.zeros(3) for n in X}  # force the cables exert on each node
    applied = {n: np.zeros(3) for n in X}  # loads and point-mass weights at nodes
    total_force = np.zeros(3)  # all applied forces and weights on the scene
    total_moment = np.zeros(3)  # their moment about the origin
    tmax = 0.0
    for ld in case.loads:
        if ld.node is not None:
            applied[ld.node] += ld.force
    for pm in case.point_masses:
        if pm.node is not None:
            applied[pm.node] += (0.0, 0.0, -pm.mass * case.gravity)
    for cab, s, f in _on_cables(case):  # those that fall on a mesh node act there
        c = case.cable(cab)
        k = s / (c.length / c.elements)
        if abs(k - round(k)) < 1e-9:
            applied[node_names(cab, c.ends, c.elements)[round(k)]] += f
    for n, f in applied.items():
        total_force += f
        total_moment += np.cross(X[n], f)
    for cable in case.cables:
        mat = case.materials[cable.material]
        w, EA = mat.weight, mat.EA
        ne = cable.elements
        le = cable.length / ne
        names = node_names(cable.name, cable.ends, ne)
        for k in range(1, ne + 1):
            a, b = names[k - 1], names[k]
            loads = _element_loads(case, cable.name, k, le)
            T_rep = ds.tension.sel(element=f"{cable.name}.{k}").values
            t_rep = T_rep[0] * (X[b] - X[a]) / np.linalg.norm(X[b] - X[a])  # a starting point
            h = solve_cable(X[b] - X[a], le, EA, w, loads, h0=t_rep - 0.5 * w * le * EZ)
            t_end = cable_end_pull(h, le, w, loads)
            np.testing.assert_allclose(T_rep, [np.linalg.norm(h), np.linalg.norm(t_end)],
                                       rtol=1e-9)
            tmax = max(tmax, *T_rep)
            pull[a] += h
            pull[b] -= t_end
            for s, f in loads:
                xf = X[a] + cable_position(h, s, EA, w, loads)
                total_force += f
                total_moment += np.cross(xf, f)
            weight = np.array([0.0, 0.0, -w * le])
            total_force += weight
            centroid = X[a] + cable_first_moment(h, le, EA, w, loads) / le
            total_moment += np.cross(centroid, weight)
    size = max(np.abs(np.array(list(X.values()))).max(), 1.0)
    reactions = np.zeros(3)
    for n in X:
        R = ds.reaction.sel(node=n).values
        if n in case.supports:
            # the support holds the node: R + pull + applied = 0
            np.testing.assert_allclose(R, -(pull[n] + applied[n]), atol=1e-9 * tmax)
            reactions += R
            total_moment += np.cross(X[n], R)
        else:
            assert np.isnan(R).all()
            np.testing.assert_allclose(pull[n] + applied[n], 0.0, atol=1e-9 * tmax)
    np.testing.assert_allclose(reactions + total_force, 0.0, atol=1e-9 * tmax)
    np.testing.assert_allclose(total_moment, 0.0, atol=1e-9 * tmax * size)
    assert ds.attrs["residual_norm"] <= 1e-9 * tmax
    assert ds.attrs["status"] == "completed"
    return tmax
