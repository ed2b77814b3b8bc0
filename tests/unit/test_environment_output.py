"""The water surface and the seabed in the results, the profile figure and the ParaView export
(catdae.output.environment; docs/case-format.md, "Water and air" and "Seabed").

Independent references: the Airy elevation η = H/2 cos(k (x cos β + y sin β) - ω t + φ) with k
from the dispersion relation ω² = g k tanh(k h) solved here by bisection, the case's heights,
and the node positions of the results for the extent of the planes.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest
from scipy.optimize import brentq

import catdae
from catdae.cli import main
from catdae.output import plot

from scene_toml import scene, step

H, T, BETA, PHI, DEPTH, G = 1.0, 4.0, 30.0, 40.0, 20.0, 9.81


def _scene(gravity=None, waves: bool = True) -> str:
    """An anchor on the seabed in 20 m of water, a fairlead 2 m above the surface; with
    ``gravity`` "x" gravity acts along -x (heights are then x, the scene turned alike); with a
    rotation matrix, the scene and its gravity turned by it."""
    Q = np.eye(3) if gravity is None else np.asarray(gravity, float) if not isinstance(
        gravity, str) else np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0],
                                     [-1.0, 0.0, 0.0]])  # z -> x
    wave = (f'waves = {{ kind = "airy", height = {H}, period = {T}, heading = {BETA}, '
            f"phase = {PHI} }}\n" if waves else "")
    steps = step("static", "s") + (step("transient", "t", duration=0.5, output_interval=0.25,
                                        rtol=1e-4, atol=1e-6) if waves else "")
    return scene(nodes={"A": Q @ np.array([0.0, 0.0, -DEPTH]), "B": Q @ np.array([30.0, 5.0,
                                                                                   2.0])},
                 cables='[[cables]]\nname = "c"\nends = ["A", "B"]\nmaterial = "chain"\n'
                        "length = 40.0\nelements = 4\n",
                 materials={"chain": {"EA": 1.0e8, "mass": 20.0, "diameter": 0.05}},
                 head={"gravity": list(Q @ np.array([0.0, 0.0, -G]))},
                 extra=f"[water]\nsurface = 0.0\ndepth = {DEPTH}\n{wave}"
                       "[seabed]\nstiffness = 1.0e5\n", steps=steps)


def wave_number() -> float:
    w = 2.0 * math.pi / T
    return brentq(lambda k: G * k * math.tanh(k * DEPTH) - w * w, 1e-6, 10.0, xtol=1e-15)


def wavelength() -> float:
    return 2.0 * math.pi / wave_number()


def airy(x, y, t):
    w, k = 2.0 * math.pi / T, wave_number()
    b = math.radians(BETA)
    return 0.5 * H * np.cos(k * (x * math.cos(b) + y * math.sin(b)) - w * t + math.radians(PHI))


@pytest.fixture(scope="module")
def waves(tmp_path_factory):
    folder = tmp_path_factory.mktemp("waves")
    (folder / "w.toml").write_text(_scene())
    out = folder / "w.nc"
    assert main(["run", str(folder / "w.toml"), "-o", str(out), "--no-progress"]) == 0
    return folder, catdae.read_results(out)


def test_groups_carry_the_still_water_level_and_the_seabed(waves):
    _, tree = waves
    for name in ("s", "t"):
        a = tree[name].to_dataset().attrs
        assert a["water_surface"] == 0.0 and a["seabed_z"] == -DEPTH
        assert a["water_depth"] == DEPTH
        np.testing.assert_array_equal(a["up"], [0.0, 0.0, 1.0])


def test_surface_elevation_at_the_nodes_is_the_airy_wave(waves):
    ds = waves[1]["t"].to_dataset()
    x = ds.position.sel(axis="x").transpose("time", "node").values
    y = ds.position.sel(axis="y").transpose("time", "node").values
    want = airy(x, y, ds.time.values[:, None])
    got = ds.surface_elevation.transpose("time", "node").values
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_profile_draws_the_seabed_the_still_level_and_the_surface(waves):
    _, tree = waves
    for name in ("s", "t"):
        ax = plot.profile(tree[name]).axes[0]
        lines = {str(ln.get_gid()).split("|")[0]: ln for ln in ax.get_lines()}
        assert set(lines.get("seabed").get_ydata()) == {-DEPTH}
        assert set(lines.get("still water").get_ydata()) == {0.0}
    ds = tree["t"].to_dataset()
    ax = plot.profile(tree["t"], times=[0.5]).axes[0]
    (surf,) = [ln for ln in ax.get_lines() if str(ln.get_gid()).startswith("surface|")]
    pos = ds.position.sel(time=0.5)
    np.testing.assert_allclose(surf.get_ydata(), airy(pos.sel(axis="x").values,
                                                      pos.sel(axis="y").values, 0.5)
                               [[list(ds.node.values).index(n) for n in
                                 plot.cable_paths(ds)["c"]]], atol=1e-12)


# gravity along +x, the upright scene's x, y, z turned to y, -z, -x: the gravity frame of the
# turned scene (its horizontal e1 = y, e2 = -z, up = -x) is the upright scene's x, y, z
G_PLUS_X = np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def _lines(fig):
    """{(panel, gid): (xdata, ydata)} of a figure's data lines."""
    return {(k, str(ln.get_gid())): (np.asarray(ln.get_xdata(), float),
                                     np.asarray(ln.get_ydata(), float))
            for k, ax in enumerate(fig.axes[:2]) for ln in ax.get_lines()}


def test_profile_under_gravity_along_x_is_the_upright_drawing(waves):
    # the turned scene's figure draws in its gravity frame: every line (the cable at each time
    # in elevation and plan, the seabed, the still-water level, the wave surface above the
    # nodes) has the upright figure's data, to round-off; only the axis labels differ
    _, upright = waves
    turned = catdae.run(catdae.load_case(_scene(gravity=G_PLUS_X)), progress=False)
    np.testing.assert_array_equal(turned["s"].to_dataset().attrs["up"], [-1.0, 0.0, 0.0])
    for name, times in (("s", None), ("t", [0.0, 0.25, 0.5])):
        a = _lines(plot.profile(upright[name], times=times))
        fig = plot.profile(turned[name], times=times)
        b = _lines(fig)
        assert a.keys() == b.keys()
        assert {"seabed", "still water"} <= {g for _, g in a}
        for key, (xa, ya) in a.items():
            np.testing.assert_allclose(b[key][0], xa, rtol=0, atol=1e-9 * 40.0, err_msg=key)
            np.testing.assert_allclose(b[key][1], ya, rtol=0, atol=1e-9 * 40.0, err_msg=key)
        assert fig.axes[0].get_ylabel().endswith("height along up = (-1, 0, 0) [m]")
        assert "along e1 = (0, 1, 0)" in fig.axes[1].get_xlabel()
    assert len([k for k in a if k[1].startswith("surface|")]) == 3


def test_profile_under_an_oblique_gravity_draws_heights_along_up():
    # closed form: the elevation's vertical of every node is its position along up = -g, the
    # seabed and the still-water level are the lines at -20 m and 0 m; the plan keeps the
    # horizontal distances (the turn about up is the frame's own choice)
    Q = TURN_OBLIQUE
    tree = catdae.run(catdae.load_case(_scene(gravity=Q, waves=False)), progress=False)
    ds = tree["s"].to_dataset()
    up = Q @ np.array([0.0, 0.0, 1.0])
    np.testing.assert_allclose(ds.attrs["up"], up, rtol=0, atol=1e-15)
    lines = _lines(plot.profile(tree["s"]))
    pos = ds.position.sel(node=plot.cable_paths(ds)["c"]).transpose("node", "axis").values
    xe, ye = lines[(0, "c|None")]
    np.testing.assert_allclose(ye, pos @ up, rtol=0, atol=1e-12 * 40.0)
    xp, yp = lines[(1, "c|None")]
    np.testing.assert_allclose(xp, xe, rtol=0, atol=0)
    flat = pos - np.outer(pos @ up, up)  # horizontal parts: distances kept in the plan
    d_plan = np.hypot(xp[:, None] - xp, yp[:, None] - yp)
    np.testing.assert_allclose(d_plan, np.linalg.norm(flat[:, None] - flat, axis=2), rtol=0,
                               atol=1e-12 * 40.0)
    assert set(lines[(0, "seabed")][1]) == {-DEPTH}
    assert set(lines[(0, "still water")][1]) == {0.0}


TURN_OBLIQUE = np.array([[0.36, 0.48, -0.8], [-0.8, 0.6, 0.0], [0.48, 0.64, 0.6]])


def test_a_gravity_vector_alone_puts_up_on_the_groups():
    # no water, no seabed: the groups still carry up, and the profile draws heights along it
    text = _scene(gravity=G_PLUS_X, waves=False).split("[water]")[0] + step("static", "s")
    ds = catdae.run(catdae.load_case(text), progress=False)["s"].to_dataset()
    np.testing.assert_array_equal(ds.attrs["up"], [-1.0, 0.0, 0.0])
    assert "seabed_z" not in ds.attrs and "water_surface" not in ds.attrs
    (_, ye), = [v for k, v in _lines(plot.profile(ds)).items() if k == (0, "c|None")]
    np.testing.assert_allclose(ye, -ds.position.sel(node=plot.cable_paths(ds)["c"],
                                                    axis="x").values, rtol=0, atol=0)


def _parts(pvd):
    """{part: [(time, file), ...]} of a collection, read with the XML parser."""
    out: dict[int, list] = {}
    for d in ET.parse(pvd).getroot().findall("./Collection/DataSet"):
        out.setdefault(int(d.get("part")), []).append((float(d.get("timestep")), d.get("file")))
    return out


def _covers(points_xy, ds_xy):
    lo, hi = points_xy.min(axis=0), points_xy.max(axis=0)
    assert np.all(ds_xy >= lo) and np.all(ds_xy <= hi)


def test_vtk_export_has_the_seabed_and_the_wave_surface_of_each_time(waves, tmp_path):
    folder, tree = waves
    assert main(["export", str(folder / "w.nc"), "--vtk", str(tmp_path)]) == 0
    ds = tree["t"].to_dataset()
    parts = _parts(tmp_path / "t.pvd")
    assert sorted(parts) == [0, 1, 2]
    for p in parts.values():
        assert [t for t, _ in p] == list(ds.time.values)
    nodes_xy = ds.position.sel(axis=["x", "y"]).values.reshape(-1, 2)
    (bed,) = {f for _, f in parts[1]}  # one file at every time
    m = meshio.read(tmp_path / bed)
    assert m.cells[0].type == "quad" and len(m.points) == 4
    np.testing.assert_array_equal(m.points[:, 2], -DEPTH)
    _covers(m.points[:, :2], nodes_xy)
    files = [f for _, f in parts[2]]
    assert len(set(files)) == ds.sizes["time"]
    for k, f in enumerate(files):
        m = meshio.read(tmp_path / f)
        assert m.cells[0].type == "quad"
        for a in (0, 1):  # about 10 points per wave length
            assert 0 < np.diff(np.unique(m.points[:, a])).max() <= wavelength() / 10 + 1e-9
        want = airy(m.points[:, 0], m.points[:, 1], float(ds.time.values[k]))
        np.testing.assert_allclose(m.points[:, 2], want, rtol=0, atol=1e-12)
        np.testing.assert_allclose(m.point_data["elevation"], want, rtol=0, atol=1e-12)
        _covers(m.points[:, :2], nodes_xy)
    # the static step: still water, one plane
    parts = _parts(tmp_path / "s.pvd")
    (water,) = {f for _, f in parts[2]}
    m = meshio.read(tmp_path / water)
    np.testing.assert_array_equal(m.points[:, 2], 0.0)
    _covers(m.points[:, :2], tree["s"].to_dataset().position.sel(axis=["x", "y"]).values)


def test_vtk_planes_are_normal_to_gravity_given_as_a_vector(tmp_path):
    # gravity along -x: the seabed is the plane x = -20, the still water x = 0, covering the
    # cable's (y, z) extent
    tree = catdae.run(catdae.load_case(_scene(gravity="x", waves=False)))
    ds = tree["s"].to_dataset()
    np.testing.assert_array_equal(ds.attrs["up"], [1.0, 0.0, 0.0])
    catdae.export.write_vtk(tree, tmp_path)
    parts = _parts(tmp_path / "s.pvd")
    bed = meshio.read(tmp_path / parts[1][0][1])
    water = meshio.read(tmp_path / parts[2][0][1])
    np.testing.assert_allclose(bed.points[:, 0], -DEPTH, rtol=0, atol=1e-12)
    np.testing.assert_allclose(water.points[:, 0], 0.0, rtol=0, atol=1e-12)
    for m in (bed, water):
        _covers(m.points[:, 1:], ds.position.sel(axis=["y", "z"]).values)
    # its anchor sits on the plane drawn (x = -20), and the line lifts off from it: nothing
    # lies on the seabed (the anchor alone counted half an element before; tester t76)
    assert float(ds.position.sel(node="A", axis="x")) == -DEPTH
    assert float(ds.position.sel(node="c.1", axis="x")) > -DEPTH
    assert float(ds.seabed_length.values[0]) == 0.0
    assert np.all(ds.position.sel(axis="x").values >= -DEPTH - 0.05)
