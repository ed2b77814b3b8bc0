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
    return ds if fl is None else with_fluid(ds, fl, rec.times[sl], rec.X[sl])


def as_dataset(obj):
    """A dataset from a solver's result: an output record is turned into one, a dataset (or
    anything else, e.g. None) is returned as it is."""
    if hasattr(obj, "n_valid") and hasattr(obj, "times"):
        return dataset(obj)
    return obj
