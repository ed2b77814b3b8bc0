"""A line resting on a rigid, frictionless seabed in a current (docs/case-format.md, "Seabed";
docs/theory.md §17.4): the drag across the resting part bends it in plan, the drag along it
changes its tension, and the static nodes converge to the continuous line.

Independent reference: ``reference_current.grounded_line_in_current``, the continuous line's
equilibrium equations integrated from the anchor and shot onto the fairlead (scipy; no catdae
code). Scene: MoorDyn's studless chain in 200 m of water with its anchor 650 m out (about 480 m
resting), uniform currents of 0.5 m/s across the chain, along it either way, and oblique.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import catdae

from reference import grounded_catenary
from reference_current import grounded_line_in_current
from scene_toml import cable, scene, section, step

EA, MASS, D, RHO, G, CD, CDA = 1.674e9, 390.0, 0.252, 1025.0, 9.81, 1.37, 0.64
W = (MASS - RHO * math.pi * D**2 / 4.0) * G  # N/m, submerged weight
ANCHOR, FAIRLEAD, LENGTH = (650.0, 0.0, -200.0), (0.0, 0.0, 0.0), 760.0


def chain(current, elements: int) -> str:
    return scene(materials={"chain": {"EA": EA, "mass": MASS, "diameter": D, "drag_normal": CD,
                                      "drag_axial": CDA}},
                 nodes={"anchor": ANCHOR, "fairlead": FAIRLEAD}, supports=("anchor", "fairlead"),
                 cables=cable("chain", ("anchor", "fairlead"), "chain", LENGTH, elements),
                 extra=section("water", density=RHO, surface=0.0, depth=200.0,
                               current=list(current)) + section("seabed"),
                 steps=step("static", "st"))


def reference(current) -> dict:
    still = grounded_catenary(650.0, 200.0, LENGTH, EA, W)
    return grounded_line_in_current(ANCHOR, FAIRLEAD, LENGTH, EA, W, RHO, D, CD, CDA, current,
                                    (still["H"], still["lying_length"]))


def errors(current, elements: int, ref: dict) -> dict:
    """Errors of the static step against the reference: reactions (relative to the fairlead
    force), lying length and touchdown point (m)."""
    ds = catdae.run(catdae.load_case(chain(current, elements)), progress=False)["st"].ds
    scale = float(np.linalg.norm(ref["fairlead_reaction"]))
    fair = ds.reaction.sel(node="fairlead").values - ref["fairlead_reaction"]
    anch = ds.reaction.sel(node="anchor").values - ref["anchor_reaction"]
    return {"force": float(max(np.abs(fair).max(), np.abs(anch).max())) / scale,
            "lying": abs(float(ds.seabed_length.values[0]) - ref["lying_length"]),
            "touchdown": float(np.abs(ds.touchdown.sel(cable="chain").values
                                      - ref["touchdown"]).max())}


def test_current_across_a_resting_chain_converges_at_second_order():
    # the resting part bends in plan under the drag across it (the anchor holds 14.7 kN across
    # the chord); end forces 2.3e-5, 5.8e-6, 1.5e-6 of the fairlead force at 10, 20, 40
    ref = reference((0.0, 0.5, 0.0))
    assert abs(ref["anchor_reaction"][1]) > 1.0e4 and ref["lying_length"] > 400.0
    e = [errors((0.0, 0.5, 0.0), n, ref) for n in (10, 20, 40)]
    f = [x["force"] for x in e]
    assert f[0] / f[1] > 3.5 and f[1] / f[2] > 3.5, f
    assert f[2] < 2.5e-6
    assert e[2]["lying"] < 1e-3 and e[2]["touchdown"] < 0.01


@pytest.mark.parametrize(("current", "elements"), [
    ((-0.5, 0.0, 0.0), 40), ((0.5, 0.0, 0.0), 40), ((0.3, -0.4, 0.0), 40),
    ((0.5, 0.0, 0.0), 80),  # the touchdown crosses a node as the current is raised
])
def test_currents_along_and_oblique_to_a_resting_chain(current, elements):
    # the drag along the resting part changes the anchor force by 5-13 % against still water;
    # the static step is within 1e-5 of the continuous line (measured 3e-6 to 9.5e-6)
    ref = reference(current)
    still = grounded_catenary(650.0, 200.0, LENGTH, EA, W)
    assert abs(np.linalg.norm(ref["anchor_reaction"]) / still["H"] - 1.0) > 0.03
    e = errors(current, elements, ref)
    assert e["force"] < 1.2e-5, e
    assert e["lying"] < 5e-3 and e["touchdown"] < 5e-3, e


def test_a_current_that_slackens_the_resting_part_is_said_plainly():
    # 3 m/s towards the anchor: the axial drag on the resting part (2.3 kN/m over about 480 m)
    # far exceeds the still-water anchor tension (300 kN), so the resting part's tension would
    # reach zero before the anchor, which a frictionless seabed cannot hold
    still = grounded_catenary(650.0, 200.0, LENGTH, EA, W)
    f_axial = 0.5 * RHO * CDA * math.pi * D * 3.0**2
    assert f_axial * still["lying_length"] > 3.0 * still["H"]
    with pytest.raises(catdae.errors.ConvergenceError, match="rests slack on the rigid seabed"):
        catdae.run(catdae.load_case(chain((3.0, 0.0, 0.0), 20)), progress=False)
