"""The mesh (``catdae.model.mesh``): nodes on the exact catenary, names, locating, quadrature.

The meshed nodes are compared with Irvine's elastic catenary (``tests/reference.py``, its own
root solve), the quadrature with exact integrals of polynomials, the heated mesh with the
thermal strain it stands for; names and numbering with what the docstring promises.
"""

from __future__ import annotations

import numpy as np
import pytest

import catdae
from catdae.case.names import mesh_node, split_mesh_node
from catdae.model.mesh import build_mesh

from reference import irvine_catenary_inclined_3d
from scene_toml import cable, cable_scene, point_mass, scene, static_step

G = 9.81


@pytest.mark.parametrize(("A", "B", "L0", "EA", "m", "ne"), [
    ((0.0, 0.0, 0.0), (100.0, 0.0, 0.0), 110.0, 1.0e7, 5.0, 7),  # level, deep sag
    ((1.0, 2.0, 3.0), (60.0, -40.0, -25.0), 110.0, 1.0e7, 5.0, 5),  # inclined in 3-D
    ((0.0, 0.0, 0.0), (30.0, 20.0, 15.0), 36.5, 2.0e5, 2.0, 4),  # taut, soft
])
def test_nodes_lie_on_the_exact_elastic_catenary(A, B, L0, EA, m, ne):
    case = catdae.load_case(cable_scene(A=A, B=B, L0=L0, EA=EA, mass=m, elements=ne,
                                        steps=static_step()))
    mesh = build_mesh(case)
    ref = irvine_catenary_inclined_3d(A, B, L0, EA, m * G)
    s = np.linspace(0.0, L0, ne + 1)
    order = [mesh.node_index(n) for n in ["A", *(f"c.{k}" for k in range(1, ne)), "B"]]
    np.testing.assert_allclose(mesh.X0[order], ref["x"](s), rtol=0, atol=1e-9 * L0)
    np.testing.assert_allclose(mesh.s_node[order], s, rtol=1e-14)
    np.testing.assert_allclose(mesh.L0, L0 / ne, rtol=1e-15)
    assert (mesh.EA == EA).all() and (mesh.m == m).all()
    np.testing.assert_allclose(mesh.w, m * G, rtol=1e-15)


def two_cables():
    """Cables a (A -> N, 3 elements) and b (B -> N, 2 elements) meeting at N, and a node S on no
    cable; N is declared before B."""
    return catdae.load_case(scene(
        materials={"m": {"EA": 1.0e6, "mass": 1.0}},
        nodes={"A": (0.0, 0.0, 0.0), "N": (6.0, 0.0, -2.0), "B": (12.0, 1.0, 0.0),
               "S": (0.0, 5.0, 0.0)},
        supports=("A", "B", "S"),
        cables=[cable("a", "AN", "m", 6.6, 3), cable("b", "BN", "m", 6.4, 2)],
        steps=static_step()))


def test_names_and_numbering():
    mesh = build_mesh(two_cables())
    # cable by cable, each from its first end; a shared node with the first cable; nodes on no
    # cable last
    assert mesh.node_names == ("A", "a.1", "a.2", "N", "B", "b.1", "S")
    assert mesh.element_names == ("a.1", "a.2", "a.3", "b.1", "b.2")
    assert mesh.cable_names == ("a", "b")
    np.testing.assert_array_equal(mesh.conn, [[0, 1], [1, 2], [2, 3], [4, 5], [5, 3]])
    np.testing.assert_array_equal(mesh.cable_of_element, [0, 0, 0, 1, 1])
    np.testing.assert_array_equal(mesh.cable_of_node, [0, 0, 0, 0, 1, 1, -1])
    np.testing.assert_allclose(mesh.s_node[:6], [0.0, 2.2, 4.4, 6.6, 0.0, 3.2])
    assert np.isnan(mesh.s_node[6])
    np.testing.assert_allclose(mesh.s_start, [0.0, 2.2, 4.4, 0.0, 3.2])
    for k, name in enumerate(mesh.node_names):
        assert mesh.node_index(name) == k
    # an interior node's name parses back to its cable and its place along it
    for i in (1, 2, 5):
        cable_name, k = split_mesh_node(mesh.node_names[i])
        assert cable_name == mesh.cable_names[mesh.cable_of_node[i]]
        le = {"a": 2.2, "b": 3.2}[cable_name]
        assert int(k) * le == pytest.approx(mesh.s_node[i], rel=1e-14)
        assert mesh_node(cable_name, int(k)) == mesh.node_names[i]
    # element k of a cable joins its nodes k-1 and k (named ends at the two extremes)
    for e, name in enumerate(mesh.element_names):
        c, k = name.split(".")
        ends = {"a": ("A", "N"), "b": ("B", "N")}[c]
        ne = {"a": 3, "b": 2}[c]
        chain = [ends[0], *(f"{c}.{j}" for j in range(1, ne)), ends[1]]
        assert [mesh.node_names[i] for i in mesh.conn[e]] == chain[int(k) - 1:int(k) + 1]


def test_locate_on_nodes_and_inside_elements():
    mesh = build_mesh(two_cables())
    le = 2.2
    assert mesh.locate("a", 0.0) == ("node", mesh.node_index("A"), 0.0)
    assert mesh.locate("a", 2 * le) == ("node", mesh.node_index("a.2"), 0.0)
    assert mesh.locate("a", 6.6) == ("node", mesh.node_index("N"), 0.0)
    kind, e, s = mesh.locate("a", 5.0)
    assert (kind, mesh.element_names[e]) == ("element", "a.3") and s == pytest.approx(5.0 - 4.4)
    kind, e, s = mesh.locate("b", 1.0)
    assert (kind, mesh.element_names[e]) == ("element", "b.1") and s == pytest.approx(1.0)
    # within 1e-9 of an element length of a node: on the node
    assert mesh.locate("a", le * (1 + 1e-11))[0] == "node"


def test_gauss_rule_integrates_polynomials_exactly():
    text = cable_scene(B=(10.0, 0.0, 0.0), L0=10.5, EA=1.0e6, mass=1.0, elements=3,
                       gauss_points=4, steps=static_step())
    mesh = build_mesh(catdae.load_case(text))
    s, w = mesh.gauss()
    np.testing.assert_allclose(w.sum(axis=1), 1.0, rtol=1e-15)
    le = mesh.L0[:, None]
    for p in range(8):  # 4 points: exact to degree 7; ∫_0^l s^p ds / l = l^p / (p + 1)
        np.testing.assert_allclose((w * s**p).sum(axis=1), (le[:, 0] ** p) / (p + 1),
                                   rtol=1e-13)
    # coverage of a part of the cable: the weights add up to its length, split at the ends
    el, s_loc, ds = mesh.coverage_points("c", 1.0, 8.0)
    assert ds.sum() == pytest.approx(7.0, rel=1e-14)
    assert set(el) == {0, 1, 2} and (s_loc >= 0).all() and (s_loc <= mesh.L0[el]).all()
    # ∫_1^8 s ds of the global arc length s = s_start + s_local
    assert (ds * (mesh.s_start[el] + s_loc)).sum() == pytest.approx((64.0 - 1.0) / 2, rel=1e-13)


def test_heated_mesh_carries_the_thermal_strain():
    text = cable_scene(B=(10.0, 0.0, 0.0), L0=10.5, EA=1.0e6, mass=1.0, elements=3,
                       steps=static_step()).replace("mass = 1.0\n",
                                                    "mass = 1.0\nthermal_expansion = 1e-3\n")
    case = catdae.load_case(text)
    mesh = build_mesh(case)
    hot = mesh.heated(case, 20.0)
    f = 1.0 + 1e-3 * 20.0
    np.testing.assert_allclose(hot.L0, mesh.L0 * f, rtol=1e-15)
    np.testing.assert_allclose(hot.EA, mesh.EA * f, rtol=1e-15)
    # the weight and mass of the whole cable are unchanged
    np.testing.assert_allclose((hot.w * hot.L0).sum(), (mesh.w * mesh.L0).sum(), rtol=1e-15)
    np.testing.assert_allclose((hot.m * hot.L0).sum(), (mesh.m * mesh.L0).sum(), rtol=1e-15)
    # a material point keeps its place: s at the reference temperature, located in the heated
    kind, e, s = hot.locate("c", 5.0)
    assert kind == "element" and e == 1 and s == pytest.approx((5.0 - 3.5) * f)
    assert mesh.heated(case, 0.0) is mesh


def test_weightless_cable_is_meshed_under_its_point_load():
    # weightless and slack: no catenary of its own; meshed under its point mass, which pulls
    # the cable into two straight pieces meeting below the mass
    text = cable_scene(B=(8.0, 0.0, 0.0), L0=10.0, EA=1.0e9, mass=1.0, weight=0.0, elements=4,
                       extra=point_mass("pm", 20.0, cable="c", s=5.0), steps=static_step())
    mesh = build_mesh(catdae.load_case(text))
    X = {n: mesh.X0[mesh.node_index(n)] for n in ("A", "c.1", "c.2", "c.3", "B")}
    # c.2 (the mass, at s = 5) at depth d: each half stretched to l = 5 (1 + T/EA) by the
    # tension T = m g l / (2 d) of the two straight halves, d = sqrt(l² - 4²) (fixed point)
    d, l_half = 3.0, 5.0
    for _ in range(50):
        l_half = 5.0 * (1.0 + 20.0 * G * l_half / (2.0 * d) / 1.0e9)
        d = np.sqrt(l_half**2 - 16.0)
    np.testing.assert_allclose(X["c.2"], [4.0, 0.0, -d], rtol=0, atol=1e-9)
    # straight on either side: c.1 halfway from A to c.2
    np.testing.assert_allclose(X["c.1"], 0.5 * (X["A"] + X["c.2"]), atol=1e-6)
    np.testing.assert_allclose(X["c.3"], 0.5 * (X["B"] + X["c.2"]), atol=1e-6)
