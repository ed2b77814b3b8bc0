"""The code passes ``ruff check`` (the rules in pyproject.toml), so lint runs with the suite and
in CI without a separate command."""

import subprocess
import sys

from repo_paths import ROOT


def test_ruff_check_passes():
    proc = subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", "catdae", "tests",
                           "benchmarks", "docs"], cwd=ROOT, capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-2000:]
