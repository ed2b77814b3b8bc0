"""Gauss points over part of a cable (Mesh.coverage_points): the rule is split at the ends of
the coverage, so each overlap gets a full Gauss-Legendre rule of its element's order."""

from __future__ import annotations

import numpy as np
import pytest

from catdae.case import load_case
from catdae.model.mesh import build_mesh

from scene_toml import cable_scene, static_step


@pytest.mark.parametrize(("a", "b"), [(13.7, 61.2), (0.0, 102.0), (12.75, 25.5), (50.0, 50.5)])
def test_coverage_points_integrate_polynomials_exactly(a, b):
    # 8 elements of 12.75 m, 3 points each: exact for degree <= 5 on every overlap
    mesh = build_mesh(load_case(cable_scene(B=(100.0, 0.0, 0.0), L0=102.0, EA=1e8, mass=1.0,
                                            elements=8, gauss_points=3, steps=static_step())))
    e, s_loc, ds = mesh.coverage_points("c", a, b)
    s = mesh.s_start[e] + s_loc
    assert np.all((s > a) & (s < b))
    assert np.all((s_loc > 0) & (s_loc < mesh.L0[e]))  # inside its element, never on a node
    for p in range(6):
        assert ds @ s**p == pytest.approx((b ** (p + 1) - a ** (p + 1)) / (p + 1), rel=1e-13)
    # overlapped elements only, each with its full rule
    first, last = int(a // 12.75), int(np.ceil(b / 12.75)) - 1
    assert sorted(set(e.tolist())) == list(range(first, last + 1))
    assert np.all(np.bincount(e)[first:] == 3)
