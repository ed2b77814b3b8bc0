"""``catdae plot --node``: the selectors of ``catdae study`` and selection by arc length
(issue 23, defect 3). ``<cable>@<p/q>`` is the mesh node at unstrained arc-length fraction p/q
of a cable, ``<cable>@s=<metres>`` the one at that arc length: both name the same material
point in any mesh that has a node there, so a script survives ``--elements``; a mesh node name
``<cable>.<k>`` does not (it moves). Messages name nodes as the user wrote them."""

from __future__ import annotations

import pytest

import catdae
from catdae.cli import main
from catdae.output import plot

from scene_toml import cable_scene, load, step

CASE = cable_scene(B=(12.0, 0.0, 0.0), L0=12.3, EA=1.0e6, mass=1.0, elements=4, cable="main",
                   extra=load("push", [0.0, 5.0, 0.0], cable="main", s=6.15),
                   steps=step("transient", "pushed", duration=0.05, output_interval=0.01))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("select")
    case = folder / "c.toml"
    case.write_text(CASE)
    out = {}
    for n in (4, 6):
        path = folder / f"r{n}.nc"
        assert main(["run", str(case), "-o", str(path), "--elements", str(n),
                     "--no-progress"]) == 0
        out[n] = path
    return out


def _plotted(fig) -> set[str]:
    return {str(ln.get_gid()).split("|")[0] for ax in fig.axes for ln in ax.get_lines()}


@pytest.mark.parametrize(("spec", "nodes"), [
    ("main@1/2", {4: "main.2", 6: "main.3"}),
    ("main@s=6.15", {4: "main.2", 6: "main.3"}),
    ("main@0.5", {4: "main.2", 6: "main.3"}),
    ("main@1/1", {4: "B", 6: "B"}),
])
def test_selectors_survive_remeshing(runs, spec, nodes, capsys):
    for n, path in runs.items():
        ds = catdae.read_results(path)["pushed"].to_dataset()
        assert plot.select_node(ds, spec) == nodes[n]
        assert _plotted(plot.history(ds, spec)) == {nodes[n]}
        assert main(["plot", str(path), "-o", str(path.parent / f"p{n}"), "--what", "history",
                     "--node", spec]) == 0


@pytest.mark.parametrize(("spec", "words"), [
    ("nowhere", ["no node 'nowhere'", "e.g. 'A'"]),
    ("main@1/3", ["no mesh node at 1/3 of cable 'main'", "main.1", "main.2"]),
    ("main@s=5", ["no mesh node at s = 5 m of cable 'main'", "main.1 (s = 3.075 m)"]),
    ("main@7/4", ["between 0 and 1"]),
    ("main@s=20", ["0 <= s <= 12.3"]),
    ("wire@1/2", ["no cable 'wire'", "main"]),
    ("main@half", ["expected <cable>@<p/q>"]),
])
def test_bad_selectors_get_a_clean_message(runs, spec, words, capsys):
    path = runs[4]
    assert main(["plot", str(path), "-o", str(path.parent / "bad"), "--what", "history",
                 "--node", spec]) == 2
    err = capsys.readouterr().err
    assert "np.str_" not in err
    for w in words:
        assert w in err, (w, err)
