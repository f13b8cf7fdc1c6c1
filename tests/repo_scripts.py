"""A script of the repository (``benchmarks/*.py``) loaded as a module, for the tests of what it computes.

The tests' folder is on ``sys.path`` (pytest puts the folder of ``tests/conftest.py`` there), so a test
imports this as ``from repo_scripts import load_script``.
"""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def load_script(relative):
    """The module of the script at ``relative`` (a path from the repository root), executed once per call."""
    path = ROOT / relative
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
