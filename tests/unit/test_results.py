"""Labelled results and netCDF files (``catdae.output.results`` through ``catdae.run``).

A run written to netCDF-4 and read back is the same tree: every value, dimension, unit and
long_name, the group and root attributes. Every variable is labelled. A failed run writes what
it computed, with a status saying why, and never replaces an existing file.
"""

from __future__ import annotations

from datetime import datetime
from pathlib import Path

import numpy as np
import pytest

import catdae
import catdae.analysis
from catdae import ConvergenceError

from scene_toml import cable as cable_toml
from scene_toml import load, modal_step, scene, static_step, step

CASE = scene(
    head={"title": "Round trip", "source": "tests/unit/test_results.py"},
    materials={"wire": {"EA": 3.4e7, "mass": 5.0}},
    nodes={"A": (0.0, 0.0, 0.0), "B": (10.0, 0.0, 1.0)},
    cables=[cable_toml("cable", material="wire", length=11.0, elements=4)],
    extra=load("tap", [0.0, 20.0, -30.0], node="cable.2",
               time={"kind": "ramp", "duration": 0.02}),
    steps=(static_step("first") + modal_step(4)
           + step("transient", "tapped", duration=0.04, output_interval=0.01)
           + static_step("second")))

ROOT_ATTRS = ("title", "source", "case_toml", "catdae_version", "created", "status")


def _same_values(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype.kind in "OUS" or b.dtype.kind in "OUS":
        return a.shape == b.shape and [str(v) for v in a.ravel()] == [str(v) for v in b.ravel()]
    return a.shape == b.shape and np.array_equal(a, b, equal_nan=True)


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    path = tmp_path_factory.mktemp("results") / "round.nc"
    tree = catdae.run(CASE, output=path)
    return tree, path


def test_netcdf_round_trip_is_identical(written):
    tree, path = written
    back = catdae.read_results(path)
    assert list(back.children) == ["first", "modes", "tapped", "second"]
    for key in ROOT_ATTRS:
        assert back.attrs[key] == tree.attrs[key], key
    for name, node in tree.children.items():
        ds, ds2 = node.to_dataset(), back[name].to_dataset()
        assert set(ds.variables) == set(ds2.variables), name
        assert ds.attrs == ds2.attrs, name
        for v in ds.variables:
            a, b = ds[v], ds2[v]
            assert a.dims == b.dims, (name, v)
            assert _same_values(a.values, b.values), (name, v)
            assert a.attrs.get("units") == b.attrs.get("units"), (name, v)
            assert a.attrs.get("long_name") == b.attrs.get("long_name"), (name, v)


def test_every_variable_is_labelled(written):
    tree, path = written
    for t in (tree, catdae.read_results(path)):
        for name, node in t.children.items():
            ds = node.to_dataset()
            for v in ds.data_vars:
                if ds[v].dtype.kind not in "OUS":  # labels (plane, symmetry): no units
                    assert ds[v].attrs.get("units"), (name, v)
                assert ds[v].attrs.get("long_name"), (name, v)
            for c in ds.coords:
                assert ds[c].attrs.get("long_name"), (name, c)
                if ds[c].dtype.kind in "OUS":  # labels: no units (not even "1")
                    assert "units" not in ds[c].attrs, (name, c)
                elif c != "mode":  # a mode number is a count
                    assert ds[c].attrs.get("units"), (name, c)


def test_root_attributes_carry_the_provenance(written):
    tree, path = written
    back = catdae.read_results(path)
    assert back.attrs["title"] == "Round trip"
    assert back.attrs["source"] == "tests/unit/test_results.py"
    assert back.attrs["case_toml"] == CASE
    assert back.attrs["catdae_version"] == catdae.__version__
    assert back.attrs["status"] == "completed"
    created = datetime.fromisoformat(back.attrs["created"])
    assert created.tzinfo is not None
    # the stored case text runs again to the same static state
    again = catdae.run(back.attrs["case_toml"])
    np.testing.assert_array_equal(again["first"].to_dataset().position.values,
                                  back["first"].to_dataset().position.values)


def test_group_kinds_and_dimensions(written):
    _, path = written
    back = catdae.read_results(path)
    st = back["first"].to_dataset()
    assert st.attrs["kind"] == "static"
    assert st.position.dims == ("node", "axis")
    assert st.tension.dims == ("element", "end")
    assert list(st.axis.values) == ["x", "y", "z"]
    assert list(st.end.values) == ["i", "j"]
    assert st.node.size == 5 and st.element.size == 4
    md = back["modes"].to_dataset()
    assert md.frequency.dims == ("mode",) and md.frequency.size == 4
    assert md.shape.dims == ("mode", "node", "axis")
    tr = back["tapped"].to_dataset()
    assert tr.position.dims == ("time", "node", "axis")
    # CF time: seconds since a nominal epoch (UDUNITS' keyword in any case; xarray decodes
    # only a lower-case "since"), kept as seconds (floats) by read_results and plain xarray
    assert tr.time.attrs["units"].lower() == "seconds since 1970-01-01 00:00:00"
    assert tr.time.attrs["standard_name"] == "time" and tr.time.dtype == np.float64
    np.testing.assert_allclose(tr.time.values, [0.0, 0.01, 0.02, 0.03, 0.04], atol=1e-12)
    assert tr.attrs["status"] == "completed"


def _fail_second_static(monkeypatch):
    """solve_static raises on its second call (the step 'second')."""
    real = catdae.analysis.solve_static
    calls = []

    def flaky(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise ConvergenceError("static equilibrium not found (test)")
        return real(*args, **kwargs)

    monkeypatch.setattr(catdae.analysis, "solve_static", flaky)


def test_a_failed_run_writes_what_it_computed(tmp_path, monkeypatch):
    _fail_second_static(monkeypatch)
    out = tmp_path / "run.nc"
    with pytest.raises(ConvergenceError) as info:
        catdae.run(CASE, output=out)
    assert info.value.output_path == out
    back = catdae.read_results(out)
    status = back.attrs["status"]
    assert "second" in status and "static equilibrium not found (test)" in status
    assert list(back.children) == ["first", "modes", "tapped"]
    assert back["tapped"].to_dataset().attrs["status"] == "completed"
    assert not (tmp_path / "run.partial.nc").exists()
    assert info.value.partial.attrs["status"] == status


def test_a_failed_run_never_overwrites_an_existing_file(tmp_path, monkeypatch):
    out = tmp_path / "run.nc"
    out.write_bytes(b"an earlier result")
    _fail_second_static(monkeypatch)
    with pytest.raises(ConvergenceError) as info:
        catdae.run(CASE, output=out)
    assert out.read_bytes() == b"an earlier result"
    failed = tmp_path / "run.failed.nc"
    assert info.value.output_path == failed
    back = catdae.read_results(failed)
    assert back.attrs["status"].startswith("failed in step 'second'")
    assert "first" in back.children


from repo_paths import CASES  # noqa: E402

THREE = CASES / "three_cables_shared_node.toml"


@pytest.fixture(scope="module")
def three():
    case = catdae.load_case(THREE)
    return case, catdae.run(case, progress=False)


def test_nodes_are_stored_along_each_cable_with_their_arc_length(three):
    case, tree = three
    for name in tree.children:
        ds = tree[name].to_dataset()
        cab = [str(c) for c in ds.node_cable.values]
        # one block of nodes per cable, in the case's order; a shared node with its first cable
        assert [c for k, c in enumerate(cab) if k == 0 or cab[k - 1] != c] == ["c1", "c2", "c3"]
        for cable in case.cables:
            ne = cable.elements
            nodes = ds.node.values[np.array(cab) == cable.name]
            s = ds.s.sel(node=nodes).values
            assert np.all(np.diff(s) > 0), (name, cable.name)  # in order along the cable
            # the mesh node <cable>.k sits at k L0 / n from the first end
            inner = [f"{cable.name}.{k}" for k in range(1, ne)]
            np.testing.assert_allclose(ds.s.sel(node=inner).values,
                                       np.arange(1, ne) * cable.length / ne, rtol=1e-14)
        # C: first end of c1 (s = 0), also the first end of c2 and the last of c3
        assert ds.node_cable.sel(node="C") == "c1" and float(ds.s.sel(node="C")) == 0.0
        assert list(ds.node.values[:2]) == ["C", "c1.1"]
        assert list(ds.node.values[8:10]) == ["P1", "c2.1"]  # c2 starts at C, stored already
        # P1 and P2 end c1 and c2 at their full length; P3 starts c3
        assert float(ds.s.sel(node="P1")) == pytest.approx(21.0, rel=1e-14)
        assert float(ds.s.sel(node="P2")) == pytest.approx(21.0, rel=1e-14)
        assert float(ds.s.sel(node="P3")) == 0.0


def test_elements_know_their_cable_end_nodes_and_arc_lengths(three):
    case, tree = three
    ds = tree["equilibrium"].to_dataset()
    for cable in case.cables:
        el = [f"{cable.name}.{k}" for k in range(1, cable.elements + 1)]
        assert (ds.element_cable.sel(element=el) == cable.name).all()
        nodes = ds.element_node.sel(element=el).values  # (n, 2)
        assert nodes[0, 0] == cable.ends[0] and nodes[-1, 1] == cable.ends[1]
        assert list(nodes[1:, 0]) == list(nodes[:-1, 1])  # a chain from end to end
        s = ds.element_s.sel(element=el).values
        assert s[0, 0] == 0.0 and s[-1, 1] == pytest.approx(cable.length, rel=1e-14)
        np.testing.assert_allclose(s[1:, 0], s[:-1, 1], rtol=1e-14)
        # the end nodes of each element are its chord apart: at most its stretched length
        # L0/n (1 + T_max/EA), and close to it for these sagging cables
        x = ds.position.sel(node=nodes.ravel()).values.reshape(-1, 2, 3)
        chord = np.linalg.norm(x[:, 1] - x[:, 0], axis=1)
        t_max = ds.tension.sel(element=el).values.max(axis=1)
        ea = case.materials[cable.material].EA
        assert np.all(chord <= cable.length / cable.elements * (1 + t_max / ea))
        assert np.all(chord > 0.9 * cable.length / cable.elements)


def _cf_high_priority_failures(path: Path, test: str) -> tuple[list, float]:
    """compliance-checker's verdict on one file: the failed high-priority checks and the score."""
    import json

    from compliance_checker.runner import CheckSuite, ComplianceChecker

    CheckSuite.load_all_available_checkers()
    report = path.with_suffix(".json")
    ComplianceChecker.run_checker(str(path), [test], 0, "normal", output_filename=str(report),
                                  output_format="json")
    res = json.loads(report.read_text())[test]
    failed = [(r["name"], r["msgs"]) for r in res["high_priorities"] if r["msgs"]]
    return failed, res["scored_points"] / res["possible_points"]


def test_every_group_passes_the_cf_checker(written, tmp_path):
    # compliance-checker reads only the root group of a grouped file: each group is checked
    # as a file of its own, as a user would write it (tree[name].to_dataset().to_netcdf)
    tree, path = written
    back = catdae.read_results(path)
    assert back.attrs["Conventions"].startswith("CF-") and back.attrs["history"]
    for name in back.children:
        f = tmp_path / f"{name}.nc"
        back[name].to_dataset().to_netcdf(f, engine="netcdf4")
        assert back[name].attrs["Conventions"] == back.attrs["Conventions"]
        assert back[name].attrs["history"] == back.attrs["history"]
        failed, score = _cf_high_priority_failures(f, "cf:1.8")
        assert failed == [], (name, failed)
        assert score > 0.95, (name, score)
    failed, _ = _cf_high_priority_failures(path, "cf:1.8")  # the root group of the file
    assert failed == []


_DASK_PROBE = r"""
import sys
import numpy as np
import catdae
tree = catdae.run(sys.argv[1], progress=False)
from catdae.output.results import write_tree
write_tree(tree, sys.argv[2])
back = catdae.read_results(sys.argv[2])
assert "dask.array" not in sys.modules, "a run imported dask.array"
assert "dask" not in sys.modules, "a run imported dask"
import dask.array as da
from catdae._xr import xr
lazy = xr.DataArray(da.ones(4, chunks=2), dims="x")
assert lazy.chunks == ((2, 2),), lazy.chunks
masked = da.ma.masked_array(np.arange(4.0), mask=[0, 1, 0, 0], chunks=2)
v = xr.Variable("x", masked).values
assert np.isnan(v[1]) and v[3] == 3.0, v
print("ok", float(back["tapped"].ds.time[-1]))
"""


def test_a_run_does_not_import_dask_and_dask_arrays_still_work(tmp_path):
    """xarray imports dask.array (0.7 s) on the first Variable it builds whenever dask is
    installed; catdae answers xarray's question without the import (catdae/_xr.py), and its
    questions of the scheduler and of dask collections too. Checked in a fresh process: a
    whole run, its netCDF write and read leave dask unimported (not even dask.base), and
    after it dask arrays are still dask arrays to xarray, masked ones still masked."""
    import subprocess
    import sys

    case = tmp_path / "case.toml"
    case.write_text(CASE)
    proc = subprocess.run([sys.executable, "-c", _DASK_PROBE, str(case), str(tmp_path / "o.nc")],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.startswith("ok")


_NUMPY_EXTRAS_PROBE = r"""
import sys
import catdae
tree = catdae.run(sys.argv[1], progress=False)  # imports scipy.sparse, .linalg, .optimize
ran = [m for m in ("numpy.f2py.f2py2e", "numpy.f2py.crackfortran", "numpy.testing._private.utils")
       if m in sys.modules]
assert not ran, f"a run executed {ran}"
import numpy as np
np.testing.assert_allclose(np.ones(3), np.ones(3))  # the first use loads the real module
from numpy.testing import assert_array_equal
assert_array_equal(np.arange(2), [0, 1])
assert "numpy.testing._private.utils" in sys.modules
import numpy.f2py
assert numpy.f2py.get_include().endswith("src"), numpy.f2py.get_include()
assert type(sys.modules["numpy.f2py"]) is type(sys)  # the ordinary module once loaded
print("ok")
"""


def test_a_run_leaves_numpy_f2py_and_testing_to_their_first_use(tmp_path):
    """scipy's array-API layer imports numpy.f2py and numpy.testing with every scipy.sparse,
    .linalg or .optimize import (about 0.06 s of CPU); catdae enters both as lazy modules
    (catdae/_numpy_extras.py). Checked in a fresh process: a whole transient run executes
    neither, and both work in full at their first use afterwards. A process that imported
    numpy.testing before catdae keeps its module as it was."""
    import subprocess
    import sys

    case = tmp_path / "case.toml"
    case.write_text(CASE)
    proc = subprocess.run([sys.executable, "-c", _NUMPY_EXTRAS_PROBE, str(case)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.strip().endswith("ok")
    before = ("import sys, numpy.testing; real = sys.modules['numpy.testing']\n"
              "import catdae, catdae._numpy_extras as x\n"
              "assert 'numpy.testing' not in x.defer()\n"
              "assert sys.modules['numpy.testing'] is real and type(real) is type(sys)\n"
              "print('ok')")
    proc = subprocess.run([sys.executable, "-c", before], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.strip().endswith("ok")


def test_overrides_are_recorded_and_rerun_the_results(tmp_path):
    """Settings given over the case file's are stored (root `overrides`, `history`): the
    stored case text with them re-runs to the same results; without them it does not."""
    path = tmp_path / "over.nc"
    tree = catdae.run(CASE, output=path, elements=6, rtol=1e-5)
    back = catdae.read_results(path)
    assert back.attrs["overrides"] == "rtol = 1e-05, elements = 6"
    assert "with rtol = 1e-05, elements = 6 over the case file's" in back.attrs["history"]
    again = catdae.run(back.attrs["case_toml"], elements=6, rtol=1e-5)
    assert np.array_equal(again["tapped"].ds.position.values, tree["tapped"].ds.position.values)
    assert catdae.run(back.attrs["case_toml"])["first"].ds.sizes["element"] == 4
    assert "overrides" not in catdae.run(CASE).attrs  # none given: none stored


def test_read_results_refuses_what_catdae_did_not_write(tmp_path):
    from catdae.errors import ResultsError

    with pytest.raises(ResultsError, match="no such file"):
        catdae.read_results(tmp_path / "nope.nc")
    (tmp_path / "text.nc").write_text("not netCDF")
    with pytest.raises(ResultsError, match="not a readable netCDF-4 results file"):
        catdae.read_results(tmp_path / "text.nc")
    import xarray as xr

    xr.Dataset({"x": ("t", [1.0, 2.0])}).to_netcdf(tmp_path / "foreign.nc")
    with pytest.raises(ResultsError, match="no step results"):
        catdae.read_results(tmp_path / "foreign.nc")


def test_an_unknown_keyword_of_run_names_run_and_what_it_takes():
    with pytest.raises(TypeError, match=r"catdae.run\(\) got an unexpected keyword argument "
                       r"'foo'; it takes output, progress, on_group and the overrides rtol"):
        catdae.run(CASE, foo=1)
