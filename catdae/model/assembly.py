"""DOF map and sparse scatter of element vectors and matrices; the model of a step (its loading
is built in ``loading``).

Degrees of freedom are node-major: dof = 3 * node + axis. A :class:`Model` is what one analysis
step sees: the mesh, the point masses and loads present in it (``active = false`` leaves one out
until a step's ``add``, ``remove`` takes one away), the supports and their prescribed motion. It
contains only what the scene has: no time functions when no load varies, no internal loads when
none sit inside an element.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from catdae.case import Case
from catdae.case.timefunc import TimeFunction
from catdae.case.timefunc_compose import Scaled
from catdae.element.elements import Elements, ElementState, PointLoads
from catdae.model.connectors import build_connectors, extend, with_connectors
from catdae.model.fluid import Fluid
from catdae.model.loading import (  # noqa: F401  (re-exported)
    Loading,
    build_loading,
    free_hanging_ends,
)
from catdae.model.mass import MassMatrices
from catdae.model.mesh import AXES, Mesh
from catdae.model.scalar import minimize_bounded
from catdae.model.settings import choose_mass_model


class Pattern:
    """CSR sparsity of element 6x6 blocks plus the diagonal, with a scatter map.

    ``edofs`` (n_elem, 6) holds row/column numbers in ``0..n-1`` or -1 for entries to drop.
    ``assemble(blocks, diag)`` sums (n_elem, 6, 6) blocks and an (n,) diagonal into the data
    array in one bincount: no Python loop over elements.
    """

    def __init__(self, edofs: np.ndarray, n: int):
        r = np.repeat(edofs, 6, axis=1)  # (n_elem, 36)
        c = np.tile(edofs, (1, 6))
        keep = (r >= 0) & (c >= 0)
        keys_e = np.where(keep, r * n + c, -1).ravel()
        diag = np.arange(n, dtype=np.int64) * (n + 1)
        keys, inv = np.unique(np.concatenate([keys_e[keys_e >= 0], diag]), return_inverse=True)
        self.n = n
        self.nnz = keys.size
        self.indices = (keys % n).astype(np.int32)
        rows = keys // n
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=n))]).astype(
            np.int32)
        n_e = int((keys_e >= 0).sum())
        self._emap_full = np.full(keys_e.size, self.nnz, np.int64)  # dropped -> dump slot
        self._emap_full[keys_e >= 0] = inv[:n_e]
        self._dmap = inv[n_e:]

    def assemble(self, blocks: np.ndarray | None = None, diag: np.ndarray | None = None,
                 scale: float = 1.0) -> np.ndarray:
        """CSR data array (nnz,) of scale * Σ blocks + diag."""
        data = np.zeros(self.nnz + 1)
        if blocks is not None:  # element blocks alone leave the connectors' out
            emap = self._emap_full[:blocks.size]
            data += np.bincount(emap, weights=blocks.reshape(-1), minlength=self.nnz + 1)
        if diag is not None:
            data[:-1][self._dmap] += diag
        return scale * data[:-1] if scale != 1.0 else data[:-1]

    def matrix(self, data: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))




class Model(MassMatrices):
    """What one analysis step sees: mesh, active loading, supports and their motion."""

    def __init__(self, case: Case, mesh: Mesh, absent: set[str], mass_model: str = "auto",
                 kind: str = "transient", snap: str = "", rerun: bool = False):
        """``absent``: names of the point masses and loads not present in this step;
        ``mass_model`` "auto" is resolved for a step of ``kind`` into ``self.mass_model``, a
        :class:`~catdae.model.settings.MassModel` that says which and why (``snap``: why a
        transient can snap, catdae.model.snap; ``rerun``: found by a first run)."""
        self.case = case
        self.mesh = mesh
        self.absent = frozenset(absent)
        self.loading = build_loading(case, mesh, absent)
        ends = (free_hanging_ends(case, mesh, self.loading.node_mass) if mass_model == "auto"
                else [])
        self.mass_model = choose_mass_model(mass_model, kind, ends, snap, rerun)
        # springs, dampers, bars (None when the scene has none); bar weights and lumped
        # masses go into the loading
        self.connectors = build_connectors(case, mesh, self.loading)
        nn = mesh.n_nodes
        self.n_dof = 3 * nn
        fixed = np.zeros((nn, 3), bool)
        for node, axes in case.supports.items():
            i = mesh.node_index(node)
            for ax in axes:
                fixed[i, AXES.index(ax)] = True
        self.fixed_mask = fixed  # (n_nodes, 3)
        self.fixed = np.flatnonzero(fixed.ravel())
        self.free = np.flatnonzero(~fixed.ravel())
        # support motion: (dof, TimeFunction) for prescribed displacements
        self.motions: list[tuple[int, TimeFunction]] = []
        for sm in case.support_motions:
            i = mesh.node_index(sm.node)
            for a, ax in enumerate(AXES):
                tf = getattr(sm, ax)
                if tf is not None:
                    self.motions.append((3 * i + a, tf))
        # the motions by their place among the fixed dofs (support_values, once per residual)
        slots = np.searchsorted(self.fixed, [dof for dof, _ in self.motions]).astype(int)
        self._fixed_motions = [(int(k), tf) for k, (dof, tf) in zip(slots, self.motions,
                                                                      strict=True)
                               if k < self.fixed.size and self.fixed[k] == dof]
        # a motion along a direction is one function scaled per axis: evaluated once per time
        groups: dict[int, tuple] = {}
        for k, tf in self._fixed_motions:
            base, c = (tf.function, tf.factor) if isinstance(tf, Scaled) else (tf, None)
            groups.setdefault(id(base), (base, []))[1].append((k, c))
        self._motion_groups = list(groups.values())
        ld = self.loading
        self.elements = Elements(mesh.L0, mesh.EA, mesh.w,
                                 PointLoads(ld.internal_ptr, ld.internal_s,
                                            ld.internal_force.copy()))
        self._t_internal: float | None = None if ld.internal_timed else 0.0
        self.edofs = (3 * mesh.conn[:, :, None] + np.arange(3)).reshape(-1, 6)  # (n_elem, 6)
        self.pattern = Pattern(with_connectors(self.edofs, self.connectors), self.n_dof)
        self.gauss_s, self.gauss_w = mesh.gauss()
        self.total_mass = float((mesh.m * mesh.L0).sum() + ld.node_mass.sum()
                                + ld.mass_value.sum())
        # water and air (docs/theory.md §13); None for a scene without them
        self.fluid = Fluid.of(case, mesh, self.mass_model.lumped_fraction, self.gauss_s,
                              self.gauss_w)

    # -------------------------------------------------------------------------------- loads
    def set_time(self, t: float) -> None:
        """Update loads inside elements that vary with time (no-op when none do)."""
        if self._t_internal == t or not self.loading.internal_timed:
            return
        f = self.loading.internal_force.copy()
        for tf, arr in self.loading.internal_timed:
            f += tf(t) * arr
        self.elements.set_load_forces(f)
        self._t_internal = t

    def nodal_load(self, t: float) -> np.ndarray:
        """External forces applied at nodes, (n_dof,) N."""
        p = self.loading.node_force.copy()
        for tf, arr in self.loading.node_timed:
            p += tf(t) * arr
        return p.ravel()

    def support_values(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Prescribed displacement, velocity and acceleration of the fixed dofs, (n_fixed,)."""
        nf = self.fixed.size
        u, v, a = np.zeros(nf), np.zeros(nf), np.zeros(nf)
        for tf, slots in self._motion_groups:
            f, df, d2f = tf.evaluate(t)
            for k, c in slots:  # c: the axis' factor of a motion along a direction
                if c is None:
                    u[k], v[k], a[k] = f, df, d2f
                else:
                    u[k], v[k], a[k] = c * f, c * df, c * d2f
        return u, v, a

    def breakpoints(self, t0: float, t1: float, rel: float = 1e-10) -> list[tuple[float, float]]:
        """Where a support motion or a load has a kink or a jump, in (t0, t1]: a sorted list of
        (t_before, t_at). Breakpoints closer than ``rel`` (relative to max(1, |t|)) are one
        group, at its last time t_at; t_before is just below its first (so that a velocity
        jump is the sum of all the group's jumps). Groups within ``rel`` of t0 belong to the
        previous step, which applies them at its end; one within ``rel`` of t1 is at t1."""
        funcs = [tf for _, tf in self.motions]
        funcs += [tf for tf, _ in self.loading.node_timed]
        funcs += [tf for tf, _ in self.loading.internal_timed]
        funcs += self.fluid.time_functions() if self.fluid is not None else []
        times = sorted({float(b) for tf in funcs for b in tf.breakpoints()})
        groups: list[list[float]] = []
        for b in times:
            if groups and b - groups[-1][-1] <= rel * max(1.0, abs(b)):
                groups[-1].append(b)
            else:
                groups.append([b])
        out = []
        for g in groups:
            first, last = g[0], g[-1]
            if last <= t0 + rel * max(1.0, abs(t0)) or first > t1 + rel * max(1.0, abs(t1)):
                continue
            at = t1 if last >= t1 - rel * max(1.0, abs(t1)) else last
            out.append((float(np.nextafter(first, -np.inf)), at))
        return out

    def support_positions(self, t: float) -> np.ndarray:
        """Positions of the fixed dofs at time t: case position + motion, (n_fixed,)."""
        return self.mesh.X0.ravel()[self.fixed] + self.support_values(t)[0]

    @property
    def has_internal_loads(self) -> bool:
        return self.loading.internal_s.size > 0

    # -------------------------------------------------------------------------- element state
    def chords(self, X: np.ndarray) -> np.ndarray:
        """(n_elem, 3) chords x_j - x_i from node positions X (n_nodes, 3)."""
        return X[self.mesh.conn[:, 1]] - X[self.mesh.conn[:, 0]]

    def element_state(self, X: np.ndarray, h0: np.ndarray | None = None) -> ElementState:
        return self.elements.solve(self.chords(X), h0)

    def internal_force(self, state: ElementState, X: np.ndarray | None = None) -> np.ndarray:
        """Σ_e r_e: forces the nodes supply to hold the elements (and, given the positions X,
        the connectors), (n_dof,) N (docs/theory.md §4, §15)."""
        r = self.elements.end_forces(state.h)  # (n_elem, 2, 3)
        f = np.bincount(self.edofs.ravel(), weights=r.reshape(-1), minlength=self.n_dof)
        if X is not None and self.connectors is not None:
            f = f + self.connectors.force(X)  # (bincount of no element gives ints)
        return f

    def unit_chords(self, X: np.ndarray) -> np.ndarray:
        """The elements' chords as unit vectors, (n_elem, 3) (zero for a chord of zero length)."""
        c = self.chords(X)
        n = np.linalg.norm(c, axis=1)
        return c / np.where(n > 0, n, 1.0)[:, None]

    def element_lambda2(self, state: ElementState, X: np.ndarray) -> np.ndarray:
        """Irvine's λ² of each element from its stiffness along the chord, (n_elem,).

        Ernst's equivalent modulus, EA_eq = EA / (1 + λ²/12), read backwards: λ² = 12
        (EA / (L0 k_cc) - 1) with k_cc = ĉᵀ K ĉ. λ² ≪ 1: the element takes a change of chord by
        stretch (a bar); λ² ≫ 1: by sag (inf for a slack element, K = 0).
        """
        u = self.unit_chords(X)
        kcc = np.einsum("ei,eij,ej->e", u, state.K, u)
        with np.errstate(divide="ignore"):
            ratio = np.where(kcc > 0, self.mesh.EA / (self.mesh.L0 * np.maximum(kcc, 1e-300)),
                             np.inf)
        return np.maximum(12.0 * (ratio - 1.0), 0.0)

    def stiffness_data(self, state: ElementState, X: np.ndarray | None = None) -> np.ndarray:
        """CSR data of the tangent stiffness K_t on the full dof set (pattern ``self.pattern``);
        with the connectors' given the positions X."""
        k6 = state.stiffness6
        if X is not None and self.connectors is not None:
            k6 = extend(k6, self.connectors.stiffness_blocks(X), self.mesh.n_elements)
        return self.pattern.assemble(k6)

    def stiffness(self, state: ElementState, X: np.ndarray | None = None) -> sp.csr_matrix:
        return self.pattern.matrix(self.stiffness_data(state, X))

    # ------------------------------------------------------------------------- reporting
    def reactions(self, state: ElementState, t: float, X: np.ndarray | None = None
                  ) -> np.ndarray:
        """Force the supports exert on the cable, (n_nodes, 3) N; NaN on free axes.

        Node equilibrium: support force + external load = Σ resisting forces. Inertia of point
        masses sitting on a support node is not included (the support carries it directly).
        """
        r = self.internal_force(state, X) - self.nodal_load(t)
        if self.fluid is not None and X is not None:  # the fluid on the support nodes
            r += self.fluid.static(X)[0]
        out = np.full(self.n_dof, np.nan)
        out[self.fixed] = r[self.fixed]
        return out.reshape(-1, 3)

    def tensions(self, state: ElementState) -> np.ndarray:
        """Tension at ends i and j of every element, (n_elem, 2) N."""
        return self.elements.end_tensions(state.h)

    def cable_summary(self, X: np.ndarray, state: ElementState,
                      sag: bool | frozenset = True) -> dict[str, np.ndarray]:
        """Per cable: tension at its two ends, horizontal tension at its first end, sag, and
        unstrained length (at the reference temperature).

        Sag is the largest vertical distance from the chord to the cable (sampled on the exact
        curve of every element); for a vertical chord, the largest distance from the chord.
        Without ``sag`` it is NaN (its search along the curve costs most: form-finding to
        tensions asks for the rest hundreds of times); a set of cable indices limits it to them.
        """
        mesh = self.mesh
        nc = len(mesh.cable_names)
        end_t = np.zeros((nc, 2))
        h_t = np.zeros(nc)
        sags = np.full(nc, np.nan)  # where searched: every cable, or those in ``sag``
        tens = self.tensions(state)
        s = np.linspace(0.0, 1.0, 17)[None, :] * mesh.L0[:, None]  # (n_elem, 17)
        pts = (X[mesh.conn[:, 0]][:, None, :] + self.elements.position(state.h, s)) if sag \
            else None
        for ci in range(nc):
            els = np.flatnonzero(mesh.cable_of_element == ci)
            end_t[ci] = tens[els[0], 0], tens[els[-1], 1]
            h_t[ci] = float(np.hypot(*state.h[els[0], :2]))
            if not sag or (isinstance(sag, frozenset) and ci not in sag):
                continue
            a = X[mesh.conn[els[0], 0]]
            b = X[mesh.conn[els[-1], 1]]
            p = pts[els].reshape(-1, 3) - a
            c = b - a
            ch = np.hypot(c[0], c[1])
            if ch > 1e-9 * np.linalg.norm(c):
                def dist(pts_rel, c=c, ch=ch):
                    return (pts_rel[..., :2] @ c[:2]) / ch**2 * c[2] - pts_rel[..., 2]
            else:
                def dist(pts_rel, c=c):
                    u = c / np.linalg.norm(c)
                    return np.linalg.norm(pts_rel - np.multiply.outer(pts_rel @ u, u), axis=-1)
            d = dist(p)
            k = int(np.argmax(d))
            # refine the sampled maximum on the exact curve: within one sample of it, which
            # at an element end reaches into the neighbouring element
            n_s = s.shape[1]
            m, j = divmod(k, n_s)
            spans = [(m, s[els[m], max(j - 1, 0)], s[els[m], min(j + 1, n_s - 1)])]
            if j == 0 and m > 0:
                spans.append((m - 1, s[els[m - 1], n_s - 2], s[els[m - 1], n_s - 1]))
            if j == n_s - 1 and m < len(els) - 1:
                spans.append((m + 1, s[els[m + 1], 0], s[els[m + 1], 1]))
            best_sag = float(d[k])
            for m_, lo, hi in spans:
                e = int(els[m_])
                xi = X[mesh.conn[e, 0]] - a

                def neg(sv, e=e, xi=xi, dist=dist):
                    return -float(dist(xi + self.elements.position_in(e, state.h[e], sv)))

                best = minimize_bounded(neg, lo, hi, xatol=1e-10 * mesh.L0[e])
                best_sag = max(best_sag, -float(best[1]))
            # round-off of a straight (weightless, unloaded) line is no sag
            sags[ci] = best_sag if best_sag > 1e-12 * float(np.linalg.norm(c)) else 0.0
        unstrained = np.bincount(mesh.cable_of_element, weights=mesh.L0 / mesh.thermal,
                                 minlength=nc)
        return {"end_tension": end_t, "horizontal_tension": h_t, "sag": sags,
                "unstrained_length": unstrained}
