"""The `mpi` marker is applied (tests/conftest.py) to exactly the tests that launch
mpirun, so that `make test-quick` (-m "not mpi and not long") is the serial tier."""
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def collected(*args):
    res = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q",
                          "-p", "no:cacheprovider", *args], capture_output=True, text=True,
                         cwd=HERE.parent, timeout=300)
    return {line.split("::")[0] + "::" + line.split("::")[1].split("[")[0]
            for line in res.stdout.splitlines() if "::" in line}


def test_mpi_marker_follows_mpirun():
    mpi = collected("-m", "mpi", "tests/test_mpi.py", "tests/test_check.py",
                    "tests/test_report.py")
    every_mpi = collected("tests/test_mpi.py")
    assert every_mpi and every_mpi <= mpi                 # each test of test_mpi runs mpirun
    assert not any(t.startswith("tests/test_check.py") for t in mpi)   # `check` is serial
    # test_report: the tests on a demo run made under mpirun -n 2, not the in-process ones
    report = {t for t in mpi if t.startswith("tests/test_report.py")}
    assert "tests/test_report.py::test_report_on_blast_demo_under_mpirun" in report
    assert len(report) < len(collected("tests/test_report.py"))


def test_no_test_module_imports_another():
    """Shared helpers live in conftest.py (or a helper module), never in a test module
    that another imports."""
    import re
    for path in HERE.glob("test_*.py"):
        text = path.read_text()
        assert not re.search(r"^\s*(from|import)\s+test_\w+", text, re.M), path.name
