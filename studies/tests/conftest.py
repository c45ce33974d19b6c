"""Tests of the research scripts under studies/ (the diagnoses, the validation record's
rows), kept beside the studies and run by `make test` with the package's tests/.

This conftest is tests/conftest.py's helpers and fixtures, loaded from there under
another module name and re-exported (not its hooks): run together, both folders'
conftest.py are imported as the module ``conftest`` and the one imported last is what
``from conftest import NAME`` finds, in tests/ as here.  A test here that launches
mpirun is marked ``mpi`` by tests/conftest.py's rule (``make test-quick`` runs tests/
only)."""
import importlib.util
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]

_spec = importlib.util.spec_from_file_location("mpipd_tests_conftest", ROOT / "tests" / "conftest.py")
_shared = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_shared)

globals().update({k: v for k, v in vars(_shared).items()
                  if not k.startswith(("__", "pytest_"))})
ROOT = HERE.parents[1]


def pytest_collection_modifyitems(config, items):
    """tests/conftest.py's rules on this folder's tests: ``mpi`` on those that launch
    mpirun, ``slow`` on those that run a simulation; ``long`` ones skipped unless --long
    (an option of tests/conftest.py)."""
    mine = [item for item in items if Path(str(item.path)).resolve().parent == HERE]
    for item in mine:
        sources = _shared._sources(item, HERE)
        if any(_shared._MPIRUN.search(src) for src in sources):
            item.add_marker(pytest.mark.mpi)
        if any(_shared._SIMULATES.search(src) for src in sources):
            item.add_marker(pytest.mark.slow)
    if not config.getoption("--long", default=False):
        for item in mine:
            if "long" in item.keywords:
                item.add_marker(pytest.mark.skip(reason="a long case: run with --long"))
