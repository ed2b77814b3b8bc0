"""Cables -> nodes and elements on the exact catenary (case-format.md, "Meshing").

Each cable becomes ``elements`` elements of equal unstrained length. Its nodes are placed on the
exact elastic catenary through its ends under self-weight (one element spanning the whole cable,
solved by the element kernel), so a scene without extra loads is in equilibrium before the first
iteration. Mesh nodes are named ``<cable>.<k>``, elements ``<cable>.<k>``.

Things that sit on a cable at an arc length s (point masses, loads) are located here: either at a
node (when s falls on one, within 1e-9 of the element length) or inside an element at a local
arc length.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from catdae.case import Case
from catdae.case.names import mesh_node, split_mesh_node
from catdae.element.elements import SLACK, Elements, PointLoads
from catdae.errors import CaseError
from catdae.model.fluid import element_weights, line_weight

AXES = ("x", "y", "z")


@dataclass(frozen=True)
class Mesh:
    """Nodes and elements of a scene. Arrays have the node or element axis first."""

    node_names: tuple[str, ...]
    X0: np.ndarray  # (n_nodes, 3) m, reference positions (meshed catenaries)
    element_names: tuple[str, ...]
    conn: np.ndarray  # (n_elem, 2) int, node indices of ends i and j
    cable_of_element: np.ndarray  # (n_elem,) int, index into cable_names
    cable_names: tuple[str, ...]
    L0: np.ndarray  # (n_elem,) m
    EA: np.ndarray  # (n_elem,) N
    w: np.ndarray  # (n_elem,) N/m, weight per unstrained length
    m: np.ndarray  # (n_elem,) kg/m, mass per unstrained length
    c: np.ndarray  # (n_elem,) N s/m², material damping per unstrained length
    gauss_points: np.ndarray  # (n_elem,) int
    s_start: np.ndarray  # (n_elem,) m, arc length of end i along its cable
    cable_of_node: np.ndarray  # (n_nodes,) int, the first cable through the node; -1: none
    s_node: np.ndarray  # (n_nodes,) m, arc length along that cable (NaN: on no cable)
    # (n_elem,) 1 + α ΔT: the element arrays above are those of the heated element (below)
    thermal: np.ndarray = field(default=None)  # type: ignore[assignment]

    @property
    def n_nodes(self) -> int:
        return len(self.node_names)

    @property
    def n_elements(self) -> int:
        return len(self.element_names)

    def node_index(self, name: str) -> int:
        return self._node_index[name]

    def __post_init__(self):
        object.__setattr__(self, "_node_index", {n: i for i, n in enumerate(self.node_names)})
        if self.thermal is None:
            object.__setattr__(self, "thermal", np.ones(len(self.element_names)))

    def heated(self, case: Case, change: float | Mapping[str, float]) -> Mesh:
        """The mesh at a temperature change ``change`` (K; one number, or per cable name, 0 for
        cables not named) from the reference temperature of ``self`` (whose ``thermal`` is 1).

        The thermal strain α ΔT adds to the elastic one: the stretch of the cable is
        1 + α ΔT + T/EA = (1 + α ΔT)(1 + T/(EA (1 + α ΔT))) per unit of unstrained length s.
        In the heated arc length s' = (1 + α ΔT) s this is exactly an elastic catenary element
        with L0' = L0 (1 + α ΔT) and EA' = EA (1 + α ΔT), whose weight, mass and damping per
        unit of s' are those per unit of s divided by 1 + α ΔT (so that w' s' = w s: the
        tension t(s) and every total are unchanged), and whose loads sit at s' = (1 + α ΔT) s
        (:meth:`locate` takes s at the reference temperature).
        """
        per_cable = np.array([
            1.0 + case.material_of(c).thermal_expansion * (
                change.get(c.name, 0.0) if isinstance(change, Mapping) else change)
            for c in case.cables])
        f = per_cable[self.cable_of_element]  # (n_elem,)
        if np.all(f == 1.0):
            return self
        bad = np.flatnonzero(per_cable <= 0.0)
        if bad.size:
            c = case.cables[int(bad[0])]
            raise CaseError(case.path, [(f"materials.{c.material}.thermal_expansion", (
                f"cable {c.name!r}: the temperature change shrinks it to nothing (1 + α ΔT = "
                f"{per_cable[bad[0]]:.3g} <= 0); expected α in 1/K (steel about 1.2e-5)"))])
        return replace(self, L0=self.L0 * f, EA=self.EA * f, w=self.w / f, m=self.m / f,
                       c=self.c / f, s_start=self.s_start * f, thermal=f)

    def locate(self, cable: str, s: float) -> tuple[str, int, float]:
        """Where arc length s of a cable falls: ("node", index, 0) or ("element", e, s_local)."""
        ci = self.cable_names.index(cable)
        elems = np.flatnonzero(self.cable_of_element == ci)
        s = float(s) * self.thermal[elems[0]]  # to the heated arc length
        starts = self.s_start[elems]
        lengths = self.L0[elems]
        total = starts[-1] + lengths[-1]
        tol = 1e-9 * lengths[0]
        s = min(max(float(s), 0.0), total)
        for k, e in enumerate(elems):
            if abs(s - starts[k]) <= tol:
                return "node", int(self.conn[e, 0]), 0.0
            if abs(s - (starts[k] + lengths[k])) <= tol:
                return "node", int(self.conn[e, 1]), 0.0
            if starts[k] < s < starts[k] + lengths[k]:
                return "element", int(e), s - starts[k]
        return "node", int(self.conn[elems[-1], 1]), 0.0  # pragma: no cover - s clipped above

    def coverage_points(self, cable: str, from_s: float, to_s: float
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Gauss-Legendre points of the part [from_s, to_s] (unstrained arc length, m) of a cable.

        Every element that the part overlaps gets its own ``gauss_points`` points on the overlap
        alone (docs/theory.md §5 on the covered sub-interval): the integration is split at the
        ends of the coverage, so a load ending inside an element is integrated as accurately as
        one covering it whole, which is then the element's usual rule. Returns the element of
        each point (k,) int, its local arc length (k,) m and its weight times the overlap length
        (k,) m: the point load of a load p per metre is ``ds * p``.
        """
        ci = self.cable_names.index(cable)
        elems, s_loc, ds = [], [], []
        for e in np.flatnonzero(self.cable_of_element == ci):
            a = max(from_s - self.s_start[e], 0.0)
            b = min(to_s - self.s_start[e], self.L0[e])
            if b - a <= 1e-12 * self.L0[e]:
                continue
            xi, wi = np.polynomial.legendre.leggauss(int(self.gauss_points[e]))
            elems.append(np.full(xi.size, e))
            s_loc.append(a + 0.5 * (xi + 1.0) * (b - a))
            ds.append(0.5 * wi * (b - a))
        if not elems:
            return np.zeros(0, np.int64), np.zeros(0), np.zeros(0)
        return (np.concatenate(elems).astype(np.int64), np.concatenate(s_loc),
                np.concatenate(ds))

    def elements(self, loads: PointLoads | None = None) -> Elements:
        return Elements(self.L0, self.EA, self.w, loads)

    def gauss(self) -> tuple[np.ndarray, np.ndarray]:
        """Gauss-Legendre points s_g (n_elem, g) in m and weights (n_elem, g) summing to 1.

        Elements with fewer points than the largest count are padded with zero weights.
        """
        gmax = int(self.gauss_points.max(initial=1))  # 1: a scene of connectors alone
        s = np.zeros((self.n_elements, gmax))
        wts = np.zeros((self.n_elements, gmax))
        for g in np.unique(self.gauss_points):
            xi, wi = np.polynomial.legendre.leggauss(int(g))
            sel = self.gauss_points == g
            s[sel, :g] = 0.5 * (xi + 1.0)[None, :] * self.L0[sel, None]
            wts[sel, :g] = 0.5 * wi
            s[sel, g:] = 0.5 * self.L0[sel, None]
        return s, wts


def build_mesh(case: Case) -> Mesh:
    """Mesh every cable of the case on its exact catenary under self-weight.

    Nodes are numbered cable by cable, in the case's order, each cable's from its first end to
    its last: a node shared by several cables is numbered (and belongs, in ``cable_of_node`` and
    ``s_node``) with the first cable that reaches it. Nodes on no cable (supports alone) come
    last, in the order of ``[nodes]``.
    """
    node_names: list[str] = []
    X: list[np.ndarray] = []
    index: dict[str, int] = {}
    node_cable: list[int] = []
    node_s: list[float] = []

    def add(name: str, x, ci: int, s: float) -> int:
        if name not in index:
            index[name] = len(node_names)
            node_names.append(name)
            X.append(np.asarray(x, float))
            node_cable.append(ci)
            node_s.append(s)
        return index[name]

    conn, cab, names, L0, EA, w, m, c, gp, s0 = [], [], [], [], [], [], [], [], [], []
    for ci, cable in enumerate(case.cables):
        mat = case.materials[cable.material]
        a = np.asarray(case.nodes[cable.ends[0]], float)
        b = np.asarray(case.nodes[cable.ends[1]], float)
        ne = int(cable.elements)
        le = cable.length / ne
        s_nodes = le * np.arange(1, ne)
        wc = line_weight(case, cable)  # the submerged weight of a cable wholly in water
        pts = _catenary_points(case, cable, a, b, mat.EA, wc, s_nodes)
        ids = [add(cable.ends[0], a, ci, 0.0)]
        for k in range(1, ne):
            ids.append(add(mesh_node(cable.name, k), pts[k - 1], ci, float(s_nodes[k - 1])))
        ids.append(add(cable.ends[1], b, ci, float(cable.length)))
        zs = np.concatenate([[a[2]], pts[:, 2], [b[2]]]) if ne > 1 else np.array([a[2], b[2]])
        w_el = element_weights(case, cable, zs)[0]  # submerged weight where under water
        for k in range(ne):
            conn.append((ids[k], ids[k + 1]))
            cab.append(ci)
            names.append(mesh_node(cable.name, k + 1))
            L0.append(le)
            EA.append(mat.EA)
            w.append(float(w_el[k]))
            m.append(mat.mass)
            c.append(mat.damping)
            gp.append(int(cable.gauss_points))
            s0.append(k * le)
    for name, x in case.nodes.items():
        add(name, x, -1, np.nan)
    return Mesh(
        node_names=tuple(node_names),
        X0=np.array(X, float).reshape(-1, 3),
        element_names=tuple(names),
        conn=np.array(conn, np.int64).reshape(-1, 2),
        cable_of_element=np.array(cab, np.int64),
        cable_names=tuple(cb.name for cb in case.cables),
        L0=np.array(L0, float),
        EA=np.array(EA, float),
        w=np.array(w, float),
        m=np.array(m, float),
        c=np.array(c, float),
        gauss_points=np.array(gp, np.int64),
        s_start=np.array(s0, float),
        cable_of_node=np.array(node_cable, np.int64),
        s_node=np.array(node_s, float),
    )


def _catenary_points(case, cable, a, b, ea, w, s_nodes) -> np.ndarray:
    """Points at arc lengths s_nodes on the elastic catenary from a to b (self-weight only).

    A weightless cable that is not taut has no shape of its own; it is then meshed under its
    own point loads, point masses and distributed loads (which the case validation requires it
    to carry), and failing that on the straight chord.
    """
    if len(s_nodes) == 0:
        return np.zeros((0, 3))
    el = Elements([cable.length], [ea], [w])
    st = el.solve((b - a)[None])
    if st.converged[0] and st.status[0] != SLACK:
        return a + el.position(st.h, s_nodes[None])[0]
    def s_of(item):  # along this cable: by cable and s, or at one of its mesh nodes
        if item.cable == cable.name:
            return item.s
        node = split_mesh_node(item.node or "")
        if node is not None and node[0] == cable.name and node[1].isdigit():
            return cable.length * int(node[1]) / int(cable.elements)
        return None

    items = [(s_of(pm), (0.0, 0.0, -pm.mass * case.gravity)) for pm in case.point_masses]
    items += [(s_of(ld), tuple(ld.force)) for ld in case.loads]
    for dl in case.distributed_loads:  # a wind on a weightless line: 8 point loads for a shape
        if dl.cable == cable.name:
            lo, hi = dl.from_s, min(dl.to_s, cable.length)
            ds = (hi - lo) / 8.0
            items += [(lo + (k + 0.5) * ds, tuple(ds * np.asarray(dl.load, float)))
                      for k in range(8)]
    items = [(s, f) for s, f in items if s is not None]
    if items:
        el = Elements([cable.length], [ea], [w], PointLoads.from_lists([items]))
        st = el.solve((b - a)[None])
        if st.converged[0] and st.status[0] != SLACK:
            return a + el.position(st.h, s_nodes[None])[0]
    if w == 0.0 and not items:
        where = f"cables[{case.cables.index(cable)}]"
        raise CaseError(case.path, [(where, f"weightless cable {cable.name!r} is slack (length "
                                     ">= chord) and carries nothing: no defined shape")])
    return a + np.outer(s_nodes / cable.length, b - a)
