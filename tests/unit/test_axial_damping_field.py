"""The ``axial_damping`` field of a transient step: read as written, and a bad value gets a
clear error naming the field and what was expected (exit code 2, nothing run)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from catdae.case import load_case
from catdae.errors import CaseError

from scene_toml import cable_scene, static_step, step


def _case(damping=None) -> str:
    """A taut cable, a static step and the transient "dyn" with ``axial_damping = damping``
    (left out when None)."""
    return cable_scene(B=(10.0, 0.0, 0.0), L0=10.01, EA=1e6, mass=1.0, elements=2,
                       steps=static_step("st") + step("transient", "dyn", duration=0.1,
                                                      output_interval=0.05, rtol=1e-6,
                                                      atol=1e-9, axial_damping=damping))


def test_read_as_written():
    step = load_case(_case({"ratio": 0.02, "frequency": 40.0})).steps[1]
    assert step.axial_damping.ratio == 0.02 and step.axial_damping.frequency == 40.0
    step = load_case(_case({"ratio": 0.5})).steps[1]
    assert step.axial_damping.frequency == "element"
    assert step.axial_damping.rate == "strain"
    step = load_case(_case({"ratio": 0.5, "rate": "chord"})).steps[1]
    assert step.axial_damping.rate == "chord"
    assert load_case(_case()).steps[1].axial_damping is None


@pytest.mark.parametrize(("damping", "where", "expected"), [
    ({"ratio": -0.1}, "steps[1].axial_damping.ratio", "expected a value > 0"),
    ({"frequency": 3.0}, "steps[1].axial_damping.ratio", "missing"),
    ({"ratio": 0.1, "frequency": "high"}, "steps[1].axial_damping.frequency", "element"),
    (0.05, "steps[1].axial_damping", "expected a table"),
    ({"ratio": 0.1, "zeta": 2}, "steps[1].axial_damping.zeta", ""),
    ({"ratio": 0.1, "rate": "segment"}, "steps[1].axial_damping.rate", "chord"),
])
def test_bad_values_are_named(damping, where, expected, tmp_path):
    with pytest.raises(CaseError) as info:
        load_case(_case(damping))
    text = str(info.value)
    assert where in text and expected in text, text
    path = tmp_path / "bad.toml"
    path.write_text(_case(damping))
    p = subprocess.run([sys.executable, "-m", "catdae", "check", str(path)],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 2 and where in p.stderr + p.stdout and "Traceback" not in p.stderr
