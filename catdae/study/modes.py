"""Modes of two meshes paired by shape, not by their place in the frequency order.

A coarse mesh lacks some of a fine mesh's modes (a 4-element string has 3 out-of-plane modes)
and has others far lower in its list (an axial mode), so the k-th frequency of a run is not
always the k-th of the reference: comparing them by index measured a 1460 % "error" between
an axial and a transverse mode. Here each run mode is sampled along every cable at unstrained
arc-length fractions (:func:`mode_samples`), interpolated linearly onto the reference's sample
points, and the two sets are paired one to one (Hungarian assignment) on the modal assurance
criterion, MAC = (phi_r . phi)^2 / (|phi_r|^2 |phi|^2), the squared cosine of the angle between
the shapes. Near-equal frequencies (within 1e-3, relative, or within the mesh's own frequency
error, :func:`match`) form a cluster whose shapes any rotation of the eigenvectors within it
leaves valid; a shape is then scored by its projection on the other side's cluster, and the
pairs within a cluster are made in frequency order.
A reference mode whose best partner scores under :data:`MAC_MIN` is not resolved by the run.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from catdae._xr import xr
from catdae.case import AXES, Case
from catdae.case.names import mesh_node

MAC_MIN = 0.5  # below this a pair is no match: the shapes are further apart than 45 degrees
CLUSTER = 1e-3  # relative frequency gap under which modes are treated as one degenerate set


def mode_samples(case_run: Case, group: xr.Dataset, attrs: dict) -> xr.Dataset:
    """``frequency``(mode) and ``shape``(mode, point, axis) at each cable's nodes, the points
    labelled by ``point_cable`` and ``point_t``, the node's unstrained arc-length fraction along
    the cable (0 and 1 at its ends)."""
    names = [str(n) for n in group.node.values]
    where = {n: i for i, n in enumerate(names)}
    rows, cables, ts = [], [], []
    for c in case_run.cables:
        n = int(c.elements)
        for k, node in enumerate([c.ends[0], *(mesh_node(c.name, k) for k in range(1, n)),
                                  c.ends[1]]):
            if node in where:
                rows.append(where[node])
                cables.append(c.name)
                ts.append(k / n)
    return xr.Dataset(
        {"frequency": ("mode", group.frequency.values),
         "shape": (("mode", "point", "axis"), group.shape.values[:, rows])},
        coords={"point_cable": ("point", np.array(cables, dtype=object)),
                "point_t": ("point", np.array(ts, float)), "axis": list(AXES)},
        attrs=attrs)


def _on(points: xr.Dataset, rec: xr.Dataset) -> np.ndarray:
    """rec's shapes interpolated at ``points``' samples: (n_modes, n_points * 3)."""
    shape = rec.shape.values
    out = np.zeros((shape.shape[0], points.sizes["point"], shape.shape[2]))
    cab_r = points.point_cable.values
    cab = rec.point_cable.values
    for name in np.unique(cab_r):
        at = np.flatnonzero(cab_r == name)
        mine = np.flatnonzero(cab == name)
        if not mine.size:
            continue
        order = mine[np.argsort(rec.point_t.values[mine], kind="stable")]
        t = rec.point_t.values[order]
        for m in range(shape.shape[0]):
            for a in range(shape.shape[2]):
                out[m, at, a] = np.interp(points.point_t.values[at], t, shape[m, order, a])
    return out.reshape(out.shape[0], -1)


def _clusters(f: np.ndarray, width: float) -> np.ndarray:
    """A cluster number per mode: consecutive (in frequency) modes closer than ``width``."""
    order = np.argsort(f, kind="stable")
    ids = np.empty(f.size, int)
    cur = 0
    for k, i in enumerate(order):
        if k and abs(f[i] - f[order[k - 1]]) > width * max(abs(f[i]), 1e-300):
            cur += 1
        ids[i] = cur
    return ids


def _projection(vectors: np.ndarray, basis_rows: np.ndarray) -> np.ndarray:
    """|P v|^2 / |v|^2 of each row v on the span of basis_rows."""
    q, _ = np.linalg.qr(basis_rows.T)
    norm = np.einsum("ij,ij->i", vectors, vectors)
    proj = vectors @ q
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(norm > 0, np.einsum("ij,ij->i", proj, proj) / norm, 0.0)


def match(ref: xr.Dataset, rec: xr.Dataset) -> tuple[np.ndarray, np.ndarray]:
    """For each reference mode, the index of the run's mode of the same shape (-1: none) and
    the pair's score (MAC, or the projection on a cluster of near-equal frequencies).

    Where some stay unpaired, the clusters are widened to three times the median frequency
    error of the pairs found: a mesh that shifts frequencies by a percent mixes the shapes of
    modes a percent apart (a coarse net's two modes 0.8 % apart each scored 0.5 on either)."""
    phi_r = ref.shape.values.reshape(ref.sizes["mode"], -1)
    phi = _on(ref, rec)
    f_r, f = ref.frequency.values, rec.frequency.values
    pair, best = _pairs(phi_r, phi, f_r, f, CLUSTER)
    if (pair < 0).any() and (pair >= 0).any():
        found = pair >= 0
        width = 3.0 * float(np.median(np.abs(f[pair[found]] / f_r[found] - 1.0)))
        if width > CLUSTER:
            _widen(phi_r, phi, f_r, f, width, pair, best)
    return pair, best


def _widen(phi_r, phi, f_r, f, width: float, pair, best) -> None:
    """Pairs of the wider clusters taken (in place) where a cluster's reference modes and
    the run modes paired with them span the same shapes, each projecting on the other set
    by MAC_MIN or more: a mesh mixes nearby modes but keeps their span. A cluster that only
    gathers modes the run cannot represent (an inclined stay's n = 5 pair near a coarse
    mesh's n = 4 pair, each at MAC 0.00 with it) keeps the first pairs."""
    wide, score = _pairs(phi_r, phi, f_r, f, width)
    cr = _clusters(f_r, width)
    for c in np.unique(cr):
        rows = np.flatnonzero(cr == c)
        cols = wide[rows]
        if rows.size < 2 or (cols < 0).any() or np.array_equal(cols, pair[rows]):
            continue
        others = np.delete(pair, rows)
        if np.isin(cols, others[others >= 0]).any():
            continue  # the run modes are taken by pairs outside the cluster
        both = min(_projection(phi_r[rows], phi[cols]).min(),
                   _projection(phi[cols], phi_r[rows]).min())
        if both >= MAC_MIN:
            pair[rows], best[rows] = cols, score[rows]


def _pairs(phi_r, phi, f_r, f, width: float) -> tuple[np.ndarray, np.ndarray]:
    cr, cj = _clusters(f_r, width), _clusters(f, width)
    score = np.zeros((phi_r.shape[0], phi.shape[0]))
    for c in np.unique(cr):  # run shapes on each reference cluster
        rows = np.flatnonzero(cr == c)
        score[rows] = _projection(phi, phi_r[rows])[None, :]
    for c in np.unique(cj):  # reference shapes on each run cluster
        cols = np.flatnonzero(cj == c)
        score[:, cols] = np.maximum(score[:, cols], _projection(phi_r, phi[cols])[:, None])
    score = np.nan_to_num(score)
    rows, cols = linear_sum_assignment(-score)
    pair = np.full(phi_r.shape[0], -1)
    best = np.zeros(phi_r.shape[0])
    keep = score[rows, cols] >= MAC_MIN
    pair[rows[keep]], best[rows[keep]] = cols[keep], score[rows[keep], cols[keep]]
    for c in np.unique(cr):  # within a degenerate set, pairs in frequency order
        rows_c = np.flatnonzero((cr == c) & (pair >= 0))
        if rows_c.size > 1:
            rows_c = rows_c[np.argsort(f_r[rows_c], kind="stable")]
            cols_c = np.sort(pair[rows_c])
            cols_c = cols_c[np.argsort(f[cols_c], kind="stable")]
            pair[rows_c], best[rows_c] = cols_c, score[rows_c, cols_c]
    return pair, best
