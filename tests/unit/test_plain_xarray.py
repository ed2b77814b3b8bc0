"""A results file opened with plain xarray, defaults and all (issue 23, defect 2).

Users and their plots expect ``time`` in seconds. ``xr.open_datatree(path)`` and
``xr.open_dataset(path, group=...)`` with their defaults must give float seconds equal to what
catdae returned, without a warning; the CF check of every group stays clean
(tests/unit/test_results.py runs compliance-checker on them).
"""

from __future__ import annotations

import warnings

import numpy as np
import xarray as xr

import catdae

from scene_toml import cable_scene, load, static_step, step

CASE = cable_scene(
    B=(10.0, 0.0, 1.0), L0=11.0, EA=3.4e7, mass=5.0, elements=4, material="wire", cable="cable",
    extra=load("tap", [0.0, 20.0, -30.0], node="cable.2",
               time={"kind": "ramp", "duration": 0.02}),
    steps=(static_step("first") + step("transient", "tapped", duration=0.1, output_interval=0.025)
           + step("transient", "later", duration=0.05, output_interval=0.025)))


def test_plain_xarray_gives_float_seconds(tmp_path):
    path = tmp_path / "r.nc"
    tree = catdae.run(catdae.load_case(CASE), output=path, progress=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with xr.open_datatree(path) as plain:
            for name in ("tapped", "later"):
                t = plain[name].ds.time
                assert t.dtype == np.float64, (name, t.dtype)
                np.testing.assert_array_equal(t.values, tree[name].ds.time.values)
        with xr.open_dataset(path, group="later") as ds:
            assert ds.time.dtype == np.float64
            np.testing.assert_allclose(ds.time.values, [0.1, 0.125, 0.15], rtol=1e-14)
            # the CF identity of the axis is kept
            assert ds.time.attrs["standard_name"] == "time"
            assert ds.time.attrs["axis"] == "T"
