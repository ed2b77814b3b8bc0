"""Two sets of ``catdae run`` results, bit for bit: every group, variable (values, dtype, shape)
and attribute of each pair of netCDF files, and the printed summaries, except what measures
the run itself (wall and CPU times, the creation date).

    python benchmarks/same_results.py DIR_A DIR_B

Each DIR holds <case>.nc and <case>.stdout of the same cases (benchmarks/startup.md shows how
they were made). Prints one line per case and exits 1 if any differs.
"""
import re
import sys
from pathlib import Path

import netCDF4
import numpy as np

TIMING = {"wall_time", "cpu_time", "created", "date_created", "history"}


def _attrs(obj) -> dict:
    return {k: obj.getncattr(k) for k in obj.ncattrs() if k not in TIMING}


def _same_value(a, b) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if a.dtype.kind == "O" or b.dtype.kind == "O":  # strings
            return a.dtype == b.dtype and a.shape == b.shape and a.tolist() == b.tolist()
        return a.dtype == b.dtype and a.shape == b.shape and (
            a.tobytes() == b.tobytes() or (a.dtype.kind in "fc" and np.array_equal(
                a, b, equal_nan=True)))
    return type(a) is type(b) and (a == b or (a != a and b != b))


def diff_groups(a, b, path="/") -> list[str]:
    out = []
    ka, kb = _attrs(a), _attrs(b)
    for k in sorted(set(ka) | set(kb)):
        if k not in ka or k not in kb or not _same_value(ka[k], kb[k]):
            out.append(f"{path} attribute {k}: {ka.get(k)!r} != {kb.get(k)!r}")
    if set(a.variables) != set(b.variables):
        out.append(f"{path} variables {sorted(set(a.variables) ^ set(b.variables))}")
    for name in sorted(set(a.variables) & set(b.variables)):
        va, vb = a.variables[name], b.variables[name]
        va.set_auto_mask(False)
        vb.set_auto_mask(False)
        if va.dimensions != vb.dimensions or not _same_value(va[...], vb[...]):
            out.append(f"{path}{name}: values differ")
        ka, kb = _attrs(va), _attrs(vb)
        if set(ka) != set(kb) or any(not _same_value(ka[k], kb[k]) for k in ka):
            out.append(f"{path}{name}: attributes differ")
    if set(a.groups) != set(b.groups):
        out.append(f"{path} groups {sorted(set(a.groups) ^ set(b.groups))}")
    for g in sorted(set(a.groups) & set(b.groups)):
        out += diff_groups(a.groups[g], b.groups[g], f"{path}{g}/")
    return out


def printed(path: Path) -> str:
    """The printed summary without its wall times and the folder of the results file."""
    text = re.sub(r"[0-9.]+ s wall", "* s wall", path.read_text())
    return text.replace(str(path.parent), "DIR")


def main() -> int:
    da, db = Path(sys.argv[1]), Path(sys.argv[2])
    bad = 0
    for nc in sorted(da.glob("*.nc")):
        other = db / nc.name
        with netCDF4.Dataset(nc) as a, netCDF4.Dataset(other) as b:
            diffs = diff_groups(a, b)
        so = nc.with_suffix(".stdout")
        if so.exists() and printed(so) != printed(other.with_suffix(".stdout")):
            diffs.append("printed summary differs")
        bad += bool(diffs)
        print(f"{nc.stem}: {'same' if not diffs else '; '.join(diffs[:5])}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
