"""Numba's on-disk kernel cache, kept in step with the kernel sources.

numba stamps each cached kernel with the modification time and size of the file that defines
it, not of the files it calls into: after an edit of catenary.py alone (a ``git pull`` into an
editable install), element_mass.py's and residual_kernel.py's cached kernels would still run
the old element code, silently. So the cache files of all kernel modules go together: a
digest of their sources is kept beside the cache, and when it differs every cached kernel of
these modules is deleted and compiled again on first use (``catdae run`` says so).

Only numba's in-tree cache (``catdae/__pycache__``, used when the package folder is writable)
is handled; a read-only install is replaced whole on upgrade, which changes every stamp.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

KERNEL_MODULES = ("catenary", "element_mass", "residual_kernel")
_STAMP = "catdae-kernels.sha256"


def sources_digest(folder: Path) -> str:
    h = hashlib.sha256()
    for name in KERNEL_MODULES:
        h.update(name.encode())
        h.update((folder / f"{name}.py").read_bytes())
    return h.hexdigest()


def purge_stale(folder: Path | None = None) -> bool:
    """Delete the cached kernels of KERNEL_MODULES if their sources changed since they were
    cached; True if something was deleted. Never raises for file-system reasons."""
    folder = Path(__file__).resolve().parent if folder is None else folder
    cache = folder / "__pycache__"
    try:
        digest = sources_digest(folder)
        stamp = cache / _STAMP
        if stamp.is_file() and stamp.read_text().strip() == digest:
            return False
        removed = False
        if cache.is_dir():
            for name in KERNEL_MODULES:
                for pattern in (f"{name}.*.nbi", f"{name}.*.nbc"):
                    for f in cache.glob(pattern):
                        f.unlink(missing_ok=True)
                        removed = True
        cache.mkdir(exist_ok=True)
        stamp.write_text(digest + "\n")
        return removed
    except OSError:
        return False
