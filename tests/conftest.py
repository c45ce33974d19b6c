"""Shared test helpers.

Serial tests run the solver in-process on a one-rank communicator; MPI tests
run the CLI or a script under ``mpirun`` with a timeout, so a deadlock fails
instead of hanging.
"""
import inspect
import os
import re
import subprocess
import sys
from pathlib import Path

os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
os.environ.setdefault("OMPI_MCA_rmaps_base_oversubscribe", "1")

import pytest  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def granite(**kw):
    d = {"model": "elastic", "density": 2660.0, "bulk_modulus": 21.9e9, "shear_modulus": 25.7e9}
    d.update(kw)
    return d


def scene_dict(shape, dx=1e-3, dt=5e-8, steps=10, hourglass=0.01, initial=(), boundaries=(),
               parts=None, **extra):
    d = {
        "scene": {"name": "test"},
        "time": {"dt": dt, "steps": steps},
        "materials": {"granite": granite()},
        "parts": parts or [{"name": "p", "material": "granite", "dx": dx, "shape": shape}],
        "solver": {"hourglass": hourglass},
        "initial": list(initial),
        "boundaries": list(boundaries),
    }
    d.update(extra)
    return d


def make_scene(d):
    from mpipd.input.scene import Scene
    from mpipd.input.schema import build
    return build(Scene, d)


@pytest.fixture(scope="session")
def team():
    from mpi4py import MPI

    from mpipd.parallel.team import Team
    return Team(MPI.COMM_SELF)


_LAUNCHER_VARS = ("PMIX_", "OMPI_MCA_ess", "OMPI_MCA_orte", "OMPI_MCA_pmix", "OMPI_COMM_WORLD",
                  "OMPI_FIRST", "OMPI_APP", "OMPI_UNIVERSE", "OMPI_NUM_APP", "OMPI_FILE_LOCATION")


def child_env():
    """The environment for child mpiruns.  Once this process has initialised MPI
    as a singleton (the ``team`` fixture), Open MPI has setenv()'d PMIx and
    launcher variables into the C environment; a child mpirun that inherits them
    fails silently.  Python's ``os.environ`` snapshot does not hold them."""
    return {k: v for k, v in os.environ.items() if not k.startswith(_LAUNCHER_VARS)}



#: a 1-2 second elastic_wave run (the CLI tests' small run)
SMALL = ["--set", "parts.0.dx=0.002", "--set", "time.dt=2e-7", "--set", "time.t_end=1.2e-5",
         "--set", "output.every=20", "--quiet"]


def md5s(folder: Path) -> dict:
    """md5 of every file in ``folder`` (nothing overwritten: compare before and after)."""
    import hashlib
    return {p.name: hashlib.md5(p.read_bytes()).hexdigest()
            for p in sorted(folder.iterdir()) if p.is_file()}


def one_error(res, *needles, code=2):
    """The CLI exited ``code`` with one distinct ``mpipd: error:`` line (the same line
    from every rank counts once), no traceback, holding every needle; returns it."""
    assert res.returncode == code, res.stdout + res.stderr
    assert "Traceback" not in res.stderr, res.stderr
    lines = {ln for ln in res.stderr.splitlines() if ln.startswith("mpipd")}
    assert len(lines) == 1, res.stderr
    line = lines.pop()
    assert line.startswith("mpipd: error: "), line
    for n in needles:
        assert n in line, line
    return line

#: a terminal colour code: under mpirun a rank's stdout is a pseudo-terminal, and
#: numba's colorama wrote a colour reset (ESC[0m, no newline) to it at exit, which
#: mpirun forwarded ahead of another rank's next line (test_restart's probe lines,
#: benchmarks/verify.py's rows).  mpipd/__init__.py turns that colouring off; the tests
#: still take any colour code out, so that one from elsewhere cannot fail them
ANSI = re.compile(r"\x1b\[[0-9;]*m")


def _clean(res):
    """``res`` with the colour codes taken out of stdout and stderr."""
    res.stdout, res.stderr = ANSI.sub("", res.stdout or ""), ANSI.sub("", res.stderr or "")
    return res


def run_cli(args, ranks=None, timeout=300, cwd=None):
    """Run ``mpipd ARGS`` (under ``mpirun -n ranks`` if given); returns CompletedProcess
    (stdout and stderr without terminal colour codes: :data:`ANSI`)."""
    cmd = [str(BIN / "mpipd"), *args]
    if ranks is not None:
        cmd = ["mpirun", "--oversubscribe", "-n", str(ranks), *cmd]
    return _clean(subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                                 cwd=cwd, env=child_env()))


def restart_matches(checkpoint, reference, keys, ranks, timeout=300) -> Path:
    """Continue ``checkpoint`` with ``mpipd run --restart`` on ``ranks`` ranks and check
    that the run file it completes equals ``reference`` bit for bit in the datasets
    ``keys``; returns the completed run file."""
    import h5py
    import numpy as np
    res = run_cli(["run", "--restart", str(checkpoint), "--quiet"], ranks=ranks, timeout=timeout)
    assert res.returncode == 0, res.stdout + res.stderr
    out = Path(checkpoint).parent / "run.h5"
    with h5py.File(out, "r") as f, h5py.File(reference, "r") as g:
        for k in keys:
            assert np.array_equal(f[k][...], g[k][...]), k
    return out


def run_mpi_script(script, ranks, *args, timeout=300):
    cmd = ["mpirun", "--oversubscribe", "-n", str(ranks), sys.executable, str(script), *args]
    return _clean(subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                                 env=child_env()))


# ------------------------------------------------------------------ long stability cases
def pytest_addoption(parser):
    parser.addoption("--long", action="store_true",
                     help="also run the tests marked `long` (minutes each; make stability)")


#: what launches mpirun in a test's source: run_cli(..., ranks=N), restart_matches,
#: run_mpi_script, or a command list that starts with "mpirun"
_MPIRUN = re.compile(r"\brun_cli\((?:[^()]|\([^()]*\))*?\branks\s*=|\brestart_matches\("
                     r"|\brun_mpi_script\(|[\[(=]\s*[\"']mpirun[\"']")
_CALL = re.compile(r"\b([A-Za-z_]\w*)\(")
#: what runs a simulation in a test's source (the `slow` marker, out of make test-quick):
#: a Simulation built in-process, `mpipd run` through run_cli or an argument list that
#: starts with "run", or the verification script
_SIMULATES = re.compile(r"\bSimulation\(|\brun_cli\(\[\s*(?:[\"']run[\"']|\*SCENE\b)"
                        r"|\bargs\s*=\s*\[\s*[\"']run[\"']|\bverify\.py\b")


def _sources(item, here=None):
    """The source of a test function, of every fixture it uses that is defined under
    ``here`` (default tests/; studies/tests/conftest.py passes its own folder), and of
    the functions of the test's own module that these call (transitively)."""
    here = here or Path(__file__).resolve().parent
    module = getattr(item, "module", None)
    todo = [getattr(item, "function", None)]
    defs = getattr(getattr(item, "_fixtureinfo", None), "name2fixturedefs", {}) or {}
    for fdefs in defs.values():
        todo += [d.func for d in fdefs]
    seen, out = set(), []
    while todo:
        f = todo.pop()
        if f is None or f in seen:
            continue
        seen.add(f)
        try:
            if Path(inspect.getsourcefile(f)).resolve().parent != here:
                continue
            src = inspect.getsource(f)
        except (OSError, TypeError):
            continue
        out.append(src)
        for name in _CALL.findall(src):
            g = getattr(module, name, None)
            if inspect.isfunction(g) and g.__module__ == getattr(module, "__name__", None):
                todo.append(g)
    return out


def pytest_collection_modifyitems(config, items):
    """Mark every test that launches mpirun (directly or through a fixture) ``mpi``, so
    that ``-m "not mpi"`` is the serial tier, and every test that runs a simulation
    (:data:`_SIMULATES`, directly or through a fixture) ``slow``, so that ``-m "not mpi
    and not long and not slow"`` (make test-quick) is the serial unit tier; skip the
    ``long`` ones unless --long."""
    for item in items:
        sources = _sources(item)
        if any(_MPIRUN.search(src) for src in sources):
            item.add_marker(pytest.mark.mpi)
        if any(_SIMULATES.search(src) for src in sources):
            item.add_marker(pytest.mark.slow)
    if config.getoption("--long"):
        return
    skip = pytest.mark.skip(reason="a long stability case: run by `make stability` "
                                   "(part of `make verify`)")
    for item in items:
        if "long" in item.keywords:
            item.add_marker(skip)


# ------------------------------------------------------------------ shared by several test modules
#: built-in scenes reduced to seconds; together they build every model (blast_demo
#: with step classes: multi-rate's arrays are state too)
SCENES = [
    ("elastic_wave", ["parts.0.dx=0.004"]),
    ("granite_ring", ["parts.0.dx=0.002"]),
    ("detonation_tube", ["parts.2.shape.radius=0.005"]),
    ("blast_demo", ["parts.0.shape.z=[0.0, 0.003]", "parts.1.shape.z=[0.0, 0.003]",
                    "parts.2.shape.z=[0.0, 0.003]", "parts.2.shape.radius=0.012",
                    "time.t_end=4e-7", "probes=[]",
                    'output.fields=["u","peak_pressure","peak_speed","pressure","damage"]',
                    "time.multirate={ max_ratio = 4, safety = 0.5 }"]),
]


def check_bad(res, out, *needles, mpirun=False):
    assert res.returncode == 2, res.stderr
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    if mpirun:                       # mpirun adds its own banner around ours
        lines = [ln for ln in lines if ln.startswith("mpipd")]
    assert len(lines) == 1, res.stderr
    assert lines[0].startswith("mpipd: error: ")
    for n in needles:
        assert n in lines[0], lines[0]
    assert not out.exists()


def free_charge(dt_factor=0.3, steps=200, radius=0.002, length=0.006, dx=5e-4):
    """A free JWL charge (a cylinder of the paper's explosive), dt at dt_factor of the stable step."""
    d = {"scene": {"name": "free_charge"},
         "time": {"dt": 1e-9, "steps": steps},
         "materials": {"explosive": {"model": "jwl", "damping": 0.0}},
         "parts": [{"name": "charge", "material": "explosive", "dx": dx,
                    "shape": {"kind": "cylinder", "center": [0, 0], "radius": radius,
                              "z": [0.0, length]}}]}
    from mpipd.model.stability import critical_dt
    d["time"]["dt"] = dt_factor * critical_dt(make_scene(d))
    return make_scene(d)


def closure_without(e, term) -> float:
    """|balance| if ``term`` were not booked."""
    from mpipd.model.ledger import DISSIPATED, HELD
    held = e.held - (getattr(e, term) if term in HELD else 0.0)
    diss = e.dissipated - (getattr(e, term) if term in DISSIPATED else 0.0)
    return abs(e.initial + e.external + e.boundary - held - diss) / e.scale


@pytest.fixture(scope="module")
def stopped(tmp_path_factory):
    """elastic_wave (SMALL) stopped at step 20 of 60: a checkpoint and 2 of 4 frames; one
    per test module that asks for it."""
    out = tmp_path_factory.mktemp("stopped") / "s"
    res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL, "--stop-after", "20"])
    assert res.returncode == 0, res.stdout + res.stderr
    return out
