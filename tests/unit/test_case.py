"""Case files: the format example, defaults, overrides, every kind of bad input, fuzzing, safety."""

from __future__ import annotations

import copy
import dataclasses
import datetime
import json
import math
import pickle
import re
import tomllib

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from catdae.case import Case, Damping, FrozenMap, case_from_dict, load_case
from catdae.case.timefunc import Cosine, Ramp, Sine, Table
from catdae.errors import CaseError

from repo_paths import CASES  # noqa: E402
from scene_toml import cable_scene, load, point_mass, step, support_motion

EXAMPLE = CASES / "format_example.toml"

# A small valid case that the bad-input tests break one key at a time.
BASE_TOML = cable_scene(
    title="base", material="strand", cable="main", B=(10.0, 0.0, 0.0), L0=10.5, EA=1.0e7,
    mass=2.0, elements=4,
    extra=(point_mass("hung", 10.0, cable="main", s=5.0)
           + load("gust", [0.0, 100.0, 0.0], node="main.2",
                  time={"kind": "ramp", "duration": 0.5})
           + support_motion("A", y={"kind": "sine", "amplitude": 0.1, "frequency": 0.5})),
    steps=step("static") + step("transient", remove=["hung"], duration=2.0,
                                output_interval=0.1))
BASE = tomllib.loads(BASE_TOML)


# -- a tiny TOML writer: every table inline, so any tomllib-compatible value can be written ------

def toml_key(key: str) -> str:
    return key if re.fullmatch(r"[A-Za-z0-9_-]+", key) else toml_string(key)


def toml_string(s: str) -> str:
    return json.dumps(s, ensure_ascii=False).replace("\x7f", "\\u007f")


def toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        return ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, str):
        return toml_string(v)
    if isinstance(v, datetime.datetime):
        return v.isoformat()
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    return "{ " + ", ".join(f"{toml_key(k)} = {toml_value(x)}" for k, x in v.items()) + " }"


def dump(data: dict) -> str:
    return "".join(f"{toml_key(k)} = {toml_value(v)}\n" for k, v in data.items())


def base(**changes):
    """A deep copy of BASE with ``changes`` applied: ``{"cables.0.length": -1}``; None deletes."""
    data = copy.deepcopy(BASE)
    for dotted, value in changes.items():
        *parents, last = dotted.split("/")
        target = data
        for p in parents:
            target = target[int(p)] if isinstance(target, list) else target[p]
        key = int(last) if isinstance(target, list) else last
        if value is None:
            del target[key]
        else:
            target[key] = value
    return data


def problems(data_or_text) -> dict[str, str]:
    """The problems of a case that must fail, as {field path: message}."""
    text = data_or_text if isinstance(data_or_text, str) else dump(data_or_text)
    with pytest.raises(CaseError) as info:
        load_case(text)
    found: dict[str, str] = {}
    for path, message in info.value.problems:
        found.setdefault(path, message)
    return found


# -- the format example and defaults ------------------------------------------------------------

def test_format_example_values():
    case = load_case(EXAMPLE)
    assert case.name == "format_example" and case.path == str(EXAMPLE)
    assert case.text == EXAMPLE.read_text()
    assert case.title.startswith("Free vibration") and case.source.startswith("Chang")
    assert case.gravity == 9.81
    strand = case.materials["strand"]
    assert (strand.name, strand.EA, strand.mass, strand.weight, strand.damping) == (
        "strand", 4.696e8, 20.3, 199.14, 0.0)
    assert case.nodes == {"A": (0.0, 0.0, 0.0), "B": (44.335, 0.0, 0.0)}
    assert case.supports == {"A": ("x", "y", "z"), "B": ("x", "y", "z")}
    (main,) = case.cables
    assert main == case.cable("main")
    assert (main.ends, main.material, main.length, main.elements, main.gauss_points) == (
        ("A", "B"), "strand", 44.304, 14, 3)
    assert case.material_of(main) is strand and case.material_of("main") is strand
    (hung,) = case.point_masses
    assert (hung.name, hung.cable, hung.s, hung.mass, hung.node) == ("hung", "main", 22.152,
                                                                      100.0, None)
    (gust,) = case.loads
    assert (gust.name, gust.node, gust.force, gust.time) == (
        "gust", "main.7", (0.0, 500.0, 0.0), Ramp(0.5))
    (wind,) = case.distributed_loads
    assert (wind.name, wind.cable, wind.load, wind.time) == (
        "distributed0", "main", (0.0, 30.0, 0.0), None)
    (motion,) = case.support_motions
    assert motion.node == "A" and motion.x is None
    assert motion.y == Cosine(-3.0, 0.5, 0.0, 3.0) and motion.z == Sine(3.0, 0.5)
    assert [a for a, _ in motion.moved()] == ["y", "z"]
    assert [(s.kind, s.name) for s in case.steps] == [
        ("static", "hanging"), ("modal", "modes"), ("transient", "release")]
    release = case.steps[2]
    assert release.remove == ("hung",) and case.steps[1].modes == 10
    assert (release.duration, release.output_interval, release.rtol, release.atol) == (
        4.0, 0.01, 1e-6, 1e-8)
    assert release.damping == Damping("rayleigh", ratio=0.00155, frequencies=(1.5, 14.0))


def test_every_case_file_loads():
    files = sorted(CASES.glob("*.toml"))
    assert EXAMPLE in files
    for file in files:
        assert load_case(file).name == file.stem


def test_defaults():
    case = load_case(BASE_TOML)
    assert (case.source, case.gravity, case.path, case.name) == ("", 9.81, None, "case")
    assert load_case(BASE_TOML, name="mine").name == "mine"
    strand = case.materials["strand"]
    assert strand.weight == pytest.approx(2.0 * 9.81) and strand.damping == 0.0
    assert case.cable("main").gauss_points == 3
    assert case.loads[0].time == Ramp(0.5, start=0.0, smooth=False)
    assert case.point_masses[0].node is None and case.loads[0].cable is None
    static, transient = case.steps
    assert (static.name, transient.name) == ("static0", "transient1")  # kind and index
    assert (static.load_steps, static.remove, static.duration) == (1, (), None)
    assert (transient.rtol, transient.atol, transient.max_order, transient.damping) == (
        1e-6, 1e-8, "auto", None)
    assert (transient.linear_solver, transient.mass_model) == ("auto", "auto")
    modal = load_case(dump({**BASE, "steps": [{"kind": "modal"}]})).steps[0]
    assert (modal.name, modal.modes, modal.mass_model) == ("modal0", 10, "auto")
    no_weight = load_case(dump(base(gravity=0.0)))
    assert no_weight.materials["strand"].weight == 0.0  # but the point mass keeps it defined


def test_weight_follows_gravity_unless_given():
    assert load_case(dump(base(gravity=1.62))).materials["strand"].weight == pytest.approx(3.24)
    given_weight = base(**{"materials/strand/weight": 5.0})
    assert load_case(dump(given_weight)).materials["strand"].weight == 5.0


def test_case_is_frozen_and_picklable():
    case = load_case(EXAMPLE)
    with pytest.raises(dataclasses.FrozenInstanceError):
        case.gravity = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        case.cables[0].length = 1.0
    with pytest.raises(TypeError):
        case.materials["other"] = case.materials["strand"]
    with pytest.raises(AttributeError):
        case.nodes._data = {}
    assert isinstance(case.nodes, FrozenMap) and isinstance(case.steps, tuple)
    again = pickle.loads(pickle.dumps(case))
    assert again == case and hash(again) == hash(case)
    # direct construction freezes plain containers too
    built = Case(nodes={"A": (0.0, 0.0, 0.0)}, steps=[])
    assert isinstance(built.nodes, FrozenMap) and built.steps == ()


def test_with_overrides():
    case = load_case(EXAMPLE)
    new = case.with_overrides(rtol=1e-3, atol=1e-5, elements=20)
    assert [(s.rtol, s.atol) for s in new.steps if s.kind == "transient"] == [(1e-3, 1e-5)]
    assert all(c.elements == 20 for c in new.cables)
    assert case.steps[2].rtol == 1e-6 and case.cables[0].elements == 14  # unchanged
    assert case.with_overrides() == case
    assert case.with_overrides(rtol=1e-4).cables == case.cables
    with pytest.raises(CaseError) as info:
        case.with_overrides(rtol=-1.0, elements=0)
    assert {p for p, _ in info.value.problems} == {"rtol", "elements"}
    # main.7 (midspan of 14 elements) does not exist with 4 elements: the load stays at
    # midspan, s = 7 L0 / 14, and lands on mesh node main.2 of the new mesh
    four = case.with_overrides(elements=4)
    (gust,) = four.loads
    assert gust.node is None and gust.cable == "main"
    assert gust.s == pytest.approx(case.cables[0].length / 2, rel=1e-15)
    from catdae.model.mesh import build_mesh

    mesh = build_mesh(four)
    kind, index, _ = mesh.locate("main", gust.s)
    assert kind == "node" and mesh.node_names[index] == "main.2"


def test_rayleigh_coefficients_give_the_ratio_at_both_frequencies():
    damping = Damping("rayleigh", ratio=0.02, frequencies=(1.5, 14.0))
    alpha, beta = damping.coefficients()
    for f in (1.5, 14.0):
        w = 2 * math.pi * f
        assert alpha / (2 * w) + beta * w / 2 == pytest.approx(0.02)  # ζ(ω) of C = αM + βK
    assert Damping("rayleigh", alpha=0.1, beta=0.002).coefficients() == (0.1, 0.002)
    with pytest.raises(ValueError):
        Damping("material").coefficients()


def test_damping_and_step_options():
    steps = [{"kind": "transient", "duration": 1.0, "output_interval": 0.5, "max_order": 2,
              "linear_solver": "band", "mass_model": "lumped", "damping": {"kind": "material"}},
             {"kind": "transient", "duration": 1.0, "output_interval": 0.5,
              "damping": {"kind": "rayleigh", "alpha": 0.1, "beta": 1e-3}},
             {"kind": "static", "load_steps": 5, "name": "ramped"}]
    a, b, c = load_case(dump(base(steps=steps))).steps
    assert (a.max_order, a.linear_solver, a.mass_model, a.damping) == (
        2, "band", "lumped", Damping("material"))
    assert b.damping.coefficients() == (0.1, 1e-3)
    assert (c.name, c.load_steps) == ("ramped", 5)


def test_table_time_function_inline_and_from_csv(tmp_path):
    (tmp_path / "gust.csv").write_text("time,value\n0,0\n1,2\n# a comment\n\n3,1\n")
    data = base(**{"loads/0/time": {"kind": "table", "file": "gust.csv"}})
    path = tmp_path / "case.toml"
    path.write_text(dump(data))
    table = load_case(path).loads[0].time
    assert table == Table((0.0, 1.0, 3.0), (0.0, 2.0, 1.0), file="gust.csv")
    assert [table(t) for t in (0.0, 1.0, 3.0, 9.0)] == pytest.approx([0.0, 2.0, 1.0, 1.0])
    inline = base(**{"loads/0/time": {"kind": "table", "t": [0, 1, 3], "value": [0, 2, 1]}})
    assert load_case(dump(inline)).loads[0].time == Table((0.0, 1.0, 3.0), (0.0, 2.0, 1.0))


def test_point_mass_and_load_at_nodes():
    data = base(**{"point_masses/0/cable": None, "point_masses/0/s": None,
                   "point_masses/0/node": "B"})
    data["loads"].append({"name": "pull", "cable": "main", "s": 10.5, "force": [1.0, 0, 0]})
    case = load_case(dump(data))
    assert case.point_masses[0].node == "B" and case.loads[1].s == 10.5


def test_supports_list_of_axes():
    case = load_case(dump(base(**{"supports/B": ["z", "y"]})))
    assert case.supports["B"] == ("y", "z")


# -- bad input ----------------------------------------------------------------------------------

def test_malformed_toml_gives_line_and_column():
    found = problems("title = 'x'\nlength = = 3\n")
    assert list(found) == [""] and "line 2, column" in found[""]


@pytest.mark.parametrize("changes, path, fragments", [
    ({"cables/0/lenght": 10.5, "cables/0/length": None}, "cables[0].lenght",
     ["unknown key 'lenght'", "did you mean 'length'?"]),
    ({"cables/0/lenght": 10.5}, "cables[0].lenght", ["did you mean 'length'"]),
    ({"cables/0/length": None}, "cables[0].length", ["missing", "required"]),
    ({"cables/0/elements": "many"}, "cables[0].elements",
     ["expected an integer", "found the string 'many'"]),
    ({"cables/0/elements": 4.0}, "cables[0].elements", ["expected an integer", "4.0"]),
    ({"cables/0/length": -2.0}, "cables[0].length", ["> 0", "-2.0"]),
    ({"cables/0/length": 0}, "cables[0].length", ["> 0", "found the integer 0"]),
    ({"materials/strand/EA": 0.0}, "materials.strand.EA", ["> 0", "0.0"]),
    ({"materials/strand/EA": float("nan")}, "materials.strand.EA", ["finite"]),
    ({"materials/strand/mass": -1.0}, "materials.strand.mass", [">= 0"]),
    ({"gravity": "9.81"}, "gravity", ["expected a number", "string"]),
    ({"nodes/B": [10.0, 0.0]}, "nodes.B", ["exactly 3"]),
    ({"nodes/B": [0.0, 0.0, 1e-12]}, "cables[0].ends", ["coincide"]),
    ({"nodes/B": [16.0, 0.0, 0.0]}, "cables[0].length", ["52%", "50%"]),
    ({"cables/0/ends": ["A", "A"]}, "cables[0].ends", ["two different nodes"]),
    ({"cables/0/ends": ["A", "C"]}, "cables[0].ends[1]", ["unknown node 'C'"]),
    ({"cables/0/material": "strnd"}, "cables[0].material", ["did you mean 'strand'"]),
    ({"cables/0/gauss_points": 11}, "cables[0].gauss_points", ["<= 10"]),
    ({"cables/0/name": None}, "cables[0].name", ["missing"]),
    ({"point_masses/0/name": None}, "point_masses[0].name", ["missing"]),
    ({"loads/0/name": "hung"}, "loads[0].name", ["duplicate name 'hung'", "point_masses[0]"]),
    ({"point_masses/0/s": 11.0}, "point_masses[0].s", ["0 <= s <= 10.5", "11"]),
    ({"point_masses/0/s": None}, "point_masses[0].s", ["missing", "arc length"]),
    ({"point_masses/0/node": "A"}, "point_masses[0]", ["either node, or cable and s"]),
    ({"point_masses/0/cable": "mian"}, "point_masses[0].cable", ["did you mean 'main'"]),
    ({"loads/0/node": "main.4"}, "loads[0].node", ["main.1 .. main.3"]),
    ({"loads/0/node": "mian.2"}, "loads[0].node", ["unknown node 'mian.2'",
                                                   "did you mean 'main.2'"]),
    ({"loads/0/force": [1.0, "x", 0.0]}, "loads[0].force[1]", ["expected a number"]),
    ({"loads/0/time": {"kind": "sine", "amplitude": 1.0}}, "loads[0].time.frequency",
     ["missing"]),
    ({"loads/0/time": {"kind": "ramp"}}, "loads[0].time.duration", ["missing"]),
    ({"loads/0/time": {"duration": 1.0}}, "loads[0].time.kind", ["missing", "'ramp'"]),
    ({"loads/0/time": {"kind": "sinus", "amplitude": 1.0, "frequency": 1.0}},
     "loads[0].time.kind", ["did you mean 'sine'"]),
    ({"loads/0/time": {"kind": "ramp", "duration": 1.0, "frequency": 2.0}},
     "loads[0].time.frequency", ["unknown key 'frequency'"]),
    ({"loads/0/time": {"kind": "table", "t": [0.0, 1.0]}}, "loads[0].time.value", ["missing"]),
    ({"loads/0/time": {"kind": "table", "t": [0, 2, 1], "value": [0, 1, 2]}},
     "loads[0].time.t", ["strictly increasing"]),
    ({"loads/0/time": {"kind": "table", "t": [0, 1], "value": [0, 1, 2]}},
     "loads[0].time.value", ["expected 2 values"]),
    ({"loads/0/time": {"kind": "table", "file": "no-such-file.csv"}}, "loads[0].time.file",
     ["cannot read table file 'no-such-file.csv'"]),
    ({"supports/C": "pinned"}, "supports.C", ["unknown node 'C'"]),
    ({"supports/B": "fixed"}, "supports.B", ['"pinned"', "the string 'fixed'"]),
    ({"supports/B": ["y", "w"]}, "supports.B[1]", ["'x', 'y', 'z'", "'w'"]),
    ({"supports": {}}, "supports", ["no support at all"]),
    ({"supports/A": None, "supports/B": None}, "supports", ["no support at all"]),
    ({"support_motions/0/node": "Q"}, "support_motions[0].node", ["unknown node 'Q'"]),
    ({"supports/A": ["z"]}, "support_motions[0].y", ["axis 'y' of node 'A' is not fixed"]),
    ({"supports/B": None, "support_motions/0/node": "B"}, "support_motions[0].node",
     ["node 'B' is not supported"]),
    ({"support_motions/0/y": None}, "support_motions[0]", ["at least one of x, y, z"]),
    ({"steps/1/remove": ["hugn"]}, "steps[1].remove[0]",
     ["unknown point mass, load or distributed load 'hugn'", "did you mean 'hung'"]),
    ({"steps/0/remove": ["hung"]}, "steps[1].remove[0]",
     ["'hung' is already removed by step 'static0' (steps[0])"]),
    ({"steps/1/name": "static0"}, "steps[1].name", ["duplicate step name 'static0'"]),
    ({"steps/1/name": "a/b"}, "steps[1].name", ["'/'"]),
    ({"steps/1/duration": None}, "steps[1].duration", ["missing"]),
    ({"steps/1/output_interval": 3.0}, "steps[1].output_interval", ["at most", "2 s"]),
    ({"steps/1/modes": 3}, "steps[1].modes", ["does not apply to a transient step",
                                              "modal"]),
    ({"steps/1/max_order": 6}, "steps[1].max_order", ['"auto" or an integer from 1 to 5']),
    # rtol = 5 (a slip for 5e-3) reported 4.5e9 N for 12 kN, status completed (a tester)
    ({"steps/1/rtol": 5.0}, "steps[1].rtol", ["expected a value <= 0.1", "5.0"]),
    # digits a double does not hold (tester t75: 1.8 million steps for 0.68 s, no word)
    ({"steps/1/rtol": 1e-15}, "steps[1].rtol", ["expected a value >= 1e-13", "1e-15"]),
    ({"steps/1/max_order": "fast"}, "steps[1].max_order", ['"auto"', "'fast'"]),
    ({"steps/1/linear_solver": "bandd"}, "steps[1].linear_solver", ["did you mean 'band'"]),
    ({"steps/0/kind": "statik"}, "steps[0].kind", ["did you mean 'static'"]),
    ({"steps/1/damping": {"kind": "rayleigh", "alpha": 0.1, "ratio": 0.01}},
     "steps[1].damping", ["not both"]),
    ({"steps/1/damping": {"kind": "rayleigh", "ratio": 0.01, "frequencies": [1.0, 1.0]}},
     "steps[1].damping.frequencies", ["two different frequencies"]),
    ({"steps/1/damping": {"kind": "rayleigh", "ratio": 0.01, "frequencies": [1.0, -2.0]}},
     "steps[1].damping.frequencies[1]", ["> 0"]),
    ({"steps/1/damping": {"kind": "rayleigh", "alpha": 0.1}}, "steps[1].damping.beta",
     ["missing"]),
    ({"nodes/A.1": [0.0, 1.0, 0.0]}, 'nodes."A.1"', ["may not contain '.'"]),
    ({"colour": "red"}, "colour", ["unknown key 'colour'"]),
])
def test_bad_input_names_the_field(changes, path, fragments):
    found = problems(base(**changes))
    assert path in found, found
    for fragment in fragments:
        assert fragment in found[path]


@pytest.mark.parametrize("changes", [
    {"cables/0/elements": 0}, {"cables/0/material": 3}, {"materials/strand/EA": -1.0},
    {"nodes/B": [1.0, 2.0]}, {"support_motions/0/y": 3}, {"loads/0/node": 3},
    {"point_masses/0/s": "x"}, {"steps/1/remove": "hung"}, {"loads/0/time": {"kind": 1}},
    {"supports/A": "fixed"},
])
def test_one_mistake_gives_one_problem(changes):
    """A bad item is left out of the cross checks without cascading into more errors."""
    with pytest.raises(CaseError) as info:
        load_case(dump(base(**changes)))
    assert len(info.value.problems) == 1, info.value.problems


def test_slack_weightless_cable_has_no_shape():
    data = base(gravity=0.0, point_masses=[], loads=[], steps=[{"kind": "static"}])
    found = problems(data)
    assert "slack: no defined shape" in found["cables[0].length"]
    taut = base(gravity=0.0, point_masses=[], loads=[], steps=[{"kind": "static"}],
                **{"cables/0/length": 9.9})
    assert load_case(dump(taut)).cable("main").length == 9.9  # shorter than the chord: defined
    loaded = base(gravity=0.0, steps=[{"kind": "static"}])
    assert load_case(dump(loaded)).materials["strand"].weight == 0.0  # point mass on it


def test_removing_an_unnamed_distributed_load_is_refused():
    # only a named distributed load can be added or removed (tests/scenes/test_loads.py)
    data = base(distributed_loads=[{"cable": "main", "load": [0.0, 1.0, 0.0]}],
                **{"steps/1/remove": ["distributed0"]})
    assert "unnamed distributed load" in problems(data)["steps[1].remove[0]"]


def test_load_on_a_node_no_cable_reaches():
    data = base(**{"nodes/C": [1.0, 2.0, 3.0], "loads/0/node": "C"})
    assert "not an end of any cable" in problems(data)["loads[0].node"]


def test_every_problem_in_one_file_is_reported():
    data = base(**{
        "materials/strand/EA": -1.0,
        "cables/0/lenght": 3.0,
        "cables/0/elements": 0,
        "loads/0/time": {"kind": "sine", "amplitude": 1.0},
        "steps/1/remove": ["nothing"],
        "steps/1/output_interval": 5.0,
        "supports/Z": "pinned",
        "title": 3,
    })
    found = problems(data)
    expected = {"materials.strand.EA", "cables[0].lenght", "cables[0].elements",
                "loads[0].time.frequency", "steps[1].remove[0]", "steps[1].output_interval",
                "supports.Z", "title"}
    assert expected <= set(found), found
    # the CaseError message carries them all, one per line, with the file
    with pytest.raises(CaseError) as info:
        load_case(dump(data))
    assert len(str(info.value).splitlines()) == len(info.value.problems) >= len(expected)


def test_paths_and_missing_files(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text(BASE_TOML)
    assert load_case(path).name == "mine"
    assert load_case(str(path)).path == str(path)
    with pytest.raises(CaseError) as info:
        load_case(tmp_path / "absent.toml")
    assert "cannot read the case file" in info.value.problems[0][1]
    with pytest.raises(CaseError):
        load_case(str(tmp_path / "absent.toml"))
    (tmp_path / "bad.toml").write_bytes(b"title = '\xff'")
    with pytest.raises(CaseError, match="UTF-8"):
        load_case(tmp_path / "bad.toml")
    with pytest.raises(CaseError):
        case_from_dict(["not", "a", "table"])


# -- a case file is data ------------------------------------------------------------------------

def string_fields(data, prefix=()):
    """Paths of every string value in a nested dict/list."""
    items = data.items() if isinstance(data, dict) else enumerate(data)
    for k, v in items:
        if isinstance(v, str):
            yield prefix + (k,)
        elif isinstance(v, dict | list):
            yield from string_fields(v, prefix + (k,))


@pytest.mark.parametrize("where", list(string_fields(BASE)) + [("title",), ("source",)])
def test_a_case_file_is_data(where, tmp_path):
    marker = tmp_path / "pwned"
    payloads = [f"__import__('os').system('touch {marker}')",
                f"{{__import__('os').system('touch {marker}')}}",
                "catdae.errors.CaseError"]
    for payload in payloads:
        data = base(**{"/".join(map(str, where)): payload})
        try:
            case = load_case(dump(data))
        except CaseError as exc:
            assert exc.problems
        else:
            assert payload in repr(case)  # kept as a plain string
        # also as a key: a node named by the payload
        data = base()
        data["nodes"][payload] = [0.0, 1.0, 2.0]
        try:
            load_case(dump(data))
        except CaseError:
            pass
    assert not marker.exists()


# -- fuzzing: nothing but CaseError ever escapes ------------------------------------------------

def check_only_case_error(text: str) -> None:
    try:
        case = load_case(text)
    except CaseError as exc:
        assert exc.problems
        assert all(isinstance(p, str) and isinstance(m, str) and m for p, m in exc.problems)
    else:
        assert isinstance(case, Case)


toml_ish = st.lists(st.sampled_from(list('abcdeEAs=[]{}."\',#\n 0123456789-+_\\')
                                     + ["cables", "[[cables]]", "[nodes]", "kind", "inf",
                                        "nan", "true", "EA = 1e6", 'name = "main"']),
                     max_size=40).map("".join)


@settings(max_examples=300, deadline=None)
@given(text=st.one_of(st.text(max_size=80), toml_ish))
def test_fuzz_random_text(text):
    check_only_case_error(text)


@settings(max_examples=300, deadline=None)
@given(text=st.lists(st.sampled_from(BASE_TOML.splitlines()), max_size=40).map("\n".join))
def test_fuzz_shuffled_lines_of_a_valid_case(text):
    check_only_case_error(text)


KEYS = ["name", "node", "cable", "s", "kind", "time", "remove", "elements", "length", "ends",
        "material", "EA", "mass", "weight", "x", "y", "z", "file", "t", "value", "damping",
        "duration", "output_interval", "frequency", "amplitude", "frequencies", "ratio"]
scalars = st.one_of(
    st.integers(-(2**64), 2**64), st.floats(), st.booleans(),
    st.text(max_size=8), st.sampled_from(["A", "B", "main", "main.2", "hung", "pinned", "ramp",
                                          "sine", "table", "static", "transient", "rayleigh"]),
    st.datetimes(min_value=datetime.datetime(1000, 1, 1)),
)
values = st.recursive(
    scalars,
    lambda inner: st.lists(inner, max_size=4)
    | st.dictionaries(st.one_of(st.sampled_from(KEYS), st.text(max_size=6)), inner, max_size=4),
    max_leaves=8,
)


def all_paths(data, prefix=()):
    yield prefix
    if isinstance(data, dict | list):
        items = data.items() if isinstance(data, dict) else enumerate(data)
        for k, v in items:
            yield from all_paths(v, prefix + (k,))


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_fuzz_mutations_of_a_valid_case(data):
    case = copy.deepcopy(BASE)
    for _ in range(data.draw(st.integers(1, 4))):
        paths = [p for p in all_paths(case) if p]
        where = data.draw(st.sampled_from(paths))
        parent = case
        for k in where[:-1]:
            parent = parent[k]
        op = data.draw(st.sampled_from(["replace", "delete", "add"]))
        if op == "replace":
            parent[where[-1]] = data.draw(values)
        elif op == "delete":
            del parent[where[-1]]
        elif isinstance(parent, dict):
            parent[data.draw(st.one_of(st.sampled_from(KEYS), st.text(max_size=6)))] = (
                data.draw(values))
        else:
            parent.append(data.draw(values))
    check_only_case_error(dump(case))


# -- fuzzing the bundled cases: values, types and keys; only catdae's own errors escape ---------

BUNDLED = {p.name: tomllib.loads(p.read_text()) for p in sorted(CASES.glob("*.toml"))}
HOSTILE = st.sampled_from([
    0, -1, 1, 10**6, 10**9, 2**63 - 1, -(2**63), 10**30, 0.0, -0.0, 1e-200, 5e-324, 1e-6,
    1e6, 1e300, -1e300, 1.7976931348623157e308, "", ".", "..", "$x", "a\x00b", "c.02", "main.0",
    "main.007", "main.99999", "/", "a/b", " ", "\t", "A", "main", "/etc/passwd", "/dev/zero",
    "../../etc/passwd", "é", "\u0301", "x" * 300, [], {}, [[]], [0.0] * 7, True,
    # issue 24: names at and beyond the length limit, bidirectional controls
    "x" * 100, "x" * 101, "n" * 100_000, "a\u202eb", "\u2067x", "b\u200f",
]).map(copy.deepcopy)  # fresh lists and tables: a mutation must not change the strategy


def _perturbed(v, draw):
    """A value near the original in kind: the same number scaled, of the other number type,
    a string edited, a list grown or shrunk."""
    if isinstance(v, bool):
        return not v
    if isinstance(v, int):
        x = v * draw(st.sampled_from([0, -1, 2, 10**3, 10**5, 10**9, 10**30]))
        return float(x) if draw(st.booleans()) else x
    if isinstance(v, float):
        x = v * draw(st.sampled_from([0.0, -1.0, 10.0, 1e-9, 1e9, 1e300, 1e-300]))
        return int(x) if abs(x) < 1e30 and draw(st.booleans()) else x
    if isinstance(v, str):
        return draw(st.sampled_from([v + "0", v[:-1], v.upper(), "0" + v, v + "/x", v * 2]))
    if isinstance(v, list):
        return v[:-1] if v and draw(st.booleans()) else v + v[-1:]
    return v


def _mutate(data: dict, draw) -> None:
    paths = [p for p in all_paths(data) if p]
    where = draw(st.sampled_from(paths))
    parent = data
    for k in where[:-1]:
        parent = parent[k]
    key = where[-1]
    op = draw(st.sampled_from(["perturb", "perturb", "perturb", "hostile", "hostile",
                               "hostile", "type", "delete", "add", "rename", "copy",
                               "duplicate"]))
    if op == "perturb":
        parent[key] = _perturbed(parent[key], draw)
    elif op == "hostile":
        parent[key] = draw(HOSTILE)
    elif op == "type":
        parent[key] = draw(values)
    elif op == "delete":
        del parent[key]
    elif op == "add":
        new = draw(st.one_of(st.sampled_from(KEYS), HOSTILE.filter(lambda h: isinstance(h, str))))
        if isinstance(parent, dict):
            parent[new] = draw(st.one_of(values, HOSTILE))
        else:
            parent.append(draw(st.one_of(values, HOSTILE)))
    elif op == "rename" and isinstance(parent, dict):
        new = draw(st.one_of(st.sampled_from(KEYS), st.text(max_size=6),
                             HOSTILE.filter(lambda h: isinstance(h, str))))
        parent[new] = parent.pop(key)
    elif op == "copy":  # a value from elsewhere in the case: a node name where a cable goes...
        other = draw(st.sampled_from(paths))
        source = data
        for k in other:
            source = source[k]
        parent[key] = copy.deepcopy(source)
    elif op == "duplicate" and isinstance(parent, list):
        parent.append(copy.deepcopy(parent[key]))  # a second cable, step, load of that name


def check_only_catdae_errors(text: str) -> None:
    """What ``catdae check`` does (read, validate, mesh, judge the steps): a Case or one of
    catdae's own errors, with every problem named."""
    from catdae.analysis import check_case
    from catdae.errors import CatdaeError

    try:
        check_case(load_case(text))
    except CaseError as exc:
        assert exc.problems
        assert all(isinstance(p, str) and isinstance(m, str) and m for p, m in exc.problems)
    except CatdaeError as exc:
        assert str(exc)


@settings(max_examples=250, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(data=st.data())
def test_fuzz_mutations_of_the_bundled_cases(data):
    """1 to 5 mutations of a bundled case: values perturbed (scaled, other number type),
    hostile values (huge counts, degenerate durations, unsafe names, paths outside the case),
    other types, keys deleted, added and renamed, values copied across, entries duplicated."""
    case = copy.deepcopy(BUNDLED[data.draw(st.sampled_from(sorted(BUNDLED)))])
    for _ in range(data.draw(st.integers(1, 5))):
        if case:
            _mutate(case, data.draw)
    check_only_catdae_errors(dump(case))
