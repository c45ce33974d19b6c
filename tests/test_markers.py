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


def test_slow_marker_follows_simulations():
    """`slow` (tests/conftest.py) is on the serial tests that run a simulation, directly
    or through a fixture, and on no other: `make test-quick` leaves them to `make test`."""
    slow = collected("-m", "slow", "tests/test_api.py", "tests/test_gas.py", "tests/test_verify.py")
    every = collected("tests/test_api.py", "tests/test_gas.py", "tests/test_verify.py")
    # test_api's run-file fixture runs blast_demo; two tests do without it
    api = {t for t in every if t.startswith("tests/test_api.py")}
    assert {t for t in slow if t.startswith("tests/test_api.py")} == api - {
        "tests/test_api.py::test_import_mpipd_loads_no_reading_code",
        "tests/test_api.py::test_not_a_run_file_is_one_clear_error"}
    assert "tests/test_gas.py::test_the_skin_changes_how_often_the_gas_is_searched_not_the_answer" in slow
    assert "tests/test_gas.py::test_the_skin_tuner_settles_at_the_cheapest_skin" not in slow
    assert {t for t in every if t.startswith("tests/test_verify.py")} <= slow   # verify.py runs
    quick = collected("-m", "not mpi and not long and not slow", "tests/test_gas.py")
    assert quick and not quick & slow
