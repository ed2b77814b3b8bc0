"""Limits judged before any work: what a case may ask for, and how files are read.

Every number here is documented in docs/case-format.md ("Limits"). A case
that exceeds one is refused by ``catdae check`` and ``catdae run`` (exit 2) with the field and
the limit, instead of failing deep inside a solver (a segfault in the sparse solver at 10⁶
elements, a 7 TiB allocation after the static step) or hanging on a file that never ends.
"""

from __future__ import annotations

import math
import os
import re
import stat
from pathlib import Path

MAX_FILE_BYTES = 16 * 2**20  # a case file or a table file
MAX_ELEMENTS_PER_CABLE = 10_000  # a transient at 1000 elements already costs ~670 s per s
MAX_DOFS = 300_000  # 3 per node, all cables together
MAX_STEP_BYTES = 2**30  # the memory one step needs: what it keeps and writes, working copies too
WORKING_COPIES = 3  # a transient step needs about 2.7 times what it stores while it runs
MAX_SIMULATED_TIME = 1e7  # s (about 116 days): the transient steps of a case together
MAX_NAME_LENGTH = 100  # characters of a name (cable, node, material, load, step, ...)
MAX_KEY_PARTS = 64  # parts of one dotted TOML key (a.b.c has 3), judged before parsing
MIN_TIME = 1e-9  # s: shortest step duration, output interval or ramp duration
MAX_FREQUENCY = 1e9  # Hz, of a sine or cosine time function
MAX_COORDINATE = 1e7  # m, of a node (10 000 km); far beyond it, squared lengths overflow
MAX_DIAMETER = 1e7  # m, of a line: its area and volume would overflow far beyond it
MAX_LINE_MASS = 1e9  # kg/m and N/m (mass, weight, damping per metre): a solid steel bar 400 m
#                      across; far beyond, the totals (times lengths up to 1e7 m) overflow
MAX_POINT_MASS = 1e15  # kg, of one point mass (a million supertankers)
MAX_EA = 1e15  # N, a material's axial stiffness (a bridge's main cable is about 1e11)
MAX_LENGTH = 1e7  # m, a cable's unstrained length, as the coordinates
MAX_THERMAL_EXPANSION = 1e-3  # 1/K in magnitude (steel 1.2e-5, polymers about 1e-4)
MAX_VECTOR = 1e15  # of a component of a force (N), a distributed load (N/m), a direction,
#                   a fluid velocity: far beyond, sums and products overflow
TABLE_ROOTS_ENV = "CATDAE_TABLE_ROOTS"  # more folders table files may be read from


def human_bytes(n: float) -> str:
    for unit in ("bytes", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024 or unit == "PiB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.3g} {unit}"
        n /= 1024
    return f"{n:.3g} PiB"  # pragma: no cover - the loop returns


class FileProblem(Exception):
    """Why a file cannot be read (worded for a message; never quotes the file's content)."""


def read_limited(path: Path, what: str) -> bytes:
    """The bytes of a regular file of at most MAX_FILE_BYTES. A FIFO, a device (``/dev/zero``)
    or a directory is refused without blocking or reading it."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise FileProblem(exc.strerror or str(exc)) from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise FileProblem(f"not a regular file (a {what} must be an ordinary file)")
        if st.st_size > MAX_FILE_BYTES:
            raise FileProblem(f"{human_bytes(st.st_size)}, above the limit of "
                              f"{human_bytes(MAX_FILE_BYTES)} for a {what}")
        chunks, size = [], 0
        while size <= MAX_FILE_BYTES:
            b = os.read(fd, 1 << 20)
            if not b:
                break
            chunks.append(b)
            size += len(b)
        if size > MAX_FILE_BYTES:
            raise FileProblem(f"it grew beyond the limit of {human_bytes(MAX_FILE_BYTES)} for "
                              f"a {what} while being read")
        return b"".join(chunks)
    except OSError as exc:
        raise FileProblem(exc.strerror or str(exc)) from None
    finally:
        os.close(fd)


def table_roots(base_dir: Path) -> list[Path]:
    """Folders a table file may be in: the case's own folder, and those listed (separated by
    ``os.pathsep``) in the environment variable CATDAE_TABLE_ROOTS."""
    roots = [base_dir]
    roots += [Path(p) for p in os.environ.get(TABLE_ROOTS_ENV, "").split(os.pathsep) if p]
    return [r.resolve() for r in roots]


def confined(name: str, base_dir: Path) -> Path:
    """The table file ``name`` (relative to the case's folder, or absolute), resolved with its
    symbolic links; FileProblem unless it lies inside one of :func:`table_roots`."""
    if "\x00" in name:
        raise FileProblem("the file name holds a NUL character")
    file = (base_dir / name).resolve()
    roots = table_roots(base_dir)
    if not any(file.is_relative_to(r) for r in roots):
        where = str(roots[0]) if len(roots) == 1 else ", ".join(str(r) for r in roots)
        raise FileProblem(f"it is outside the case's folder ({where}); table files must be "
                          f"inside it, or in a folder listed in {TABLE_ROOTS_ENV}")
    return file


def output_count(duration: float, output_interval: float) -> float:
    """Output times of a transient step (as transient.run_transient lays them out), as a float
    so that absurd requests are counted without overflow."""
    q = duration / output_interval  # inf for a duration near 1e308: counted, not floored
    return (math.floor(q + 1e-9) if math.isfinite(q) else math.inf) + 2.0


def transient_bytes(n_out: float, n_nodes: int, n_elements: int) -> float:
    """What a transient step stores: per output, position, displacement, velocity,
    acceleration and reaction (n_nodes, 3), tension (n_elements, 2), four energies."""
    return 8.0 * n_out * (5 * 3 * n_nodes + 2 * n_elements + 4)


def modal_bytes(modes: int, n_free: int, n_nodes: int, dense: bool) -> float:
    """Mode shapes (modes, n_nodes, 3); with the dense solver, K and M (n_free²), the
    eigenvectors and the solver's working copies of K and M too."""
    k = min(modes, n_free)
    return 8.0 * (k * 3 * n_nodes + (5.0 * n_free * n_free if dense else 2.0 * k * n_free))


def size_problems(case) -> list[tuple[str, str]]:
    """Counts and sizes of a validated Case against the limits: the mesh (dofs) and what each
    step will store, as ``(field path, message)``; empty when all fit."""
    ends = {e for c in case.cables for e in c.ends}
    n_elements = sum(c.elements for c in case.cables)
    n_nodes = len(ends) + sum(c.elements - 1 for c in case.cables)
    if 3 * n_nodes > MAX_DOFS:
        return [("cables", f"the mesh would have {n_nodes} nodes ({3 * n_nodes} degrees of "
                 f"freedom, {n_elements} elements), above the limit of {MAX_DOFS} degrees of "
                 "freedom; use fewer elements")]
    n_free = 3 * n_nodes - sum(len(axes) for node, axes in case.supports.items() if node in ends)
    problems = []
    for i, step in enumerate(case.steps):
        if step.kind == "transient":
            n_out = output_count(step.duration, step.output_interval)
            size = transient_bytes(n_out, n_nodes, n_elements)
            if WORKING_COPIES * size > MAX_STEP_BYTES:
                problems.append((f"steps[{i}].output_interval", (
                    f"transient step '{step.name}' would store {n_out:.4g} outputs of "
                    f"{n_nodes} nodes and {n_elements} elements, {human_bytes(size)}, and need "
                    f"about {human_bytes(WORKING_COPIES * size)} of memory with its working "
                    f"copies, above the limit of {human_bytes(MAX_STEP_BYTES)} per step; make "
                    "output_interval longer, the duration shorter, or split the step")))
        elif step.kind == "modal":
            size = modal_bytes(step.modes, n_free, n_nodes, dense=step.modes >= n_free - 1)
            if size > MAX_STEP_BYTES:
                problems.append((f"steps[{i}].modes", (
                    f"modal step '{step.name}': {min(step.modes, n_free)} modes of {n_free} "
                    f"free degrees of freedom need {human_bytes(size)}, above the limit of "
                    f"{human_bytes(MAX_STEP_BYTES)} per step; ask for fewer modes")))
    total = sum(s.duration for s in case.steps if s.kind == "transient")
    if total > MAX_SIMULATED_TIME:
        problems.append(("steps", f"the transient steps simulate {total:.4g} s together, above "
                         f"the limit of {MAX_SIMULATED_TIME:g} s (about 116 days) of simulated "
                         "time per case; shorten the durations"))
    return problems


_PART = r"""(?:[A-Za-z0-9_-]+|"(?:[^"\\\n]|\\.)*"|'[^'\n]*')"""
_DOTTED = re.compile(rf"(?:[ \t]*\.[ \t]*{_PART})+")  # a run of ".part" on one line
_SEPARATORS = re.compile(rf"[ \t]*\.[ \t]*(?={_PART})")


def key_depth_problem(text: str) -> str | None:
    """A dotted key of more than MAX_KEY_PARTS parts, judged before parsing (the TOML parser
    takes time quadratic in the parts of one key: 50 000 parts of a 100 KB file take minutes).
    Finds runs of ``.part`` (bare or quoted) on one line, in linear time; such a run inside a
    string counts too, which no real case holds. Returns the message, or None."""
    if text.count(".") < MAX_KEY_PARTS:
        return None
    for m in _DOTTED.finditer(text):
        if m[0].count(".") >= MAX_KEY_PARTS and \
                len(_SEPARATORS.findall(m[0])) >= MAX_KEY_PARTS:
            line = text.count("\n", 0, m.start()) + 1
            return (f"line {line}: a dotted key of more than {MAX_KEY_PARTS} parts, above the "
                    f"limit of {MAX_KEY_PARTS} parts per key")
    return None
