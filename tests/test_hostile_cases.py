"""Hostile case files (issue 12), through ``python -m catdae check`` and ``run``.

An invalid case gets exit 2 and one clear message naming the file, the field and what was
expected, judged before any work: no traceback, nothing written. What is accepted runs without
NaN in its results.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from scenes import cable_scene, static_step, transient_step

PUSH = '[[loads]]\nname = "push"\nnode = "c.1"\nforce = [0.0, 1.0, 0.0]\n'


def catdae(*args, cwd, timeout=300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "catdae", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=timeout)


def refused(path: Path, field: str, expected: str, *, cwd) -> str:
    """``check`` and ``run`` both exit 2 with the one problem ``field: ...expected...``."""
    for command in ("check", "run"):
        args = [command, path] + (["-o", cwd / "out.nc"] if command == "run" else [])
        proc = catdae(*args, cwd=cwd)
        assert proc.returncode == 2, (command, proc.stdout, proc.stderr)
        assert "Traceback" not in proc.stderr and proc.stdout == ""
        line = proc.stderr.strip()
        assert line.count("\n") == 0, proc.stderr
        assert line.startswith(f"catdae: invalid case: {path}: {field}: "), line
        assert expected in line, line
    assert not list(cwd.glob("*.nc"))
    return line


def massless(elements=4, extra="") -> str:
    return cable_scene(B=(10.0, 0.0, 0.0), L0=9.5, EA=1e4, mass=0.0, weight=0.0,
                       elements=elements, extra=PUSH + extra,
                       steps=static_step("static") + transient_step(
                           "dyn", 1.0, 0.1, rtol=1e-6, atol=1e-9, remove=["push"]))


def test_a_transient_of_a_massless_cable_is_refused(tmp_path):
    """No mass and no weight: M is zero on the free dofs; the run used to write NaN
    accelerations and reactions."""
    f = tmp_path / "massless.toml"
    f.write_text(massless())
    line = refused(f, "steps[1]", "free node(s) c.1, c.2, c.3 have no mass", cwd=tmp_path)
    assert "give the cable's material a mass > 0 or put a point mass there" in line


def test_a_massless_cable_with_a_mass_on_each_free_node_is_accepted(tmp_path):
    f = tmp_path / "beads.toml"
    f.write_text(massless(elements=2, extra='[[point_masses]]\nname = "bead"\nnode = "c.1"\n'
                                            "mass = 1.0\n"))
    proc = catdae("check", f, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "valid" in proc.stdout
