"""Time functions built from others (issue 23): ``product`` (a sine inside a ramp envelope),
``trapezoid`` (ramp up, hold, ramp down), and a support motion along a ``direction``.

Derivatives are checked against central finite differences, values against their definitions
(the trapezoid's area A (rise/2 + hold + fall/2) by quadrature), and a case's support moved
along a direction against the prescribed path."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

import catdae
from catdae.case.timefunc import Ramp, Sine
from catdae.case.timefunc_compose import Product, Trapezoid
from catdae.cli import main
from catdae.errors import CaseError

from scene_toml import cable_scene, step, support_motion, value


def _fd(f, t, h=1e-5):
    v = [f.evaluate(t + k * h)[0] for k in (-1, 0, 1)]
    return (v[2] - v[0]) / (2 * h), (v[2] - 2 * v[1] + v[0]) / h**2


@pytest.mark.parametrize("t", [0.05, 0.37, 0.9, 1.6])
def test_product_rule(t):
    f = Product((Sine(0.3, 2.0, 0.4, 0.1), Ramp(1.2, 0.0, True, 1.0), Sine(1.0, 0.25, 1.0, 0.5)))
    v, d, d2 = f.evaluate(t)
    parts = [g.evaluate(t)[0] for g in f.factors]
    assert v == pytest.approx(math.prod(parts), rel=1e-14)
    fd1, fd2 = _fd(f, t)
    assert d == pytest.approx(fd1, rel=1e-6, abs=1e-8)  # FD: O(h² f''')
    assert d2 == pytest.approx(fd2, rel=1e-4, abs=1e-5)


def test_product_breakpoints_are_the_factors():
    f = Product((Sine(1.0, 1.0), Ramp(0.5, 0.2), Ramp(0.3, 1.0)))
    assert f.breakpoints() == (0.2, 0.7, 1.0, 1.3)


@pytest.mark.parametrize("smooth", [False, True])
def test_trapezoid(smooth):
    f = Trapezoid(rise=0.2, hold=0.5, fall=0.4, start=0.1, amplitude=3.0, smooth=smooth)
    assert f(0.0) == 0.0 and f(0.05) == 0.0
    assert f(0.3) == pytest.approx(3.0) and f(0.55) == pytest.approx(3.0)
    assert f(1.2) == pytest.approx(0.0, abs=1e-15) and f(5.0) == pytest.approx(0.0, abs=1e-15)
    area = quad(f, 0.0, 2.0, points=[0.1, 0.3, 0.8, 1.2], limit=200)[0]
    assert area == pytest.approx(3.0 * (0.1 + 0.5 + 0.2), rel=1e-9)
    for t in (0.15, 0.25, 0.6, 0.9, 1.1):
        fd1, fd2 = _fd(f, t)
        v, d, d2 = f.evaluate(t)
        assert d == pytest.approx(fd1, rel=1e-6, abs=1e-8)
        if smooth:
            assert d2 == pytest.approx(fd2, rel=1e-4, abs=1e-5)
    assert f.breakpoints() == pytest.approx(() if smooth else (0.1, 0.3, 0.8, 1.2),
                                            rel=1e-15)
    if not smooth:
        assert f.evaluate(0.2)[1] == pytest.approx(15.0) and f.evaluate(1.0)[1] == -7.5


def case(motion: dict, b_support="pinned") -> str:
    """A 10 m span (10.5 m of cable, 4 elements) whose end B (held as ``b_support`` says) moves
    as ``motion`` (the fields of its support motion) in the transient "shake"."""
    return cable_scene(B=(10.0, 0.0, 0.0), L0=10.5, EA=1.0e6, mass=1.0, elements=4,
                       supports=("A", f"B = {value(b_support)}"),
                       extra=support_motion("B", **motion),
                       steps=step("transient", "shake", duration=0.4, output_interval=0.05))


CONSTANT = {"kind": "constant", "value": 1.0}


def test_support_moves_along_its_direction():
    motion = {"direction": [3.0, 0.0, 4.0],
              "value": {"kind": "product", "factors": [
                  {"kind": "sine", "amplitude": 0.2, "frequency": 2.0},
                  {"kind": "ramp", "duration": 0.3, "smooth": True}]}}
    tree = catdae.run(catdae.load_case(case(motion)), progress=False)
    ds = tree["shake"].ds
    t = ds.time.values
    x = Product((Sine(0.2, 2.0), Ramp(0.3, 0.0, True)))(t)
    d = ds.displacement.sel(node="B").values  # (time, 3)
    np.testing.assert_allclose(d, np.outer(x, [0.6, 0.0, 0.8]), atol=1e-12)
    # a sine inside a smooth ramp starts with no velocity jump: no restart at t = 0
    assert ds.attrs["n_restarts"] == 0


@pytest.mark.parametrize(("support", "motion", "where", "words"), [
    ("pinned", {"direction": [1.0, 0.0, 0.0], "value": CONSTANT, "x": CONSTANT},
     "support_motions[0]", "not both"),
    ("pinned", {"direction": [0.0, 0.0, 0.0], "value": CONSTANT},
     "support_motions[0].direction", "non-zero length"),
    (["x", "z"], {"direction": [1.0, 1.0, 0.0], "value": CONSTANT},
     "support_motions[0].direction", "axis 'y'"),
    ("pinned", {"direction": [1.0, 0.0, 0.0]}, "support_motions[0].value", "missing"),
    ("pinned", {"direction": [1.0, 0.0, 0.0], "value": {"kind": "trapezoid", "rise": 0.1}},
     "support_motions[0].value.fall", "missing"),
    ("pinned", {"x": {"kind": "product", "factors": [
        {"kind": "sine", "amplitude": 1.0, "frequency": 1.0}]}},
     "support_motions[0].x.factors", "at least 2"),
])
def test_bad_directed_motions_are_named(support, motion, where, words, tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(case(motion, support))
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert where in err and words in err, err
    with pytest.raises(CaseError):
        catdae.load_case(path)
