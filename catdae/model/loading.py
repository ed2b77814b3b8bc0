"""What a step holds (docs/theory.md §4, §7): the point masses, point loads and distributed
loads present in it, split by where they act (at nodes, inside elements), and the free-hanging
ends that decide the mass model ``auto`` picks (catdae.model.settings).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from catdae.case import Case
from catdae.case.timefunc import TimeFunction
from catdae.model.mesh import Mesh


def free_hanging_ends(case: Case, mesh: Mesh, node_mass: np.ndarray) -> list[str]:
    """Names of the nodes that end one element and nothing else: on no other element, with no
    support on any axis and no point mass on them (``node_mass`` (n_nodes,) kg). A cable hangs
    free there, with zero tension at the tip (unless a load pulls it)."""
    degree = np.bincount(mesh.conn.ravel(), minlength=mesh.n_nodes)
    supported = np.zeros(mesh.n_nodes, bool)
    for node, axes in case.supports.items():
        if axes:
            supported[mesh.node_index(node)] = True
    tips = (degree == 1) & ~supported & (node_mass <= 0.0)
    return [mesh.node_names[k] for k in np.flatnonzero(tips)]


@dataclass
class Loading:
    """Point masses and loads active in one step, split by where they act."""

    node_mass: np.ndarray  # (n_nodes,) kg
    node_force: np.ndarray  # (n_nodes, 3) N, constant (weights of point masses, constant loads)
    node_timed: list[tuple[TimeFunction, np.ndarray]]  # f(t) * (n_nodes, 3)
    internal_ptr: np.ndarray  # (n_elem+1,) CSR of loads inside elements
    internal_s: np.ndarray  # (m,) m, local arc length
    internal_force: np.ndarray  # (m, 3) N, constant part
    internal_timed: list[tuple[TimeFunction, np.ndarray]]  # f(t) * (m, 3)
    mass_elem: np.ndarray  # (p,) int, point masses inside elements
    mass_s: np.ndarray  # (p,) m
    mass_value: np.ndarray  # (p,) kg
    names: tuple[str, ...] = field(default=())


def build_loading(case: Case, mesh: Mesh, absent: set[str]) -> Loading:
    """Collect the point masses, point loads and distributed loads of a step: all but those
    named in ``absent`` (not yet added, or removed)."""
    g = case.gravity
    nn, ne = mesh.n_nodes, mesh.n_elements
    node_mass = np.zeros(nn)
    node_force = np.zeros((nn, 3))
    node_timed: dict[int, tuple[TimeFunction, np.ndarray]] = {}
    items: list[tuple[int, float, np.ndarray, TimeFunction | None]] = []
    m_e, m_s, m_v = [], [], []
    names = []

    def where(obj):
        if obj.node is not None:
            return "node", mesh.node_index(obj.node), 0.0
        return mesh.locate(obj.cable, obj.s)

    for pm in case.point_masses:
        if pm.name in absent:
            continue
        names.append(pm.name)
        kind, idx, s = where(pm)
        weight = np.array([0.0, 0.0, -pm.mass * g])
        if kind == "node":
            node_mass[idx] += pm.mass
            node_force[idx] += weight
        else:
            items.append((idx, s, weight, None))
            m_e.append(idx)
            m_s.append(s)
            m_v.append(pm.mass)
    for ld in case.loads:
        if ld.name in absent:
            continue
        names.append(ld.name)
        kind, idx, s = where(ld)
        f = np.asarray(ld.force, float)
        if kind == "node":
            if ld.time is None:
                node_force[idx] += f
            else:
                arr = np.zeros((nn, 3))
                arr[idx] = f
                node_timed[id(ld)] = (ld.time, arr)
        else:
            items.append((idx, s, f, ld.time))
    for dl in case.distributed_loads:
        if dl.name in absent:
            continue
        names.append(dl.name)
        # Gauss points on the covered part of each element (§5), split at the coverage ends
        p = np.asarray(dl.load, float)
        # heated cables (mesh.thermal = 1 + α ΔT, uniform along a cable): the coverage is given
        # in unstrained arc length at the reference temperature, p per metre of it
        ci = mesh.cable_names.index(dl.cable)
        on = np.flatnonzero(mesh.cable_of_element == ci)
        fc = float(mesh.thermal[on[0]]) if on.size else 1.0
        elems, s_loc, ds = mesh.coverage_points(dl.cable, dl.from_s * fc, dl.to_s * fc)
        for e, s, d in zip(elems, s_loc, ds, strict=True):
            items.append((int(e), float(s), d / mesh.thermal[e] * p, dl.time))
    # CSR of internal loads, sorted by element then s
    items.sort(key=lambda it: (it[0], it[1]))
    counts = np.bincount([it[0] for it in items], minlength=ne) if items else np.zeros(ne, int)
    ptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    s_arr = np.array([it[1] for it in items], float)
    f_const = np.zeros((len(items), 3))
    timed: dict[int, tuple[TimeFunction, np.ndarray]] = {}
    for k, (_, _, f, tf) in enumerate(items):
        if tf is None:
            f_const[k] = f
        else:
            key = id(tf)
            if key not in timed:
                timed[key] = (tf, np.zeros((len(items), 3)))
            timed[key][1][k] = f
    return Loading(
        node_mass=node_mass,
        node_force=node_force,
        node_timed=list(node_timed.values()),
        internal_ptr=ptr,
        internal_s=s_arr,
        internal_force=f_const,
        internal_timed=list(timed.values()),
        mass_elem=np.array(m_e, np.int64),
        mass_s=np.array(m_s, float),
        mass_value=np.array(m_v, float),
        names=tuple(names),
    )
