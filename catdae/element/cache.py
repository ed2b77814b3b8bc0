"""Numba's on-disk kernel cache, kept in step with the kernel sources.

numba stamps each cached kernel with the modification time and size of the file that defines
it, not of the files it calls into: after an edit of catenary.py alone (a ``git pull`` into an
editable install), element_mass.py's and residual_kernel.py's cached kernels would still run
the old element code, silently. So the cache files of all kernel modules go together: a
digest of their sources is kept beside the cache, and when it differs every cached kernel of
these modules is deleted and compiled again on first use (``catdae run`` says so).

KERNEL_MODULES lists every module with numba kernels, as paths relative to the package root
(``element/catenary``): a new kernel module anywhere in catdae must be added (a test checks).
Only numba's in-tree cache (each module's ``__pycache__``, used when the folder is writable)
is handled; a read-only install is replaced whole on upgrade, which changes every stamp.

Loading a cached kernel (:func:`load_lightly`): before the first one, numba "refreshes" its
compiler, importing and registering the typing and lowering rules of everything it can compile
(its string, list, dict, set, random, linear-algebra and datetime support, cffi, jitclass),
about 0.06-0.1 s of CPU in every ``catdae run`` (benchmarks/startup.md), although a cached
kernel is machine code that needs none of it. Only two parts of that refresh reach machine
code: numba's runtime (NRT, the memory management of the arrays a kernel allocates, whose
functions a kernel calls by name) and the hash secret symbols of ``numba.cpython.hashing``; the
rest only serves compiling. So a cached kernel is loaded after those two; compiling (a kernel
not in the cache, a call with new argument types) goes through numba's own path, which
refreshes fully first. The machine code run is the same, so are the results (bit for bit:
benchmarks/same_results.py).

The bytecode of catdae's own modules (:func:`write_bytecode`): where the interpreter was told not
to write bytecode (``PYTHONDONTWRITEBYTECODE``, ``python -B``), an editable or source install
compiled all of catdae's modules from source in every process, about 0.1 s of CPU per ``catdae
run`` (benchmarks/startup.md). A regular ``pip install`` writes that bytecode at install; for the
others it is written at import, beside numba's kernel cache in the package's ``__pycache__``
folders, and only for files whose bytecode is missing or older than the source (Python checks
each file's stamp at import and ignores bytecode that no longer matches its source).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

KERNEL_MODULES = ("element/catenary", "element/catenary_batch", "element/mass",
                  "element/mass_gradient", "element/lagrange", "element/residual_kernel",
                  "element/fluid_kernel", "element/fluid_kinematics", "element/grounded",
                  "solvers/axial_damping", "solvers/envelope")
_STAMP = "catdae-kernels.sha256"
_ROOT = Path(__file__).resolve().parents[1]  # the catdae package folder
_OWN = str(_ROOT)


def load_lightly() -> bool:
    """Make numba load cached kernels without refreshing its compiler first (see above); True if
    installed. Left as it is (False) when numba's loader is not the one this was written for
    (numba 0.68: ``Cache.load_overload`` refreshes, then calls ``_load_overload``; its names
    are checked). A load that fails the light way is retried the ordinary way. Only catdae's
    own kernels (their cache under the package's folder) are loaded this way: any other numba
    function in the process loads as numba loads it."""
    from numba.core import caching
    from numba.core.runtime import rtsys

    cache = caching.Cache
    real = cache.load_overload
    if getattr(real, "_catdae_light", False):
        return True
    if real.__code__.co_names != ("refresh", "_guard_against_spurious_io_errors",
                                  "_load_overload"):
        return False

    def load_overload(self, sig, target_context):
        if not str(getattr(self, "_cache_path", "")).startswith(_OWN):
            return real(self, sig, target_context)  # not a catdae kernel: numba's own way
        try:
            rtsys.initialize(target_context)  # NRT: its symbols, once per process
            import numba.cpython.hashing  # noqa: F401  (its symbols)

            with self._guard_against_spurious_io_errors():
                return self._load_overload(sig, target_context)
        except Exception:  # whatever the light way misses: numba's own way
            return real(self, sig, target_context)

    load_overload._catdae_light = True
    cache.load_overload = load_overload
    return True


def write_bytecode(root: Path | None = None) -> bool:
    """Write the missing or stale bytecode of the modules under ``root`` (the catdae package
    folder by default); False if it could not be done (a read-only install). Up to date, the
    check costs about 2 ms. Never raises: the bytecode is only a saving."""
    import compileall

    root = _ROOT if root is None else root
    try:
        return bool(compileall.compile_dir(str(root), quiet=2, workers=1))
    except Exception:  # noqa: BLE001 - whatever goes wrong, the modules compile as before
        return False


def sources_digest(root: Path) -> str:
    h = hashlib.sha256()
    for name in KERNEL_MODULES:
        h.update(name.encode())
        h.update((root / f"{name}.py").read_bytes())
    return h.hexdigest()


def purge_stale(root: Path | None = None) -> bool:
    """Delete the cached kernels of KERNEL_MODULES if their sources changed since they were
    cached; True if something was deleted. ``root`` is the package folder (``catdae/``); the
    digest is kept in ``root/__pycache__``. Never raises for file-system reasons."""
    root = _ROOT if root is None else root
    stamp_dir = root / "__pycache__"
    try:
        digest = sources_digest(root)
        stamp = stamp_dir / _STAMP
        if stamp.is_file() and stamp.read_text().strip() == digest:
            return False
        removed = False
        for name in KERNEL_MODULES:
            module = root / name
            cache = module.parent / "__pycache__"
            if not cache.is_dir():
                continue
            for pattern in (f"{module.name}.*.nbi", f"{module.name}.*.nbc"):
                for f in cache.glob(pattern):
                    f.unlink(missing_ok=True)
                    removed = True
        stamp_dir.mkdir(exist_ok=True)
        stamp.write_text(digest + "\n")
        return removed
    except OSError:
        return False
