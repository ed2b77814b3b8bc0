"""Springs, dampers and bars between two nodes (docs/theory.md §15), batched over connectors.

A connector joins nodes a and b and acts along the line between them, e = (x_b - x_a) / d with
d = |x_b - x_a|. Its axial force (tension positive) is

    N = k (d - L) + c ḋ,     ḋ = eᵀ (v_b - v_a),

with k the stiffness (a spring's ``stiffness``, a bar's EA / L), L the length at rest and c a
damper's ``coefficient`` (each connector has the terms of its kind only; the others are 0). The
forces the nodes supply to hold it are r_b = N e, r_a = -N e: exact for any rotation (the
strain of a bar is (d - L) / L of its current length). Their derivatives are analytic:

    ∂r_b/∂x_b = k e eᵀ + (N / d) P + (c / d) e (v_b - v_a)ᵀ P,     P = I - e eᵀ
    ∂r_b/∂v_b = c e eᵀ,

and ∂r/∂(x_a, v_a) = -∂r/∂(x_b, v_b), r_a = -r_b, which fills the 6x6 block [[K, -K], [-K, K]].

A bar has a mass m L (``mass`` per metre times its length). Its weight m L g is split half to
each end (the exact work of a uniform weight on a linear interpolation). Its mass is the
consistent mass of a straight uniform bar, m L / 6 [[2, 1], [1, 2]] ⊗ I, whatever the step's
mass model: it is exact for the bar's rigid motion (its swing), and a bar is one member that no
mesh refines, so a lumped part would stay an error (docs/theory.md §15). It is written as the
halves m L / 2, which go into the step's nodal masses (every solver sees them with no change),
plus the correction ρ [[-1, 1], [1, -1]] ⊗ I, ρ = m L / 6, which comes from here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from catdae.errors import CaseError

_TINY = 1e-300


@dataclass(frozen=True)
class Connectors:
    """The springs, dampers and bars of a scene, as arrays over connectors.

    ``ends`` (n, 2) node indices; ``stiffness`` (n,) N/m; ``rest`` (n,) m; ``coefficient``
    (n,) N s/m; ``rho`` (n,) kg, the consistent-mass correction ρ; ``names`` and ``kinds``
    ("spring", "damper", "bar") per connector.
    """

    names: tuple[str, ...]
    kinds: tuple[str, ...]
    ends: np.ndarray  # (n, 2) int
    stiffness: np.ndarray  # (n,) N/m
    rest: np.ndarray  # (n,) m
    coefficient: np.ndarray  # (n,) N s/m
    rho: np.ndarray  # (n,) kg

    @property
    def n(self) -> int:
        return len(self.names)

    @property
    def edofs(self) -> np.ndarray:
        """(n, 6) dofs of ends a and b, node-major."""
        return (3 * self.ends[:, :, None] + np.arange(3)).reshape(-1, 6)

    # ----------------------------------------------------------------------- kinematics
    def _geometry(self, X: np.ndarray):
        """(unit vectors e (n, 3), lengths d (n,)) from node positions X (n_nodes, 3)."""
        X = X.reshape(-1, 3)
        dv = X[self.ends[:, 1]] - X[self.ends[:, 0]]  # (n, 3) m
        d = np.linalg.norm(dv, axis=1)  # (n,) m
        return dv / np.maximum(d, _TINY)[:, None], d

    def _relative(self, V: np.ndarray | None) -> np.ndarray:
        if V is None:
            return np.zeros((self.n, 3))
        V = V.reshape(-1, 3)
        return V[self.ends[:, 1]] - V[self.ends[:, 0]]  # (n, 3) m/s

    def axial_force(self, X: np.ndarray, V: np.ndarray | None = None) -> np.ndarray:
        """N = k (d - L) + c ḋ, (n,) N, tension positive."""
        e, d = self._geometry(X)
        w = self._relative(V)
        return self.stiffness * (d - self.rest) + self.coefficient * np.einsum("ni,ni->n", e, w)

    def _scatter(self, fb: np.ndarray, n_dof: int) -> np.ndarray:
        """(n_dof,) from forces fb (n, 3) at the b ends and -fb at the a ends."""
        out = np.zeros(n_dof)
        np.add.at(out.reshape(-1, 3), self.ends[:, 1], fb)
        np.add.at(out.reshape(-1, 3), self.ends[:, 0], -fb)
        return out

    # ----------------------------------------------------------------------- forces
    def force(self, X: np.ndarray, V: np.ndarray | None = None, A: np.ndarray | None = None,
              alpha: float = 0.0) -> np.ndarray:
        """Forces the nodes supply to the connectors, (n_dof,) N: N e at b, -N e at a, plus
        the consistent-mass correction ρ [[-1, 1], [1, -1]] (A + α V) (α: Rayleigh)."""
        e, d = self._geometry(X)
        w = self._relative(V)
        N = self.stiffness * (d - self.rest) + self.coefficient * np.einsum("ni,ni->n", e, w)
        fb = N[:, None] * e  # (n, 3) N
        if A is not None and np.any(self.rho):
            rel = self._relative(A) + alpha * w
            fb -= self.rho[:, None] * rel
        return self._scatter(fb, X.size)

    def stiffness_blocks(self, X: np.ndarray, V: np.ndarray | None = None) -> np.ndarray:
        """∂(force)/∂x as (n, 6, 6) blocks on ``edofs``."""
        e, d = self._geometry(X)
        w = self._relative(V)
        N = self.stiffness * (d - self.rest) + self.coefficient * np.einsum("ni,ni->n", e, w)
        P = np.eye(3)[None] - e[:, :, None] * e[:, None, :]  # (n, 3, 3)
        inv_d = 1.0 / np.maximum(d, _TINY)
        k3 = (self.stiffness[:, None, None] * e[:, :, None] * e[:, None, :]
              + (N * inv_d)[:, None, None] * P
              + (self.coefficient * inv_d)[:, None, None]
              * e[:, :, None] * np.einsum("nj,njk->nk", w, P)[:, None, :])
        return _pair(k3)

    def damping_blocks(self, X: np.ndarray) -> np.ndarray:
        """∂(force)/∂v, c e eᵀ in (n, 6, 6) blocks."""
        e, _ = self._geometry(X)
        return _pair(self.coefficient[:, None, None] * e[:, :, None] * e[:, None, :])

    def mass_blocks(self) -> np.ndarray:
        """The consistent-mass correction ρ [[-1, 1], [1, -1]] ⊗ I, (n, 6, 6)."""
        return _pair(-self.rho[:, None, None] * np.eye(3)[None])

    # ----------------------------------------------------------------------- energies
    def strain_energy(self, X: np.ndarray) -> float:
        """Σ ½ k (d - L)², J."""
        _, d = self._geometry(X)
        return float(0.5 * self.stiffness @ (d - self.rest) ** 2)

    def kinetic_correction(self, V: np.ndarray) -> float:
        """The consistent-mass correction's share of ½ vᵀ M v, J: -½ Σ ρ |v_b - v_a|²."""
        w = self._relative(V)
        return float(-0.5 * self.rho @ np.einsum("ni,ni->n", w, w))


def _pair(k3: np.ndarray) -> np.ndarray:
    """[[K, -K], [-K, K]] (n, 6, 6) from K (n, 3, 3): a block acting on x_b - x_a."""
    top = np.concatenate([k3, -k3], axis=2)
    return np.concatenate([top, -top], axis=1)


def build_connectors(case, mesh, loading) -> Connectors | None:
    """The connectors of ``case`` on ``mesh`` (None when there are none). The halves of the
    bars' weight and lumped mass are added to ``loading`` (its node_force and node_mass)."""
    items = [("spring", s) for s in case.springs] + [("damper", d) for d in case.dampers]
    items += [("bar", b) for b in case.bars]
    if not items:
        return None
    ends = np.array([[mesh.node_index(e) for e in x.ends] for _, x in items], np.int64)
    X0 = mesh.X0
    initial = np.linalg.norm(X0[ends[:, 1]] - X0[ends[:, 0]], axis=1)  # (n,) m
    where = [f"{kind}s[{i}]" for kind, group in (("spring", case.springs),
                                                 ("damper", case.dampers), ("bar", case.bars))
             for i in range(len(group))]
    problems = [(f"{at}.ends", f"a {kind} of zero length: nodes {x.ends[0]!r} and "
                 f"{x.ends[1]!r} coincide in the meshed reference configuration"
                 + ("" if kind == "damper" else "; give its length"))
                for at, (kind, x), d in zip(where, items, initial, strict=True)
                if d <= 1e-9 and (kind == "damper" or x.length is None)]
    if problems:
        raise CaseError(case.path, problems)
    rest = np.array([0.0 if kind == "damper" else (d if x.length is None else x.length)
                     for (kind, x), d in zip(items, initial, strict=True)])
    k = np.array([x.stiffness if kind == "spring" else x.EA / r if kind == "bar" else 0.0
                  for (kind, x), r in zip(items, rest, strict=True)])
    c = np.array([x.coefficient if kind == "damper" else 0.0 for kind, x in items])
    mass = np.array([x.mass * r if kind == "bar" else 0.0
                     for (kind, x), r in zip(items, rest, strict=True)])  # (n,) kg
    if np.any(mass):
        half = 0.5 * mass
        np.add.at(loading.node_mass, ends[:, 0], half)
        np.add.at(loading.node_mass, ends[:, 1], half)
        np.add.at(loading.node_force[:, 2], ends[:, 0], -case.gravity * half)
        np.add.at(loading.node_force[:, 2], ends[:, 1], -case.gravity * half)
    return Connectors(tuple(x.name for _, x in items), tuple(kind for kind, _ in items), ends,
                      k, rest, c, mass / 6.0)


def with_connectors(edofs: np.ndarray, connectors: Connectors | None) -> np.ndarray:
    """The element dofs followed by the connectors' (the sparsity pattern of a step)."""
    return edofs if connectors is None else np.vstack([edofs, connectors.edofs])


def extend(blocks: np.ndarray | None, extra: np.ndarray, n_elem: int) -> np.ndarray:
    """Element blocks (n_elem, 6, 6), or None for none (zeros), followed by the connectors'."""
    return np.concatenate([np.zeros((n_elem, 6, 6)) if blocks is None else blocks, extra])
