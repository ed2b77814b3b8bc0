"""Transient dynamics with IDA, checked against independent facts.

- the frequency read from a free-vibration record equals the modal step's frequency;
- a prescribed damping ratio is recovered from the decay;
- a very slow support motion reproduces the static solution at every instant;
- the energy of an undamped free vibration is conserved, better as the tolerance tightens;
- the iteration matrix is the analytic one (jacfn is called; no finite-difference fallback);
- failures keep what was computed.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

import catdae
from catdae.case import load_case
from catdae.errors import SolverError

from scene_toml import cable_scene, static_step, transient_step

SPAN = 40.0
L0 = 40.05
EA = 2.0e7
MASS = 5.0
N_EL = 8


def taut_case(*, loads_y=0.0, loads_z=0.0, steps: str, elements: int = N_EL,
              extra: str = "") -> str:
    """A level cable with a sine-shaped set of nodal loads (named p1..p{n-1})."""
    loads = []
    for k in range(1, elements):
        amp = math.sin(math.pi * k / elements)
        loads.append(f"""
[[loads]]
name = "p{k}"
node = "c.{k}"
force = [0.0, {loads_y * amp!r}, {loads_z * amp!r}]
""")
    return cable_scene(B=(SPAN, 0.0, 0.0), L0=L0, EA=EA, mass=MASS, elements=elements,
                       gauss_points=3, title="taut test cable", extra="".join(loads) + extra,
                       steps=steps)


def release_steps(duration, dt, *, rtol=1e-8, atol=1e-10, damping="", names=None):
    names = names or [f"p{k}" for k in range(1, N_EL)]
    return f"""
[[steps]]
kind = "static"
name = "loaded"
[[steps]]
kind = "transient"
name = "free"
remove = {names!r}
duration = {duration!r}
output_interval = {dt!r}
rtol = {rtol!r}
atol = {atol!r}
{damping}
"""


def modal_frequencies(elements=N_EL):
    """Frequencies, labels and shapes of the unloaded cable (the modal step)."""
    text = taut_case(steps='[[steps]]\nkind = "static"\nname = "s"\n'
                     '[[steps]]\nkind = "modal"\nname = "m"\nmodes = 6\n',
                     elements=elements)
    tree = catdae.run(load_case(text))
    ds = tree["m"].ds
    return ds.frequency.values, list(ds.plane.values), list(ds.symmetry.values), ds.shape


def first(freq, plane, sym, which_plane, which_sym="symmetric"):
    for f, p, s in zip(freq, plane, sym, strict=True):
        if p == which_plane and s == which_sym:
            return float(f)
    raise AssertionError("mode not found")


def first_index(plane, sym, which_plane, which_sym="symmetric"):
    for i, (p, s) in enumerate(zip(plane, sym, strict=True)):
        if p == which_plane and s == which_sym:
            return i
    raise AssertionError("mode not found")


def modal_coordinate(ds, shape) -> np.ndarray:
    """Projection of the displacement history on a mode shape (suppresses the other modes;
    only the shape is used, not the modal step's frequency)."""
    u = ds.displacement.sel(node=shape.node).values  # (time, node, axis)
    return np.einsum("tna,na->t", u, shape.values)


def crossings_period(t: np.ndarray, x: np.ndarray) -> tuple[float, int]:
    """Mean period from upward zero crossings (linear interpolation), and their count."""
    x = x - x.mean()
    idx = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    tc = t[idx] - x[idx] * (t[idx + 1] - t[idx]) / (x[idx + 1] - x[idx])
    return (tc[-1] - tc[0]) / (len(tc) - 1), len(tc)


@pytest.fixture(scope="module")
def modes():
    return modal_frequencies()


def test_free_vibration_frequency_matches_modal(modes):
    """Out-of-plane: a sine-shaped lateral load is released; the record's period is 1/f1."""
    freq, plane, sym, shapes = modes
    f1 = first(freq, plane, sym, "out-of-plane")
    text = taut_case(loads_y=2.0, steps=release_steps(12 / f1, 0.002, rtol=1e-9, atol=1e-11))
    ds = catdae.run(load_case(text))["free"].ds
    y = ds.displacement.sel(node=f"c.{N_EL // 2}", axis="y").values
    assert np.abs(y).max() > 1e-3  # a real vibration, small against the sag
    period, n = crossings_period(ds.time.values, y)
    assert n >= 10
    assert abs(1.0 / period - f1) / f1 < 2e-3


def test_in_plane_frequency_matches_modal(modes):
    """In-plane symmetric: a vertical sine load is released (excites the axial modes too)."""
    freq, plane, sym, shapes = modes
    f1 = first(freq, plane, sym, "in-plane")
    text = taut_case(loads_z=-5.0, steps=release_steps(6 / f1, 0.002, rtol=1e-8, atol=1e-10))
    ds = catdae.run(load_case(text))["free"].ds
    z = modal_coordinate(ds, shapes[first_index(plane, sym, "in-plane")])
    period, n = crossings_period(ds.time.values, z)
    assert n >= 5
    assert abs(1.0 / period - f1) / f1 < 2e-3


def test_damping_ratio_recovered_from_decay(modes):
    """Rayleigh damping set to zeta at f1 and 3 f1: the logarithmic decrement gives zeta."""
    freq, plane, sym, shapes = modes
    f1 = first(freq, plane, sym, "out-of-plane")
    zeta = 0.02
    damping = (f'damping = {{ kind = "rayleigh", ratio = {zeta}, '
               f'frequencies = [{f1!r}, {3 * f1!r}] }}')
    text = taut_case(loads_y=2.0, steps=release_steps(8 / f1, 0.002, rtol=1e-9, atol=1e-11,
                                                      damping=damping))
    ds = catdae.run(load_case(text))["free"].ds
    y = ds.displacement.sel(node=f"c.{N_EL // 2}", axis="y").values
    t = ds.time.values
    peaks = np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:]) & (y[1:-1] > 0)) + 1
    # parabolic refinement of each peak
    amp = []
    for p in peaks:
        a, b, c = y[p - 1], y[p], y[p + 1]
        amp.append(b - 0.25 * (a - c) ** 2 / (a - 2 * b + c))
    amp = np.array(amp)
    assert amp.size >= 6
    k = np.arange(amp.size)
    slope = np.polyfit(k, np.log(amp), 1)[0]  # ln decrement per cycle
    zeta_measured = -slope / math.sqrt(4 * math.pi**2 + slope**2)
    assert abs(zeta_measured - zeta) / zeta < 0.05
    assert t[-1] > 7 / f1


def test_slow_support_motion_is_quasi_static():
    """Support B moved 0.02 m along the span over 10 fundamental periods (smooth ramp):
    at every output the cable sits where a static solution with B there puts it."""
    freq = modal_frequencies()[0]
    f1 = float(freq.min())
    ramp = 10.0 / f1
    # the support displacement: 0.02 m along a C2 smoothstep, given as a table
    ts = np.linspace(0.0, ramp, 41)
    xs = 0.02 * (10 * (ts / ramp) ** 3 - 15 * (ts / ramp) ** 4 + 6 * (ts / ramp) ** 5)
    motion = ("\n[[support_motions]]\nnode = \"B\"\n"
              f"x = {{ kind = \"table\", t = {ts.tolist()!r}, value = {xs.tolist()!r} }}\n")
    steps = f"""
[[steps]]
kind = "static"
name = "start"
[[steps]]
kind = "transient"
name = "move"
duration = {ramp!r}
output_interval = {ramp / 4!r}
rtol = 1e-6
atol = 1e-8
damping = {{ kind = "rayleigh", ratio = 0.05, frequencies = [{f1!r}, {5 * f1!r}] }}
"""
    ds = catdae.run(load_case(taut_case(steps=steps, extra=motion)))["move"].ds
    mid = f"c.{N_EL // 2}"
    for k, t in enumerate(ds.time.values):
        dx = float(np.interp(t, ts, xs))
        static_text = taut_case(steps='[[steps]]\nkind = "static"\nname = "s"\n').replace(
            f"B = [{SPAN!r}, 0.0, 0.0]", f"B = [{SPAN + dx!r}, 0.0, 0.0]")
        st = catdae.run(load_case(static_text))["s"].ds
        z_dyn = float(ds.position.sel(node=mid, axis="z")[k])
        z_sta = float(st.position.sel(node=mid, axis="z"))
        z_ref = float(ds.position.sel(node=mid, axis="z")[0])
        change = abs(z_sta - z_ref)
        assert abs(z_dyn - z_sta) <= 0.01 * max(change, 1e-3), (t, z_dyn, z_sta)
    assert float(np.abs(ds.displacement.sel(node="B", axis="x")[-1] - 0.02)) < 1e-9


def test_energy_conserved_and_drift_shrinks_with_tolerance(modes):
    freq, plane, sym, shapes = modes
    f1 = first(freq, plane, sym, "out-of-plane")
    drifts = []
    for rtol in (1e-5, 1e-8):
        text = taut_case(loads_y=2.0, loads_z=-2.0,
                         steps=release_steps(3 / f1, 0.01, rtol=rtol, atol=rtol * 1e-2))
        ds = catdae.run(load_case(text))["free"].ds
        e = ds.energy_total.values
        ke = ds.energy_kinetic.values
        drifts.append(np.abs(e - e[0]).max() / ke.max())
    assert drifts[1] < drifts[0] / 5
    assert drifts[1] < 1e-4


def test_paper_inertia_and_lumped_mass_run(modes):
    """The paper's M(q) v' form and the lumped mass give the same small-amplitude frequency."""
    freq, plane, sym, shapes = modes
    f1 = first(freq, plane, sym, "out-of-plane")
    text = taut_case(loads_y=2.0, steps=release_steps(4 / f1, 0.002, rtol=1e-9, atol=1e-11))
    case = load_case(text)
    s = list(case.steps)
    s[1] = dataclasses.replace(s[1], inertia="paper")
    ds = catdae.run(dataclasses.replace(case, steps=tuple(s)))["free"].ds
    assert ds.attrs["inertia"] == "paper"
    y = ds.displacement.sel(node=f"c.{N_EL // 2}", axis="y").values
    period, _ = crossings_period(ds.time.values, y)
    assert abs(1.0 / period - f1) / f1 < 3e-3
    s[1] = dataclasses.replace(s[1], mass_model="lumped", inertia="lagrangian")
    ds = catdae.run(dataclasses.replace(case, steps=tuple(s)))["free"].ds
    assert ds.attrs["mass_model"] == "lumped"
    y = ds.displacement.sel(node=f"c.{N_EL // 2}", axis="y").values
    period, _ = crossings_period(ds.time.values, y)
    # lumped mass: lower frequency at the same mesh (consistent is an upper bound)
    assert 1.0 / period < f1


def test_analytic_iteration_matrix_is_used(monkeypatch):
    from catdae.solvers import transient

    calls = {"jac": 0}
    orig_dense = transient.TransientProblem.jac_dense
    orig_sparse = transient.TransientProblem.jac_sparse

    def count_dense(self, t, y, yp, res, cj, JJ):
        calls["jac"] += 1
        return orig_dense(self, t, y, yp, res, cj, JJ)

    def count_sparse(self, t, y, yp, res, cj, JJ):
        calls["jac"] += 1
        return orig_sparse(self, t, y, yp, res, cj, JJ)

    monkeypatch.setattr(transient.TransientProblem, "jac_dense", count_dense)
    monkeypatch.setattr(transient.TransientProblem, "jac_sparse", count_sparse)
    for solver in ("band", "sparse", "dense"):
        calls["jac"] = 0
        text = taut_case(loads_y=2.0, steps=release_steps(0.2, 0.01, rtol=1e-6, atol=1e-8))
        case = load_case(text)
        s = list(case.steps)
        s[1] = dataclasses.replace(s[1], linear_solver=solver)
        ds = catdae.run(dataclasses.replace(case, steps=tuple(s)))["free"].ds
        assert ds.attrs["linear_solver"] == solver
        assert calls["jac"] == ds.attrs["n_jacobian_evaluations"] > 0
        # an analytic matrix is reused over many residuals (a finite-difference one is not)
        assert ds.attrs["n_residual_evaluations"] > 3 * ds.attrs["n_jacobian_evaluations"]


def test_band_sparse_dense_agree():
    out = {}
    for solver in ("band", "sparse", "dense"):
        text = taut_case(loads_y=2.0, loads_z=-3.0,
                         steps=release_steps(0.3, 0.05, rtol=1e-9, atol=1e-11))
        case = load_case(text)
        s = list(case.steps)
        s[1] = dataclasses.replace(s[1], linear_solver=solver)
        out[solver] = catdae.run(dataclasses.replace(case, steps=tuple(s)))["free"].ds
    ref = out["dense"].position.values
    for solver in ("band", "sparse"):
        assert np.abs(out[solver].position.values - ref).max() < 1e-7


def test_failure_keeps_partial_results(tmp_path, monkeypatch):
    """An element that cannot be solved after t = 0.05 s: IDA gives up, the run keeps its
    outputs up to then, says why, and never overwrites an existing file."""
    from catdae.solvers import transient

    orig = transient.TransientProblem.evaluate  # where a transient solves its elements

    def failing(self, t, y, yp, res, **kw):
        if t > 0.05:
            return False
        return orig(self, t, y, yp, res, **kw)

    monkeypatch.setattr(transient.TransientProblem, "evaluate", failing)
    out = tmp_path / "run.nc"
    out.write_text("previous results")
    text = taut_case(loads_y=2.0, steps=release_steps(0.2, 0.01, rtol=1e-6, atol=1e-8))
    with pytest.raises(SolverError) as info:
        catdae.run(load_case(text), output=out)
    assert out.read_text() == "previous results"
    failed = tmp_path / "run.failed.nc"
    tree = catdae.read_results(failed)
    assert "failed" in tree.attrs["status"]
    ds = tree["free"].ds
    assert ds.attrs["status"] != "completed"
    assert 0.04 <= float(ds.time[-1]) <= 0.05 + 1e-12
    assert np.isfinite(ds.position.values).all()
    assert "loaded" in tree.children  # the static step before it is kept
    assert info.value.partial is not None


def test_energy_balance_with_a_time_varying_load():
    """A load with a time function has no potential: the total energy changes by its work,
    E(t) - E(0) = ∫ P(t)·v dt (trapezoid over fine outputs), and is not shifted by -P(t)·x."""
    text = taut_case(steps=static_step("hanging")
                     + transient_step("forced", 0.5, 0.0005, rtol=1e-9, atol=1e-11), extra="""
[[loads]]
name = "shake"
node = "c.3"
force = [0.0, 200.0, 50.0]
time = { kind = "sine", amplitude = 1.0, frequency = 3.0, offset = 0.5 }
""")
    ds = catdae.run(text, progress=False)["forced"].to_dataset()
    t = ds.time.values
    f = 0.5 + np.sin(2 * np.pi * 3.0 * t)
    power = f * (ds.velocity.sel(node="c.3").values @ np.array([0.0, 200.0, 50.0]))
    work = cumulative_trapezoid(power, t, initial=0.0)
    e = ds.energy_total.values - ds.energy_total.values[0]
    assert np.abs(work).max() > 1.0  # the load does real work
    np.testing.assert_allclose(e, work, atol=1e-3 * np.abs(work).max())


def _released(shift, rtol, atol):
    """The taut cable released from a small sideways load, its nodes moved by ``shift``: the
    midspan's displacement history (m) and the step count."""
    loads = "".join(f'[[loads]]\nname = "p{k}"\nnode = "c.{k}"\n'
                    f"force = [0.0, {2.0 * math.sin(math.pi * k / N_EL)!r}, 0.0]\n"
                    for k in range(1, N_EL))
    A = np.asarray(shift, float)
    text = cable_scene(A=tuple(A), B=tuple(A + [SPAN, 0.0, 0.0]), L0=L0, EA=EA, mass=MASS,
                       elements=N_EL, gauss_points=3, title="taut cable, moved", extra=loads,
                       steps=release_steps(2.0, 0.01, rtol=rtol, atol=atol))
    ds = catdae.run(load_case(text))["free"].ds
    return ds.displacement.sel(node=f"c.{N_EL // 2}", axis="y").values, ds.attrs["n_steps"]


def test_the_accuracy_of_a_transient_does_not_depend_on_where_the_origin_is():
    """The same scene 3.6 km from the origin: IDA's error test weighs the displacements, not
    the coordinates (docs/theory.md §18.7), so the run takes the same steps and its error
    against a converged run is the same. With the coordinates weighed, rtol 1e-4 of 3.6 km
    (0.36 m) let the millimetre motion go untested."""
    far = (3000.0, -2000.0, 400.0)
    ref, _ = _released((0.0, 0.0, 0.0), 1e-9, 1e-12)
    near, n_near = _released((0.0, 0.0, 0.0), 1e-4, 1e-7)
    moved, n_moved = _released(far, 1e-4, 1e-7)
    amp = np.abs(ref).max()
    assert amp > 1e-3  # m: the motion followed
    err_near, err_moved = np.abs(near - ref).max(), np.abs(moved - ref).max()
    assert err_near < 0.02 * amp
    assert err_moved < 1.5 * err_near + 1e-6 * amp, (err_near, err_moved)
    assert abs(n_moved - n_near) <= 0.1 * n_near, (n_near, n_moved)
