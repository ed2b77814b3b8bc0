"""How problems are worded: field paths and "expected ..., found ..." messages."""

from __future__ import annotations

import difflib
import math
import re
from collections.abc import Iterable, Mapping
from typing import Any

_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")
MAX_KEY_SHOWN = 60  # characters of one key of a field path in a message


def fmt_path(parts: Iterable[str | int]) -> str:
    """``("cables", 0, "length")`` -> ``cables[0].length``; odd keys are quoted."""
    out = ""
    for p in parts:
        if isinstance(p, int):
            out += f"[{p}]"
        else:
            if len(p) > MAX_KEY_SHOWN:  # a key of 100 000 characters is named, not repeated
                p = f"{p[:MAX_KEY_SHOWN - 20]}...({len(p)} characters)"
            if not _BARE_KEY.fullmatch(p):
                p = '"' + p.replace("\\", "\\\\").replace('"', '\\"') + '"'
            out += f".{p}" if out else p
    return out


def shorten(s: str, n: int = 40) -> str:
    return repr(s if len(s) <= n else s[: n - 3] + "...")


def found_text(v: Any) -> str:
    """Describe a TOML value in a message: what was found."""
    if v is None:
        return "nothing"
    if isinstance(v, bool):
        return f"the boolean {str(v).lower()}"
    if isinstance(v, int):
        text = str(v) if abs(v) < 10**30 else f"{str(v)[:10]}... (too large)"
        return f"the integer {text}"
    if isinstance(v, float):
        return f"the number {v!r}"
    if isinstance(v, str):
        return f"the string {shorten(v)}"
    if isinstance(v, list | tuple):
        if 0 < len(v) <= 6 and all(isinstance(x, int | float) and not isinstance(x, bool)
                                   and (not isinstance(x, int) or abs(x) < 10**15) for x in v):
            return f"the array [{', '.join(repr(x) for x in v)}]"  # e.g. [nan, 0.0, 0.0]
        return f"an array of {len(v)} item{'s' if len(v) != 1 else ''}"
    if isinstance(v, Mapping):
        keys = ", ".join(shorten(str(k), 20) for k in list(v)[:5])
        return f"a table with keys {keys}" if v else "an empty table"
    return f"a {type(v).__name__} value ({shorten(str(v))})"


def suggest(word: str, choices: Iterable[str]) -> str:
    close = difflib.get_close_matches(word, list(choices), n=1)
    return f"; did you mean {close[0]!r}?" if close else ""


def unknown_word(word: str, what: str, choices: Iterable[str]) -> str:
    choices = list(choices)
    hint = suggest(word, choices)
    if not hint:
        hint = (f"; expected one of: {', '.join(repr(c) for c in choices)}" if choices
                else f"; there is no {what} at all")
    return f"unknown {what} {shorten(word)}{hint}"


def pydantic_message(err: dict, fields: Iterable[str], foreign: Mapping[str, str]) -> str:
    """Turn one pydantic error into 'expected ..., found ...'."""
    typ, inp, ctx = err["type"], err.get("input"), err.get("ctx") or {}
    found = found_text(inp)
    if typ == "missing":
        return "missing: this key is required"
    if typ == "extra_forbidden":
        key = str(err["loc"][-1])
        if key in foreign:
            return f"key {key!r} {foreign[key]}"
        close = difflib.get_close_matches(key, list(fields), n=1)
        hint = (f"; did you mean {close[0]!r}?" if close
                else f"; expected one of: {', '.join(fields)}")
        return f"unknown key {shorten(key)}{hint}"
    simple = {
        "float_type": "a number", "int_type": "an integer", "string_type": "a string",
        "bool_type": "true or false", "list_type": "an array", "dict_type": "a table",
        "finite_number": "a finite number", "string_too_short": "a non-empty string",
    }
    if typ in simple:
        return f"expected {simple[typ]}, found {found}"
    bounds = {"greater_than": (">", "gt"), "greater_than_equal": (">=", "ge"),
              "less_than": ("<", "lt"), "less_than_equal": ("<=", "le")}
    if typ in bounds:
        op, key = bounds[typ]
        return f"expected a value {op} {ctx.get(key)}, found {found}"
    if typ in ("too_short", "too_long"):
        # every array with a length constraint has an exact length: [x, y, z], ends, frequencies
        want = ctx.get("min_length") if typ == "too_short" else ctx.get("max_length")
        return f"expected an array of exactly {want} items, found {found}"
    if typ == "literal_error":
        hint = ""
        if isinstance(inp, str):
            hint = suggest(inp, re.findall(r"'([^']*)'", str(ctx.get("expected", ""))))
        return f"expected {ctx.get('expected')}, found {found}{hint}"
    return f"{err.get('msg', 'invalid value')}, found {found}"


def is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
