"""Bad ``[seabed]`` input: exit 2 with one located message (the file, the field, what was
expected), through ``catdae check`` and ``catdae run`` (as tests/unit/test_hostile_cases.py)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from scene_toml import cable_scene, section, static_step, transient_step


def invalid(text: str, field: str, expected: str, tmp_path, capsys, *,
            subprocess_check: bool = True) -> None:
    """``catdae check`` and ``catdae run`` refuse the case with exit 2 and the one line
    ``catdae: invalid case: <file>: <field>: ...<expected>...``; nothing is written."""
    from catdae.cli import main

    f = tmp_path / "case.toml"
    f.write_text(text)
    want = f"catdae: invalid case: {f}: {field}: "
    if subprocess_check:
        proc = subprocess.run([sys.executable, "-m", "catdae", "check", str(f)], cwd=tmp_path,
                              capture_output=True, text=True, timeout=120)
        assert proc.returncode == 2, proc.stderr
        assert proc.stderr.startswith(want) and expected in proc.stderr, proc.stderr
        assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    out = tmp_path / "out.nc"
    for args in (["check", str(f)], ["run", str(f), "-o", str(out)]):
        capsys.readouterr()
        assert main(args) == 2
        err = capsys.readouterr().err
        assert err.startswith(want) and expected in err, err
        assert err.count("\n") == 1
    assert not out.exists()


def scene(seabed: dict, steps: str | None = None, diameter: bool = True) -> str:
    """A chain from an anchor at z = -20 (diameter 0.1 m unless ``diameter`` is false) over a
    ``[seabed]`` of the fields ``seabed``."""
    return cable_scene(A=(0.0, 0.0, -20.0), B=(40.0, 0.0, -10.0), L0=60.0, EA=5e8, mass=80.0,
                       elements=4, properties={"diameter": 0.1} if diameter else None,
                       extra=section("seabed", **seabed),
                       steps=static_step("st") if steps is None else steps)


@pytest.mark.parametrize("seabed, field, expected", [
    ({"z": -15.0}, "seabed.z", "lies above support 'A'"),
    ({"z": -20.0, "stiffness": -1.0e5}, "seabed.stiffness", "expected a value > 0"),
    ({"z": -20.0, "stiffness": 1e5, "damping": -3.0}, "seabed.damping",
     "expected a value >= 0"),
    ({"z": -20.0, "friction": -0.5}, "seabed.friction", "Coulomb coefficient >= 0"),
    ({"z": -20.0, "friction": {"axial": 0.5}}, "seabed.friction.lateral", "required"),
    ({"z": -20.0, "friction_velocity": 0.0}, "seabed.friction_velocity",
     "expected a value > 0"),
    ({"stiffness": 1e5}, "seabed.z", "give the height of the seabed"),
    # a rigid seabed is static and frictionless: friction and damping there did nothing
    ({"z": -20.0, "friction": 0.5}, "seabed.friction", "the rigid seabed (no stiffness)"),
    ({"z": -20.0, "damping": 2.0e4}, "seabed.damping", "give [seabed] stiffness, or leave out"),
    ({"z": -20.0, "roughness": 2}, "seabed.roughness", ""),
])
def test_bad_seabed_fields(seabed, field, expected, tmp_path, capsys):
    invalid(scene(seabed), field, expected, tmp_path, capsys, subprocess_check=False)


def test_a_rigid_seabed_refuses_a_transient_step(tmp_path, capsys):
    steps = static_step("st") + transient_step("tr", 1.0, 0.1, rtol=1e-4, atol=1e-4)
    invalid(scene({"z": -20.0}, steps), "steps[1]", "give [seabed] stiffness", tmp_path,
            capsys, subprocess_check=False)


def test_contact_stiffness_needs_a_diameter(tmp_path, capsys):
    invalid(scene({"z": -20.0, "stiffness": 1e5}, diameter=False), "seabed.stiffness",
            "need a diameter > 0", tmp_path, capsys)


@pytest.mark.parametrize("extra", [section("seabed", z=-15.0),
                                   section("water", depth=15.0)
                                   + section("seabed", stiffness=1e5)])
def test_a_seabed_above_an_anchor_along_a_gravity_vector(extra, tmp_path, capsys):
    # gravity along -x: heights are x; anchor A at height -20 lies below a seabed at -15 (given
    # as z, or as the water's surface - depth)
    text = cable_scene(A=(-20.0, 0.0, 0.0), B=(-10.0, 0.0, 40.0), L0=60.0, EA=5e8, mass=80.0,
                       elements=4, gravity=[-9.81, 0.0, 0.0], properties={"diameter": 0.1},
                       extra=extra, steps=static_step("st"))
    invalid(text, "seabed.z", "lies above support 'A' (z = -20 m)", tmp_path, capsys,
            subprocess_check=False)
