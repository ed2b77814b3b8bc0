"""Files around a results file: the temporary names of atomic writes, and what every output
must be before any work is done (a name the file system takes with every name derived from it,
a folder where a file can be created, not a file the case reads). Stale temporary files of
processes that no longer run are removed here too."""

from __future__ import annotations

import glob
import os
import re
import uuid
from pathlib import Path

from catdae._xr import xr
from catdae.case import Case
from catdae.errors import OutputError

INCOMPLETE_SUFFIX = ".incomplete"
"""The temporary name ends so: ``<name>.<pid>-<random>.incomplete``, never ``.nc``."""


def incomplete_name(path: Path) -> Path:
    """The temporary file that :func:`write_atomic` writes before moving it to ``path``. Only a
    process killed outright (SIGKILL, power loss) leaves one behind; its name says what it is
    and no ``*.nc`` pattern matches it, so it is never taken for a result."""
    return path.with_name(f"{path.name}.{os.getpid()}-{uuid.uuid4().hex[:8]}{INCOMPLETE_SUFFIX}")


def free_name(path: Path, tag: str) -> Path:
    """The first of ``<stem><tag>.nc``, ``<stem><tag>-2.nc``, ... (up to -99) that is not
    there yet: a file beside ``path`` that replaces none."""
    for k in range(1, 100):
        p = path.with_name(f"{path.stem}{tag}{'' if k == 1 else f'-{k}'}.nc")
        if not p.exists():
            return p
    return p


_INCOMPLETE_TAIL = f".{2**22 - 1}-{'f' * 8}{INCOMPLETE_SUFFIX}"  # the longest pid (Linux)


def longest_name(path: Path, derived: tuple[str, ...] = ()) -> str:
    """The longest file name that writing ``path`` (and the files derived from it: ``derived``
    suffixes in place of ``.nc``) creates, temporary names included."""
    names = [path.name] + [path.stem + d for d in derived]
    return max(names, key=lambda n: len(os.fsencode(n))) + _INCOMPLETE_TAIL


def name_max(folder: Path) -> int:
    """The file system's limit on the length of a file name in ``folder`` (bytes)."""
    try:
        return int(os.pathconf(folder, "PC_NAME_MAX"))
    except (OSError, ValueError):
        return 255


def probe_writable(path: Path) -> None:
    """Create (and remove) a temporary file beside ``path``: whether files can be created
    there, found by trying (permissions alone do not say it: root under /proc, a read-only
    mount). Raises OSError."""
    probe = incomplete_name(path)
    fd = os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    os.close(fd)
    probe.unlink(missing_ok=True)


def warm_writer(path: Path) -> None:
    """Write (and remove) an empty netCDF file beside ``path``: loads what every write needs,
    so that a later write (of what a run computed before it ran out of memory) does not."""
    probe = incomplete_name(path)
    try:
        xr.Dataset().to_netcdf(probe, engine="netcdf4")
    except (OSError, RuntimeError):
        pass  # check_output judged the folder; the real write reports its own failure
    finally:
        probe.unlink(missing_ok=True)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return pid > 0  # someone else's process: alive
    return True


_STALE = re.compile(r"\.(\d{1,10})-[0-9a-f]{8}" + re.escape(INCOMPLETE_SUFFIX) + "$")


def clean_stale(folder: Path, prefix: str) -> list[Path]:
    """Remove the temporary files ``<prefix>*.<pid>-<random>.incomplete`` in ``folder`` left
    by processes that no longer run (killed outright while writing). A live process's file is
    never touched. Returns the files removed."""
    removed = []
    try:
        candidates = list(folder.glob(f"{glob.escape(prefix)}*{INCOMPLETE_SUFFIX}"))
    except OSError:
        return removed
    for f in candidates:
        m = _STALE.search(f.name)
        if m is None or _alive(int(m[1])):
            continue
        try:
            if f.is_file() and not f.is_symlink():
                f.unlink()
                removed.append(f)
        except OSError:
            pass
    return removed


def check_output(output: str | os.PathLike, case: Case | None = None,
                 derived: tuple[str, ...] = (".partial.nc", ".failed-99.nc")) -> Path:
    """The output path, judged before any work: a regular file (or none yet) in a directory
    catdae can create files in (tried, not guessed from permissions: root cannot create files
    under /proc), with a name short enough for every file derived from it (``derived``: the
    suffixes that replace ``.nc``, each also written under a temporary name), and not a file the
    case reads (the case file itself or one of its table files). Raises OutputError."""
    out = Path(output)

    def refuse(why: str):
        raise OutputError(f"cannot write the results to {out}: {why}")

    if str(output) == "" or out.is_dir():
        refuse("it is a directory (give a file name, e.g. -o results.nc)")
    if "\x00" in str(output):
        refuse("the name holds a NUL character")
    if out.exists() and not out.is_file():
        refuse("it exists and is not a regular file")
    parent = out.parent
    if not parent.is_dir():
        refuse(f"no directory {parent}")
    if not os.access(parent, os.W_OK | os.X_OK):
        refuse(f"no permission to create files in {parent}")
    if out.exists() and not os.access(out, os.W_OK):
        refuse("it exists and is read-only")
    longest = longest_name(out, derived)
    limit = name_max(parent)
    if len(os.fsencode(longest)) > limit:
        refuse(f"the name is too long: catdae also writes {longest[:24]}...{longest[-24:]} "
               f"({len(os.fsencode(longest))} bytes) beside it, above the file system's limit of "
               f"{limit} bytes for a file name; give a shorter name")
    for src in read_files(case):
        if out.exists() and src.exists() and out.samefile(src):
            refuse("it is the case file" if src == _case_file(case) else
                   f"it is a table file that the case reads ({src.name})")
    try:
        probe_writable(out)
    except OSError as exc:
        refuse(f"cannot create files in {parent}: {exc.strerror or exc}")
    return out


def _case_file(case) -> Path | None:
    src = getattr(case, "path", None)
    return None if src is None else Path(src)


def read_files(case) -> list[Path]:
    """The files a case reads: its case file and the table files of its time functions."""
    if case is None:
        return []
    files = [f] if (f := _case_file(case)) is not None else []
    base = f.parent if f is not None else Path.cwd()
    items = (*getattr(case, "loads", ()), *getattr(case, "distributed_loads", ()),
             *getattr(case, "support_motions", ()))
    for item in items:
        for attr in ("time", "x", "y", "z"):
            name = getattr(getattr(item, attr, None), "file", None)
            if isinstance(name, str):
                files.append(base / name)
    return files


def check_folder(folder: str | os.PathLike, what: str) -> Path:
    """An output folder, judged before any work and without creating anything: an existing
    folder, or a name whose nearest existing parent is a folder, where a file can be created
    (tried, not guessed from permissions). Raises OutputError."""
    path = Path(folder)

    def refuse(why: str):
        raise OutputError(f"cannot write {what} to {path}: {why}")

    if str(folder) == "":
        refuse("no folder given")
    if "\x00" in str(folder):
        refuse("the name holds a NUL character")
    there = path
    while not there.exists():
        if there.is_symlink():
            refuse(f"{there} is a broken symbolic link")
        if there.parent == there:
            break
        there = there.parent
    if not there.is_dir():
        refuse("it exists and is not a folder" if there == path else
               f"{there} is not a folder")
    try:
        probe_writable(there / "probe")
    except OSError as exc:
        refuse(f"cannot create files in {there}: {exc.strerror or exc}")
    return path
