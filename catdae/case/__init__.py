"""TOML case file -> validated, frozen model of the scene and its analysis steps.

``load_case`` reads a case file (the public format, case-format.md, names every key) and returns a
:class:`Case`: frozen dataclasses, tuples and read-only mappings, nothing mutable. Reading works
in three passes, and every problem of every pass is collected before anything is raised, so that a
single :class:`~catdae.errors.CaseError` lists all of them with their field paths
(``cables[0].length``, ``materials.strand.EA``):

1. TOML syntax (``tomllib``); a malformed file stops here, with line and column.
2. Shape and types of each item on its own (pydantic v2 models, strict, ``extra='forbid'``):
   unknown keys get a did-you-mean suggestion, wrong types say what was expected and found.
3. Cross references and physics: names that exist and are unique, mesh-node references, supports,
   removals, coinciding ends, excessive strain, slack weightless cables.

An item that fails pass 2 is left out of pass 3, but its name still counts as declared so that
one typo does not cascade into a list of "unknown" errors elsewhere.

A case is data: values are only ever read as numbers, strings and tables, never evaluated, and no
module is imported by a name taken from the file. The only side effect is reading the CSV file a
``table`` time function names, relative to the case file's folder.

The package follows those seams, so that a field is found where it is declared, checked and
explained:

- :mod:`~catdae.case.model`: the frozen model (dataclasses) the rest of catdae reads;
- :mod:`~catdae.case.read`: ``load_case`` and ``case_from_dict``, pass 1 (TOML);
- :mod:`~catdae.case.schema`: pass 2, the shape and types of each item (pydantic);
- :mod:`~catdae.case.build`: pass 3, cross references and physics, building the model;
- :mod:`~catdae.case.messages`: how problems are worded (field paths, "expected ..., found ...");
- :mod:`~catdae.case.limits`: counts and sizes judged before any work, and how files are read
  (regular files only, bounded, table files confined to the case's folder).
"""

from catdae.case.model import (
    AXES,
    Cable,
    Case,
    Damping,
    DistributedLoad,
    Form,
    FrozenMap,
    Load,
    Material,
    PointMass,
    Step,
    SupportMotion,
)
from catdae.case.read import case_from_dict, load_case

__all__ = [
    "AXES",
    "Cable",
    "Case",
    "Damping",
    "DistributedLoad",
    "Form",
    "FrozenMap",
    "Load",
    "Material",
    "PointMass",
    "Step",
    "SupportMotion",
    "case_from_dict",
    "load_case",
]
