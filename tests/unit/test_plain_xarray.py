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

CASE = """
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
kind = "transient"
name = "tapped"
duration = 0.1
output_interval = 0.025
[[steps]]
kind = "transient"
name = "later"
duration = 0.05
output_interval = 0.025
"""


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
