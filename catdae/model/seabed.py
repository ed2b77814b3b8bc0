"""The seabed in a step's model (docs/theory.md §17).

Two descriptions of one flat bottom at height z_b:

- rigid and frictionless, for static steps (``GroundedModel``): nodes resting on the seabed
  are held at z_b (an active set chosen by ``catdae.solvers.seabed_static``), and the elements
  that touch it take their grounded relations (``catdae.element.grounded``): exact at any mesh.
- a penalty contact for every kind of step when ``[seabed] stiffness`` is given
  (``SeabedContact``): at each free node below z_b a vertical force (k δ - c ż) d ℓ (δ the
  penetration, d the contact width, ℓ the node's unstrained tributary length, as MoorDyn's
  kBot and cBot), and a smoothed Coulomb friction on its horizontal velocity.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from catdae.element import grounded as g
from catdae.element.elements import ElementState, sym_from_upper
from catdae.errors import ConvergenceError
from catdae.model.assembly import Model


@dataclass(frozen=True)
class GroundedState(ElementState):
    """An element state whose grounded elements' h is the tension continued to s = 0 from the
    suspended part (catdae.element.grounded); ``slope`` (n, 2) is ∂t_z/∂V at s = 0 and L0
    (1 where the end is suspended, 0 where it lies)."""

    mode: np.ndarray | None = None  # (n,) FREE, AT_I, AT_J, LYING
    slope: np.ndarray | None = None  # (n, 2)

    @property
    def stiffness6(self) -> np.ndarray:
        """∂(r_i, r_j)/∂(u_i, u_j) = [[P_i K, -P_i K], [-P_j K, P_j K]], P = diag(1, 1, slope):
        the end forces of a lying end have no vertical part (docs/theory.md §17.3)."""
        k = self.K
        p0 = np.ones((k.shape[0], 3, 1))
        p1 = np.ones((k.shape[0], 3, 1))
        p0[:, 2, 0] = self.slope[:, 0]
        p1[:, 2, 0] = self.slope[:, 1]
        top = np.concatenate([p0 * k, -p0 * k], axis=2)
        bot = np.concatenate([-p1 * k, p1 * k], axis=2)
        return np.concatenate([top, bot], axis=1)


class GroundedElements:
    """The step's ``Elements`` with the grounded ones (``mode != FREE``) answered by their
    grounded relations: end forces, end tensions, positions. Everything else is delegated."""

    def __init__(self, base, mode: np.ndarray):
        self.base = base
        self.mode = mode
        self.idx = np.flatnonzero(mode != g.FREE)

    def __getattr__(self, name):
        return getattr(self.base, name)

    def _tz(self, h):
        b = self.base
        return g.end_tensions_z(h[self.idx], b.w[self.idx], b.L0[self.idx], self.mode[self.idx])

    def end_forces(self, h):
        r = self.base.end_forces(h)
        if self.idx.size:
            h = np.asarray(h)
            tz = self._tz(h)
            r[self.idx, 0, :2] = -h[self.idx, :2]
            r[self.idx, 0, 2] = -tz[:, 0]
            r[self.idx, 1, :2] = h[self.idx, :2]
            r[self.idx, 1, 2] = tz[:, 1]
        return r

    def end_tensions(self, h):
        t = self.base.end_tensions(h)
        if self.idx.size:
            h = np.asarray(h)
            hh = np.hypot(h[self.idx, 0], h[self.idx, 1])
            t[self.idx] = np.hypot(hh[:, None], self._tz(h))
        return t

    def position(self, h, s):
        out = np.array(self.base.position(h, s))
        b = self.base
        sarr = np.ascontiguousarray(np.broadcast_to(np.asarray(s, float), out.shape[:2]))
        g.position_batch(np.ascontiguousarray(h, float), b.w, b.EA, b.L0, self.mode, sarr, out)
        return out

    def position_in(self, e: int, h_e, s: float) -> np.ndarray:
        """x(s) - x_i of element ``e`` alone (catdae.element.elements.Elements.position_in),
        on the seabed where it lies."""
        b = self.base
        out = np.array(b.position_in(e, h_e, s), float).reshape(1, 1, 3)
        g.position_batch(np.array(h_e, float).reshape(1, 3), b.w[e:e + 1], b.EA[e:e + 1],
                         b.L0[e:e + 1], self.mode[e:e + 1], np.full((1, 1), float(s)), out)
        return out[0, 0]

    def lying_length(self, h) -> np.ndarray:
        """Unstrained length of each element resting on the seabed, (n,) m."""
        b = self.base
        h = np.asarray(h)
        s_star = np.clip(-h[:, 2] / np.where(b.w > 0, b.w, 1.0), 0.0, b.L0)
        out = np.zeros(b.n)
        out[self.mode == g.AT_I] = s_star[self.mode == g.AT_I]
        out[self.mode == g.AT_J] = (b.L0 - s_star)[self.mode == g.AT_J]
        out[self.mode == g.LYING] = b.L0[self.mode == g.LYING]
        return out


class GroundedModel(Model):
    """``model`` on a rigid, frictionless seabed at ``zb``: the free nodes of ``contact``
    (n_nodes,) bool held at z_b, the elements with an end ``on`` the seabed grounded."""

    def __init__(self, model: Model, contact: np.ndarray, on: np.ndarray, zb: float):
        self.__dict__.update(model.__dict__)
        self.base = model
        self.zb = zb
        self.contact = contact
        conn = model.mesh.conn
        oi, oj = on[conn[:, 0]], on[conn[:, 1]]
        mode = np.where(oi & oj, g.LYING, np.where(oi, g.AT_I, np.where(oj, g.AT_J, g.FREE)))
        mode[model.elements.w <= 0.0] = g.FREE  # weightless or buoyant: nothing to lay down
        self.mode = mode.astype(np.int64)
        bad = (np.diff(model.elements.loads.ptr) > 0) & (self.mode != g.FREE)
        if bad.any():
            name = model.mesh.element_names[int(np.flatnonzero(bad)[0])]
            raise ConvergenceError(
                f"element {name} rests on the seabed and carries loads inside it (point loads, "
                "point masses or distributed loads): the rigid seabed statics takes loads at "
                "nodes only; give [seabed] stiffness, or put the loads at nodes")
        self.elements = GroundedElements(model.elements, self.mode)
        fixed = model.fixed_mask.copy()
        fixed[contact, 2] = True
        self.fixed_mask = fixed
        self.fixed = np.flatnonzero(fixed.ravel())
        self.free = np.flatnonzero(~fixed.ravel())

    def support_positions(self, t: float) -> np.ndarray:
        full = np.zeros(self.n_dof)
        full[self.base.fixed] = self.base.support_positions(t)
        full.reshape(-1, 3)[self.contact, 2] = self.zb
        return full[self.fixed]

    def element_state(self, X: np.ndarray, h0: np.ndarray | None = None) -> GroundedState:
        st = self.base.element_state(X, h0)
        idx = self.elements.idx
        h = np.array(st.h)
        K = np.array(st.K)
        F = np.array(st.F)
        its = np.array(st.iterations)
        stat = np.array(st.status)
        if idx.size:
            if h0 is not None:
                h[idx] = h0[idx]
            fflat = np.zeros((h.shape[0], 6))
            b = self.base.elements
            g.solve_batch(np.ascontiguousarray(self.chords(X)), b.L0, b.EA, b.w, self.mode,
                          idx, h, h0 is not None, 1e-13, 100, fflat, K, its, stat)
            F[idx] = sym_from_upper(fflat[idx])
        b = self.base.elements
        v0 = h[:, 2]
        v1 = v0 + b.w * b.L0
        m = self.mode
        slope = np.ones((h.shape[0], 2))
        for mode, sign in ((g.AT_I, 1.0), (g.AT_J, -1.0)):
            sel = m == mode
            slope[sel, 0] = sign * v0[sel] > 0
            slope[sel, 1] = sign * v1[sel] > 0
        slope[m == g.LYING] = 0.0
        return GroundedState(h, F, K, its, stat, self.mode, slope)

    def reactions(self, state, t: float, X: np.ndarray | None = None) -> np.ndarray:
        """Force of the supports on the cable (the seabed's point forces are not reactions)."""
        r = self.internal_force(state, X) - self.nodal_load(t)
        if self.fluid is not None and X is not None:
            r += self.fluid.static(X)[0]
        out = np.full(self.n_dof, np.nan)
        out[self.base.fixed] = r[self.base.fixed]
        return out.reshape(-1, 3)


class SeabedContact:
    """Penalty contact of the free nodes with the seabed (docs/theory.md §17.5).

    Node k has the contact area a_k = Σ_e ½ L0_e d_e of its elements (d the contact width,
    the materials' ``diameter``). Below the seabed (δ = z_b - z > 0) the seabed pushes it up
    with N = a k δ and damps it with -a c ż (MoorDyn's kBot, cBot); a smoothed Coulomb
    friction opposes the horizontal velocity u: F_f = -N M u / sqrt(|u|² + v_s²), with
    M = μ_a ê êᵀ + μ_l (I - ê êᵀ) on the horizontal plane, ê the horizontal direction of the
    line at the node (of its chord through the neighbouring nodes). Below v_s friction is
    viscous (N μ / v_s), well above it Coulomb's μ N.
    """

    def __init__(self, seabed, mesh, free_z: np.ndarray, area: np.ndarray,
                 stiffness: float | None = None):
        """``free_z`` (n_nodes,) bool: nodes whose z is free; ``area`` (n_nodes,) m²."""
        self.zb = float(seabed.z)
        self.k = float(seabed.stiffness if stiffness is None else stiffness)
        self.c = float(seabed.damping) if stiffness is None else 0.0
        self.mu_a = float(seabed.friction_axial) if stiffness is None else 0.0
        self.mu_l = float(seabed.friction_lateral) if stiffness is None else 0.0
        self.vs = float(seabed.friction_velocity)
        self.nodes = np.flatnonzero(free_z & (area > 0))  # (p,)
        self.area = area[self.nodes]
        # neighbours for the line direction: the other ends of the node's elements
        conn = mesh.conn
        nbr = np.full((mesh.n_nodes, 2), -1, np.int64)
        for col, other in ((0, 1), (1, 0)):
            nbr[conn[:, col], other] = conn[:, other]
        nb = nbr[self.nodes]
        self.nb_a = np.where(nb[:, 0] >= 0, nb[:, 0], self.nodes)
        self.nb_b = np.where(nb[:, 1] >= 0, nb[:, 1], self.nodes)

    @classmethod
    def of_model(cls, model: Model, stiffness: float | None = None,
                 width: np.ndarray | None = None) -> SeabedContact:
        """The contact of ``model``'s free nodes; ``width`` (n_elem,) m defaults to the
        materials' diameters; with ``stiffness`` (N/m per m² of area) a frictionless,
        undamped contact of that stiffness (the rigid statics' first approach)."""
        mesh = model.mesh
        if width is None:
            width = np.array([getattr(model.case.material_of(c), "diameter", None) or 0.0
                              for c in model.case.cables])[mesh.cable_of_element]
        area = np.zeros(mesh.n_nodes)
        np.add.at(area, mesh.conn.ravel(), np.repeat(0.5 * mesh.L0 * width, 2))
        return cls(model.case.seabed, mesh, ~model.fixed_mask[:, 2], area, stiffness)

    @classmethod
    def of_step(cls, model: Model) -> SeabedContact | None:
        """The contact of a modal or transient step: None without a seabed (a rigid one is
        for static steps only, the case validation says so)."""
        sb = model.case.seabed
        if sb is None or sb.stiffness is None:
            return None
        out = cls.of_model(model)
        out.slots = out.block_slots(model.pattern).ravel()
        return out

    def add_derivatives(self, kdata, vdata, X, V):
        """CSR data (``slots`` of the step's pattern) of ∂r/∂q and ∂r/∂v with the contact's
        -∂f/∂q and -∂f/∂v added (copies)."""
        kq, kv = self.derivatives(X.reshape(-1, 3), V.reshape(-1, 3))
        kdata, vdata = kdata.copy(), vdata.copy()
        kdata[self.slots] += kq.ravel()  # the nodes' own blocks: no slot twice
        vdata[self.slots] += kv.ravel()
        return kdata, vdata

    def forces(self, X: np.ndarray, V: np.ndarray | None = None):
        """Force of the seabed on the nodes, (n_nodes, 3) N (one compiled pass,
        ``grounded.contact_forces``)."""
        out = np.zeros_like(X)
        g.contact_forces(X, X if V is None else V, self.nodes, self.nb_a, self.nb_b, self.area,
                         self.zb, self.k, self.c, self.mu_a, self.mu_l, self.vs, V is not None,
                         out)
        return out

    def derivatives(self, X: np.ndarray, V: np.ndarray | None = None):
        """-∂F/∂q and -∂F/∂v as (p, 3, 3) blocks at the contact nodes (the residual holds -F;
        one compiled pass, ``grounded.contact_derivatives``). The line direction ê is held
        fixed (its derivative is left out of the iteration matrix, which only has to be good)."""
        p = self.nodes.size
        kq = np.zeros((p, 3, 3))
        kv = np.zeros((p, 3, 3))
        g.contact_derivatives(X, X if V is None else V, self.nodes, self.nb_a, self.nb_b,
                              self.area, self.zb, self.k, self.c, self.mu_a, self.mu_l, self.vs,
                              V is not None, kq, kv)
        return kq, kv

    def energy(self, X: np.ndarray) -> float:
        """Elastic energy of the contact springs, Σ ½ a k δ², J."""
        delta = np.maximum(self.zb - X[self.nodes, 2], 0.0)
        return 0.5 * self.k * float(self.area @ (delta * delta))

    def dissipation(self, X: np.ndarray, V: np.ndarray) -> float:
        """Power taken out of the motion by the seabed's damping and friction, W (>= 0): minus
        the power of the contact forces less that of the springs (a k δ on ż)."""
        elastic = self.k * np.maximum(self.zb - X[self.nodes, 2], 0.0) * self.area
        return float(elastic @ V[self.nodes, 2]) - float(np.vdot(self.forces(X, V), V))

    def block_slots(self, pattern) -> np.ndarray:
        """Positions in the CSR data of ``pattern`` of the 3×3 block of every contact node,
        (p, 3, 3) int (the element blocks hold every node's own 3×3 block)."""
        d = 3 * self.nodes[:, None] + np.arange(3)[None]  # (p, 3)
        rows = np.repeat(d[:, :, None], 3, axis=2)
        cols = np.repeat(d[:, None, :], 3, axis=1)
        out = np.empty(rows.shape, np.int64)
        for idx in np.ndindex(rows.shape):
            r, c = rows[idx], cols[idx]
            lo, hi = pattern.indptr[r], pattern.indptr[r + 1]
            k = lo + int(np.searchsorted(pattern.indices[lo:hi], c))
            out[idx] = k
        return out


@dataclass(frozen=True)
class ContactState(ElementState):
    """An element state that also carries the node positions (the contact forces need them)."""

    X: np.ndarray | None = None  # (n_nodes, 3) m


class ContactModel(Model):
    """``model`` with the seabed's penalty contact (no velocity: static and modal steps) in its
    internal force and tangent stiffness."""

    def __init__(self, model: Model, contact: SeabedContact):
        self.__dict__.update(model.__dict__)
        self.base = model
        self.contact = contact
        self._slots = contact.block_slots(model.pattern)

    @classmethod
    def of(cls, model: Model) -> ContactModel:
        """``model`` with the penalty contact of its case's seabed."""
        return cls(model, SeabedContact.of_model(model))

    def element_state(self, X: np.ndarray, h0: np.ndarray | None = None) -> ContactState:
        st = self.base.element_state(X, h0)
        return ContactState(st.h, st.F, st.K, st.iterations, st.status, np.array(X))

    def internal_force(self, state, X: np.ndarray | None = None) -> np.ndarray:
        X = state.X if X is None else X
        return self.base.internal_force(state, X) - self.contact.forces(X).ravel()

    def stiffness_data(self, state, X: np.ndarray | None = None) -> np.ndarray:
        X = state.X if X is None else X
        data = self.base.stiffness_data(state, X)
        kq, _ = self.contact.derivatives(X)
        np.add.at(data, self._slots.ravel(), kq.ravel())
        return data

    def stiffness(self, state, X: np.ndarray | None = None):
        return self.pattern.matrix(self.stiffness_data(state, X))

    def summary(self, X: np.ndarray) -> dict[str, np.ndarray]:
        """Per cable, at node resolution: unstrained length resting on the seabed (elements
        with both nodes in contact, half of those with one; :func:`ends_on_seabed`) and the
        touchdown point (the last
        node in contact seen from the cable's upper end, where the suspended part that reaches
        it leaves the seabed; catdae.solvers.seabed_static.seabed_summary)."""
        mesh = self.mesh
        nc = len(mesh.cable_names)
        on = np.zeros(mesh.n_nodes, bool)
        on[self.contact.nodes] = X[self.contact.nodes, 2] < self.contact.zb
        anchor = self.fixed_mask[:, 2] & (X[:, 2] <= self.contact.zb + 1e-9)
        n_on = ends_on_seabed(on & ~anchor, anchor, mesh.conn)
        length = np.bincount(mesh.cable_of_element, weights=0.5 * n_on * mesh.L0, minlength=nc)
        on &= ~anchor  # the touchdown is a free node's (an anchor alone: lifted off)
        touchdown = np.full((nc, 3), np.nan)
        for ci in range(nc):
            els = np.flatnonzero(mesh.cable_of_element == ci)
            first, last = mesh.conn[els[0], 0], mesh.conn[els[-1], 1]
            walk = els[::-1] if X[last, 2] >= X[first, 2] else els
            for e in walk:
                a, b = mesh.conn[e]
                if on[a] or on[b]:  # the first contact from the upper end (none: it rests)
                    if on[a] != on[b] and length[ci] > 0:
                        touchdown[ci] = X[a] if on[a] else X[b]
                    break
        return {"seabed_length": length, "touchdown": touchdown}


def ends_on_seabed(free_on: np.ndarray, anchor: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """(..., n_elem) how many of each element's two ends lie on the seabed: free nodes in
    contact (``free_on``, (..., n_nodes)), and a support at the seabed (``anchor``) only where
    the element's other end lies too: a line lifted off at its anchor has nothing on the
    seabed (a sitting anchor counted half an element laid and the touchdown there; tester
    t76), a line lying up to it has its last element whole."""
    a, b = conn[:, 0], conn[:, 1]
    fa, fb = free_on[..., a], free_on[..., b]
    return (fa.astype(int) + fb + (anchor[..., a] & fb) + (anchor[..., b] & fa))
