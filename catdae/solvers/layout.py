"""Where the unknowns of a transient sit (docs/theory.md §8): y = [q, v] of the free dofs,
interleaved per dof after a reverse Cuthill-McKee ordering of the free-free stiffness graph
(so that a single cable's iteration matrix is narrowly banded), and the sparsity pattern of
the iteration matrix with the maps from the stiffness and mass blocks into it. Fixed by the
mesh and the supports: computed once per step, apart from the residual's state."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import reverse_cuthill_mckee


class UnknownLayout:
    """Ordering of the free dofs and the iteration matrix's pattern.

    ``fidx[k]``: the full dof of unknown k; ``ff_sel``/``ff_a``/``ff_b``: the entries of the
    full CSR data in the free-free block and their (row, column) unknowns; ``j_pattern``: the
    CSC pattern of J (rows 2a for q, 2a+1 for v); ``jmap_*``: where the qq, qv, vq and vv
    blocks go in its data; ``bandwidth``: of the free-free block in the unknowns' order."""

    def __init__(self, pattern, free: np.ndarray, n_dof: int):
        pat = pattern
        full = sp.csr_matrix((np.ones(pat.nnz), pat.indices, pat.indptr),
                             shape=(n_dof, n_dof))
        ff = full[free][:, free]
        perm = np.asarray(reverse_cuthill_mckee(ff.tocsr(), symmetric_mode=True), np.int64)
        self.fidx = free[perm]  # full dof of unknown k
        self.n = self.fidx.size
        pos = np.full(n_dof, -1, np.int64)
        pos[self.fidx] = np.arange(self.n)
        rows = np.repeat(np.arange(n_dof), np.diff(pat.indptr))
        cols = pat.indices.astype(np.int64)
        keep = (pos[rows] >= 0) & (pos[cols] >= 0)
        self.ff_sel = np.flatnonzero(keep)  # entries of the full CSR data in the ff block
        self.ff_a = pos[rows[keep]]
        self.ff_b = pos[cols[keep]]
        self.bandwidth = int(np.abs(self.ff_a - self.ff_b).max(initial=0))
        # --- sparse pattern of J (interleaved): rows 2a (q) and 2a+1 (v)
        a, b = self.ff_a, self.ff_b
        n = self.n
        jr = np.concatenate([2 * np.arange(n), 2 * np.arange(n), 2 * a + 1, 2 * a + 1])
        jc = np.concatenate([2 * np.arange(n), 2 * np.arange(n) + 1, 2 * b, 2 * b + 1])
        keys = jc * (2 * n) + jr  # column-major for CSC
        ukeys, inv = np.unique(keys, return_inverse=True)
        self.j_nnz = ukeys.size
        jcsc_rows = (ukeys % (2 * n)).astype(np.int32)
        jcsc_cols = ukeys // (2 * n)
        indptr = np.concatenate([[0], np.cumsum(np.bincount(jcsc_cols, minlength=2 * n))])
        self.j_pattern = sp.csc_matrix((np.ones(self.j_nnz), jcsc_rows, indptr),
                                       shape=(2 * n, 2 * n))
        m = a.size
        self.jmap_qq = inv[:n]
        self.jmap_qv = inv[n:2 * n]
        self.jmap_vq = inv[2 * n:2 * n + m]
        self.jmap_vv = inv[2 * n + m:]
