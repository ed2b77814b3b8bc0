"""The mass (and material damping) matrices of a step's model (docs/theory.md §7): consistent
(the catenary interpolation functions), lumped, blended or linear, as ``self.mass_model`` (a
:class:`~catdae.model.settings.MassModel`) says. A mixin of :class:`catdae.model.assembly.Model`,
which provides the mesh, loading, elements, Gauss points and DOF pattern it uses."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from catdae.element.elements import ElementState
from catdae.model.connectors import extend


class MassMatrices:
    """Mass matrices of a Model (see the module docstring)."""

    def element_mass(self, state: ElementState) -> np.ndarray:
        """Consistent element matrices Σ_g m L0 w_g NᵀN + point masses, (n_elem, 6, 6).

        docs/theory.md §7. The compiled quadrature that the transient step also uses
        (Elements.solve_dynamic).
        With the linear mass model the constant matrices of straight-line interpolation.
        """
        if self.mass_model.linear:
            return self.linear_element_mass()
        ld = self.loading
        me = self.elements.element_masses(state, self.gauss_s, self.gauss_w, self.mesh.m,
                                          (ld.mass_elem, ld.mass_s, ld.mass_value))
        if self.mass_model.catenary and self.mass_model.lumped_fraction:
            me *= 1.0 - self.mass_model.lumped_fraction
        return me

    def diagonal_mass(self, per_length: np.ndarray | None = None) -> np.ndarray:
        """The diagonal part of the mass matrix (of damping with ``per_length``), (n_dof,):
        nodal masses, plus μ times the lumped element masses (μ = 1 lumped, 1/2 blended, 0
        consistent and linear)."""
        mu = self.mass_model.lumped_fraction
        node = (np.zeros(self.n_dof) if per_length is not None
                else np.repeat(self.loading.node_mass, 3))
        if mu == 0.0:
            return node
        return node + mu * (self.lumped_mass_diag(per_length) - (
            node if per_length is None else 0.0))

    def linear_element_mass(self, damping: bool = False) -> np.ndarray:
        """Element matrices of straight-line interpolation N = [(1-ξ) I, ξ I], (n_elem, 6, 6).

        m L0 / 6 [[2, 1], [1, 2]] ⊗ I per element, plus m_p N(ξ_p)ᵀ N(ξ_p) for point masses
        inside elements; with ``damping`` the same for the material damping per length (point
        masses carry none). The interior of an element moves with its chord, not with its
        static catenary shape: the element carries axial waves as a bar does, and the matrix
        does not depend on q (computed once per model).
        """
        cache = self.__dict__.setdefault("_linear_mass_cache", {})
        if damping in cache:
            return cache[damping]
        mesh = self.mesh
        q = mesh.c if damping else mesh.m
        base = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6.0
        blocks = (q * mesh.L0)[:, None, None] * base[None]  # (n, 2, 2)
        ld = self.loading
        if not damping and ld.mass_value.size:
            xi = ld.mass_s / mesh.L0[ld.mass_elem]
            nn = np.stack([1.0 - xi, xi], axis=1)  # (p, 2)
            np.add.at(blocks, ld.mass_elem, ld.mass_value[:, None, None]
                      * nn[:, :, None] * nn[:, None, :])
        out = np.kron(blocks, np.eye(3)[None])  # (n, 6, 6): node-major blocks of 3
        cache[damping] = out
        return out

    def dynamic_state(self, X: np.ndarray, h0: np.ndarray | None, material_damping: bool,
                      gradient: bool = False):
        """Element state with element mass (and material damping) matrices in one pass.

        Returns (state, M_e (n_elem, 6, 6) or None when the mass is lumped, C_e or None,
        ∂M_e/∂c_k (n_elem, 3, 6, 6) or None): the gradient (analytic, of the consistent part)
        with ``gradient`` and a consistent or blended mass only.
        """
        mesh = self.mesh
        ld = self.loading
        if self.mass_model.linear:
            state = self.elements.solve(self.chords(X), h0)
            ce = self.linear_element_mass(damping=True) if material_damping else None
            return state, self.linear_element_mass(), ce, None
        gradient = gradient and self.mass_model.catenary
        out = self.elements.solve_dynamic(
            self.chords(X), h0, self.gauss_s, self.gauss_w, mesh.m,
            mesh.c if material_damping and self.mass_model.catenary
            else None, (ld.mass_elem, ld.mass_s, ld.mass_value), gradient=gradient)
        state, me, ce = out[:3]
        dm = out[3] if gradient else None
        if self.mass_model.lumped:
            me = None
        elif self.mass_model.catenary and self.mass_model.lumped_fraction:
            keep = 1.0 - self.mass_model.lumped_fraction
            me *= keep
            if ce is not None:
                ce *= keep
            if dm is not None:
                dm *= keep
        return state, me, ce, dm

    def lumped_mass_diag(self, per_length: np.ndarray | None = None) -> np.ndarray:
        """Lumped diagonal on the dofs: half of each element at each end, (n_dof,).

        Default: masses (kg), with point masses split by arc length and nodal masses added.
        With ``per_length`` (e.g. material damping per length): that quantity alone.
        """
        mesh = self.mesh
        q = mesh.m if per_length is None else per_length
        node = np.zeros(mesh.n_nodes)
        np.add.at(node, mesh.conn.ravel(), np.repeat(0.5 * q * mesh.L0, 2))
        ld = self.loading
        if per_length is None:
            if ld.mass_value.size:
                frac = ld.mass_s / mesh.L0[ld.mass_elem]
                np.add.at(node, mesh.conn[ld.mass_elem, 0], (1 - frac) * ld.mass_value)
                np.add.at(node, mesh.conn[ld.mass_elem, 1], frac * ld.mass_value)
            node += ld.node_mass
        return np.repeat(node, 3)

    def mass_data(self, state: ElementState) -> np.ndarray:
        """CSR data of the mass matrix M(q) on the full dof set."""
        if self.mass_model.lumped:
            me, diag = None, self.lumped_mass_diag()
        else:
            me, diag = self.element_mass(state), self.diagonal_mass()
        if self.connectors is not None:  # the bars' consistent-mass correction (theory §15)
            me = extend(me, self.connectors.mass_blocks(), self.mesh.n_elements)
        return self.pattern.assemble(me, diag)

    def mass(self, state: ElementState) -> sp.csr_matrix:
        return self.pattern.matrix(self.mass_data(state))
