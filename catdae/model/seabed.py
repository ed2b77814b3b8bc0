"""The seabed in a step's model (docs/theory.md §13).

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
from catdae.element.elements import ElementState, _sym_from_upper
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
        the end forces of a lying end have no vertical part (docs/theory.md §13.3)."""
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
            F[idx] = _sym_from_upper(fflat[idx])
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

    def reactions(self, state, t: float) -> np.ndarray:
        """Force of the supports on the cable (the seabed's point forces are not reactions)."""
        r = self.internal_force(state) - self.nodal_load(t)
        out = np.full(self.n_dof, np.nan)
        out[self.base.fixed] = r[self.base.fixed]
        return out.reshape(-1, 3)
