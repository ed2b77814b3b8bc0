"""The dataset of a transient step from its output record (catdae.solvers.record)."""

from __future__ import annotations

from catdae._xr import xr
from catdae.output import results
from catdae.output.connectors import with_connector_forces
from catdae.output.fluid import with_fluid


def dataset(rec) -> xr.Dataset:
    """Histories of the first ``rec.n_valid`` outputs, with the step's attributes."""
    sl = slice(0, rec.n_valid)
    E = rec.E[sl]
    energy = {
        "energy_kinetic": (E[:, 0], "kinetic energy ½ vᵀ M v"),
        "energy_strain": (E[:, 1], "elastic strain energy ∫ T²/(2EA) ds"),
        "energy_potential": (E[:, 2], "potential of gravity and constant loads"),
        "energy_total": (E.sum(axis=1), "kinetic + strain + potential"),
    }
    ds = results.transient_dataset(rec.mesh, rec.times[sl], rec.X[sl], rec.V[sl], rec.A[sl],
                                   rec.T[sl], rec.R[sl], energy, dict(rec.attrs))
    if rec.work is not None:
        ds["energy_fluid_work"] = xr.Variable("time", rec.W[sl], {
            "units": "J", "long_name": "work done on the cables by the water and the air"})
    ds = with_connector_forces(ds, rec.prob.model.connectors, rec.X[sl], rec.V[sl])
    fl = rec.prob.model.fluid  # water and air: surface elevation, fluid velocity
    if fl is not None:
        ds = with_fluid(ds, fl, rec.times[sl], rec.X[sl])
    env = getattr(rec, "envelope", None)
    return ds if env is None else ds.assign(envelope_variables(env))


def envelope_variables(env) -> dict:
    """tension_max, tension_min, time_tension_max, time_tension_min (element, end) of a
    TensionEnvelope (catdae.solvers.envelope): every accepted step and every output."""
    d = ("element", "end")
    how = "over every accepted integrator step and output"
    return {
        "tension_max": results.var(d, env.t_max.copy(), "N",
                                    f"largest cable tension at element end, {how}"),
        "tension_min": results.var(d, env.t_min.copy(), "N",
                                    f"smallest cable tension at element end, {how}"),
        "time_tension_max": results.var(d, env.time_max.copy(), "s",
                                         "time of tension_max on the case's clock"),
        "time_tension_min": results.var(d, env.time_min.copy(), "s",
                                         "time of tension_min on the case's clock"),
    }


def as_dataset(obj):
    """A dataset from a solver's result: an output record is turned into one, a dataset (or
    anything else, e.g. None) is returned as it is."""
    if hasattr(obj, "n_valid") and hasattr(obj, "times"):
        return dataset(obj)
    return obj
