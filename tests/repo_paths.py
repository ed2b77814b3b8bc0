"""Folders of the repository that tests read (cases, docs, notebooks)."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"
