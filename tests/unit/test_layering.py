"""The pipeline is the folder list and no import points back up it (issue 20): a module may
import its own stage and earlier ones only, in the order

    base (errors, _version, _xr, _numpy_extras, interrupts, progress) -> case -> element
    -> model -> solvers -> output -> analysis -> study -> cli

(element and case are independent; element imports neither). Checked on the source with ast,
imports inside functions included, so a lazy import cannot hide an upward arrow."""

from __future__ import annotations

import ast

import pytest

from repo_paths import ROOT

PACKAGE = ROOT / "catdae"
RANK = {"errors": 0, "_version": 0, "_xr": 0, "_numpy_extras": 0, "interrupts": 0, "progress": 0,
        "case": 1, "element": 1, "model": 2, "solvers": 3, "output": 4, "analysis": 5,
        "study": 6, "cli": 7, "__main__": 8, "_entry": 8, "__init__": 8}
MODULES = sorted(p for p in PACKAGE.rglob("*.py"))


def _stage(parts: list[str]) -> str:
    """The stage of a module path inside catdae (``["solvers", "residual"]`` -> solvers)."""
    return parts[0]


def _imports(path):
    """(line, imported catdae module as parts) of every import of catdae in a file."""
    tree = ast.parse(path.read_text(), str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module == "catdae":
                for alias in node.names:
                    yield node.lineno, [alias.name]
            elif node.module.startswith("catdae."):
                yield node.lineno, node.module.split(".")[1:]
        elif isinstance(node, ast.ImportFrom) and node.level:
            yield node.lineno, None  # relative imports are not used (absolute, one style)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("catdae."):
                    yield node.lineno, alias.name.split(".")[1:]


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_import_points_back_up_the_pipeline(path):
    rel = path.relative_to(PACKAGE).with_suffix("").parts
    own = RANK[_stage(list(rel))]
    bad = []
    for line, target in _imports(path):
        if target is None:
            bad.append(f"line {line}: a relative import")
            continue
        stage = _stage(target)
        if stage == "__version__":
            bad.append(f"line {line}: __version__ from the package root (use catdae._version)")
        elif stage in RANK and RANK[stage] > own and stage != rel[0]:
            bad.append(f"line {line}: imports catdae.{'.'.join(target)} (a later stage)")
    assert not bad, f"{path.relative_to(ROOT)}: " + "; ".join(bad)


def test_every_stage_is_ranked():
    stages = {p.relative_to(PACKAGE).parts[0].removesuffix(".py") for p in MODULES}
    assert stages <= set(RANK), stages - set(RANK)


def test_no_module_over_400_lines():
    """A module a newcomer can read in one sitting (issue 20): none over 400 lines."""
    long = {str(p.relative_to(PACKAGE)): n for p in MODULES
            if (n := len(p.read_text().splitlines())) > 400}
    assert not long, long


def test_no_solver_function_over_60_lines():
    """The solver drivers read as named phases (issue 20): no function in catdae/solvers is
    longer than 60 lines (decorators and docstring included)."""
    long = {}
    for p in sorted((PACKAGE / "solvers").glob("*.py")):
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                first = min([node.lineno] + [d.lineno for d in node.decorator_list])
                if node.end_lineno - first + 1 > 60:
                    long[f"{p.name}:{node.name}"] = node.end_lineno - first + 1
    assert not long, long


def test_no_private_name_is_imported_across_modules():
    """A name another module imports is part of its module's interface, so it is public: no
    ``from catdae.x import _name`` (``import x as _alias`` of a public name is fine)."""
    private = [f"{p.relative_to(PACKAGE)}:{node.lineno} {node.module}.{a.name}"
               for p in MODULES for node in ast.walk(ast.parse(p.read_text()))
               if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("catdae")
               for a in node.names if a.name.startswith("_") and not a.name.startswith("__")]
    assert not private, private
