"""Reading a case: pass 1 (TOML syntax), then the builder (passes 2 and 3)."""

from __future__ import annotations

import os
import re
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from catdae.case.build import Builder
from catdae.case.limits import FileProblem, key_depth_problem, read_limited
from catdae.case.messages import found_text
from catdae.case.model import Case
from catdae.errors import CaseError


def load_case(path_or_text: str | os.PathLike, *, name: str | None = None,
              elements: int | None = None) -> Case:
    """Read and validate a case.

    ``elements``: the case as ``Case.with_overrides(elements=...)`` gives it, its counts and
    sizes judged against the limits for that mesh, not for the file's (``catdae run
    --elements``: fewer elements than the file's may fit where the file's do not).

    ``path_or_text`` is a path (a ``PathLike``, or a one-line string ending in ``.toml`` or naming
    an existing file) or the TOML text itself. ``name`` defaults to the file's stem, or ``"case"``
    for text. A ``table`` time function's ``file`` is relative to the case file's folder (to the
    current directory for text). Raises ``CaseError`` listing every problem found.
    """
    path: str | None = None
    if isinstance(path_or_text, os.PathLike) or _looks_like_path(path_or_text):
        path = os.fspath(path_or_text)
        try:
            raw = read_limited(Path(path), "case file")
        except FileProblem as exc:
            raise CaseError(path, [("", f"cannot read the case file: {exc}")]) from None
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise CaseError(path, [("", f"the case file is not UTF-8 text: {exc}")]) from None
    elif isinstance(path_or_text, bytes | bytearray):
        try:
            text = bytes(path_or_text).decode("utf-8")
        except UnicodeDecodeError as exc:
            raise CaseError(None, [("", f"the case text is not UTF-8: {exc}")]) from None
    elif isinstance(path_or_text, str):
        text = path_or_text
    else:
        raise CaseError(None, [("", "expected a path or TOML text, found "
                                    f"{type(path_or_text).__name__}")])
    text = text.removeprefix("\ufeff")
    if (deep := key_depth_problem(text)) is not None:  # before parsing: its cost is quadratic
        raise CaseError(path, [("", deep)])
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CaseError(path, [("", _toml_message(str(exc)))]) from None
    except RecursionError:
        msg = "malformed TOML: arrays or tables nested too deeply"
        raise CaseError(path, [("", msg)]) from None
    if name is None:
        name = Path(path).stem if path else "case"
    base_dir = Path(path).parent if path else Path.cwd()
    case = case_from_dict(data, path=path, text=text, name=name, base_dir=base_dir,
                          judge_size=elements is None)
    return case if elements is None else case.with_overrides(elements=elements)


def case_from_dict(data: Mapping[str, Any], *, path: str | None = None, text: str = "",
                   name: str = "case", base_dir: str | os.PathLike | None = None,
                   judge_size: bool = True) -> Case:
    """Validate an already-parsed case (the dict ``tomllib`` returns) and build the Case.

    ``base_dir`` resolves ``table`` files (default: the current directory). ``judge_size``
    False leaves the limits on counts and sizes to the caller's ``with_overrides(elements=)``.
    """
    if not isinstance(data, Mapping):
        raise CaseError(path, [("", f"expected a table of keys, found {found_text(data)}")])
    builder = Builder(path, Path(base_dir) if base_dir is not None else Path.cwd())
    return builder.build(dict(data), text=text, name=name, judge_size=judge_size)


def _looks_like_path(obj: Any) -> bool:
    if not isinstance(obj, str) or "\n" in obj:
        return False
    try:
        if Path(obj).exists():  # a file, or a directory (reported as unreadable)
            return True
    except (OSError, ValueError):
        return False
    return obj.strip().endswith(".toml") and "=" not in obj


def _toml_message(msg: str) -> str:
    m = re.search(r"\s*\(at line (\d+), column (\d+)\)\s*$", msg)
    if m:
        return f"malformed TOML at line {m[1]}, column {m[2]}: {msg[: m.start()]}"
    m = re.search(r"\s*\(at end of document\)\s*$", msg)
    if m:
        return f"malformed TOML at the end of the document: {msg[: m.start()]}"
    return f"malformed TOML: {msg}"
