"""numba stamps a cached kernel with its own file only (catdae/element/cache.py): the cached
kernels of all kernel modules are dropped together when any of their sources changes, so an
edit of catenary.py cannot leave element_mass.py's cached kernels running the old code."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import catdae
from catdae.element.cache import KERNEL_MODULES, purge_stale, write_bytecode


def _tree(tmp_path):
    for name in KERNEL_MODULES:
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / f"{name}.py").write_text(f"# {name}\n")
        ((tmp_path / name).parent / "__pycache__").mkdir(exist_ok=True)
    return tmp_path / "element" / "__pycache__"


def _leaf(m):
    return m.rsplit("/", 1)[-1]


def _fill(cache):
    """Cached kernels of every kernel module in its own folder's __pycache__ (``cache`` is
    element's), and two files that are not kernels of these modules."""
    root = cache.parent.parent
    names = []
    for m in KERNEL_MODULES:
        for ext in ("nbi", "nbc"):
            n = f"{_leaf(m)}._k-1.py311.{ext}"
            ((root / m).parent / "__pycache__" / n).write_text("x")
            if (root / m).parent == cache.parent:
                names.append(n)
    names += ["catenary.cpython-311.pyc", "other._k-1.py311.nbi"]
    for n in names[-2:]:
        (cache / n).write_text("x")
    return names


def test_cached_kernels_go_together_when_one_kernel_source_changes(tmp_path):
    cache = _tree(tmp_path)
    _fill(cache)
    assert purge_stale(tmp_path)  # no digest yet: whatever is cached may be stale
    left = sorted(p.name for p in cache.iterdir())
    assert left == ["catenary.cpython-311.pyc", "other._k-1.py311.nbi"]
    assert (tmp_path / "__pycache__" / "catdae-kernels.sha256").is_file()

    _fill(cache)
    assert not purge_stale(tmp_path)  # sources unchanged: the cache stays
    assert all((cache / n).exists() for n in _fill(cache))

    (tmp_path / "element" / "catenary.py").write_text("# catenary, edited\n")
    assert purge_stale(tmp_path)
    for m in KERNEL_MODULES:  # the callers' kernels too, not only catenary's
        mcache = (tmp_path / m).parent / "__pycache__"
        assert not list(mcache.glob(f"{_leaf(m)}.*.nb?")), m
    assert (cache / "other._k-1.py311.nbi").exists()
    assert not purge_stale(tmp_path)


def test_a_missing_or_read_only_cache_folder_is_no_error(tmp_path):
    for name in KERNEL_MODULES:
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / f"{name}.py").write_text("")
    assert not purge_stale(tmp_path)  # creates the folder and the digest, deletes nothing
    assert (tmp_path / "__pycache__" / "catdae-kernels.sha256").is_file()
    assert not purge_stale(tmp_path / "missing")  # sources missing: no error, nothing done


def test_every_module_with_compiled_kernels_is_in_the_digest():
    """A module with numba kernels left out of KERNEL_MODULES would bring the stale-cache
    problem back for its callers."""
    from pathlib import Path

    import catdae

    root = Path(catdae.__file__).parent
    with_kernels = {p.relative_to(root).with_suffix("").as_posix() for p in root.rglob("*.py")
                    if "@njit" in p.read_text()}
    assert with_kernels == set(KERNEL_MODULES)


_LIGHT_PROBE = r"""
import sys
from pathlib import Path
import numpy as np
from catdae.element.elements import Elements
from numba import njit
# a taut, weightless element: h is EA (chord / L0 - 1) along the chord, whatever loaded it
el = Elements(np.array([10.0]), np.array([1.0e6]), np.array([0.0]))
st = el.solve(np.array([[6.0, 0.0, 8.0]]) * 1.001)
light = "numba.np.arraymath" not in sys.modules  # numba's compiler rules never loaded
@njit
def twice(x):
    return 2.0 * x
import json
print(json.dumps([light, twice(np.arange(3.0)).tolist(), st.h[0].tolist()]))
"""


def test_cached_kernels_load_without_numba_compiler_set_up_and_compiling_still_works():
    """catdae/element/cache.py load_lightly: a cached kernel is loaded without numba's
    compiler rules (which only compiling needs) and gives the exact answer; compiling a new
    function afterwards still works (numba's own path sets the rules up). A fresh process, so
    that nothing else has loaded them."""
    import json
    import subprocess
    import sys

    subprocess.run([sys.executable, "-c", "from catdae.element.elements import Elements; "
                    "import numpy as np; Elements(np.array([10.0]), np.array([1.0e6]), "
                    "np.array([0.0])).solve(np.array([[6.0, 0.0, 8.0]]))"],
                   check=True, capture_output=True, timeout=600)  # the cache filled
    out = subprocess.run([sys.executable, "-c", _LIGHT_PROBE], check=True, capture_output=True,
                         text=True, timeout=600).stdout
    light, twice, h = json.loads(out)
    assert light
    assert twice == [0.0, 2.0, 4.0]
    tension = 1.0e6 * (10.01 / 10.0 - 1.0)
    assert abs(h[0] - 0.6 * tension) < 1e-6 * tension and abs(h[2] - 0.8 * tension) < 1e-6 * \
        tension and h[1] == 0.0


def test_bytecode_is_written_for_missing_and_stale_modules_only(tmp_path):
    """write_bytecode: each module's bytecode where it is missing or older than its source,
    nothing where it is fresh, no error where the folder cannot be written."""
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "a.py").write_text("A = 1\n")
    (pkg / "sub" / "b.py").write_text("B = 2\n")
    pycs = [Path(importlib.util.cache_from_source(str(p))) for p in (pkg / "a.py",
                                                                       pkg / "sub" / "b.py")]
    assert write_bytecode(pkg)
    assert all(p.is_file() for p in pycs)
    stamps = [p.stat().st_mtime_ns for p in pycs]
    assert write_bytecode(pkg)
    assert [p.stat().st_mtime_ns for p in pycs] == stamps  # fresh: not written again
    (pkg / "a.py").write_text("A = 10  # changed\n")
    os.utime(pkg / "a.py", ns=(stamps[0] + 10**9, stamps[0] + 10**9))
    assert write_bytecode(pkg)
    assert pycs[0].stat().st_mtime_ns != stamps[0] and pycs[1].stat().st_mtime_ns == stamps[1]
    write_bytecode(tmp_path / "missing")  # a missing folder: no error


def test_import_under_dont_write_bytecode_leaves_catdae_bytecode_fresh():
    """With PYTHONDONTWRITEBYTECODE (python -B) an editable install compiled every catdae
    module from source in every process (about 0.1 s of CPU); importing catdae writes its own
    bytecode, so the next process reads it. Checked with a fresh ``python -B`` process after
    one module's bytecode is removed: afterwards every catdae module has bytecode that
    Python accepts for its source (the stamp of a timestamp .pyc: mtime and size)."""
    root = Path(catdae.__file__).parent
    if not os.access(root / "solvers", os.W_OK):  # a read-only install: nothing to write
        return
    gone = Path(importlib.util.cache_from_source(str(root / "solvers" / "order.py")))
    gone.unlink(missing_ok=True)
    proc = subprocess.run([sys.executable, "-B", "-c", "import catdae, sys; "
                           "print(sys.flags.dont_write_bytecode)"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.strip() == "1"
    stale = []
    for p in root.rglob("*.py"):
        c = Path(importlib.util.cache_from_source(str(p)))
        head = c.read_bytes()[:16] if c.is_file() else b""
        st = p.stat()
        if (len(head) < 16 or int.from_bytes(head[4:8], "little") != 0
                or int.from_bytes(head[8:12], "little") != int(st.st_mtime) & 0xFFFFFFFF
                or int.from_bytes(head[12:16], "little") != st.st_size & 0xFFFFFFFF):
            stale.append(str(p.relative_to(root)))
    assert not stale, stale
