"""Statics on a rigid, frictionless seabed (docs/theory.md §17): a mooring line from an anchor
on the seabed to a fairlead is the closed-form grounded elastic catenary at any mesh.

Independent references: ``reference.grounded_catenary`` (nested root solves from the textbook
relations, no catdae code) and MoorPy's ``Catenary.catenary`` (PyPI ``moorpy``, the
quasi-static line of FAST v7). Scenes: MoorDyn's studless chain against OrcaFlex, 200 m and
600 m of water (tests/data/moordyn), with the submerged weight given as the material weight.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import catdae
from catdae.case import load_case

from reference import grounded_catenary
from scene_toml import cable, load, scene, section, static_step

EA = 1.674e9
MASS = 390.0
DIAMETER = 0.252
RHO = 1025.0
G = 9.81
W_SUB = (MASS - RHO * math.pi * DIAMETER**2 / 4.0) * G  # N/m, submerged weight
CHAINS = {200: (700.0, 760.0), 600: (1500.0, 1700.0)}  # depth: (anchor x, length)


def chain_toml(depth: int, elements: int, *, reverse: bool = False, fairlead=(0.0, 0.0, 0.0),
               steps: str = "", free_fairlead: bool = False, extra: str = "") -> str:
    """The studless chain from its anchor on the seabed at ``depth`` to the fairlead (pinned
    unless ``free_fairlead``); ``reverse``: the cable runs from the fairlead to the anchor."""
    x, length = CHAINS[depth]
    ends = ("fairlead", "anchor") if reverse else ("anchor", "fairlead")
    return scene(head={"title": f"studless chain, {depth} m"},
                 materials={"chain": {"EA": EA, "mass": MASS, "weight": W_SUB}},
                 nodes={"anchor": (x, 0.0, -float(depth)), "fairlead": fairlead},
                 supports=("anchor",) if free_fairlead else ("anchor", "fairlead"),
                 cables=cable("chain", ends, "chain", length, elements),
                 extra=extra + section("seabed", z=-float(depth)), steps=steps)


def run_static(text: str):
    tree = catdae.run(load_case(text), progress=False)
    return tree[next(iter(tree.children))].to_dataset()


@pytest.mark.parametrize("depth", [200, 600])
@pytest.mark.parametrize("elements", [4, 10, 40])
@pytest.mark.parametrize("reverse", [False, True])
def test_grounded_chain_is_the_closed_form(depth, elements, reverse):
    """Fairlead and anchor forces, lying length and touchdown point equal the closed-form
    grounded catenary to 1e-6 relative (they agree to ~1e-12), at 4, 10 and 40 elements and
    with the cable written either way round; every node lies on the closed-form curve."""
    x, length = CHAINS[depth]
    ref = grounded_catenary(x, float(depth), length, EA, W_SUB)
    ds = run_static(chain_toml(depth, elements, reverse=reverse))
    fair = ds.reaction.sel(node="fairlead").values  # force of the support on the cable
    anch = ds.reaction.sel(node="anchor").values
    H, V = ref["H"], ref["V"]
    assert fair == pytest.approx([-H, 0.0, V], rel=1e-6, abs=1e-9 * H)
    assert anch == pytest.approx([H, 0.0, 0.0], rel=1e-6, abs=1e-9 * H)
    assert float(ds.seabed_length.item()) == pytest.approx(ref["lying_length"], rel=1e-6)
    td = ds.touchdown.sel(cable="chain").values
    assert td == pytest.approx([x - ref["touchdown_x"], 0.0, -depth], rel=1e-6, abs=1e-6)
    # fairlead tension from the element end tensions too
    ends = ds.cable_end_tension.sel(cable="chain").values
    t_fair = ends[0] if reverse else ends[1]
    assert t_fair == pytest.approx(ref["fairlead_tension"], rel=1e-6)
    # every node on the curve: suspended nodes satisfy the catenary through the touchdown
    pos = ds.position.values
    horiz = x - pos[:, 0]  # distance from the anchor
    lying = horiz <= ref["touchdown_x"]
    assert np.allclose(pos[lying, 2], -depth, atol=1e-9 * depth)
    xs = horiz[~lying] - ref["touchdown_x"]  # from the touchdown point
    zs = pos[~lying, 2] + depth
    # inextensible shape plus stretch is not closed in x(z) form: check slope-free invariant
    # z(x) of the elastic catenary through the touchdown, by the parameter l (arc from TD)
    for xi, zi in zip(xs, zs, strict=True):
        l = _arc_from_x(xi, H, W_SUB)
        z_ref = (H / W_SUB) * (math.sqrt(1 + (W_SUB * l / H) ** 2) - 1) + W_SUB * l * l / (2 * EA)
        assert zi == pytest.approx(z_ref, rel=1e-7, abs=1e-7)


def _arc_from_x(x, H, w):
    """Unstrained arc length from the touchdown point at horizontal distance x (elastic)."""
    from scipy.optimize import brentq

    return brentq(lambda l: (H / w) * math.asinh(w * l / H) + H * l / EA - x, 0.0, 10 * x + 1.0,
                  xtol=1e-14, rtol=1e-15)


@pytest.mark.parametrize("depth", [200, 600])
def test_grounded_chain_matches_moorpy(depth):
    """MoorPy's catenary (FAST v7's closed form, CB = 0: frictionless seabed) as a second,
    independent reference, at 10 elements."""
    catenary = pytest.importorskip("moorpy.Catenary").catenary
    x, length = CHAINS[depth]
    fa_h, fa_v, fb_h, fb_v, info = catenary(x, float(depth), length, EA, W_SUB, CB=0.0,
                                            Tol=1e-12, MaxIter=300)
    ds = run_static(chain_toml(depth, 10))
    fair = ds.reaction.sel(node="fairlead").values
    anch = ds.reaction.sel(node="anchor").values
    # MoorPy: end A (anchor) forces (fa_h, fa_v), end B (fairlead) (fb_h, fb_v), on the ends
    assert abs(fair[0]) == pytest.approx(abs(fb_h), rel=1e-6)
    assert fair[2] == pytest.approx(-fb_v, rel=1e-6)
    assert abs(anch[0]) == pytest.approx(fa_h, rel=1e-6)
    assert float(ds.seabed_length.item()) == pytest.approx(info["LBot"], rel=1e-6)


@pytest.mark.parametrize("depth, fair_kN, anchor_kN", [(200, 2065.4, 1402.2),
                                                       (600, 5232.6, 3244.2)])
def test_chain_static_tensions_published(depth, fair_kN, anchor_kN):
    """The quasi-static codes' tensions that MoorDyn's test compares with (its tolerance is
    10 %): catdae's exact grounded statics is within 0.5 % of them."""
    ds = run_static(chain_toml(depth, 20))
    fair = np.linalg.norm(ds.reaction.sel(node="fairlead").values) / 1e3
    anch = np.linalg.norm(ds.reaction.sel(node="anchor").values) / 1e3
    assert fair == pytest.approx(fair_kN, rel=5e-3)
    assert anch == pytest.approx(anchor_kN, rel=5e-3)


@pytest.mark.parametrize("elements", [4, 10, 40])
def test_free_fairlead_finds_the_grounded_equilibrium(elements):
    """The fairlead is free and pulled by the closed form's fairlead force, starting 20 m
    too close to the anchor and 30 m too low: Newton and the contact set (nodes joining and
    leaving the seabed) bring it to the closed form's fairlead position to 1e-6 relative.
    (A dead load on a free fairlead is a hard start: from some starts, e.g. 10 m too far out,
    the 10-element line does not converge; docs/theory.md §17.4.)"""
    x, length = CHAINS[200]
    ref = grounded_catenary(x, 200.0, length, EA, W_SUB)
    text = chain_toml(200, elements, fairlead=(20.0, 0.0, -30.0), free_fairlead=True,
                      extra=load("pull", [-ref["H"], 0.0, ref["V"]], node="fairlead"))
    ds = run_static(text)
    fair = ds.position.sel(node="fairlead").values
    assert fair == pytest.approx([0.0, 0.0, 0.0], abs=1e-6 * x)
    assert float(ds.seabed_length.item()) == pytest.approx(ref["lying_length"], rel=1e-6)
    assert int(ds.attrs["iterations"]) > 0


def laid_chain(stiffness=None) -> str:
    """A 100 m chain laid straight on the seabed at z = 0, pinned at A, its end B free; a rigid
    seabed without ``stiffness``, contact springs with it."""
    return scene(materials={"chain": {"EA": 7.5e8, "mass": 110.0, "diameter": 0.17}},
                 nodes={"A": (0.0, 0.0, 0.0), "B": (-100.0, 0.0, 0.0)}, supports=("A",),
                 cables=cable("chain", ("A", "B"), "chain", 100.0, 20),
                 extra=section("seabed", z=0.0, stiffness=stiffness), steps=static_step("rest"))


def test_a_laid_chain_with_a_free_end_folds_on_contact_springs_and_says_so():
    """A chain laid straight on the seabed, pinned at one end, free at the other, has no
    tension: on the rigid seabed it stays straight (its free end 100 m away, tension 0), but the
    contact springs act at the nodes only, and each tension-free element hangs into the seabed
    as a loop: a tester found every node folded onto the pinned end with no word of it. The
    static step's note now says the cable hangs below its nodes, and what to use instead."""
    rigid = catdae.run(load_case(laid_chain()))["rest"].ds
    assert float(rigid.position.sel(node="B", axis="x")) == pytest.approx(-100.0, abs=1e-6)
    assert float(np.abs(rigid.tension).max()) < 1e-6 * 110.0 * 9.81 * 100.0
    assert "note" not in rigid.attrs
    springs = catdae.run(load_case(laid_chain(1.0e6)))["rest"].ds
    low = float(springs.lowest_point_elevation.sel(cable="chain"))
    assert low < -1.0  # the fold: 5 m elements hanging as loops
    note = springs.attrs["note"]
    assert "cable 'chain' hangs to z = " in note and "act at the nodes only" in note
    assert "use the rigid seabed" in note


def _spread_toml(ne: int, force: float) -> str:
    """Three 850 m chains at 120 degrees, from anchors 800 m out on a 200 m deep seabed, to a
    body node held in z only, pushed along x by ``force``."""
    angles = np.radians([0.0, 120.0, 240.0])
    anchors = {f"a{i}": (800 * math.cos(a), 800 * math.sin(a), -200.0)
               for i, a in enumerate(angles)}
    return scene(materials={"chain": {"EA": 7.5e8, "mass": 110.0, "diameter": 0.17}},
                 nodes={"body": (0.0, 0.0, -20.0), **anchors},
                 supports=('body = ["z"]', *anchors),
                 cables=[cable(f"L{i}", (a, "body"), "chain", 850.0, ne)
                         for i, a in enumerate(anchors)],
                 extra=section("water", density=1025.0, depth=200.0) + "[seabed]\n"
                 + load("wind", [force, 0.0, 0.0], node="body"), steps=static_step("s"))


def test_a_spread_mooring_pushed_far_matches_moorpy():
    """Three 850 m chains at 120 degrees to a body held in z only, pushed by 1.0 MN: a tester
    found the static step failing at 1.0-1.2 MN (10 elements) while 0.8 and 1.3 MN converged:
    the touchdowns cross elements as the body moves, which Newton at one contact set cannot
    follow; the loads are now raised in stages. The body's offset is MoorPy's System's."""
    mp = pytest.importorskip("moorpy")
    ds = catdae.run(load_case(_spread_toml(10, 1.0e6)))["s"].ds
    off = ds.position.sel(node="body").values
    ms = mp.System(depth=200.0, rho=1025.0, g=9.81)
    w = (110.0 - 1025.0 * math.pi * 0.17**2 / 4) * 9.81
    ms.lineTypes["chain"] = dict(name="chain", d_vol=0.17, m=110.0, EA=7.5e8, w=w,
                                 material="c", d_nom=0.17, MBL=1e9, Cd=1, Ca=1, CdAx=0, CaAx=0,
                                 cost=0)
    ms.addPoint(0, [0, 0, -20.0], DOFs=[0, 1])
    for a in (0.0, 120.0, 240.0):
        ms.addPoint(1, [800 * math.cos(math.radians(a)), 800 * math.sin(math.radians(a)),
                        -200.0])
        ms.addLine(850.0, "chain", pointA=len(ms.pointList), pointB=1)
    ms.initialize()
    ms.pointList[0].fExt = np.array([1.0e6, 0.0, 0.0])
    ms.solveEquilibrium(tol=1e-7, maxIter=5000)
    np.testing.assert_allclose(off[:2], ms.pointList[0].r[:2], rtol=0, atol=1e-6)
    assert off[0] > 20.0  # pushed far: the chain towards the load lies on the seabed longer
