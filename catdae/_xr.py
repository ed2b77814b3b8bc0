"""xarray, imported once for catdae, without its probe of dask.array.

xarray asks, for every Variable it builds from data, whether the data is a dask array; the
first time, it answers by importing ``dask.array`` whenever dask is installed (catdae installs
it for studies), although no catdae result holds a dask array. On this project's 2-core
machines that import was about 0.3 s of CPU in every ``catdae run`` (``python
benchmarks/startup.py``, benchmarks/speed_accuracy.md §8). Two more questions xarray asks of
dask on every run (is this a dask collection? which scheduler?) are answered below without
importing dask where dask's answer is known without it: a ``catdae run`` imports no dask.

The answer needs no import: an object can only be a ``dask.array.Array`` if ``dask.array`` has
been imported. ``_LazyDask`` gives xarray exactly that answer: the real array type once
``dask.array`` is in ``sys.modules`` (imported by the user, by a study, by xarray's own
chunking), and no type before. Everything else xarray may ask of it (the module, its version,
whether it is available) imports dask and answers as xarray would. It is put in xarray's
private cache of duck-array modules only if that cache is as expected and empty for dask;
otherwise nothing changes (and the probe costs its 0.7 s again).
"""

from __future__ import annotations

import sys

import xarray as xr

__all__ = ["xr"]


class _LazyDask:
    """xarray's DuckArrayModule("dask"), answering ``type`` without importing dask."""

    def __init__(self, real_class):
        self._real_class = real_class
        self._real = None

    def _load(self):
        if self._real is None:
            self._real = self._real_class("dask")
        return self._real

    @property
    def type(self):
        if "dask.array" in sys.modules:
            return self._load().type
        return ()

    @property
    def module(self):
        return self._load().module

    @property
    def version(self):
        return self._load().version

    @property
    def available(self):
        return self._load().available


def _install() -> bool:
    try:
        from xarray.namedarray import pycompat
    except ImportError:  # pragma: no cover - another xarray layout: keep its own probe
        return False
    cache = getattr(pycompat, "_cached_duck_array_modules", None)
    real = getattr(pycompat, "DuckArrayModule", None)
    if not isinstance(cache, dict) or real is None or "dask" in cache:
        return False
    cache["dask"] = _LazyDask(real)
    return True


def _install_scheduler_probe() -> bool:
    """Answer xarray's question "which dask scheduler is active?" (asked by every netCDF write
    and file lock) without importing dask or dask.distributed when it cannot matter.

    xarray's ``get_dask_scheduler`` asks dask, which imports ``distributed`` (about 0.1-0.15 s
    of CPU in every ``catdae run``) to see whether a distributed Client is active; merely
    importing ``dask.config`` to read the configured scheduler imports the whole ``dask``
    package (about 0.05-0.07 s, benchmarks/startup.md). The answer only matters for chunked
    (dask) variables, whose writes it may spread over processes, and for the kind of lock
    around this process's own writes. So:

    - dask not imported at all: no dask array, collection or Client can exist in the process,
      the write is this process's alone, and the answer is "threaded" (a threading lock, the
      file written exactly as with any other answer);
    - dask imported but not ``distributed``: a Client cannot exist; with no scheduler
      configured dask falls back to its default, for which xarray answers "threaded";
    - anything else (distributed imported, a scheduler configured, a collection given) goes
      to xarray's own function."""
    try:
        from xarray.backends import locks, writers
    except ImportError:  # pragma: no cover - another xarray layout: keep its own probe
        return False
    real = getattr(locks, "get_dask_scheduler", None)
    if real is None or getattr(writers, "get_dask_scheduler", None) is not real:
        return False

    def get_dask_scheduler(get=None, collection=None):
        if get is None and collection is None and "dask" not in sys.modules:
            return "threaded"
        if get is None and collection is None and "distributed" not in sys.modules:
            try:
                import dask.config
            except ImportError:
                return real(get, collection)
            if dask.config.get("scheduler", None) is None and dask.config.get("get", None) is None:
                return "threaded"
        return real(get, collection)

    locks.get_dask_scheduler = writers.get_dask_scheduler = get_dask_scheduler
    return True


def _install_collection_probe() -> bool:
    """Answer xarray's question "is this object a dask collection?" (asked of the data of every
    index it builds) without importing dask when the object cannot be one.

    xarray's ``is_dask_collection`` imports ``dask.base`` (the whole ``dask`` package, about
    0.05 s of CPU in every ``catdae run``, benchmarks/startup.md) to ask it. dask's own
    function answers False at once for a class or for an object without a ``__dask_graph__``
    attribute (a numpy array, a pandas index): that first test is made here, and only the
    objects that pass it go to xarray's function. The answer is dask's in every case."""
    try:
        from xarray.namedarray import utils
    except ImportError:  # pragma: no cover - another xarray layout: keep its own probe
        return False
    real = getattr(utils, "is_dask_collection", None)
    if real is None:
        return False

    def is_dask_collection(x):
        if isinstance(x, type) or not hasattr(x, "__dask_graph__"):
            return False
        return real(x)

    for name, module in list(sys.modules.items()):  # the modules that import it by name
        if (name == "xarray" or name.startswith("xarray.")) and getattr(
                module, "is_dask_collection", None) is real:
            module.is_dask_collection = is_dask_collection
    return True


INSTALLED = _install()
SCHEDULER_PROBE = _install_scheduler_probe()
COLLECTION_PROBE = _install_collection_probe()
