"""Outputs computed in batches (catdae.solvers.deferred, docs/theory.md §8.9) against the same
outputs computed one by one (``TransientProblem.observe``), on scenes that take every branch of
the batch: each mass model, material and Rayleigh damping, a point mass and a constant load
inside an element (their potential), a nodal load that varies in time and a moving support (its
reactions). The runs that stop or are interrupted (tests/unit/test_interrupts.py and the
nothing-lost tests) go through the batch too.

The two paths share only the compiled residual pass: the batch adds its own gathering of the
reactions, kinetic energy of a constant element mass, energy integrals and envelope merge.
"""

from __future__ import annotations

import numpy as np
import pytest

import catdae
import catdae.solvers.record as record

from scene_toml import cable_scene, load, point_mass, static_step, support_motion, transient_step

DAMPING = {"none": "", "material": 'damping = { kind = "material" }',
           "rayleigh": 'damping = { kind = "rayleigh", ratio = 0.02, frequencies = [1.0, 8.0] }'}


def _scene(mass_model: str, damping: str) -> str:
    extra = (point_mass("pm", 4.0, cable="c", s=5.3)
             + load("lamp", [0.0, 30.0, -80.0], cable="c", s=9.1)
             + load("push", [0.0, 200.0, 0.0], node="c.2",
                    time={"kind": "sine", "amplitude": 1.0, "frequency": 1.5})
             + support_motion("B", z={"kind": "sine", "amplitude": 0.05, "frequency": 2.0}))
    text = cable_scene(
        B=(12.0, 0.0, 2.0), L0=13.0, EA=2.0e6, mass=1.5, elements=5, extra=extra,
        steps=static_step() + transient_step(
            "dyn", 0.6, 0.01, rtol=1e-6, atol=1e-8,
            extra=f'mass_model = "{mass_model}"\n' + DAMPING[damping]))
    return text.replace("mass = 1.5\n", "mass = 1.5\ndamping = 2.0\n", 1)  # c per metre


def _run(text: str, tmp_path, defer: bool, monkeypatch):
    if not defer:
        monkeypatch.setattr(record, "can_defer", lambda prob: False)
    path = tmp_path / f"scene_{defer}.toml"
    path.write_text(text)
    ds = catdae.run(str(path))["dyn"].to_dataset()
    monkeypatch.undo()
    return ds


@pytest.mark.parametrize(("mass_model", "damping"), [
    ("blended", "none"), ("consistent", "material"), ("lumped", "rayleigh"),
    ("linear", "material")])
def test_batched_outputs_are_those_computed_one_by_one(mass_model, damping, tmp_path,
                                                       monkeypatch):
    text = _scene(mass_model, damping)
    one = _run(text, tmp_path, False, monkeypatch)
    batch = _run(text, tmp_path, True, monkeypatch)
    assert one.time.size == batch.time.size == 61
    compared = 0
    for name, var in one.data_vars.items():
        if var.dtype.kind != "f" or name.endswith("_time"):
            continue  # the times of the envelope's extremes: a tie may pick another
        a, b = var.values, batch[name].values
        assert np.array_equal(np.isnan(a), np.isnan(b)), name
        scale = max(float(np.nanmax(np.abs(a), initial=0.0)), 1e-12)
        assert np.nanmax(np.abs(a - b), initial=0.0) <= 1e-9 * scale, name
        compared += 1
    assert compared >= 10
    for name in ("reaction", "energy_kinetic", "energy_strain", "energy_potential", "tension"):
        assert name in one.data_vars
