"""ParaView export (``catdae export --vtk``): read back with meshio, the files hold the node
positions, the elements and the tensions of every output time, and the collection's times."""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET

import meshio
import numpy as np

import catdae
from catdae.cli import main

from repo_paths import CASES  # noqa: E402


def test_export_writes_a_time_series_that_meshio_reads_back(tmp_path, capsys):
    out = tmp_path / "gentle.nc"
    assert main(["run", str(CASES / "example2_support_motion_gentle.toml"), "--elements", "4",
                 "--rtol", "1e-4", "-o", str(out), "--no-progress"]) == 0
    assert main(["export", str(out), "--vtk", str(tmp_path / "vtk")]) == 0
    assert "excitation.pvd" in capsys.readouterr().out
    tree = catdae.read_results(out)
    ds = tree["excitation"].to_dataset()
    pvd = ET.parse(tmp_path / "vtk" / "excitation.pvd").getroot()
    sets = pvd.findall("./Collection/DataSet")
    np.testing.assert_array_equal([float(s.get("timestep")) for s in sets], ds.time.values)
    node = list(ds.node.values)
    for k in (0, len(sets) // 2, len(sets) - 1):
        m = meshio.read(tmp_path / "vtk" / sets[k].get("file"))
        np.testing.assert_array_equal(m.points, ds.position.isel(time=k).values)
        np.testing.assert_array_equal(m.point_data["displacement"],
                                      ds.displacement.isel(time=k).values)
        (block,) = m.cells
        assert block.type == "line"
        ends = [[node[i] for i in pair] for pair in block.data]
        assert ends == [list(p) for p in ds.element_node.values]
        tens = ds.tension.isel(time=k).values
        np.testing.assert_array_equal(m.cell_data["tension_i"][0], tens[:, 0])
        np.testing.assert_array_equal(m.cell_data["tension_j"][0], tens[:, 1])
    # the static step too: one file at its state
    m = meshio.read(tmp_path / "vtk" / "initial" / "initial_00000.vtu")
    np.testing.assert_array_equal(m.points, tree["initial"].to_dataset().position.values)


def test_run_with_vtk_writes_the_collections(tmp_path):
    assert main(["run", str(CASES / "example1_free_vibration.toml"), "--elements", "4",
                 "--rtol", "1e-4", "-o", str(tmp_path / "ex1.nc"), "--no-progress",
                 "--vtk", str(tmp_path / "vtk")]) == 0
    tree = catdae.read_results(tmp_path / "ex1.nc")
    kinds = {n: tree[n].to_dataset().attrs["kind"] for n in tree.children}
    assert sorted(kinds.values()) == ["modal", "static", "static", "transient"]
    expected = {n for n, k in kinds.items() if k != "modal"}
    assert {p.stem for p in (tmp_path / "vtk").glob("*.pvd")} == expected


def test_a_second_export_into_the_folder_leaves_no_files_of_the_first(tmp_path, capsys):
    """A tester exported a longer run, then a shorter one into the same folder: 401 files on
    disk against 101 in the collection, which ParaView's grouping of numbered files mixes.
    The step's folder now holds exactly the files its collection names (a user's own file
    there is left alone)."""
    from catdae.output.export import write_vtk

    base = (CASES / "example2_support_motion_gentle.toml").read_text()
    trees = [catdae.run(catdae.load_case(base), elements=4, rtol=1e-4, progress=False)]
    case = catdae.load_case(base)
    short = tuple(dataclasses.replace(s, duration=s.duration / 2) if s.kind == "transient"
                  else s for s in case.steps)
    trees.append(catdae.run(dataclasses.replace(case, steps=short), elements=4, rtol=1e-4,
                            progress=False))
    folder = tmp_path / "vtk"
    write_vtk(trees[0], folder)
    mine = folder / "excitation" / "notes.vtu"
    mine.write_text("a user's file")
    write_vtk(trees[1], folder)
    sets = ET.parse(folder / "excitation.pvd").getroot().findall("./Collection/DataSet")
    named = {(folder / s.get("file")).resolve() for s in sets}
    on_disk = {p.resolve() for p in (folder / "excitation").glob("*.vtu")} - {mine.resolve()}
    assert on_disk == named
    assert len(named) == trees[1]["excitation"].to_dataset().sizes["time"]
    assert mine.exists()
