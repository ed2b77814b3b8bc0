"""Natural frequencies and mode shapes about a static state (docs/theory.md §6-7).

K_t φ = ω² M φ on the free dofs, with the tangent stiffness and the consistent (or lumped) mass
of the catenary interpolation functions at the current configuration. Small models use LAPACK's
dense symmetric-definite solver; larger ones sparse shift-invert Lanczos about zero (the cable
is stable, so K_t is positive definite and the lowest modes are nearest to zero).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from catdae.element.elements import ElementState
from catdae.errors import ConvergenceError
from catdae.model.assembly import Model

DENSE_LIMIT = 600  # free dofs up to which the dense solver is used


@dataclass
class ModalSolution:
    frequency: np.ndarray  # (n_modes,) Hz
    shape: np.ndarray  # (n_modes, n_nodes, 3), largest component = 1 (sign: its max is +)
    plane: list[str]
    symmetry: list[str]
    solver: str


def solve_modal(model: Model, X: np.ndarray, state: ElementState, n_modes: int) -> ModalSolution:
    """The n_modes lowest modes of the model linearised about positions X and element state."""
    free = model.free
    k = model.stiffness(state, X)[free][:, free]
    m = model.mass(state)
    if model.fluid is not None:  # the added mass of the water (docs/theory.md §13)
        m = m + model.pattern.matrix(model.pattern.assemble(model.fluid.mass(X)))
    m = m[free][:, free]
    nf = free.size
    n_modes = min(int(n_modes), nf)
    if n_modes < 1:
        raise ConvergenceError("modal step: the model has no free degree of freedom")
    if nf <= DENSE_LIMIT or n_modes >= nf - 1:  # ARPACK needs n_modes < nf - 1
        kd, md = k.toarray(), m.toarray()
        try:
            lam, vec = sla.eigh(kd, md, subset_by_index=[0, n_modes - 1])
        except np.linalg.LinAlgError:  # M singular: massless dofs (a cable of zero mass)
            lam, vec = _reciprocal(kd, md, n_modes, _loose_massless(model, kd, md))
            n_modes = lam.size
        solver = "dense"
    else:
        try:
            lam, vec = spla.eigsh(k.tocsc(), n_modes, m.tocsc(), sigma=0.0, which="LM")
        except (RuntimeError, spla.ArpackNoConvergence) as exc:
            raise ConvergenceError(f"modal step: eigensolver failed ({exc})") from exc
        order = np.argsort(lam)
        lam, vec = lam[order], vec[:, order]
        solver = "sparse shift-invert"
    if np.any(lam <= 0.0):
        raise ConvergenceError(
            "modal step: the tangent stiffness is not positive definite about this state "
            f"(smallest eigenvalue {lam.min():.3g}); the static state is not stable")
    freq = np.sqrt(lam) / (2.0 * np.pi)
    shapes = np.zeros((n_modes, model.n_dof))
    shapes[:, free] = vec.T
    shapes = shapes.reshape(n_modes, -1, 3)
    for i in range(n_modes):
        flat = shapes[i].ravel()
        j = np.argmax(np.abs(flat))
        shapes[i] /= flat[j]
    plane, symmetry = classify(model, X, shapes)
    return ModalSolution(freq, shapes, plane, symmetry, solver)


def _loose_massless(model: Model, k: np.ndarray, m: np.ndarray) -> list[str]:
    """The free nodes without mass that some direction of motion leaves without stiffness
    (null vectors of K over the massless dofs): a node held only by one spring or bar, which
    acts along its line alone (at zero force it has no stiffness across it)."""
    dofs = np.flatnonzero(np.diag(m) <= 0.0)
    if dofs.size == 0:
        return []
    kk = k[np.ix_(dofs, dofs)]
    lam, vec = np.linalg.eigh(kk)
    null = vec[:, lam <= 1e-10 * max(float(np.abs(lam).max()), 1e-300)]
    hit = dofs[np.abs(null).max(axis=1) > 1e-6] if null.size else dofs[:0]
    nodes = sorted(set((model.free[hit] // 3).tolist()))
    return [model.mesh.node_names[n] for n in nodes]


def _reciprocal(k: np.ndarray, m: np.ndarray, n_modes: int,
                loose: list[str] = ()) -> tuple[np.ndarray, np.ndarray]:
    """Lowest modes when M is only semi-definite: M φ = μ K φ with μ = 1/ω² (K must be positive
    definite, as it is about a stable state). Massless dofs give μ = 0 (infinite frequency) and
    are left out, so fewer than n_modes modes may come back. ``loose``: the massless nodes
    that lack stiffness in some direction (named when K is singular)."""
    if loose:
        shown = ", ".join(loose[:5]) + (f" and {len(loose) - 5} more" if len(loose) > 5 else "")
        raise ConvergenceError(
            f"modal step: free node(s) {shown} have no mass and no stiffness in some direction "
            "about this state (a spring or a bar acts along its line only; at zero force it "
            "has no stiffness across it), so they have no motion of their own: put a point "
            "mass there, join them in more directions, or support them")
    try:
        mu, vec = sla.eigh(m, k)
    except np.linalg.LinAlgError as exc:
        raise ConvergenceError(
            "modal step: the mass matrix is singular and the tangent stiffness is not positive "
            "definite about this state; the static state is not stable") from exc
    finite = np.flatnonzero(mu > 1e-12 * max(mu.max(), 0.0))
    if finite.size == 0:
        raise ConvergenceError("modal step: the model has no mass on its free dofs")
    sel = finite[np.argsort(-mu[finite])][:n_modes]
    return 1.0 / mu[sel], vec[:, sel]


SYMMETRY_SHARE = 0.9  # of a shape's squares, in its symmetric or antisymmetric part, to say so


def _cable_plane(P: np.ndarray):
    """(along the chord, normal to it in the cable's plane, normal to the plane) of the nodes
    P (n_along, 3) in order: the plane through the chord that holds their offsets from it
    best (the sag's direction), or the vertical plane through the chord of a straight cable;
    None for a straight vertical one, and for ends brought together (no chord)."""
    chord = P[-1] - P[0]
    if np.linalg.norm(chord) <= 1e-9 * np.ptp(P, axis=0).max(initial=0.0):
        return None  # a loop: its ends met (a support motion brought them together)
    t_chord = chord / np.linalg.norm(chord)
    rel = P - P[0]
    offsets = rel - np.outer(rel @ t_chord, t_chord)  # normal to the chord
    w, v = np.linalg.eigh(offsets.T @ offsets)
    if np.sqrt(w[-1]) > 1e-6 * np.linalg.norm(chord):  # the sag's direction: the cable's plane
        e2 = np.cross(t_chord, v[:, -1])
    else:
        horiz = np.array([chord[0], chord[1], 0.0])
        if np.linalg.norm(horiz) < 1e-9 * np.linalg.norm(chord):
            return None
        e2 = np.cross([0.0, 0.0, 1.0], horiz)
    e2 = e2 / np.linalg.norm(e2)
    return t_chord, np.cross(e2, t_chord), e2


def classify(model: Model, X: np.ndarray, shapes: np.ndarray) -> tuple[list[str], list[str]]:
    """Label the modes of a single-span cable: in-plane/out-of-plane, symmetric/antisymmetric.

    The plane is the cable's own: through its chord and its sag (the plane that holds the
    nodes' offsets from the chord best; the vertical plane through the chord in still air, tilted
    by the swing under a wind), or the vertical plane through the chord when the cable is
    straight. A mode is out-of-plane when most of its nodal motion (sum of squares over the
    nodes) is normal to that plane. Symmetry is read from the
    mirror image about the cable's middle (the shape at unstrained arc length L - s against
    that at s, interpolated between nodes): "symmetric" or "antisymmetric" when that part is
    at least SYMMETRY_SHARE of the shape, else "mixed" (a scene that is not symmetric, such as
    a mass off midspan, mixes the two). Scenes with several cables, or a straight vertical
    cable, are labelled "unclassified".
    """
    mesh = model.mesh
    n = shapes.shape[0]
    if len(mesh.cable_names) != 1:
        return ["unclassified"] * n, ["unclassified"] * n
    order = np.concatenate([mesh.conn[:, 0], mesh.conn[-1:, 1]])  # nodes along the cable
    frame = _cable_plane(X[order])
    if frame is None:
        return ["unclassified"] * n, ["unclassified"] * n
    t_chord, n_chord, e2 = frame
    s_along = mesh.s_node[order]
    s_mirror = s_along[0] + s_along[-1] - s_along

    def mirrored(a):  # the component at the mirror point of every node
        return np.interp(s_mirror, s_along, a)

    plane, sym = [], []
    for i in range(n):
        u = shapes[i, order]  # (n_along, 3)
        out = u @ e2
        in_plane = float(np.sum(u * u)) - float(out @ out) >= float(out @ out)
        plane.append("in-plane" if in_plane else "out-of-plane")
        # mirror about the chord's middle: the component along the chord changes sign, the
        # one normal to it (in the plane) keeps its sign (an inclined stay's modes too)
        if in_plane:
            ac, an = u @ t_chord, u @ n_chord
            mc, mn = mirrored(ac), mirrored(an)
            s_part = np.sum((an + mn) ** 2) + np.sum((ac - mc) ** 2)
            a_part = np.sum((an - mn) ** 2) + np.sum((ac + mc) ** 2)
        else:
            mo = mirrored(out)
            s_part = np.sum((out + mo) ** 2)
            a_part = np.sum((out - mo) ** 2)
        total = s_part + a_part
        share = max(s_part, a_part) / total if total > 0 else 1.0
        sym.append("mixed" if share < SYMMETRY_SHARE else
                   "symmetric" if s_part >= a_part else "antisymmetric")
    return plane, sym
