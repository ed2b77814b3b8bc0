"""Pass 3 for time functions: their kinds, tables and the CSV files behind them. A mixin of
:class:`~catdae.case.build.Builder`, whose ``problem`` and ``validate`` collect what is
wrong (see ``build``)."""

from __future__ import annotations

import csv
import math
import re
import warnings
from collections.abc import Mapping

import numpy as np

from catdae.case.limits import FileProblem, confined, read_limited
from catdae.case.messages import found_text, shorten, suggest, unknown_word
from catdae.case.records import AccelerationRecord, VelocityRecord
from catdae.case.schema import (
    TIME_MODELS,
    TableSchema,
)
from catdae.case.timefunc import Constant, Cosine, Ramp, Sine, Table, TimeFunction
from catdae.case.timefunc_compose import Product, Trapezoid

_OVERFLOW = ("its value, rate or second derivative overflows (not a finite number): check the "
             "amplitude against the duration, the frequency or the spacing of the points")


class TimePass:
    """Time functions and tables (methods of ``_Builder``)."""

    def kind_of(self, raw: dict, where: tuple, models: Mapping, what: str) -> str | None:
        kind = raw.get("kind")
        if isinstance(kind, str) and kind in models:
            return kind
        if "kind" not in raw:
            self.problem(where + ("kind",), "missing: this key is required (one of "
                         f"{', '.join(repr(k) for k in models)})")
        elif isinstance(kind, str):
            self.problem(where + ("kind",), unknown_word(kind, what, models))
        else:
            self.problem(where + ("kind",), f"expected a string, found {found_text(kind)}")
        return None

    def kinded(self, raw: dict, where: tuple, models: Mapping, what: str):
        """(kind, validated fields) of a table with a ``kind`` key choosing its model, or
        (None, None) where the kind or a field is wrong (the problems are recorded)."""
        kind = self.kind_of(raw, where, models, what)
        if kind is None:
            return None, None
        v, complete = self.validate(models[kind], raw, where)
        return (kind, v) if complete else (None, None)

    def time_function(self, raw: dict, where: tuple, motion: bool = False
                      ) -> TimeFunction | None:
        """A time function; ``motion``: it prescribes a support's displacement (a ``table``
        may then be a velocity or acceleration record)."""
        kind, v = self.kinded(raw, where, TIME_MODELS, "time function kind")
        if kind is None:
            return None
        if kind == "constant":
            tf: TimeFunction | None = Constant(float(v.value))
        elif kind == "ramp":
            tf = Ramp(float(v.duration), float(v.start), v.smooth, float(v.amplitude))
        elif kind in ("sine", "cosine"):
            cls = Sine if kind == "sine" else Cosine
            tf = cls(float(v.amplitude), float(v.frequency), float(v.phase), float(v.offset))
        elif kind in ("product", "trapezoid"):
            tf = self.composed(kind, v, where, motion)
        else:
            tf = self.table(v, where, motion)
        if tf is not None and not _finite(tf):
            self.problem(where, _OVERFLOW)
            return None
        return tf

    def composed(self, kind: str, v, where: tuple, motion: bool) -> TimeFunction | None:
        """A ``product`` of time functions or a ``trapezoid`` (catdae.case.timefunc_compose)."""
        if kind == "trapezoid":
            return Trapezoid(float(v.rise), float(v.hold), float(v.fall), float(v.start),
                             float(v.amplitude), v.smooth)
        if len(v.factors) < 2:
            self.problem(where + ("factors",), "expected at least 2 time functions to "
                         f"multiply, found {len(v.factors)}")
            return None
        factors = []
        for j, raw in enumerate(v.factors):
            f = self.time_function(raw, where + ("factors", j), motion)
            if f is None:
                return None
            factors.append(f)
        return Product(tuple(factors))

    def table(self, v: TableSchema, where: tuple, motion: bool = False
              ) -> Table | AccelerationRecord | VelocityRecord | None:
        inline = v.t is not None or v.value is not None
        if v.file is not None and inline:
            self.problem(where, "give either file, or t and value, not both")
            return None
        if v.file is None and not inline:
            self.problem(where, 'a table needs file = "points.csv" or inline t = [...] and '
                         "value = [...]")
            return None
        if v.quantity != "displacement" and not motion:
            self.problem(where + ("quantity",), f"quantity = {v.quantity!r} applies to support "
                         "motions only; a load's time function is a factor that multiplies it")
            return None
        if v.column is not None and v.file is None:
            self.problem(where + ("column",), "column selects a column of a table file; an "
                         "inline table has one list of values")
            return None
        if v.file is not None:
            rows = self.read_csv(v.file, where + ("file",), v.column, where + ("column",))
            if rows is None:
                return None
            t, value, at = [r[0] for r in rows], [r[1] for r in rows], where + ("file",)
        else:
            for k in ("t", "value"):
                if getattr(v, k) is None:
                    self.problem(where + (k,), f"missing: needed together with "
                                 f"{'value' if k == 't' else 't'}")
            if v.t is None or v.value is None:
                return None
            t, value, at = v.t, v.value, where + ("t",)
            if len(t) != len(value):
                self.problem(where + ("value",), f"expected {len(t)} values, one per time in "
                             f"t, found {len(value)}")
                return None
        src = f"{shorten(v.file)}: " if v.file is not None else ""  # a file's rows: name it
        if len(t) < 2:
            self.problem(at, f"{src}expected at least 2 points, found {len(t)}")
            return None
        for j in range(1, len(t)):
            if not t[j] > t[j - 1]:
                where_j = f"data rows {j} and {j + 1}" if src else f"point {j}"
                self.problem(at, f"{src}expected strictly increasing times, found "
                             f"{t[j - 1]:g} then {t[j]:g} ({where_j})")
                return None
        t, value = tuple(float(x) for x in t), tuple(float(x) for x in value)
        with np.errstate(all="ignore"), warnings.catch_warnings():
            # points too close for their values overflow the spline (judged by _finite), or
            # values near 1e308 overflow its slopes (scipy refuses them: the same problem)
            warnings.simplefilter("ignore", RuntimeWarning)
            try:
                if v.quantity == "acceleration":
                    return AccelerationRecord(t, value, v.file, v.column)
                if v.quantity == "velocity":
                    return VelocityRecord(t, value, v.file, v.column)
                return Table(t, value, v.file)
            except (ValueError, OverflowError, ZeroDivisionError):
                self.problem(where, _OVERFLOW)
                return None

    def read_csv(self, name: str, where: tuple, column: str | None = None,
                 column_where: tuple = ()) -> list[tuple[float, float]] | None:
        """Rows ``time, value`` of a CSV file; blank and ``#`` lines skipped, one header allowed.

        With ``column``, the file has a header naming its columns (time first) and the value
        is taken from the column of that name. The file must be a regular file inside the case's
        folder (or a folder listed in CATDAE_TABLE_ROOTS) of at most MAX_FILE_BYTES; problems
        name the line, never quote a data row.
        """
        try:
            file = confined(name, self.base_dir)
            raw = read_limited(file, "table file")
        except FileProblem as exc:
            self.problem(where, f"cannot read table file {shorten(name)}: {exc}")
            return None
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            self.problem(where, f"cannot read table file {shorten(name)}: not UTF-8 text "
                         f"(byte {exc.start})")
            return None
        lines = []
        reader = csv.reader(text.splitlines())
        while True:
            try:
                row = next(reader)
            except StopIteration:
                break
            except csv.Error as exc:  # a field over the csv module's limit, a stray quote...
                self.problem(where, f"{shorten(name)}, line {reader.line_num}: not readable "
                             f"as CSV ({str(exc)[:80]})")
                return None
            cells = [c.strip() for c in row]
            if any(cells) and not cells[0].startswith("#"):
                lines.append((reader.line_num, cells))
        header: list[str] | None = None
        if lines and not all(_is_float(c) for c in lines[0][1]):
            header = lines[0][1]  # a header line such as "time,value" or "t,ax,ay,az"
            lines = lines[1:]
        width = len(header) if header is not None else len(lines[0][1]) if lines else 2
        first = lines[0][1] if lines else (header or [])  # a data row, else the header
        sep = next((c for c in (";", "\t", " ") if len(first) == 1 and c in first[0]), None)
        if sep is not None:  # one column: another separator than the comma
            self.problem(where, f"{name} has one column per line, its values separated by "
                         f"{'a tab' if sep == chr(9) else repr(sep)}: catdae reads CSV, values "
                         "separated by commas (e.g. t,ax)")
            return None
        if column is None and width != 2:
            names = f" ({_columns(header)})" if header is not None else ""
            self.problem(where, f"{name} has {width} columns{names}: choose the value column "
                         'with column = "<name>" (time is the first column)')
            return None
        index = 1
        if column is not None:
            if header is None:
                self.problem(column_where, f"column = {column!r} needs a header line in {name} "
                             "naming its columns, time first (e.g. t,ax,ay,az); found none")
                return None
            if column not in header[1:]:
                listed = _listed(header)
                hint = (f"{column!r} is the time column" if column == header[0] else
                        f"{name} has no column {shorten(column)}"
                        f"{suggest(column, header[1:]) if listed else ''} (its columns: "
                        f"{_columns(header)}; time is the first)")
                self.problem(column_where, hint)
                return None
            index = header.index(column)
        expect = "two numbers 'time,value'" if width == 2 else f"{width} numbers per row"
        rows = []
        for lineno, cells in lines:
            if len(cells) != width or not all(_is_float(c) for c in cells):
                found = (f"{len(cells)} field(s)" if len(cells) != width
                         else "a field that is not a number")
                self.problem(where, f"{shorten(name)}, line {lineno}: expected {expect}, found "
                             f"{found}")
                return None
            pair = (float(cells[0]), float(cells[index]))
            if not all(math.isfinite(float(c)) for c in cells):
                self.problem(where, f"{shorten(name)}, line {lineno}: expected finite numbers, "
                             "found inf or nan")
                return None
            rows.append(pair)
        return rows


def _finite(tf: TimeFunction) -> bool:
    """f, f' and f'' finite, and with finite squares (below 1e150: energies and norms square
    them), where they are largest: at 0, the breakpoints, inside a ramp (f'' peaks at x = 0.21
    and 0.79), at a quarter period, at a table's points and between."""
    ts = [0.0, *tf.breakpoints()]
    if isinstance(tf, Ramp):
        ts += [tf.start + tf.duration * x for x in (0.2113, 0.5, 0.7887)]
    elif isinstance(tf, Sine | Cosine):
        ts += [0.25 / tf.frequency, 0.5 / tf.frequency]
    elif isinstance(tf, Table):
        t = np.asarray(tf.t)
        ts += [*t, *(0.5 * (t[1:] + t[:-1]))]
    with np.errstate(all="ignore"):
        values = tf.evaluate(np.asarray(ts, float))
    return all((np.isfinite(v) & (np.abs(v) < 1e150)).all() for v in values)


_LABEL = re.compile(r"[A-Za-z_][A-Za-z0-9_.()/ -]{0,31}")
MAX_LISTED_COLUMNS = 20


def _listed(header: list[str]) -> bool:
    """Whether a header line is a short list of column names, shown in messages; any other
    line (long, many columns, odd characters) is described, never quoted."""
    return len(header) <= MAX_LISTED_COLUMNS and all(_LABEL.fullmatch(c) for c in header)


def _columns(header: list[str]) -> str:
    if _listed(header):
        return ", ".join(header)
    return (f"{len(header)} columns, not listed: the header line is not a short list of "
            "names")


def _is_float(cell: str) -> bool:
    """Whether a CSV cell reads as a number (inf and nan included: reported as not finite)."""
    try:
        float(cell)
    except ValueError:
        return False
    return True

