"""The connectors' terms of the transient residual, iteration matrix, mass and energies
(docs/theory.md §15): a mixin of :class:`~catdae.solvers.residual.TransientProblem`, whose
hooks call these only when the scene has connectors (``self.connectors`` is not None)."""

from __future__ import annotations

import numpy as np

from catdae.model.connectors import extend


class ConnectorTerms:
    """Springs, dampers and bars in the transient problem (methods of TransientProblem)."""

    @property
    def connectors(self):
        return self.model.connectors

    def _add_connector_force(self, res: np.ndarray) -> None:
        """Add their forces at the state of the compiled pass's buffers to ``res`` (the free
        dofs' r_v) and to the full-dof force buffer (reactions)."""
        f = self.connectors.force(self._Xb, self._Vb, self._Ab, self.alpha)
        self._force += f
        res[1::2] += f[self.fidx]

    def _place(self, t: float, q: np.ndarray) -> None:
        """Positions of the configuration (t, q) into self.X, where their blocks read them."""
        self.X[self.fidx] = q
        self.X[self.model.fixed] = self._supports(t)[0]

    def _connector_blocks(self, k6, vv, V, cj: float):
        """Element blocks followed by the connectors': ∂f/∂x, and ∂f/∂v + (cj + α) M_bar."""
        cn, ne = self.connectors, self.model.mesh.n_elements
        return (extend(k6, cn.stiffness_blocks(self.X, V), ne),
                extend(vv, cn.damping_blocks(self.X) + (cj + self.alpha) * cn.mass_blocks(), ne))

    def _with_bar_mass(self, me):
        """Element mass blocks (or None) followed by the bars' consistent-mass correction."""
        return extend(me, self.connectors.mass_blocks(), self.model.mesh.n_elements)

    def _connector_energies(self, X, V, kinetic: float, strain: float) -> tuple[float, float]:
        """Kinetic and strain energies with the connectors' shares."""
        cn = self.connectors
        return kinetic + cn.kinetic_correction(V), strain + cn.strain_energy(X)
