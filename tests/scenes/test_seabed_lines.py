"""Mooring lines on a rigid, frictionless seabed beyond the single uniform chain
(docs/theory.md §17.4): a chain-wire-chain line whose touchdown falls in the wire, a line
too long to be taut, a spread mooring with load steps, and the touchdown point's definition.

Independent references: ``reference.grounded_line`` (the segments' elastic catenaries shot
down from the fairlead by nested root solves, no catdae code), ``reference.grounded_catenary``
and MoorPy's ``Catenary.catenary``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import catdae
from catdae.case import load_case
from catdae.errors import CatdaeError

from reference import grounded_line
from scene_toml import cable, scene, section

RHO, G = 1025.0, 9.81
CHAIN = {"EA": 1.674e9, "mass": 390.0, "diameter": 0.252}
WIRE = {"EA": 6.0e8, "mass": 40.0, "diameter": 0.1}


def w_sub(mat) -> float:
    """Submerged weight per metre (the default water, density 1025 kg/m³, g = 9.81)."""
    return (mat["mass"] - RHO * math.pi * mat["diameter"] ** 2 / 4.0) * G


def run_static(text: str):
    tree = catdae.run(load_case(text), progress=False)
    return tree[next(iter(tree.children))].to_dataset()


def mseg_toml(j1, j2, *, reverse: bool = False) -> str:
    """300 m chain from the anchor (x = 700 m on the seabed, 200 m down), 420 m wire, 60 m
    chain to the fairlead at the origin; the junctions j1, j2 start where given."""
    def ends(a, b):
        return (b, a) if reverse else (a, b)
    return scene(head={"title": "chain-wire-chain"},
                 materials={"chain": CHAIN, "wire": WIRE},
                 nodes={"anchor": (700.0, 0.0, -200.0), "j1": j1, "j2": j2,
                        "fairlead": (0.0, 0.0, 0.0)},
                 supports=("anchor", "fairlead"),
                 cables=[cable("bottom", ends("anchor", "j1"), "chain", 300.0, 8),
                         cable("mid", ends("j1", "j2"), "wire", 420.0, 10),
                         cable("top", ends("j2", "fairlead"), "chain", 60.0, 4)],
                 extra=section("water", depth=200.0) + section("seabed"))


@pytest.mark.parametrize("j1, j2, reverse", [
    ((399.0, 0.0, -200.0), (40.0, 0.0, -45.0), False),  # the tester's failing start
    ((380.0, 0.0, -200.0), (40.0, 0.0, -45.0), False),
    ((401.0, 0.0, -200.0), (40.0, 0.0, -45.0), False),
    ((410.0, 0.0, -197.0), (55.0, 0.0, -50.0), False),  # junction off the seabed
    ((300.0, 0.0, -150.0), (30.0, 0.0, -50.0), True),  # far off, cables written reversed
])
def test_chain_wire_chain_line_is_the_shooting_solution(j1, j2, reverse):
    """Touchdown in the wire, the junction j1 on the seabed: from junction starts 20 m short,
    1 m short, 1 m long of the answer or far off it, the equilibrium is the shooting solution's
    (H = 90 096 N, 395.21 m lying) to 1e-7 relative, and so are the junctions' positions and
    the touchdown point."""
    ref = grounded_line(700.0, 200.0, [(60.0, CHAIN["EA"], w_sub(CHAIN)),
                                       (420.0, WIRE["EA"], w_sub(WIRE)),
                                       (300.0, CHAIN["EA"], w_sub(CHAIN))])
    ds = run_static(mseg_toml(j1, j2, reverse=reverse))
    H, V = ref["H"], ref["V"]
    assert H == pytest.approx(90095.6, rel=1e-6)  # the tester's figure
    fair = ds.reaction.sel(node="fairlead").values
    anch = ds.reaction.sel(node="anchor").values
    assert fair == pytest.approx([-H, 0.0, V], rel=1e-7, abs=1e-9 * H)
    assert anch == pytest.approx([H, 0.0, 0.0], rel=1e-7, abs=1e-9 * H)
    assert float(ds.seabed_length.sum()) == pytest.approx(ref["lying_length"], rel=1e-7)
    (x2, d2), (x1, d1), _ = ref["joints"]
    assert ds.position.sel(node="j2").values == pytest.approx([x2, 0.0, -d2], abs=1e-6)
    assert ds.position.sel(node="j1").values == pytest.approx([x1, 0.0, -d1], abs=1e-6)
    in_wire = ref["lying_length"] - 300.0
    td = ds.touchdown.sel(cable="mid").values
    assert td == pytest.approx([x1 - in_wire * (1.0 + H / WIRE["EA"]), 0.0, -200.0], abs=1e-6)


@pytest.mark.parametrize("buoy, clump", [(3.0e4, 0.0), (2.0e4, -5.0e4), (1.0e4, 0.0)])
def test_a_buoy_and_a_clump_at_the_junctions_are_the_shooting_solution(buoy, clump):
    """A tester's chain-wire-chain line with a buoy at the upper junction (and a clump at the
    lower one, resting on the seabed) had no static solution on the rigid seabed above a
    10 kN buoy ("ramped up to 0 %"), though MoorPy found one (H = 99 954 N for 30 kN): the
    line's start now carries the vertical loads at its junctions. Against the shooting
    solution with the same jumps of V."""
    w_c, w_w = w_sub(CHAIN), w_sub(WIRE)
    ref = grounded_line(750.0, 190.0, [(150.0, CHAIN["EA"], w_c, buoy),
                                       (400.0, WIRE["EA"], w_w, clump),
                                       (300.0, CHAIN["EA"], w_c)])
    text = scene(head={"title": "buoyed line"}, materials={"chain": CHAIN, "wire": WIRE},
                 nodes={"anchor": (-750.0, 0.0, -200.0), "J1": (-480.0, 0.0, -199.0),
                        "J2": (-100.0, 0.0, -120.0), "fairlead": (0.0, 0.0, -10.0)},
                 supports=("anchor", "fairlead"),
                 cables=[cable("bottom", ("anchor", "J1"), "chain", 300.0, 10),
                         cable("wire", ("J1", "J2"), "wire", 400.0, 10),
                         cable("top", ("J2", "fairlead"), "chain", 150.0, 5)],
                 extra=(section("water", depth=200.0) + section("seabed", z=-200.0)
                        + "".join(f'[[loads]]\nname = "{n}"\nnode = "{j}"\n'
                                  f"force = [0.0, 0.0, {f!r}]\n"
                                  for n, j, f in (("buoy", "J2", buoy), ("clump", "J1", clump))
                                  if f)))
    ds = run_static(text)
    H, V = ref["H"], ref["V"]
    if buoy == 3.0e4 and not clump:
        assert H == pytest.approx(99954.0, rel=1e-5)  # MoorPy's figure, the tester's run
    assert ds.reaction.sel(node="fairlead").values == pytest.approx([H, 0.0, V], rel=1e-7)
    (x2, d2), (x1, d1), _ = ref["joints"]
    assert ds.position.sel(node="J2").values == pytest.approx([-x2, 0.0, -10.0 - d2], abs=1e-6)
    assert ds.position.sel(node="J1").values == pytest.approx([-x1, 0.0, -10.0 - d1], abs=1e-6)
    assert float(ds.seabed_length.sum()) == pytest.approx(ref["lying_length"], rel=1e-7)


def test_line_longer_than_span_plus_depth_is_refused():
    """2200 m of chain from an anchor 1400 m out to a fairlead 600 m up: H = 0 (MoorPy:
    V = w depth at the fairlead, the rest on the seabed), with 200 m to spare lying slack
    anywhere on a frictionless seabed: no unique equilibrium. The step is refused before any
    Newton iteration with the cable, its length, and span + height in the message."""
    catenary = pytest.importorskip("moorpy.Catenary").catenary
    w = w_sub(CHAIN)
    fa_h, fa_v, fb_h, fb_v, info = catenary(1400.0, 600.0, 2200.0, CHAIN["EA"], w, CB=0.0)
    assert abs(fb_h) <= 1e-6 * w * 600.0  # MoorPy: no horizontal tension
    text = scene(materials={"m": CHAIN}, nodes={"anchor": (1400.0, 0.0, -600.0),
                                               "fairlead": (0.0, 0.0, 0.0)},
                 supports=("anchor", "fairlead"),
                 cables=cable("line", ("anchor", "fairlead"), "m", 2200.0, 15),
                 extra=section("water", depth=600.0) + section("seabed"))
    with pytest.raises(CatdaeError) as err:
        run_static(text)
    msg = str(err.value)
    for part in ("cable 'line'", "2200 m", "1400 m + 600 m = 2000 m", "cables.length"):
        assert part in msg, msg
    assert "Newton" not in msg
    # a line of 1990 m (10 m to spare below span + depth) is taut and solved
    ds = run_static(text.replace("length = 2200.0", "length = 1990.0"))
    assert float(-ds.reaction.sel(node="fairlead").values[0]) > 0.0
    assert np.isfinite(ds.position.values).all()


def spread_toml(load_steps: int) -> str:
    """Three 760 m chains from anchors on the seabed 700 m around a free shared node C, which
    a buoy pulls with (500 kN, 0, 3000 kN)."""
    anchors = {f"a{k}": (700.0 * math.cos(2 * math.pi * k / 3),
                         700.0 * math.sin(2 * math.pi * k / 3), -200.0) for k in range(3)}
    return scene(materials={"chain": CHAIN}, nodes={**anchors, "C": (0.0, 0.0, -20.0)},
                 supports=tuple(anchors),
                 cables=[cable(f"l{k}", (f"a{k}", "C"), "chain", 760.0, 10) for k in range(3)],
                 extra=section("water", depth=200.0) + section("seabed")
                 + "[[loads]]\nname = \"buoy\"\nnode = \"C\"\nforce = [500000.0, 0.0, 3000000.0]\n",
                 steps=f"[[steps]]\nkind = \"static\"\nname = \"s\"\nload_steps = {load_steps}\n")


@pytest.mark.parametrize("load_steps", [1, 2, 4])
def test_spread_mooring_with_load_steps(load_steps):
    """The shared node's equilibrium, with each line the closed-form grounded catenary
    (``reference.grounded_catenary``) and the buoy's force, found by fsolve on C's position:
    catdae's C, fairlead tensions and lying lengths agree to 1e-6 relative with 1, 2 and 4
    load steps. (With load steps the contact-set rounds after the first used to ramp the load
    again from a fraction, from a configuration and set of the full load, and failed.)"""
    from scipy.optimize import fsolve

    from reference import grounded_catenary

    w = w_sub(CHAIN)
    anchors = np.array([[700.0 * math.cos(2 * math.pi * k / 3),
                         700.0 * math.sin(2 * math.pi * k / 3), -200.0] for k in range(3)])
    force = np.array([5.0e5, 0.0, 3.0e6])

    def lines(c):
        out = []
        for a in anchors:
            d = a[:2] - c[:2]
            span = float(np.hypot(*d))
            out.append((grounded_catenary(span, c[2] + 200.0, 760.0, CHAIN["EA"], w), d / span))
        return out

    def residual(c):
        f = force.copy()
        for ref, e in lines(c):
            f += [ref["H"] * e[0], ref["H"] * e[1], -ref["V"]]
        return f / 1e6

    c = fsolve(residual, [13.0, 0.0, -42.0], xtol=1e-12)
    ds = run_static(spread_toml(load_steps))
    assert ds.position.sel(node="C").values == pytest.approx(c, abs=1e-6 * 700.0)
    for k, (ref, _) in enumerate(lines(c)):
        anch = np.linalg.norm(ds.reaction.sel(node=f"a{k}").values)
        assert anch == pytest.approx(ref["anchor_tension"], rel=1e-6)
        assert float(ds.seabed_length.sel(cable=f"l{k}")) == pytest.approx(ref["lying_length"],
                                                                          rel=1e-6)


def lifted_anchor_reference(span, height, lift, L0, EA, w):
    """A chain from an anchor ``lift`` above a frictionless seabed (``height`` below the
    fairlead, ``span`` away) that touches down between them: one H, a catenary from the
    seabed up to each end (suspended lengths l_f, l_a from the rises), the rest lying,
    stretched by H/EA. H by ``brentq`` on the span. Returns H and the touchdown's horizontal
    distance from the fairlead (where the part reaching the fairlead leaves the seabed)."""
    from scipy.optimize import brentq

    def rise(H, ls):
        a = w * ls / H
        return (H / w) * (math.sqrt(1.0 + a * a) - 1.0) + w * ls * ls / (2.0 * EA)

    def run(H, ls):
        return (H / w) * math.asinh(w * ls / H) + H * ls / EA

    def parts(H):
        lf = brentq(lambda s: rise(H, s) - height, 0.0, L0, xtol=1e-13, rtol=1e-15)
        la = brentq(lambda s: rise(H, s) - lift, 0.0, L0, xtol=1e-13, rtol=1e-15)
        return lf, la

    def span_of(H):
        lf, la = parts(H)
        return (L0 - lf - la) * (1.0 + H / EA) + run(H, lf) + run(H, la) - span

    H = brentq(span_of, 1e4, 3e6, xtol=1e-9, rtol=1e-15)  # the suspended parts fit at 3 MN
    return H, run(H, parts(H)[0])


@pytest.mark.parametrize("reverse", [False, True])
@pytest.mark.parametrize("lift", [0.0, 0.1, 4.0])
def test_touchdown_is_where_the_line_leaves_the_seabed_for_the_fairlead(lift, reverse):
    """A 760 m chain, anchor 700 m out and ``lift`` above the seabed, 200 m down: the line
    touches down near the anchor too when the anchor is lifted, but ``touchdown`` is where it
    leaves the seabed for the fairlead (the higher end) with either end order: the reference
    to 1e-6 m (it used to report the touchdown near the anchor, 690.8 m, at a 0.1 m lift).
    On contact springs (node resolution) it is the last node in contact from the fairlead,
    the same node with either end order."""
    H, x_td = lifted_anchor_reference(700.0, 200.0, lift, 760.0, CHAIN["EA"], w_sub(CHAIN))
    ends = ("fairlead", "anchor") if reverse else ("anchor", "fairlead")

    def text(seabed):
        return scene(materials={"m": CHAIN}, nodes={"anchor": (700.0, 0.0, -200.0 + lift),
                                                   "fairlead": (0.0, 0.0, 0.0)},
                     supports=("anchor", "fairlead"), cables=cable("line", ends, "m", 760.0, 10),
                     extra=section("water", depth=200.0) + seabed)

    ds = run_static(text(section("seabed", z=-200.0)))
    assert float(-ds.reaction.sel(node="fairlead").values[0]) == pytest.approx(H, rel=1e-7)
    td = ds.touchdown.sel(cable="line").values
    assert td == pytest.approx([x_td, 0.0, -200.0], abs=1e-6)
    springs = run_static(text(section("seabed", z=-200.0, stiffness=3.0e6)))
    node = springs.touchdown.sel(cable="line").values
    pos = springs.position.values
    lying = pos[pos[:, 2] < -200.0]  # the nodes in contact
    assert node[0] == pytest.approx(lying[:, 0].min(), abs=1e-9)  # the one nearest the fairlead
    assert abs(node[0] - x_td) < 76.0  # within an element of the exact touchdown


def test_failed_static_names_the_node_with_the_largest_residual():
    """A static solve that cannot finish (one Newton iteration allowed per load increment)
    says where the out-of-balance force is largest: a node of the cable, its axis and size."""
    import re

    from catdae.errors import ConvergenceError
    from catdae.model.assembly import Model
    from catdae.model.mesh import build_mesh
    from catdae.solvers.static import solve_static

    case = load_case(scene(materials={"m": CHAIN}, nodes={"A": (0.0, 0.0, 0.0),
                                                         "B": (300.0, 0.0, 0.0)},
                           cables=cable("c", ("A", "B"), "m", 320.0, 6),
                           extra="[[loads]]\nname = \"p\"\nnode = \"c.3\"\n"
                                 "force = [0.0, 0.0, -2000000.0]\n"))
    mesh = build_mesh(case)
    model = Model(case, mesh, set())
    with pytest.raises(ConvergenceError) as err:
        solve_static(model, mesh.X0, max_iter=1)
    found = re.search(r"largest at node '([^']+)', ([xyz]): ([0-9.e+]+) N", str(err.value))
    assert found, str(err.value)
    assert found.group(1) in mesh.node_names and found.group(1) not in ("A", "B")
    assert float(found.group(3)) > 0.0


def test_the_summary_gives_the_seabed_and_the_note_says_statics_has_no_friction():
    """A mooring engineer reads the grounded length and the touchdown (the results held them,
    the summary did not print them), and a static step on a seabed with friction says that its
    state is the frictionless one (an anchor tension read as friction-reduced otherwise:
    tester t67)."""
    from catdae.output.summary import summary

    text = mseg_toml((399.0, 0.0, -200.0), (40.0, 0.0, -45.0))
    tree = catdae.run(load_case(text))
    ds = tree[next(iter(tree.children))].to_dataset()
    lying = float(ds.seabed_length.sel(cable="bottom"))
    td = ds.touchdown.sel(cable="mid").values
    printed = summary(tree)
    assert f"on the seabed {lying:.6g} m" in printed
    assert "touchdown at (" + ", ".join(f"{x:.6g}" for x in td) + ") m" in printed
    assert "friction" not in ds.attrs.get("note", "")
    springs = text.replace("[seabed]", "[seabed]\nstiffness = 1e6\nfriction = 0.5")
    note = run_static(springs).attrs.get("note", "")
    assert "this static state is the frictionless one" in note, note
