"""The documented module names stay importable after the move into stage packages
(``catdae.plot`` and ``catdae.export`` live in catdae/output/), and stay lazy: ``import
catdae`` does not load matplotlib or meshio."""

import subprocess
import sys

PROBE = """
import sys
import catdae
assert "matplotlib" not in sys.modules and "meshio" not in sys.modules
import catdae.plot
from catdae.plot import modes, profile, write_all
from catdae import export
from catdae.export import write_vtk
import catdae.output.plot as real
assert catdae.plot is real and modes is real.modes and export.write_vtk is write_vtk
print("ok")
"""


def test_documented_modules_import_lazily():
    proc = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0 and proc.stdout.strip() == "ok", proc.stderr[-3000:]
