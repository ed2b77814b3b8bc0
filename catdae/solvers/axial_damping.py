"""Axial (strain-rate, Kelvin-Voigt) damping of the catenary elements (docs/theory.md §18).

A Kelvin-Voigt material carries, besides its elastic tension, a viscous tension η A ε̇ on the
rate of axial strain only. An element's strain is that of its catenary: the elastic elongation
e = ∫₀^L0 T(s)/EA ds, a function of the chord c = x_j - x_i through the end force h(c). With a
uniform viscous tension c_d ė (c_d = η A / L0, ė the elongation rate) the Rayleigh dissipation
function is D = ½ c_d ė²; with ė = g·ċ and g = ∂e/∂c the element forces are

    f_i = -c_d ė g,   f_j = +c_d ė g        (added to the resisting forces)

g comes from the element solve without a new integral: T = |t(s)| with ∂t(s)/∂h = I, so
∂e/∂h = (1/EA) ∫ t̂ ds, and the chord is c = ∫ t̂ ds + (1/EA) ∫ t ds (t linear in s between the
concentrated loads), hence

    ∂e/∂h = (c - (1/EA) ∫ t ds) / EA,    g = K ∂e/∂h   (K = ∂h/∂c, symmetric)

A straight taut element has g = ĉ (the unit chord); a rigid rotation has ė = 0 (the swing of a
taut line is not damped); a slack element (K = 0) has g = 0. The iteration matrix gets
∂f/∂v = c_d [[g gᵀ, -g gᵀ], [-g gᵀ, g gᵀ]]; the derivative of g with respect to the positions
is left out (it is of the order of c_d ė / ℓ, small beside the geometric stiffness T / ℓ
wherever the viscous tension is small beside the elastic one).

The coefficient is a share ζ of critical at a frequency f: a taut bar's axial mode at ω gets
ζ(ω) = η ω / (2 E), so η A = 2 ζ EA / (2π f) and c_d = 2 ζ EA / (2π f L0). With
``frequency = "element"`` f is each element's own highest axial frequency 2c/L0 (c = sqrt(EA/m),
that of two lumped halves), and c_d = ζ sqrt(EA m): ζ times the wave impedance, the same for
every element of a cable whatever the mesh. A mode of frequency ω then gets ζ ω L0 / (2c),
which vanishes as the mesh is refined: damping of what the mesh cannot resolve, like the
numerical dissipation of a generalised-α scheme, but acting on the axial strain only.

``rate = "chord"`` puts the same c_d on the rate of change of the chord length instead,
ė = ĉ·ċ and g = ĉ (MoorDyn's BA on its straight segments, whose elongation is all strain):
in a sagging element it also damps the breathing of the element's sag, which the strain rate
hardly sees (g = K ∂e/∂h is about 12/λ² of ĉ there, docs/theory.md §18.6).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def element_g(i, j, X, he, ke, L, ea, w, ls, lf, k0, k1, gout):
    """g = ∂e/∂c (3,) of one element (nodes' first dofs i, j; end force he, stiffness ke)."""
    inv = 1.0 / ea
    d0 = L * he[0]
    d1 = L * he[1]
    d2 = L * he[2] + 0.5 * w * L * L  # ∫ t ds, t(s) = h + (0, 0, w s) - Σ_{s_k < s} f_k
    for k in range(k0, k1):
        d0 -= lf[k, 0] * (L - ls[k])
        d1 -= lf[k, 1] * (L - ls[k])
        d2 -= lf[k, 2] * (L - ls[k])
    d0 = (X[j] - X[i] - inv * d0) * inv
    d1 = (X[j + 1] - X[i + 1] - inv * d1) * inv
    d2 = (X[j + 2] - X[i + 2] - inv * d2) * inv
    for a in range(3):
        gout[a] = ke[a, 0] * d0 + ke[a, 1] * d1 + ke[a, 2] * d2


@njit(cache=True)
def axial_rates(conn, X, V, h, kmat, l0, ea, w, ptr, ls, lf, g, edot):
    """g = ∂e/∂c (n, 3) and ė = g·ċ (n,) of every element, from the solved end forces h and
    stiffnesses kmat (∂h/∂c) at positions X, velocities V (full dofs)."""
    for e in range(conn.shape[0]):
        i = 3 * conn[e, 0]
        j = 3 * conn[e, 1]
        element_g(i, j, X, h[e], kmat[e], l0[e], ea[e], w[e], ls, lf, ptr[e], ptr[e + 1], g[e])
        rate = 0.0
        for a in range(3):
            rate += g[e, a] * (V[j + a] - V[i + a])
        edot[e] = rate


@njit(cache=True)
def unit_chord(c, k, out):
    """out[:] = the unit vector of c[k:k + 3] (zero for a zero chord)."""
    n2 = c[k] * c[k] + c[k + 1] * c[k + 1] + c[k + 2] * c[k + 2]
    inv = 1.0 / np.sqrt(n2) if n2 > 0.0 else 0.0
    for a in range(3):
        out[a] = c[k + a] * inv


@njit(cache=True)
def chord_rates(conn, X, V, g, edot):
    """g = ĉ (n, 3), the unit chord, and ė = ĉ·ċ (n,), the rate of change of the chord length,
    of every element at positions X, velocities V (full dofs)."""
    c = np.empty(3)
    for e in range(conn.shape[0]):
        i = 3 * conn[e, 0]
        j = 3 * conn[e, 1]
        for a in range(3):
            c[a] = X[j + a] - X[i + a]
        unit_chord(c, 0, g[e])
        rate = 0.0
        for a in range(3):
            rate += g[e, a] * (V[j + a] - V[i + a])
        edot[e] = rate


@njit(cache=True)
def add_forces(conn, cd, g, edot, out):
    """out (n_dof,) += the element damping forces on the full dofs."""
    for e in range(conn.shape[0]):
        i = 3 * conn[e, 0]
        j = 3 * conn[e, 1]
        f = cd[e] * edot[e]
        for a in range(3):
            out[i + a] -= f * g[e, a]
            out[j + a] += f * g[e, a]


@njit(cache=True)
def add_residual(conn, cd, g, edot, unknown, res):
    """res[2 k + 1] += the damping force on the free dof of unknown k (``unknown``: the unknown
    of each full dof, -1 where the dof is fixed)."""
    for e in range(conn.shape[0]):
        i = 3 * conn[e, 0]
        j = 3 * conn[e, 1]
        f = cd[e] * edot[e]
        for a in range(3):
            ki = unknown[i + a]
            kj = unknown[j + a]
            if ki >= 0:
                res[2 * ki + 1] -= f * g[e, a]
            if kj >= 0:
                res[2 * kj + 1] += f * g[e, a]


class AxialDamping:
    """The strain-rate damping of one transient step: coefficients and evaluations."""

    def __init__(self, model, ratio: float, frequency: float | str, fidx=None,
                 rate: str = "strain"):
        el = model.elements
        mesh = model.mesh
        self.ratio = float(ratio)
        self.frequency = frequency
        self.chord = rate == "chord"  # on the chord's rate (MoorDyn's segments), §18.6
        if frequency == "element":
            # ω_e = 2 c / L0: c_d = 2 ζ EA / (ω_e L0) = ζ sqrt(EA m)
            self.cd = self.ratio * np.sqrt(el.EA * mesh.m)
            with np.errstate(divide="ignore"):
                self.f_element = np.sqrt(el.EA / mesh.m) / (np.pi * el.L0)
        else:
            self.cd = 2.0 * self.ratio * el.EA / (2.0 * np.pi * float(frequency) * el.L0)
            self.f_element = None
        self.cd = np.ascontiguousarray(self.cd, float)
        ne = el.L0.size
        self.g = np.zeros((ne, 3))
        self.edot = np.zeros(ne)
        self._conn = np.ascontiguousarray(mesh.conn, np.int64)
        self._model = model
        # the unknown of each full dof (-1 where fixed), for the residual
        self._unknown = np.full(model.n_dof, -1, np.int64)
        if fidx is not None:
            self._unknown[fidx] = np.arange(len(fidx))

    @classmethod
    def of(cls, model, step, fidx=None) -> AxialDamping | None:
        """The damping a transient step asks for (None: none); ``fidx``: the full dof of
        each unknown of the residual."""
        spec = getattr(step, "axial_damping", None)
        if spec is None:
            return None
        return cls(model, spec.ratio, spec.frequency, fidx, getattr(spec, "rate", "strain"))

    def describe(self) -> str:
        on = " on the chord's rate" if self.chord else ""
        if self.frequency == "element":
            f = self.f_element
            return (f"{100 * self.ratio:g} % of critical at each element's highest axial "
                    f"frequency ({np.nanmin(f):.4g}-{np.nanmax(f):.4g} Hz){on}")
        return f"{100 * self.ratio:g} % of critical at {float(self.frequency):g} Hz{on}"

    def rates(self, X, V, h, kmat) -> None:
        """g and ė at positions X, velocities V (full dofs) and the solved h, kmat."""
        if self.chord:
            chord_rates(self._conn, X, V, self.g, self.edot)
            return
        el = self._model.elements
        axial_rates(self._conn, X, V, h, kmat, el.L0, el.EA, el.w, el._ptr, el._ls, el._lf,
                    self.g, self.edot)

    def add_residual(self, res, X, V, h, kmat) -> None:
        """res (interleaved q, v rows of the unknowns) += the forces at positions X and
        velocities V (full dofs) with the solved h, kmat (``rates`` first)."""
        self.rates(X, V, h, kmat)
        add_residual(self._conn, self.cd, self.g, self.edot, self._unknown, res)

    def add_forces(self, out, X=None, V=None, state=None) -> None:
        """out (n_dof,) += the forces, at (X, V, state.h, state.K) when given, else at the
        last ``rates``."""
        if state is not None:
            self.rates(X, V, state.h, state.K)
        add_forces(self._conn, self.cd, self.g, self.edot, out)

    def add_to_output(self, f, tension):
        """The forces into f (n_dof,) and the viscous tension onto the end tensions (n, 2),
        at the last ``rates`` (an output state)."""
        add_forces(self._conn, self.cd, self.g, self.edot, f)
        return tension + self.tension()[:, None]

    def tension(self) -> np.ndarray:
        """The viscous tension c_d ė of every element (n,) N, at the last ``rates``."""
        return self.cd * self.edot

    def velocity_data(self, prob, t, y, yp, conf) -> np.ndarray:
        """CSR data (full dofs) of ∂f/∂v at the state (t, y, yp) of the configuration conf of
        the TransientProblem prob (the iteration matrix's velocity block)."""
        V, _ = prob.full_vectors(t, y[1::2], yp[1::2])
        X = np.empty(prob.n_dof)
        X[prob.fidx] = y[0::2]
        X[prob.model.fixed] = prob._supports(t)[0]
        self.rates(X, V, conf[0].h, conf[0].K)
        return prob.model.pattern.assemble(self.velocity_blocks())

    def velocity_blocks(self) -> np.ndarray:
        """∂f/∂v (n, 6, 6) at the last ``rates``."""
        gg = self.cd[:, None, None] * self.g[:, :, None] * self.g[:, None, :]
        return np.block([[gg, -gg], [-gg, gg]])
