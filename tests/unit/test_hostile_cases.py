"""Hostile case files (issue 12), through ``python -m catdae check`` and ``run``.

An invalid case gets exit 2 and one clear message naming the file, the field and what was
expected, judged before any work: no traceback, nothing written. What is accepted runs without
NaN in its results.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from scene_toml import (
    cable,
    cable_scene,
    damper,
    load,
    modal_step,
    point_mass,
    static_step,
    transient_step,
)

PUSH = load("push", [0.0, 1.0, 0.0], node="c.1")


def catdae(*args, cwd, timeout=300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "catdae", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=timeout)


def massless(elements=4, extra="") -> str:
    return cable_scene(B=(10.0, 0.0, 0.0), L0=9.5, EA=1e4, mass=0.0, weight=0.0,
                       elements=elements, extra=PUSH + extra,
                       steps=static_step("static") + transient_step(
                           "dyn", 1.0, 0.1, rtol=1e-6, atol=1e-9, remove=["push"]))


def test_a_transient_of_a_massless_cable_is_refused(tmp_path, capsys):
    """No mass and no weight: M is zero on the free dofs; the run used to write NaN
    accelerations and reactions."""
    err = invalid(massless(), "steps[1]", "free node(s) c.1, c.2, c.3 have no mass", tmp_path,
                  capsys)
    assert "give the cable's material a mass > 0 or put a point mass there" in err


def test_a_massless_cable_with_a_mass_on_each_free_node_is_accepted(tmp_path, capsys):
    from catdae.cli import main

    f = tmp_path / "beads.toml"
    f.write_text(massless(elements=2, extra=point_mass("bead", 1.0, node="c.1")))
    assert main(["check", str(f)]) == 0
    assert "valid" in capsys.readouterr().out


# ------------------------------------------------------------------------------------------------
# the same, for each kind of hostile input; ``check`` in a new process, ``run`` in this one
# ------------------------------------------------------------------------------------------------
def scene(extra="", steps=None, **kw) -> str:
    d = dict(B=(10.0, 0.0, 0.0), L0=10.5, EA=1e6, mass=1.0, elements=4)
    d.update(kw)
    return cable_scene(**d, extra=extra, steps=static_step("st") if steps is None else steps)


def invalid(text: str, field: str, expected: str, tmp_path, capsys, *, subprocess_check=True,
            name="case.toml", run_args=()) -> str:
    """The case is refused by ``check`` and ``run`` (with ``run_args``: by ``run`` only) with
    exit 2 and the single problem ``<file>: <field>: ...<expected>...``, without a traceback;
    nothing is written."""
    from catdae.cli import main

    f = tmp_path / name
    f.write_text(text)
    want = f"catdae: invalid case: {f}: {field}: "
    if subprocess_check:
        proc = catdae("check", f, cwd=tmp_path, timeout=120)
        assert proc.returncode == 2, proc.stderr
        assert proc.stdout == "" and "Traceback" not in proc.stderr
        assert proc.stderr.count("\n") == 1 and proc.stderr.startswith(want), proc.stderr
        assert expected in proc.stderr, proc.stderr
    out = tmp_path / "out.nc"
    commands = [["run", str(f), "-o", str(out), *run_args]]
    if not run_args:  # the file alone is invalid: check says so too
        commands.insert(0, ["check", str(f)])
    for args in commands:
        assert main(args) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith(want) and expected in err, err
    assert not list(tmp_path.glob("*.nc"))
    return err


def valid(text: str, tmp_path, name="ok.toml"):
    from catdae.cli import main

    f = tmp_path / name
    f.write_text(text)
    out = tmp_path / f"{f.stem}.nc"
    assert main(["run", str(f), "-o", str(out)]) == 0
    import catdae

    return catdae.read_results(out)


# -- 3. table files: inside the case's folder, regular, bounded; content never echoed ----------
def table_load(file: str) -> str:
    return timed({"kind": "table", "file": file})


def test_a_table_file_outside_the_case_folder_is_refused_unread(tmp_path, capsys):
    for file in ("../../etc/passwd", "/etc/passwd"):
        err = invalid(scene(table_load(file)), "loads[0].time.file",
                      f"cannot read table file '{file}': it is outside the case's folder "
                      f"({tmp_path})", tmp_path, capsys, subprocess_check=file == "/etc/passwd")
        assert "root:" not in err


def test_a_symbolic_link_out_of_the_case_folder_is_refused(tmp_path, capsys):
    (tmp_path / "points.csv").symlink_to("/etc/passwd")
    err = invalid(scene(table_load("points.csv")), "loads[0].time.file",
                  "it is outside the case's folder", tmp_path, capsys, subprocess_check=False)
    assert "root:" not in err


def test_a_fifo_or_a_device_as_table_file_is_refused_without_blocking(tmp_path, capsys):
    import os

    os.mkfifo(tmp_path / "fifo.csv")
    invalid(scene(table_load("fifo.csv")), "loads[0].time.file",
            "cannot read table file 'fifo.csv': not a regular file", tmp_path, capsys)
    (tmp_path / "dev").symlink_to("/dev")
    invalid(scene(table_load("dev/zero")), "loads[0].time.file", "outside the case's folder",
            tmp_path, capsys, subprocess_check=False)


def test_a_device_in_an_allowed_root_is_still_refused(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("CATDAE_TABLE_ROOTS", "/dev")
    invalid(scene(table_load("/dev/zero")), "loads[0].time.file",
            "cannot read table file '/dev/zero': not a regular file", tmp_path, capsys,
            subprocess_check=False)


def test_a_table_file_above_the_size_limit_is_refused_unread(tmp_path, capsys):
    with open(tmp_path / "huge.csv", "wb") as fh:
        fh.truncate(16 * 2**20 + 1)  # sparse: no disk used
    invalid(scene(table_load("huge.csv")), "loads[0].time.file",
            "cannot read table file 'huge.csv': 16 MiB, above the limit of 16 MiB for a table "
            "file", tmp_path, capsys, subprocess_check=False)


def test_a_bad_table_line_is_named_not_quoted(tmp_path, capsys):
    (tmp_path / "points.csv").write_text("t,v\n0.0,0.0\nsecret-token,hunter2\n")
    err = invalid(scene(table_load("points.csv")), "loads[0].time.file",
                  "'points.csv', line 3: expected two numbers 'time,value', found a field "
                  "that is not a number", tmp_path, capsys, subprocess_check=False)
    assert "secret" not in err and "hunter2" not in err


def test_a_table_in_an_allowed_root_is_read(tmp_path, monkeypatch):
    shared = tmp_path / "shared"
    shared.mkdir()
    (shared / "points.csv").write_text("0.0,0.0\n1.0,2.0\n")
    case_dir = tmp_path / "case"
    case_dir.mkdir()
    monkeypatch.setenv("CATDAE_TABLE_ROOTS", str(shared))
    tree = valid(scene(table_load(str(shared / "points.csv"))), case_dir)
    assert tree.attrs["status"] == "completed"


def test_a_fifo_or_device_as_the_case_file_is_refused_without_blocking(tmp_path):
    import os

    fifo = tmp_path / "fifo.toml"
    os.mkfifo(fifo)
    for f in (fifo, Path("/dev/zero")):
        proc = catdae("check", f, cwd=tmp_path, timeout=120)
        assert proc.returncode == 2 and "Traceback" not in proc.stderr
        assert proc.stderr == (f"catdae: invalid case: {f}: cannot read the case file: not a "
                               "regular file (a case file must be an ordinary file)\n")


# -- 4. counts: elements per cable and degrees of freedom, judged before any work ---------------
def test_element_counts_beyond_the_limit_are_refused(tmp_path, capsys):
    for n in (10**6, 10**9, 2**63 - 1, 10**30):
        invalid(scene(elements=n), "cables[0].elements", "expected a value <= 10000, found the "
                "integer", tmp_path, capsys, subprocess_check=n == 10**30)


def test_the_elements_override_is_held_to_the_same_limits(tmp_path, capsys):
    # the same message as the case file's (one schema type for both)
    invalid(scene(), "elements", "expected a value <= 10000, found the integer 1000000",
            tmp_path, capsys, subprocess_check=False, run_args=["--elements", "1000000"])


def test_a_mesh_above_the_dof_limit_is_refused(tmp_path, capsys):
    extra = "".join(cable(f"d{k}", ("A", "B"), "m", 10.5 + 0.01 * k, 10000) for k in range(10))
    invalid(scene(extra, elements=10000), "cables", "the mesh would have 109991 nodes "
            "(329973 degrees of freedom, 110000 elements), above the limit of 300000",
            tmp_path, capsys)


def test_a_line_diameter_beyond_the_limit_is_refused(tmp_path, capsys):
    """A diameter of 1e300 m overflowed the line's area (pi d^2 / 4) in the fluid model, a
    RuntimeWarning deep in a run (found by the fuzz test on the jumper case); refused on read
    since a line's diameter is at most 1e7 m (docs/case-format.md, limits)."""
    water = "[water]\ndensity = 1025.0\nsurface = 5.0\ndepth = 50.0\n"
    for d in (1e300, 1.1e7):
        text = scene(water).replace("mass = 1.0\n", f"mass = 1.0\ndiameter = {d!r}\n", 1)
        invalid(text, "materials.m.diameter", "expected a value <= 10000000.0", tmp_path,
                capsys, subprocess_check=d == 1e300)


def test_an_axial_stiffness_a_length_or_an_expansion_beyond_the_limits_is_refused(tmp_path,
                                                                                  capsys):
    """EA = 1e308 and a length of 1e300 m passed check and then failed the static step with a
    numpy overflow (exit 1, an independent tester); a thermal expansion of 1.0 (a units slip)
    failed the run naming 'cables.c'. All are refused on read, naming the field."""
    base = scene()
    assert "EA = 1000000.0\n" in base and "length = 10.5\n" in base, base
    for old, bad, field, said in (
            ("EA = 1000000.0\n", "EA = 1e308\n", "materials.m.EA", "<= 1000000000000000.0"),
            ("length = 10.5\n", "length = 1e300\n", "cables[0].length", "<= 10000000.0"),
            ("mass = 1.0\n", "mass = 1.0\nthermal_expansion = 1.0\n",
             "materials.m.thermal_expansion", "<= 0.001")):
        invalid(base.replace(old, bad, 1), field, said, tmp_path, capsys,
                subprocess_check=field.endswith("EA"))


# -- 5. names: step names are netCDF group names; no control characters; mesh-node spelling ----
def test_unsafe_step_names_are_refused(tmp_path, capsys):
    for k, name in enumerate(["$x", ".", "a\\u0000b", "-a", "a/b", "a "]):
        invalid(scene(steps=static_step(name)), "steps[0].name", "a step name names a group "
                "of the results file", tmp_path, capsys, subprocess_check=k == 0)


def test_step_names_that_would_overflow_a_file_name_are_refused(tmp_path, capsys):
    """85 CJK characters are within the 100-character limit of names but 255 bytes in UTF-8:
    the figures and VTK series named after the step could not be written (a tester's exit 1
    after the run); refused before it, with the reason."""
    invalid(scene(steps=static_step("電" * 85)), "steps[0].name", "a step name of 255 bytes "
            "in UTF-8, above the limit of 200", tmp_path, capsys, subprocess_check=False)


def test_safe_step_names_are_written_as_given(tmp_path):
    names = ["équilibre", "ok-1", "a.b", "_x", "2nd step"]
    tree = valid(scene(steps="".join(static_step(n) for n in names)), tmp_path)
    assert list(tree.children) == names


def test_control_characters_in_names_and_title_are_refused(tmp_path, capsys):
    invalid(scene(title="a\\u0000b"), "title", "expected text without control characters, "
            "found 'a\\x00b' (U+0000)", tmp_path, capsys, subprocess_check=False)
    invalid(scene(cable="c\\u0007"), "cables[0].name", "(U+0007)", tmp_path, capsys,
            subprocess_check=False)


def test_a_mesh_node_with_a_leading_zero_is_refused(tmp_path, capsys):
    def on(node):
        return load("p", [0.0, 1.0, 0.0], node=node)

    invalid(scene(on("c.02")), "loads[0].node", "mesh node 'c.02' is written with a leading "
            "zero: its name is 'c.2'", tmp_path, capsys)
    tree = valid(scene(on("c.2")), tmp_path)
    assert tree.attrs["status"] == "completed"


# -- 7. sizes: what a step stores, estimated before it starts -----------------------------------
def test_a_transient_that_would_store_terabytes_is_refused(tmp_path, capsys):
    steps = static_step("st") + transient_step("dyn", 1e6, 1e-6, rtol=1e-6, atol=1e-8)
    invalid(scene(steps=steps), "steps[1].output_interval", "transient step 'dyn' would "
            "store 1e+12 outputs of 5 nodes and 4 elements, 633 TiB, and need about 1.85 PiB of "
            "memory with its working copies, above the limit of 1 GiB per step", tmp_path, capsys)


def test_the_size_limit_is_judged_again_after_an_elements_override(tmp_path, capsys):
    steps = static_step("st") + transient_step("dyn", 100.0, 1e-3, rtol=1e-6, atol=1e-8)
    invalid(scene(steps=steps), "steps[1].output_interval", "above the limit of 1 GiB",
            tmp_path, capsys, subprocess_check=False, run_args=["--elements", "200"])


def test_fewer_elements_asked_for_are_judged_not_the_files(tmp_path, capsys):
    """A file whose 200 elements would store too much, run with --elements 4 (an independent
    tester was refused on the file's mesh, with the file's figures in the message): check
    passes and says 4 elements; the file alone is refused."""
    from catdae.case import load_case
    from catdae.cli import main

    steps = static_step("st") + transient_step("dyn", 100.0, 1e-3, rtol=1e-6, atol=1e-8)
    f = tmp_path / "case.toml"
    f.write_text(scene(steps=steps, elements=200))
    assert main(["check", str(f)]) == 2
    assert "201 nodes and 200 elements" in capsys.readouterr().err
    assert main(["check", str(f), "--elements", "4"]) == 0
    assert "4 elements, 5 nodes" in capsys.readouterr().out
    case = load_case(f, elements=4)
    assert [c.elements for c in case.cables] == [4]


def test_a_modal_step_that_needs_a_dense_solve_too_large_is_refused(tmp_path, capsys):
    invalid(scene(steps=static_step("st") + modal_step(10**9), elements=10000), "steps[1].modes",
            "modal step 'modes': 29997 modes of 29997 free degrees of freedom need", tmp_path,
            capsys, subprocess_check=False)


# -- 8. no NaN on disk: degenerate time functions ------------------------------------------------
def timed(time: dict) -> str:
    """The load "p" at c.1 along y, following the time function ``time``."""
    return load("p", [0.0, 1.0, 0.0], node="c.1", time=time)


DYN = static_step("st") + transient_step("dyn", 0.2, 0.05, rtol=1e-6, atol=1e-8)


def test_a_degenerate_ramp_is_refused(tmp_path, capsys):
    invalid(scene(timed({"kind": "ramp", "duration": 1e-200, "smooth": True}), steps=DYN),
            "loads[0].time.duration", "expected a value >= 1e-09, found the number 1e-200",
            tmp_path, capsys)


def test_time_functions_that_overflow_are_refused(tmp_path, capsys):
    for time, field, expected in [
        ({"kind": "sine", "amplitude": 1.0, "frequency": 1e300}, "loads[0].time.frequency",
         "expected a value <= 1000000000.0"),
        ({"kind": "sine", "amplitude": 1e300, "frequency": 1e6}, "loads[0].time",
         "its value, rate or second derivative overflows"),
        ({"kind": "ramp", "duration": 1e-6, "smooth": True, "amplitude": 1e300},
         "loads[0].time", "overflows"),
        ({"kind": "table", "t": [0.0, 1e-300], "value": [0.0, 1.0]}, "loads[0].time",
         "overflows"),
    ]:
        invalid(scene(timed(time), steps=DYN), field, expected, tmp_path, capsys,
                subprocess_check=False)


def test_a_short_smooth_ramp_runs_without_nan(tmp_path):
    import numpy as np

    tree = valid(scene(timed({"kind": "ramp", "duration": 1e-3, "smooth": True}), steps=DYN),
                 tmp_path)
    ds = tree["dyn"].to_dataset()
    assert ds.attrs["status"] == "completed"
    for name in ("position", "velocity", "acceleration", "tension"):
        assert np.isfinite(ds[name].values).all(), name
    assert np.isfinite(ds.reaction.sel(node=["A", "B"]).values).all()


def test_a_static_state_stretched_far_beyond_a_cable_is_noted(tmp_path):
    """A 1e9 N load on a cable of EA 1e7 passes the case check (loads are not bounded) and
    solves to a strain of 50 (an independent tester's case, 1e12 N, took 53 s): the step's
    note says the strain, the element and what to check; an ordinary load gets none."""
    text = scene(EA=1e7).replace("[[steps]]", '[[loads]]\nname = "P"\nnode = "c.2"\n'
                           "force = [0.0, 0.0, {f}]\n[[steps]]", 1)
    for force, noted in ((-1e9, True), (-100.0, False)):
        ds = valid(text.replace("{f}", repr(force)), tmp_path)
        step = next(iter(ds.children.values())).to_dataset()
        assert ("far beyond what a cable carries" in step.attrs.get("note", "")) == noted


def test_a_static_step_with_a_mistake_is_no_unknown_jump_reference(tmp_path, capsys):
    """One mistake in the static step that a transient's jump_reference names: that mistake is
    the only problem said (an independent tester got a second, false one: "unknown static step
    'bare'", sending the user to the wrong field)."""
    steps = ('[[steps]]\nkind = "static"\nname = "bare"\nload_steps = 0\n'
             + transient_step("shed", 0.1, 0.05, rtol=1e-4, atol=1e-6,
                              extra='jump_reference = "bare"\n'))
    invalid(scene(steps=steps), "steps[0].load_steps", "expected", tmp_path, capsys)


def test_a_connector_end_between_mesh_nodes_says_how_to_place_it(tmp_path, capsys):
    """A damper given an end between mesh nodes, "c@s=3.5" (the syntax ``catdae plot --node``
    takes) or "c.3.5": the message says connectors end on nodes, which mesh nodes the cable has
    and how to put one elsewhere, not "did you mean 'c.5'?" (a node 2.5 m away; "c.35" for
    "c.3.5", 32 m away; an independent tester)."""
    for end in ("c@s=3.5", "c.3.5"):
        err = invalid(scene(damper("d", [end, "B"], 10.0)), "dampers[0].ends[0]",
                      "is not a node: a connector ends on a [nodes] entry or on a mesh node "
                      "'c.<k>' of cable 'c' (k = 1 to 3", tmp_path, capsys,
                      subprocess_check=False)
        assert "did you mean" not in err


def test_a_damper_with_a_mistake_is_not_also_unknown_to_a_sweep(tmp_path, capsys):
    """A negative damper coefficient, swept in a modal step: the coefficient is the only
    problem said (a second, false one, "unknown damper 'd'; there is no damper at all", came
    with every mistake in a damper)."""
    steps = static_step("st") + ('[[steps]]\nkind = "modal"\nname = "m"\nmodes = 2\n'
                                 'sweep = { field = "dampers.d.coefficient", values = [1.0] }\n')
    invalid(scene(damper("d", ["c.2", "B"], -1.0), steps=steps), "dampers[0].coefficient",
            "expected", tmp_path, capsys, subprocess_check=False)
