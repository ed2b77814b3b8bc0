"""The test tree: ``unit/`` mirrors the package (one file per module or stage), ``scenes/``
holds the physics scenes. Shared helpers live here, beside this file, and are importable from
both: ``scene_toml`` (the TOML text of the common scenes), ``reference`` (closed forms),
``repo_paths`` (the repository's folders). Test modules are imported with
``--import-mode=importlib`` (pyproject.toml), so two folders may hold files of the same name."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
