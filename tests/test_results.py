"""Labelled results and netCDF files (``catdae.results`` through ``catdae.run``).

A run written to netCDF-4 and read back is the same tree: every value, dimension, unit and
long_name, the group and root attributes. Every variable is labelled. A failed run writes what
it computed, with a status saying why, and never replaces an existing file.
"""

from __future__ import annotations

from datetime import datetime

import numpy as np
import pytest

import catdae
import catdae.analysis
from catdae import ConvergenceError

CASE = """
title = "Round trip"
source = "tests/test_results.py"

[materials.wire]
EA = 3.4e7
mass = 5.0

[nodes]
A = [0.0, 0.0, 0.0]
B = [10.0, 0.0, 1.0]

[supports]
A = "pinned"
B = "pinned"

[[cables]]
name = "cable"
ends = ["A", "B"]
material = "wire"
length = 11.0
elements = 4

[[loads]]
name = "tap"
node = "cable.2"
force = [0.0, 20.0, -30.0]
time = { kind = "ramp", duration = 0.02 }

[[steps]]
kind = "static"
name = "first"

[[steps]]
kind = "modal"
name = "modes"
modes = 4

[[steps]]
kind = "transient"
name = "tapped"
duration = 0.04
output_interval = 0.01

[[steps]]
kind = "static"
name = "second"
"""

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
                assert ds[v].attrs.get("units"), (name, v)
                assert ds[v].attrs.get("long_name"), (name, v)
            for c in ds.coords:
                assert ds[c].attrs.get("long_name"), (name, c)
                assert ds[c].attrs.get("units"), (name, c)  # "1" for names and numbers


def test_root_attributes_carry_the_provenance(written):
    tree, path = written
    back = catdae.read_results(path)
    assert back.attrs["title"] == "Round trip"
    assert back.attrs["source"] == "tests/test_results.py"
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
    assert tr.time.attrs["units"] == "s"
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
