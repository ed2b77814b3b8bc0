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
"""

from __future__ import annotations

import hashlib
from pathlib import Path

KERNEL_MODULES = ("element/catenary", "element/catenary_batch", "element/mass",
                  "element/mass_gradient", "element/residual_kernel", "element/fluid_kernel",
                  "element/fluid_kinematics", "element/grounded", "solvers/axial_damping",
                  "solvers/envelope")
_STAMP = "catdae-kernels.sha256"


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
    root = Path(__file__).resolve().parent.parent if root is None else root
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
