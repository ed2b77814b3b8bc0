"""The resumable store: one netCDF file per finished run, ``<store>/<key>.nc``, written
atomically, so that a rerun skips what is stored."""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from catdae._xr import xr
from catdae.output.results import write_atomic
from catdae.study.core import STORE_FORMAT


def store_read(store: Path, key: str) -> xr.Dataset | None:
    path = store / f"{key}.nc"
    if not path.exists():
        return None
    try:
        ds = xr.load_dataset(path, engine="netcdf4")
    except (OSError, ValueError):
        return None  # unreadable: computed again
    if ds.attrs.get("key") != key or ds.attrs.get("store_format") != STORE_FORMAT:
        return None
    return ds


def store_write(store: Path, key: str, ds: xr.Dataset, settings: Mapping | None) -> None:
    """Atomically: a temporary file moved into place, so a crash never leaves half a run."""
    out = ds.copy()
    out.attrs.update(key=key, store_format=STORE_FORMAT,
                     settings=json.dumps({k: _plain(v) for k, v in (settings or {}).items()}))
    write_atomic(out, store / f"{key}.nc")


def _plain(v):
    return v.item() if isinstance(v, np.generic) else v


def clean(attrs: dict) -> dict:
    return {k: _plain(v) for k, v in attrs.items() if v is not None}
