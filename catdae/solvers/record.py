"""What a transient step records at its output times (docs/theory.md §8, §10): positions,
velocities, accelerations, tensions, reactions and energies as arrays (NaN where not
reached), and the run's own advice on its accuracy. Datasets are made from them in
``catdae.output.transient``."""

from __future__ import annotations

import numpy as np

from catdae.model.assembly import Model
from catdae.model.fluid import plausibility_note
from catdae.solvers.deferred import GAUSS8, DeferredOutputs, can_defer
from catdae.solvers.energy_check import balance_notes
from catdae.solvers.envelope import TensionEnvelope
from catdae.solvers.fluid_work import FluidWork


class OutputRecord:
    """Arrays at the output times ``times``, filled by ``record``; ``n_valid`` of them are
    reached, and ``attrs`` hold the step's statistics and settings (result attributes)."""

    def __init__(self, prob, times: np.ndarray):
        mesh = prob.model.mesh
        self.prob = prob
        self.mesh = mesh
        self.times = times
        nn, ne = mesh.n_nodes, mesh.n_elements
        self.X = np.full((times.size, nn, 3), np.nan)  # (n_out, n_nodes, 3) m
        self.V = np.full_like(self.X, np.nan)  # m/s
        self.A = np.full_like(self.X, np.nan)  # m/s²
        self.T = np.full((times.size, ne, 2), np.nan)  # (n_out, n_elem, 2) N, end tensions
        self.R = np.full_like(self.X, np.nan)  # N, support reactions (NaN on free axes)
        self.E = np.full((times.size, 3), np.nan)  # J: kinetic, strain, potential
        # J: work of the water and air (docs/theory.md §13.5); None without a fluid
        self.work = FluidWork(prob) if prob.model.fluid is not None else None
        self.W = np.full(times.size, np.nan)
        self.n_valid = 0
        self.attrs: dict = {}
        self.envelope = TensionEnvelope(prob)  # every accepted step and every output
        # outputs computed in batches where no Python is needed at each (catdae.solvers.deferred)
        self.deferred = DeferredOutputs(prob, times.size) if can_defer(prob) else None
        self.n_computed = 0  # outputs 0 .. n_computed - 1 are in the arrays

    def record(self, k: int, t: float, y: np.ndarray, yp: np.ndarray) -> None:
        """Output k at t from IDA's y, y' (kept for a batch, or computed now)."""
        d = self.deferred
        if d is not None:
            if d.count and k != d.first + d.count:  # outputs again after a lost order race
                d.compute(self)
            if d.keep(k, t, y, yp):
                d.compute(self)
            return
        X, V, A, T, R, E = self.prob.observe(t, y, yp)
        self.X[k], self.V[k], self.A[k] = X.reshape(-1, 3), V.reshape(-1, 3), A.reshape(-1, 3)
        self.T[k], self.R[k], self.E[k] = T, R, E
        self.envelope.update(t, tension=T)
        if self.work is not None:  # observe's residual pass left the fluid's M_a A - f
            self.W[k] = self.work.at(t, y, yp, power=-float(self.prob.model.fluid.out @ V))
        self.n_computed = k + 1

    def flush(self) -> None:
        """Compute the outputs kept for a batch (SolverError where one cannot be)."""
        if self.deferred is not None:
            self.deferred.compute(self)

    def upto(self, n_valid: int, attrs: dict) -> OutputRecord:
        """This record with its first ``n_valid`` outputs valid and ``attrs`` set."""
        self.n_valid = n_valid
        self.attrs = attrs
        return self


def output_times(t0: float, duration: float, dt_out: float) -> np.ndarray:
    """t0, t0 + dt, ... and the end exactly (the next step starts there)."""
    t_end = t0 + duration
    n_out = int(np.floor((t_end - t0) / dt_out + 1e-9)) + 1
    times = t0 + dt_out * np.arange(n_out)
    if times[-1] < t_end - 1e-9 * dt_out:
        times = np.append(times, t_end)
    times[-1] = t_end
    return times


def potential(model: Model, X: np.ndarray, h: np.ndarray, t: float):
    """Strain energy ∫T²/(2EA) ds and potential of gravity and constant loads, J (loads with a
    time function have no potential: their work changes the total energy)."""
    mesh = model.mesh
    el = model.elements
    per_element = el.energies(h, *GAUSS8)  # strain (exact), ∫ w (z - z_i) ds
    strain = float(per_element[:, 0].sum())
    gravity = float(per_element[:, 1].sum() + mesh.w @ (mesh.L0 * X[mesh.conn[:, 0], 2]))
    # loads inside elements (point-mass weights, constant loads) and at nodes
    ld = model.loading
    if ld.internal_s.size:
        counts = np.diff(ld.internal_ptr)
        e_of = np.repeat(np.arange(mesh.n_elements), counts)
        sq = np.zeros((mesh.n_elements, max(int(counts.max()), 1)))
        slot = np.arange(ld.internal_s.size) - ld.internal_ptr[e_of]
        sq[e_of, slot] = ld.internal_s
        xk = X[mesh.conn[:, 0]][:, None, :] + el.position(h, sq)
        gravity -= float(np.sum(ld.internal_force * xk[e_of, slot]))
    # only the constant loads have a potential; the work of loads that vary in time (like that
    # of moving supports) changes the total energy instead
    gravity -= float(ld.node_force.reshape(-1) @ X.reshape(-1))
    return strain, gravity


def note(model: Model, prob, rec: OutputRecord | None = None, n_valid: int = 0) -> str:
    """Advice on the result's accuracy that the run itself found ("" when none): on the mass
    model, and (given the record and its ``n_valid`` outputs) an energy balance that does not
    close (catdae/solvers/energy_check.py)."""
    advice = [_mass_note(model, prob), balance_notes(model, prob, rec, n_valid),
              _slack_note(model, rec, n_valid), plausibility_note(model.case),
              _tolerance_note(model, prob, rec, n_valid)]
    return "; ".join(a for a in advice if a)


def _tolerance_note(model: Model, prob, rec: OutputRecord | None, n_valid: int) -> str:
    """A word when rtol times the largest displacement (of a coordinate, since the step's start:
    what IDA's error test weighs) is below atol: the error test then
    follows atol alone, and a tighter rtol changes nothing (an independent tester's plucked
    string: rtol 1e-6 to 1e-9 gave the same run to the bit, its error set by atol)."""
    if rec is None or n_valid < 2:
        return ""
    # IDA's unknowns: each coordinate's displacement since the step's start (tester t78: the
    # displacement from the case's geometry made example 1's note say 0.0296 m for 0.0585 m)
    u = rec.X[:n_valid] - rec.X[0][None]
    largest = float(np.nanmax(np.abs(u), initial=0.0))
    rtol, atol = float(prob.step.rtol), float(prob.step.atol)
    if not largest > 0.0 or rtol * largest >= atol:
        return ""
    return (f"rtol {rtol:g} times the largest displacement since the step's start "
            f"({largest:.3g} m) is below atol ({atol:g} m): the displacements' error test "
            "follows atol, and a tighter rtol alone gains little there; tighten atol with it "
            "(docs/accuracy.md)")


SLACK, SNAP = 0.1, 1.5  # an element end that fell below SLACK of its start tension and rose
# above SNAP times it during a step went nearly slack and snapped taut


def slack_snapped(t_min: np.ndarray, t_max: np.ndarray, start: np.ndarray) -> np.ndarray:
    """Element ends (a mask like ``start``) loaded at the start whose tension envelope fell
    below SLACK of it and rose above SNAP times it, or went into compression below -SLACK of it
    (a cable cannot be: a slack element the catenary mass mis-carries)."""
    return (start > 0.0) & (((t_min < SLACK * start) & (t_max > SNAP * start))
                            | (t_min < -SLACK * start))


def slack_where(model: Model, rec: OutputRecord | None, n_valid: int) -> str:
    """Which element ends went nearly slack and snapped taut (``slack_snapped``): the element
    that fell furthest, its tensions and when ("" if none)."""
    if rec is None or n_valid < 1:
        return ""
    env = rec.envelope
    start = rec.T[0]
    fell = slack_snapped(env.t_min, env.t_max, start)
    if not fell.any():
        return ""
    loaded = start > 0.0
    e, k = np.argwhere(fell)[np.argmin((env.t_min / np.where(loaded, start, 1.0))[fell])]
    return (f"element {model.mesh.element_names[e]!r} went nearly slack and snapped taut "
            f"(tension {env.t_min[e, k]:.4g} N at t = {env.time_min[e, k]:.6g} s, "
            f"{start[e, k]:.4g} N at the start, up to {env.t_max[e, k]:.4g} N)")


def _slack_note(model: Model, rec: OutputRecord | None, n_valid: int) -> str:
    """An element end that went nearly slack and snapped taut (``slack_where``): with a
    catenary (consistent or blended) mass, which only a mass that carries axial waves carries
    in full (docs/accuracy.md; an independent tester's smooth but violent support motion: +33 %
    on the peak tension with the blended mass, not converging with rtol or the mesh); with the
    lumped or linear mass, that the peaks of repeated snaps are sensitive (tester t73)."""
    where = slack_where(model, rec, n_valid)
    if not where:
        return ""
    if not model.mass_model.catenary:  # carried: but a sequence of snaps is sensitive
        return (f"{where}: the peak of a snap after slack, and of the snaps after it, can "
                "depend on small differences (an independent tester's heaved wire read 78 to "
                "108 kN from rtol 1e-4 to 1e-10 after repeated snaps); check it with catdae "
                "study over rtol, or add axial_damping (docs/accuracy.md)")
    return (f"{where}: a snap after slack is carried in full only by a mass that carries "
            f"axial waves, and mass_model {model.mass_model.name!r} does not: compare the peak "
            "tension with mass_model = \"lumped\" (docs/accuracy.md)")


def _mass_note(model: Model, prob) -> str:
    if model.mass_model.snap:
        why = model.mass_model.snap
        advice = ("set mass_model = \"lumped\" on the step to save that first run"
                  if model.mass_model.rerun else "give mass_model = \"blended\" where no snap "
                  "is expected (smooth motion converges faster with it; docs/accuracy.md)")
        return ("mass_model \"auto\" chose \"lumped\", a mass that carries axial (snap) waves, "
                f"because {why}; {advice}")
    if not model.mass_model.catenary:
        return ""
    floor = prob.jump_floor  # jumps whose wave counts (catdae.model.snap.jump_floor)
    jumps = [j for j in prob.velocity_jumps if j[2] > 1.0 and j[1] >= floor]
    changed = [*prob.step.add, *prob.step.remove]
    lam2 = getattr(prob, "lambda2_start", 0.0)
    acts = getattr(prob, "unbalance_start", 1.0) > 1e-6  # of the largest tension: a change
    if not jumps and changed and acts and lam2 > 1.0:
        return (f"{', '.join(repr(c) for c in changed)} added or removed at the start of the "
                "step act(s) suddenly: the axial wave that sends (a snap where elements are "
                "slack) is not fully carried by the consistent catenary mass of elements that "
                f"take a chord change by sag (element λ² up to {lam2:.3g} here, > 1); "
                f"mass_model {model.mass_model.setting!r} kept {model.mass_model.name!r} (the "
                "paper's scenes depend on it); peak tensions may be underestimated (try "
                "mass_model = \"lumped\" or \"linear\"; docs/accuracy.md)")
    if not jumps:
        return ""
    t, dv, lam2 = jumps[0]
    return (f"a support velocity jumps by up to {dv:.3g} m/s at t = {t:.6g} s: the axial "
            f"(water-hammer) wave it sends is not carried by the {model.mass_model.name} mass "
            f"(catenary) of elements that take a chord change by sag (element λ² up to "
            f"{lam2:.3g} here, "
            "> 1); tensions may be underestimated (try mass_model = \"lumped\" or \"linear\", "
            "or more elements; docs/accuracy.md)")
