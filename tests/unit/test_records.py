"""Ground-motion records against analytic motions: the record's own samples are kept, and the
displacement converges at the order the interpolation claims (catdae/case/records.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import catdae
from catdae.case.records import AccelerationRecord, VelocityRecord

A, W = 0.05, 2.0 * math.pi * 1.3  # m, rad/s


def motion(t):
    """u = A (1 - cos ωt): starts from rest at u = 0 (the acceleration A ω² jumps on at t = 0)."""
    return A * (1 - np.cos(W * t)), A * W * np.sin(W * t), A * W**2 * np.cos(W * t)


def sampled(cls, dt, duration=2.0, which=2):
    ts = np.linspace(0.0, duration, int(round(duration / dt)) + 1)
    return cls(tuple(ts), tuple(motion(ts)[which])), ts


def max_errors(rec, duration=2.0):
    t = np.linspace(0.0, duration, 4001)
    got = rec.evaluate(t)
    exact = motion(t)
    return [float(np.max(np.abs(g - e))) for g, e in zip(got, exact, strict=True)]


def order(cls, which, dts):
    errs = np.array([max_errors(sampled(cls, dt, which=which)[0]) for dt in dts])  # (k, 3)
    return [float(np.polyfit(np.log(dts), np.log(errs[:, j]), 1)[0]) for j in range(3)], errs


def test_acceleration_record_keeps_its_samples_and_starts_from_rest():
    rec, ts = sampled(AccelerationRecord, 0.05)
    u, v, a = rec.evaluate(ts)
    np.testing.assert_allclose(a, motion(ts)[2], rtol=0, atol=1e-13 * A * W**2)
    assert rec.evaluate(-0.1) == (0.0, 0.0, 0.0)
    assert rec.evaluate(0.0)[:2] == (0.0, 0.0)
    # between samples the acceleration stays between its neighbours (no overshoot)
    mid = 0.5 * (ts[1:] + ts[:-1])
    am = rec.evaluate(mid)[2]
    lo = np.minimum(motion(ts)[2][1:], motion(ts)[2][:-1])
    hi = np.maximum(motion(ts)[2][1:], motion(ts)[2][:-1])
    assert np.all((am >= lo - 1e-12) & (am <= hi + 1e-12))
    # derivatives consistent: central differences of u and v
    h = 1e-6
    for tk in (0.0137, 0.731, 1.42):
        up, vp, _ = rec.evaluate(tk + h)
        um, vm, _ = rec.evaluate(tk - h)
        _, v0, a0 = rec.evaluate(tk)
        assert (up - um) / (2 * h) == pytest.approx(v0, rel=1e-7)
        assert (vp - vm) / (2 * h) == pytest.approx(a0, rel=1e-6)
    assert rec.breakpoints() == (0.0, 2.0)  # the acceleration jumps on and off


def test_acceleration_record_converges_at_second_order():
    dts = np.array([0.04, 0.02, 0.01, 0.005])
    rates, errs = order(AccelerationRecord, 2, dts)
    # displacement and velocity: the piecewise-linear interpolation error, integrated
    assert rates[0] == pytest.approx(2.0, abs=0.1), errs[:, 0]
    assert rates[1] == pytest.approx(2.0, abs=0.1), errs[:, 1]
    # and its size: the trapezoid-rule error of each interval, Δt² a''/12 on average, integrated
    # twice for u = A (1 - cos ωt) gives Δt² A ω² (1 - cos ωt)/12 <= Δt² A ω²/6
    bound = dts**2 * A * W**2 / 6
    assert np.all(errs[:, 0] <= 1.05 * bound) and np.all(errs[:, 0] >= 0.8 * bound), errs[:, 0]


def test_velocity_record_converges_at_fourth_order():
    dts = np.array([0.04, 0.02, 0.01, 0.005])
    rates, errs = order(VelocityRecord, 1, dts)
    assert rates[0] == pytest.approx(4.0, abs=0.3), errs[:, 0]
    assert rates[1] == pytest.approx(4.0, abs=0.3), errs[:, 1]
    assert rates[2] == pytest.approx(3.0, abs=0.3), errs[:, 2]
    rec, ts = sampled(VelocityRecord, 0.05, which=1)
    np.testing.assert_allclose(rec.evaluate(ts)[1], motion(ts)[1], atol=1e-13 * A * W)


def test_after_the_record_the_support_keeps_its_last_velocity():
    # a constant acceleration for 1 s: v = g t, u = g t²/2; then it coasts at v = g
    rec = AccelerationRecord((0.0, 1.0), (9.81, 9.81))
    assert rec.evaluate(1.0) == pytest.approx((9.81 / 2, 9.81, 9.81))
    assert rec.evaluate(3.0) == pytest.approx((9.81 / 2 + 2 * 9.81, 9.81, 0.0))
    vel = VelocityRecord((0.5, 1.5), (2.0, 2.0))
    assert vel.evaluate(0.4) == (0.0, 0.0, 0.0)
    assert vel.evaluate(2.5) == pytest.approx((4.0, 2.0, 0.0))


# ---------------------------------------------------------------------------------------------
# Through the case format: a support driven by an acceleration record in a multi-column CSV
# ---------------------------------------------------------------------------------------------
def record_scene(tmp_path, dt, motion_y):
    """The taut string with a heavy midspan mass of tests/scenes/test_loads.py, support A moving
    in y as the time function ``motion_y`` (a mapping) says."""
    from scene_toml import cable_scene, point_mass, support_motion, transient_step

    ts = np.linspace(0.0, 1.0, int(round(1.0 / dt)) + 1)
    u, v, a = motion(ts)
    rows = "\n".join(f"{float(tk)!r},0.0,{float(ak)!r},{float(vk)!r}"
                     for tk, ak, vk in zip(ts, a, v, strict=True))
    (tmp_path / "record.csv").write_text("# a synthetic record\nt,ax,ay,vy\n" + rows + "\n")
    text = cable_scene(B=(10.0, 0.0, 0.0), L0=9.99, EA=1e7, mass=0.01, elements=2, gravity=0.0,
                       extra=(point_mass("M", 100.0, node="c.1")
                              + support_motion("A", y=motion_y)),
                       steps=transient_step("shake", 1.0, 0.01, rtol=1e-9, atol=1e-12))
    case = tmp_path / f"shake-{dt}.toml"
    case.write_text(text)
    return catdae.run(case)["shake"].ds


def test_acceleration_record_drives_the_support_as_its_analytic_motion(tmp_path):
    exact = record_scene(tmp_path, 0.01, {"kind": "cosine", "amplitude": -A,
                                          "frequency": W / (2 * math.pi), "offset": A})
    t = exact["time"].values
    np.testing.assert_allclose(exact["displacement"].sel(node="A", axis="y"), motion(t)[0],
                               atol=1e-15)
    record = {"kind": "table", "file": "record.csv", "column": "ay", "quantity": "acceleration"}
    errs_a, errs_m = [], []
    dts = np.array([0.02, 0.01, 0.005])
    for dt in dts:
        ds = record_scene(tmp_path, dt, record)
        ua = ds["displacement"].sel(node="A", axis="y").values
        # the support follows the integrated record: within the interpolation bound
        errs_a.append(np.abs(ua - motion(t)[0]).max())
        assert errs_a[-1] <= 1.05 * dt**2 * A * W**2 / 6
        # and it starts from rest at the case position
        assert ua[0] == 0.0 and ds["velocity"].sel(node="A", axis="y").values[0] == 0.0
        um = ds["displacement"].sel(node="c.1", axis="y").values
        errs_m.append(np.abs(um - exact["displacement"].sel(node="c.1", axis="y").values).max())
    # the cable's response converges to the analytic motion's at the record's order
    assert np.polyfit(np.log(dts), np.log(errs_a), 1)[0] == pytest.approx(2.0, abs=0.1)
    assert np.polyfit(np.log(dts), np.log(errs_m), 1)[0] == pytest.approx(2.0, abs=0.2), errs_m


def test_record_columns_and_quantity_are_checked(tmp_path, capsys):
    from catdae.cli import main

    from scene_toml import cable_scene, load, support_motion, transient_step

    (tmp_path / "three.csv").write_text("t,ax,ay\n0.0,0.0,1.0\n1.0,0.0,2.0\n")
    (tmp_path / "bare.csv").write_text("0.0,0.0,1.0\n1.0,0.0,2.0\n")
    (tmp_path / "back.csv").write_text("t,ax\n0.0,0.0\n0.2,1.0\n0.1,2.0\n")
    (tmp_path / "one.csv").write_text("t,ax\n0.0,0.0\n")
    (tmp_path / "semi.csv").write_text("t;ax\n0.0;0.0\n1.0;2.0\n")
    (tmp_path / "tabs.csv").write_text("t\tax\n0.0\t0.0\n1.0\t2.0\n")
    motions = [
        ({"kind": "table", "file": "back.csv", "column": "ax"},  # the file named, its rows
         "support_motions[0].x.file: 'back.csv': expected strictly increasing times, found "
         "0.2 then 0.1 (data rows 2 and 3)"),
        ({"kind": "table", "file": "one.csv", "column": "ax"},
         "support_motions[0].x.file: 'one.csv': expected at least 2 points, found 1"),
        ({"kind": "table", "file": "semi.csv", "column": "ax"},  # not the column's fault
         "support_motions[0].x.file: semi.csv has one column per line, its values separated "
         "by ';': catdae reads CSV, values separated by commas"),
        ({"kind": "table", "file": "tabs.csv"},
         "support_motions[0].x.file: tabs.csv has one column per line, its values separated "
         "by a tab"),
        ({"kind": "table", "file": "three.csv", "column": "ayy", "quantity": "acceleration"},
         "support_motions[0].x.column: three.csv has no column 'ayy'; did you mean 'ay'? (its "
         "columns: t, ax, ay; time is the first)"),
        ({"kind": "table", "file": "three.csv"},
         "support_motions[0].x.file: three.csv has 3 columns (t, ax, ay): choose the value "
         'column with column = "<name>"'),
        ({"kind": "table", "file": "bare.csv", "column": "ax"},
         "support_motions[0].x.column: column = 'ax' needs a header line in bare.csv"),
        ({"kind": "table", "t": [0.0, 1.0], "value": [0.0, 1.0], "column": "ax"},
         "support_motions[0].x.column: column selects a column of a table file"),
        ({"kind": "table", "file": "three.csv", "column": "t"},
         "support_motions[0].x.column: 't' is the time column"),
        ({"kind": "table", "file": "three.csv", "column": "ax", "quantity": "jerk"},
         "support_motions[0].x.quantity:"),
    ]
    velocity = {"kind": "table", "t": [0.0, 1.0], "value": [0.0, 1.0], "quantity": "velocity"}
    for x, message in motions:
        case = tmp_path / "bad.toml"
        case.write_text(cable_scene(
            B=(10.0, 0.0, 0.0), L0=10.2, EA=1e7, mass=1.0, elements=2,
            extra=(support_motion("A", x=x)
                   + load("P", [0.0, 1.0, 0.0], node="c.1", time=velocity)),
            steps=transient_step("s", 1.0, 0.1, rtol=1e-6, atol=1e-8)))
        assert main(["check", str(case)]) == 2
        err = capsys.readouterr().err
        assert f"{case}: {message}" in err, err
        assert (f"{case}: loads[0].time.quantity: quantity = 'velocity' applies to support "
                "motions only") in err
    case.write_text(cable_scene(  # a mesh node cannot be moved: says why, not 'unknown'
        B=(10.0, 0.0, 0.0), L0=10.2, EA=1e7, mass=1.0, elements=2,
        extra=support_motion("c.1", x={"kind": "sine", "amplitude": 0.1, "frequency": 1.0}),
        steps=transient_step("s", 1.0, 0.1, rtol=1e-6, atol=1e-8)))
    assert main(["check", str(case)]) == 2
    err = capsys.readouterr().err
    assert (f"{case}: support_motions[0].node: 'c.1' is a mesh node of cable 'c', and mesh "
            "nodes cannot be supported") in err, err
    case.write_text(cable_scene(  # listed in [supports] too: refused there, not listed as held
        B=(10.0, 0.0, 0.0), L0=10.2, EA=1e7, mass=1.0, elements=2,
        supports=("A", "B", '"c.1" = "pinned"'),
        extra=support_motion("c.1", x={"kind": "sine", "amplitude": 0.1, "frequency": 1.0}),
        steps=transient_step("s", 1.0, 0.1, rtol=1e-6, atol=1e-8)))
    assert main(["check", str(case)]) == 2
    err = capsys.readouterr().err
    assert "(supported nodes: 'A', 'B')" in err and "unknown node 'c.1'" in err, err


def test_velocity_and_displacement_columns_through_the_case_format(tmp_path):
    from scene_toml import cable_scene, static_step, support_motion

    ts = np.linspace(0.0, 1.0, 101)
    u, v, a = motion(ts)
    rows = "\n".join(",".join(repr(float(x)) for x in r) for r in zip(ts, u, v, a, strict=True))
    (tmp_path / "m.csv").write_text("time,ux,vx,ax\n" + rows + "\n")
    extra = support_motion(
        "A", x={"kind": "table", "file": "m.csv", "column": "vx", "quantity": "velocity"},
        y={"kind": "table", "file": "m.csv", "column": "ux"},
        z={"kind": "table", "file": "m.csv", "column": "ax", "quantity": "acceleration"})
    case_file = tmp_path / "c.toml"
    case_file.write_text(cable_scene(B=(10.0, 0.0, 0.0), L0=10.2, EA=1e7, mass=1.0, elements=2,
                                     extra=extra, steps=static_step()))
    sm = catdae.load_case(case_file).support_motions[0]
    assert isinstance(sm.x, VelocityRecord) and isinstance(sm.z, AccelerationRecord)
    np.testing.assert_allclose(sm.x.evaluate(ts)[1], v, atol=1e-13 * A * W)  # its own samples
    np.testing.assert_allclose(sm.y(ts[:-1]), u[:-1], atol=1e-15)  # the displacement table
    np.testing.assert_allclose(sm.z.evaluate(ts)[2], a, atol=1e-13 * A * W**2)
    # the three descriptions of one motion agree, to the accuracy of each
    t = np.linspace(0.0, 0.99, 97)
    assert np.abs(sm.x(t) - motion(t)[0]).max() < 1e-6 * A  # O(Δt⁴): 1.2e-7 A measured
    assert np.abs(sm.z(t) - motion(t)[0]).max() < 1.05 * 0.01**2 * A * W**2 / 6
