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


def in_current(current, *, stiffness=None, drag: float = 1.2) -> str:
    """The chain of ``scene`` in 20 m of water (the rigid seabed at the depth, or on contact
    springs of ``stiffness``) in a ``current``, with a normal drag coefficient ``drag`` (no axial
    drag)."""
    bed = {} if stiffness is None else {"stiffness": stiffness}
    return cable_scene(A=(0.0, 0.0, -20.0), B=(40.0, 0.0, -10.0), L0=60.0, EA=5e8, mass=80.0,
                       elements=4,
                       properties={"diameter": 0.1, "drag_normal": drag, "drag_axial": 0.0},
                       extra=section("water", surface=0.0, depth=20.0, current=current)
                       + section("seabed", **bed), steps=static_step("st"))


PROFILE_AT_BED = {"z": [-20.0, 0.0], "velocity": [[0.3, 0.4, 0.0], [1.0, 0.0, 0.0]]}
ZERO_AT_BED = {"z": [-20.0, 0.0], "velocity": [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]}


TWICE = {"kind": "cosine", "amplitude": 2.0, "frequency": 0.5}  # 2 at t = 0


@pytest.mark.parametrize("current, speed", [([0.0, 0.5, 0.0], "0.5"), (PROFILE_AT_BED, "0.5"),
                                            ({**PROFILE_AT_BED, "time": TWICE}, "1")])
def test_a_current_at_a_rigid_seabed_is_refused_at_input(current, speed, tmp_path, capsys):
    # the exact grounded element takes no drag on the part resting on the rigid seabed: refused
    # before any step runs, naming the current, its speed at the seabed and the way out
    invalid(in_current(current), "water.current", f"a current of {speed} m/s at the height of "
            "the rigid [seabed] (z = -20 m, no stiffness) on lines with drag (material m)",
            tmp_path, capsys, subprocess_check=False)
    err_text = "give [seabed] stiffness (Pa/m: contact springs), or a current profile that is "
    invalid(in_current(current), "water.current", err_text, tmp_path, capsys,
            subprocess_check=False)


def test_the_ways_out_of_a_current_at_a_rigid_seabed_are_accepted():
    import catdae

    still = {**PROFILE_AT_BED, "time": {"kind": "sine", "amplitude": 2.0, "frequency": 0.5}}
    for text in (in_current(ZERO_AT_BED), in_current([0.0, 0.5, 0.0], drag=0.0),
                 in_current(still)):
        catdae.load_case(text)  # no current at the bed (at t = 0), or nothing for it to drag
    # contact springs: the chain rests on them and the anchor holds the drag across it
    ds = catdae.run(catdae.load_case(in_current([0.0, 0.5, 0.0], stiffness=1.0e7)),
                    progress=False)["st"].ds
    assert float(ds.seabed_length.values[0]) > 10.0
    drag = 0.5 * 1025.0 * 1.2 * 0.1 * 0.5**2  # N/m across a straight line at most
    ry = float(ds.reaction.sel(node="A", axis="y") + ds.reaction.sel(node="B", axis="y"))
    # the supports hold the drag across the nearly straight 60 m chain (-911.6 N measured)
    assert -drag * 60.0 < ry < -0.95 * drag * 60.0
