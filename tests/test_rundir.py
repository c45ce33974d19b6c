"""A run never writes into a file that is not its own, and says exactly what
went wrong: restarts matched to their run file by run id, --overwrite leaving
nothing resumable, run-length changes on restart, bad input (exit 2, files
unchanged), a read-only or full file system (one line, no .tmp left), signals."""
import hashlib
import os
import shutil
import signal
import subprocess
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import BIN, child_env, one_error, run_cli

SMALL = ["--set", "parts.0.dx=0.002", "--set", "time.dt=2e-7", "--set", "time.t_end=1.2e-5",
         "--set", "output.every=20", "--set", 'output.fields=["u","v","stress"]', "--quiet"]
OTHER = ["--set", "parts.0.dx=0.004", "--set", "time.dt=4e-7", "--set", "time.t_end=2.4e-5",
         "--set", "output.every=20", "--set", 'output.fields=["u","v","stress"]', "--quiet"]


def md5(path: Path) -> str:
    return hashlib.md5(path.read_bytes()).hexdigest()


def mpipd_lines(res):
    return [ln for ln in res.stderr.splitlines() if ln.startswith("mpipd")]


# ----------------------------------------------------------------- restart ownership

def test_restart_never_writes_into_another_run(tmp_path):
    """The issue's sequence: run A stopped in D, run B --overwrite in D, restart
    D/checkpoint.h5 -- and a kept copy of A's checkpoint restarted into B's files,
    and into an unrelated run of the same frame count: all refused, B unchanged."""
    d = tmp_path / "D"
    res = run_cli(["run", "elastic_wave", "--out", str(d), "--stop-after", "20", *SMALL], ranks=2)
    assert res.returncode == 0, res.stderr
    kept = tmp_path / "A_checkpoint.h5"
    shutil.copy(d / "checkpoint.h5", kept)
    res = run_cli(["run", "elastic_wave", "--out", str(d), "--overwrite", *OTHER])
    assert res.returncode == 0, res.stderr
    # --overwrite removed what belonged to the replaced run
    assert not (d / "checkpoint.h5").exists()
    assert "stopped at step 20" not in (d / "run.log").read_text()
    before = md5(d / "run.h5")
    res = run_cli(["run", "--restart", str(d / "checkpoint.h5")], ranks=2)
    one_error(res, "no such checkpoint")
    res = run_cli(["run", "--restart", str(kept), "--out", str(d)], ranks=2)
    one_error(res, "belongs to another run")
    # an unrelated run with the same scene and frame count
    e = tmp_path / "E"
    assert run_cli(["run", "elastic_wave", "--out", str(e), *SMALL]).returncode == 0
    e_before = md5(e / "run.h5")
    res = run_cli(["run", "--restart", str(kept), "--out", str(e)])
    one_error(res, "belongs to another run")
    assert md5(d / "run.h5") == before and md5(e / "run.h5") == e_before
    # a directory without the run file
    res = run_cli(["run", "--restart", str(kept), "--out", str(tmp_path / "new")])
    one_error(res, "does not exist")
    assert not (tmp_path / "new").exists()
    with h5py.File(d / "run.h5", "r") as f:           # the run file names its run
        assert len(f.attrs["run_id"]) == 32


def test_extend_a_run_on_restart(tmp_path):
    """A restart with a new t_end continues into a longer run file: the frames are
    bitwise those of the uninterrupted longer run (2 ranks, then 1)."""
    longer = ["--set", "time.t_end=2.0e-5"]
    ref = tmp_path / "ref"
    assert run_cli(["run", "elastic_wave", "--out", str(ref), *SMALL, *longer]).returncode == 0
    a = tmp_path / "a"
    res = run_cli(["run", "elastic_wave", "--out", str(a), "--stop-after", "40", *SMALL],
                  ranks=2)
    assert res.returncode == 0, res.stderr
    res = run_cli(["run", "--restart", str(a / "checkpoint.h5"), "--quiet", *longer])
    assert res.returncode == 0, res.stdout + res.stderr
    with h5py.File(ref / "run.h5", "r") as f, h5py.File(a / "run.h5", "r") as g:
        assert g["time"].shape == f["time"].shape == (6,)
        assert g.attrs["frames_written"] == 6 and g.attrs["steps"] == 100
        for k in ("time", "fields/u", "fields/v", "fields/stress"):
            assert np.array_equal(f[k][...], g[k][...]), k
        # global sums: the same to round-off on 1 and 2 ranks
        assert np.allclose(f["energy/kinetic"][...], g["energy/kinetic"][...], rtol=1e-12)


def test_restart_cannot_change_the_frame_layout(tmp_path):
    a = tmp_path / "a"
    assert run_cli(["run", "elastic_wave", "--out", str(a), "--stop-after", "20",
                    *SMALL]).returncode == 0
    before = md5(a / "run.h5")
    for extra, needle in ((["--set", "output.every=10"], "output.every"),
                          (["--set", "time.dt=1e-7"], "time.dt"),
                          (["--set", "time.steps=10"], "ends before the checkpoint's step 20"),
                          (["--overwrite"], "a restart continues one")):
        res = run_cli(["run", "--restart", str(a / "checkpoint.h5"), *extra])
        one_error(res, needle)
    assert md5(a / "run.h5") == before


def test_non_finite_checkpoint_is_refused(tmp_path):
    a = tmp_path / "a"
    assert run_cli(["run", "elastic_wave", "--out", str(a), "--stop-after", "20",
                    *SMALL]).returncode == 0
    with h5py.File(a / "checkpoint.h5", "r+") as f:
        f["points/v"][7, 1] = np.nan
    before = md5(a / "run.h5")
    res = run_cli(["run", "--restart", str(a / "checkpoint.h5")], ranks=2)
    one_error(res, "non-finite values in v")
    assert md5(a / "run.h5") == before


# ----------------------------------------------------------------- bad input

def test_later_time_setting_wins(tmp_path):
    """--set time.steps on a scene that gives t_end: the override wins."""
    out = tmp_path / "o"
    res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL, "--set", "time.steps=7"])
    assert res.returncode == 0, res.stderr
    with h5py.File(out / "run.h5", "r") as f:
        assert f.attrs["steps"] == 7


@pytest.fixture(scope="module")
def existing(tmp_path_factory):
    out = tmp_path_factory.mktemp("existing") / "o"
    assert run_cli(["run", "elastic_wave", "--out", str(out), *SMALL]).returncode == 0
    return out


@pytest.mark.parametrize("args,needles", [
    (["--stop-after", "0"], ("--stop-after must be a step >= 1",)),
    (["--stop-after", "-5"], ("--stop-after must be a step >= 1",)),
    (["--set", 'probes=[{name="far", position=[0.5, 0.0, 0.0]}]'],
     ("probes.0.position", "beyond its horizon")),
    (["--set", 'loads=[{kind="borehole_pressure", center=[0.0, 0.0], radius=0.5, p0=1e8, '
               'alpha=1e5, beta=2e5}]'], ("loads.0.radius", "meets no part")),
    (["--set", 'loads=[{kind="borehole_pressure", center=[0.01, 0.01], radius=0.003, p0=1e8, '
               'alpha=1e5, beta=2e5}]'], ("loads.0.radius", "lands inside part")),
])
def test_bad_run_input_changes_nothing(existing, args, needles):
    """One line, exit 2, and an existing run's files byte for byte unchanged."""
    out = existing
    sums = {p.name: md5(p) for p in out.iterdir()}
    res = run_cli(["run", "elastic_wave", "--out", str(out), "--overwrite", *SMALL, *args])
    one_error(res, *needles)
    assert {p.name: md5(p) for p in out.iterdir()} == sums


def test_probe_moved_more_than_dx_is_reported(tmp_path):
    out = tmp_path / "o"
    # elastic_wave's bar is 16 mm wide: 3.5 mm beyond its side, 4.5 mm from the last
    # lattice line (dx 2 mm, horizon 6 mm)
    res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL, "--set", "time.steps=2",
                   "--set", 'probes=[{name="side", position=[0.05, 0.0195, 0.008]}]'])
    assert res.returncode == 0, res.stderr
    assert "probe 'side' moved" in res.stdout and "mm (more than dx" in res.stdout
    assert "probe 'side' moved" in (out / "run.log").read_text()


def test_rigid_motion_is_not_a_runaway(tmp_path):
    """A stress-free body moving at 1.5e4 m/s (|v| dt = 1.5 dx) runs to the end:
    the runaway test looks at relative motion within families."""
    out = tmp_path / "o"
    res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL, "--set", "time.steps=40",
                   "--set", 'initial=[{kind="uniform_velocity", region={lo=[-1,-1,-1], '
                            'hi=[1,1,1]}, velocity=[15000.0, 0.0, 0.0]}]'])
    assert res.returncode == 0, res.stdout + res.stderr
    with h5py.File(out / "run.h5", "r") as f:
        v = f["fields/v"][-1]
        assert np.allclose(v[:, 0], 15000.0, rtol=1e-9) and np.abs(v[:, 1:]).max() < 1e-6


# ----------------------------------------------------------------- file systems

def _mount_tmpfs(path: Path, opts: str) -> bool:
    path.mkdir(parents=True, exist_ok=True)
    return subprocess.run(["mount", "-t", "tmpfs", "-o", opts, "tmpfs", str(path)],
                          capture_output=True).returncode == 0


@pytest.fixture
def tmpfs(tmp_path):
    """mount(opts) -> a fresh tmpfs at a path under tmp_path (needs root)."""
    mounted = []

    def mount(opts):
        p = tmp_path / f"fs{len(mounted)}"
        if not _mount_tmpfs(p, opts):
            if os.geteuid() == 0:            # CI runs as root: there it must work
                pytest.fail(f"mount -t tmpfs -o {opts} failed as root")
            pytest.skip("mounting a tmpfs needs root")
        mounted.append(p)
        return p
    yield mount
    for p in mounted:
        subprocess.run(["umount", "-l", str(p)], capture_output=True)


def test_read_only_out_is_one_line(tmpfs):
    ro = tmpfs("ro,size=1m")
    # --force-size: past the size check, which a 1 MB file system fails first
    res = run_cli(["run", "elastic_wave", "--out", str(ro / "run"), *SMALL, "--force-size"],
                  ranks=2)
    one_error(res, "cannot write to --out", "Read-only file system")


def test_full_disk_is_one_line_and_leaves_no_tmp(tmpfs):
    """3 MB: the run file fits, the first checkpoint does not.  Exit 4, one line
    naming the directory and the free space, no checkpoint.h5.tmp left behind
    (--force-size: the size check, which keeps a tenth free, would refuse it first)."""
    fs = tmpfs("size=3m")
    out = fs / "run"
    res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL, "--force-size",
                   "--set", "output.checkpoint_every=10"], ranks=2, timeout=120)
    one_error(res, f"cannot write in {out}", "MB free", code=4)
    assert (out / "run.h5").exists() and not list(out.glob("*.tmp"))


def test_finished_run_whose_end_checkpoint_fails_says_its_run_file_is_complete(tmpfs):
    """Checkpoints asked for but none due before the end: the run file fits, the
    end checkpoint does not.  Exit 4 with one error line that says so and that the
    run file is complete to the last step (60); the summary still printed; the run
    file holds every frame to t_end; no checkpoint and no .tmp left."""
    fs = tmpfs("size=3m")
    out = fs / "run"
    res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL, "--force-size",
                   "--set", "output.checkpoint_every=1000"], ranks=2, timeout=120)
    one_error(res, f"cannot write in {out}", "MB free", "end checkpoint was not written",
              "(no checkpoint)", f"{out / 'run.h5'} is complete to step 60", code=4)
    assert "energy ledger" in res.stdout, res.stdout
    with h5py.File(out / "run.h5", "r") as f:
        assert int(f.attrs["frames_written"]) == f["time"].shape[0] == 4
        assert f["time"][-1] == pytest.approx(1.2e-5)
    assert not list(out.glob("*.tmp")) and not (out / "checkpoint.h5").exists()


# ----------------------------------------------------------------- signals

def _start(out, extra=()):
    cmd = ["mpirun", "--oversubscribe", "-n", "2", str(BIN / "mpipd"), "run", "elastic_wave",
           "--out", str(out), *SMALL, "--set", "time.t_end=1e-3", *extra]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env=child_env())
    t0 = time.time()
    while not (out / "run.log").exists() and time.time() - t0 < 120:
        time.sleep(0.2)
    time.sleep(1.0)                       # stepping (the handler is installed before setup)
    return p


@pytest.mark.parametrize("how", ["USR1 to mpirun", "TERM to the ranks"])
def test_signal_stop_exits_0_with_a_checkpoint(tmp_path, how):
    out = tmp_path / "o"
    p = _start(out)
    if how == "USR1 to mpirun":
        p.send_signal(signal.SIGUSR1)     # Open MPI forwards USR1 to every rank
    else:
        ranks = subprocess.run(["pgrep", "-P", str(p.pid)], capture_output=True, text=True)
        for pid in ranks.stdout.split():
            os.kill(int(pid), signal.SIGTERM)
    stdout, stderr = p.communicate(timeout=120)
    assert p.returncode == 0, stdout + stderr
    assert "stopped at step" in stdout and (out / "checkpoint.h5").exists()


def test_git_commit_marks_uncommitted_solver_changes(tmp_path):
    """A run made from changed tracked files records HEAD with the dirty mark; an
    untracked file leaves it clean; short_commit keeps the mark."""
    import subprocess

    from mpipd.output.writer import DIRTY, git_commit, short_commit
    git = ["git", "-C", str(tmp_path), "-c", "user.name=t", "-c", "user.email=t@t"]
    subprocess.run(git + ["init", "-q"], check=True)
    (tmp_path / "a.py").write_text("x = 1\n")
    subprocess.run(git + ["add", "a.py"], check=True)
    subprocess.run(git + ["commit", "-qm", "a"], check=True)
    head = subprocess.run(git + ["rev-parse", "HEAD"], capture_output=True, text=True,
                          check=True).stdout.strip()
    assert git_commit(tmp_path) == head
    (tmp_path / "new.py").write_text("y = 2\n")                 # untracked
    assert git_commit(tmp_path) == head
    (tmp_path / "a.py").write_text("x = 2\n")
    assert git_commit(tmp_path) == head + DIRTY
    assert short_commit(head + DIRTY) == head[:12] + DIRTY
    assert short_commit(head, 7) == head[:7]
    assert git_commit(tmp_path / "nowhere") == "unknown"
