"""The cluster job scripts (jobs/) against a real single-node SLURM.

``scripts/slurm_local.sh start`` installs Debian's slurm-wlm and munge if needed
and starts munged, slurmctld and slurmd on this machine.  If that is impossible
(not root, no apt, a daemon that will not start) the scheduler tests are
skipped and say why; nothing is simulated.

One run of the scheduler drives, side by side:

* **the restart chain**: ``jobs/slurm/blast_paper.sbatch`` on a small
  ``elastic_wave`` on 2 ranks with ``--time=2``.  The scripts' own timer (the
  wall-time limit SLURM reports, minus ``MPIPD_WALLTIME_MARGIN=115`` s) asks for a
  checkpoint 5 s into each link; the script holds the request until mpipd prints
  its first progress line (every 200 steps), so each link does 200-300 of the 600
  steps whatever the machine's load, and the job requeues itself and restarts
  from the checkpoint until the run is done (2-3 links).  SLURM's own
  ``--signal=B:USR1@T`` is checked only every ~30 s and ``--time`` counts in
  minutes, so it cannot stop a link a few seconds in reliably; the timer can (and
  is what the PBS scripts use);
* **the uninterrupted reference**: the same script, ``MPIPD_CHAIN=none``, a long
  wall time.  The chained run.h5 must equal it bit for bit (every field, the
  times and the energies, all indexed by global id);
* **the dependent post-processing job**: ``postprocess.sbatch`` submitted with
  ``--dependency=afterok:<chain>``; it may only start after the last link;
* **the sweep**: ``jobs/slurm/dx_study.sbatch`` as a 2-task array over a cases
  file of ``--set`` overrides of ``elastic_wave``, launched with ``mpirun``.  The
  test sends each task ``scancel --batch --signal=USR1``: the same delivery to
  the batch shell that ``--signal=B:USR1@T`` uses; task 0 right after its mpipd
  was launched (the script must hold the signal until mpipd is stepping, or the
  rank would die), task 1 once mpipd is stepping.  Each task must checkpoint,
  requeue, finish, and submit its own post-processing job
  (``MPIPD_SUBMIT_POSTPROCESS=1``).

SLURM holds a requeued job for 121 s before it may start again; the test
releases it after a few seconds with ``scontrol update StartTime=now``, as an
administrator can.  ``python -m mpipd.post summary`` stands in for ``report``.
"""
import os
import re
import shutil
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest
from conftest import ROOT, child_env

SLURM_LOCAL = ROOT / "scripts" / "slurm_local.sh"
VENV = sys.prefix        # the jobs activate the virtualenv this test runs in
TIMEOUT = 420            # s for all jobs together
RELEASE_AFTER = 4        # s a requeued job stays held before the test releases it

# The chain runs an elastic bar on 2 ranks: quick, and the links fall wherever the
# timer puts them.  Restarts through fracture (bonds breaking in the checkpoint's
# step) are bit-identical too: tests/test_restart.py and tests/test_blast_demo.py.
CHAIN_SCENE = "elastic_wave"
CHAIN_ARGS = ("--set parts.0.dx=0.002 --set time.t_end=6e-5 --set output.every=50 "
              '--set solver.progress_every=200 --set output.fields=["u","v","stress"]')
CHAIN_POINTS = 6144
CASES = ("# name  mpipd run arguments (the dx_study script runs elastic_wave with each)\n"
         "slow  --set initial.0.velocity=[0.5,0.0,0.0]\n"
         "fast  --set initial.0.velocity=[1.0,0.0,0.0]\n")
SWEEP_ARGS = ("--set parts.0.dx=0.004 --set time.t_end=2e-4 --set output.every=100 "
              "--set solver.progress_every=100")


def _run(*cmd, timeout=60, **kw):
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True,
                          timeout=timeout, **kw)


def _scheduler_env(**settings):
    """The test's environment for sbatch: no MPIPD_*/SBATCH_* or enclosing job's
    SLURM_* settings leak in; the given settings are added."""
    env = {k: v for k, v in child_env().items()
           if not k.startswith(("MPIPD_", "SBATCH_"))
           and not (k.startswith("SLURM_") and k != "SLURM_CONF")}
    env.update({k: str(v) for k, v in settings.items()})
    return env


def test_job_scripts_parse():
    """Every job script and the shared library is valid bash (PBS included: there
    is no PBS here to run them)."""
    scripts = sorted((ROOT / "jobs").glob("*/*.sbatch")) + sorted((ROOT / "jobs").glob("*/*.pbs"))
    assert len(scripts) >= 10
    for s in [*scripts, ROOT / "jobs" / "lib" / "chain.sh", SLURM_LOCAL]:
        res = _run("bash", "-n", s)
        assert res.returncode == 0, f"{s}: {res.stderr}"


@pytest.fixture(scope="module")
def slurm():
    if os.geteuid() != 0:
        pytest.skip("starting a local SLURM needs root (it starts munged, slurmctld, slurmd)")
    if not shutil.which("apt-get") and not shutil.which("sbatch"):
        pytest.skip("no sbatch and no apt-get to install slurm-wlm")
    was_running = _run("bash", SLURM_LOCAL, "status").returncode == 0
    try:
        res = _run("bash", SLURM_LOCAL, "start", timeout=900)
    except subprocess.TimeoutExpired:
        pytest.skip("the local SLURM did not start within 15 minutes")
    if res.returncode != 0:
        why = (res.stderr.strip().splitlines() or ["no reason given"])[-1]
        pytest.skip(f"the local SLURM could not start on this machine: {why}")
    # the cluster is this test's own (slurm_local.sh never touches a site's SLURM):
    # clear what an interrupted earlier run left in its queue
    _run("scancel", "--user", "root", "--quiet")
    yield
    if not was_running:
        _run("bash", SLURM_LOCAL, "stop")


def sbatch(script, *options, args=(), **settings) -> str:
    res = _run("sbatch", "--parsable", *options, ROOT / "jobs" / "slurm" / script, *args,
               cwd=ROOT, env=_scheduler_env(**settings))
    assert res.returncode == 0, f"sbatch {script}: {res.stderr}"
    return res.stdout.strip().split(";")[0]


def job_records(job_id: str) -> list[dict]:
    """scontrol's record(s) of a job: one per array task."""
    res = _run("scontrol", "-o", "show", "job", job_id)
    assert res.returncode == 0, res.stderr
    return [dict(re.findall(r"(\w+)=(\S*)", line)) for line in res.stdout.splitlines() if line]


def read_run(path) -> dict:
    out = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: out.__setitem__(name, obj[...])
                     if isinstance(obj, h5py.Dataset) and not name.startswith("geometry") else None)
        for k in ("bonds_broken", "failed_points_by_mode", "frames_written", "steps"):
            if k in f.attrs:
                out["@" + k] = f.attrs[k]
    return out


def starts(chain_log) -> int:
    return len(re.findall(r" link \d+: start ", chain_log.read_text()))


def test_sweep_and_restart_chain_on_slurm(slurm, tmp_path):
    t_start = time.monotonic()
    logs = tmp_path / "logs"
    logs.mkdir()
    common = dict(MPIPD_VENV=VENV, MPIPD_SIGNAL_GRACE=60, MPIPD_MAX_LINKS=50)
    sig_late = "--signal=B:USR1@1"          # SLURM's own warning: effectively never, here

    # the restart chain, the uninterrupted reference and the dependent report
    chain_out, ref_out = tmp_path / "chain", tmp_path / "ref"
    chain = sbatch("blast_paper.sbatch", "--ntasks=2", "--time=2", sig_late,
                   f"--output={logs}/chain-%j.out", "--job-name=test-chain",
                   MPIPD_SCENE=CHAIN_SCENE, MPIPD_OUT=chain_out, MPIPD_ARGS=CHAIN_ARGS,
                   MPIPD_WALLTIME_MARGIN=115, **common)
    ref = sbatch("blast_paper.sbatch", "--ntasks=2", "--time=15", sig_late,
                 f"--output={logs}/ref-%j.out", "--job-name=test-ref",
                 MPIPD_SCENE=CHAIN_SCENE, MPIPD_OUT=ref_out, MPIPD_ARGS=CHAIN_ARGS,
                 MPIPD_WALLTIME_MARGIN=0, MPIPD_CHAIN="none", **common)
    report = sbatch("postprocess.sbatch", "--ntasks=1", "--time=5", f"--dependency=afterok:{chain}",
                    f"--output={logs}/report-%j.out", "--job-name=test-report", args=[chain_out],
                    MPIPD_POSTPROCESS="summary", MPIPD_POSTPROCESS_ARGS="", **common)

    # the sweep: a 2-task array, each stopped once by a scheduler signal
    cases = tmp_path / "cases.txt"
    cases.write_text(CASES)
    sweep_out = tmp_path / "sweep"
    sweep = sbatch("dx_study.sbatch", "--array=0-1", "--ntasks=1", "--time=15", sig_late,
                   f"--output={logs}/sweep-%A_%a.out", "--job-name=test-sweep",
                   MPIPD_SCENE="elastic_wave", MPIPD_CASES_FILE=cases, MPIPD_OUT=sweep_out,
                   MPIPD_ARGS=SWEEP_ARGS, MPIPD_LAUNCHER="mpirun", MPIPD_WALLTIME_MARGIN=0,
                   MPIPD_SUBMIT_POSTPROCESS=1, MPIPD_POSTPROCESS="summary",
                   MPIPD_POSTPROCESS_ARGS="",
                   MPIPD_POSTPROCESS_SUBMIT_ARGS=f"--ntasks=1 --time=5 --output={logs}/pp-%j.out",
                   **common)
    names = ["slow", "fast"]

    signalled, held_since = set(), {}
    while True:
        q = _run("squeue", "-h", "-o", "%A %F %K %T %r").stdout.split("\n")
        rows = [r.split() for r in q if r.strip()]
        if not rows:
            break
        now = time.monotonic()
        for job, base, task, state, reason in (r + [""] * (5 - len(r)) for r in rows):
            if state == "PENDING" and reason == "BeginTime":     # a requeued link
                held_since.setdefault(job, now)
                if now - held_since[job] >= RELEASE_AFTER:
                    _run("scontrol", "update", f"JobId={job}", "StartTime=now")
                    held_since.pop(job)
            if base == sweep and state == "RUNNING" and task not in signalled:
                # task 0: as soon as its link has launched mpipd, most likely still in
                # its set-up (the script must hold the signal back until mpipd steps);
                # task 1: once mpipd is stepping
                folder = sweep_out / names[int(task)]
                log, pattern = ((folder / "chain.log", r" link 1: start ") if task == "0"
                                else (folder / "run.log", r"^step "))
                if log.exists() and re.search(pattern, log.read_text(), re.M):
                    res = _run("scancel", "--batch", "--signal=USR1", f"{sweep}_{task}")
                    assert res.returncode == 0, res.stderr
                    signalled.add(task)
        if now - t_start > TIMEOUT:
            _run("scancel", "--user", "root")
            dump = "\n".join(f"--- {p.name}\n{p.read_text()[-3000:]}" for p in sorted(logs.iterdir()))
            pytest.fail(f"jobs still queued after {TIMEOUT} s:\n{q}\n{dump}")
        time.sleep(1)

    def outputs():
        return "\n".join(f"--- {p.name}\n{p.read_text()[-4000:]}" for p in sorted(logs.iterdir()))

    # every job and every array task completed with status 0
    for jid in (chain, ref, report, sweep):
        for rec in job_records(jid):
            assert (rec["JobState"], rec["ExitCode"]) == ("COMPLETED", "0:0"), \
                f"job {rec['JobId']}: {rec['JobState']} {rec['ExitCode']}\n{outputs()}"

    # the chain: several links (each stopped by the own timer), then finished
    text = (chain_out / "chain.log").read_text()
    assert starts(chain_out / "chain.log") >= 2, text
    assert "own timer" in text and "requeueing job" in text and "finished" in text, text
    assert "stop:" not in text, text
    assert int(job_records(chain)[0]["Restarts"]) == starts(chain_out / "chain.log") - 1
    assert starts(ref_out / "chain.log") == 1 and "checkpoint requested" not in \
        (ref_out / "chain.log").read_text()

    # ... equal to the uninterrupted run, bit for bit
    a, b = read_run(chain_out / "run.h5"), read_run(ref_out / "run.h5")
    assert a.keys() == b.keys() and {"fields/u", "fields/v", "fields/stress", "time"} <= a.keys()
    for k in a:
        assert np.array_equal(a[k], b[k]), f"{k} differs between the chained and the single run"
    assert a["@frames_written"] == len(a["time"])

    # the dependent report ran after the last link, on the finished run
    rep, last = job_records(report)[0], job_records(chain)[0]
    assert rep["StartTime"] >= last["EndTime"], (rep["StartTime"], last["EndTime"])
    assert f"points {CHAIN_POINTS}" in (chain_out / "postprocess.log").read_text()

    # the sweep: each task signalled once by the scheduler, requeued, finished,
    # and its own report job ran
    assert signalled == {"0", "1"}
    for name in names:
        log = sweep_out / name / "chain.log"
        text = log.read_text()
        assert starts(log) == 2 and "USR1 from the scheduler" in text and "finished" in text, text
        assert "stop:" not in text and f"requeueing job {sweep}_" in text, text
        pp = re.search(r"submitted post-processing job (\d+)", text)
        assert pp, text
        assert [r["JobState"] for r in job_records(pp.group(1))] == ["COMPLETED"]
        assert "points 768" in (sweep_out / name / "postprocess.log").read_text()
        with h5py.File(sweep_out / name / "run.h5", "r") as f:
            assert f.attrs["frames_written"] == f["time"].shape[0] == 21
    with h5py.File(sweep_out / "slow" / "run.h5", "r") as f, \
            h5py.File(sweep_out / "fast" / "run.h5", "r") as g:   # each task ran its own case
        assert not np.array_equal(f["fields/v"][-1], g["fields/v"][-1])
    print(f"SLURM jobs: {time.monotonic() - t_start:.0f} s")
