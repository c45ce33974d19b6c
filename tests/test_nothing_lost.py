"""Issue 61: nothing a run wrote is lost or hidden by a later command.

A restart of a finished run writes nothing; a restart never rewrites the frame
counter downwards, never drops a frame it does not write again, and refuses
changed physics or output fields (exit 2, one line, every file unchanged)."""
import json
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import ROOT, SMALL, md5s, one_error, run_cli


def runstate(out: Path) -> str:
    res = subprocess.run([sys.executable, str(ROOT / "jobs/lib/runstate.py"), str(out)],
                         capture_output=True, text=True)
    return res.stdout.strip()


def frames(h5: Path) -> dict:
    """Every frame dataset's written rows, the counter and the time axis."""
    with h5py.File(h5, "r") as f:
        n = int(f.attrs["frames_written"])
        d = {k: f[k][:n] for k in ("time", "fields/u", "fields/v")}
        d["frames_written"] = n
        d["scene"] = str(f.attrs["scene"])
        return d


# ----------------------------------------------------------------- data loss 1

@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished run of 50 steps (frames 0, 20, 40 and the off-cadence 50)."""
    out = tmp_path_factory.mktemp("fin") / "fin"
    res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL, "--set", "time.steps=50",
                   "--set", "output.checkpoint_every=10"])
    assert res.returncode == 0, res.stdout + res.stderr
    return out


def test_restart_of_a_finished_run_writes_nothing(finished):
    before = md5s(finished)
    res = run_cli(["run", "--restart", str(finished / "checkpoint.h5")])
    assert res.returncode == 0, res.stdout + res.stderr
    assert "nothing to do" in res.stdout
    assert md5s(finished) == before
    with h5py.File(finished / "run.h5", "r") as f:
        assert int(f.attrs["frames_written"]) == 4 and f["time"][3] == pytest.approx(1e-5)
    assert runstate(finished) == "done 50 50"
    assert "frame3" in (finished / "run.xdmf").read_text()


@pytest.mark.parametrize("length", ["time.steps=100", "time.steps=40", "time.t_end=2e-5"])
def test_extending_past_an_off_cadence_last_frame_is_refused(finished, length):
    before = md5s(finished)
    res = run_cli(["run", "--restart", str(finished / "checkpoint.h5"), "--set", length])
    if length == "time.steps=40":
        one_error(res, "ends before the checkpoint's step 50")
    else:
        one_error(res, "last frame is at step 50", "output.every = 20")
    assert md5s(finished) == before


def test_extending_a_finished_run_keeps_its_frames(tmp_path):
    """On cadence (40 steps, every 20): the extension adds frames, the old stay."""
    out = tmp_path / "o"
    assert run_cli(["run", "elastic_wave", "--out", str(out), *SMALL, "--set", "time.steps=40",
                    "--set", "output.checkpoint_every=20"]).returncode == 0
    old = frames(out / "run.h5")
    res = run_cli(["run", "--restart", str(out / "checkpoint.h5"), "--set", "time.steps=60"])
    assert res.returncode == 0, res.stdout + res.stderr
    new = frames(out / "run.h5")
    assert new["frames_written"] == 4 and old["frames_written"] == 3
    for k in ("time", "fields/u", "fields/v"):
        assert np.array_equal(new[k][:3], old[k]), k
    assert new["scene"] == old["scene"]              # the run's scene, not rewritten
    with h5py.File(out / "run.h5", "r") as f:
        segs = json.loads(f.attrs["segments"])
        assert [s["to_step"] for s in segs] == [40, 60]
        assert segs[1]["restart_set"] == ["time.steps=60"]
        assert int(f.attrs["steps"]) == 60
    assert runstate(out) == "done 60 60"


@pytest.mark.mpi
def test_an_early_stop_keeps_frames_written_after_the_checkpoint(tmp_path):
    """A checkpoint at step 20 of a run whose file holds frames to step 60 (as after
    a kill past the checkpoint): a restart stopped at 40 keeps frame 60 counted and
    whole (its broken-bond rows included), and frames 0-40 bitwise the same."""
    out = tmp_path / "o"
    res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL, "--stop-after", "20"],
                  ranks=2)
    assert res.returncode == 0, res.stdout + res.stderr
    at20 = tmp_path / "ck20.h5"
    shutil.copy(out / "checkpoint.h5", at20)
    assert run_cli(["run", "--restart", str(out / "checkpoint.h5")], ranks=2).returncode == 0
    full = frames(out / "run.h5")
    assert full["frames_written"] == 4
    res = run_cli(["run", "--restart", str(at20), "--out", str(out), "--stop-after", "40"],
                  ranks=2)
    assert res.returncode == 0, res.stdout + res.stderr
    after = frames(out / "run.h5")
    assert after["frames_written"] == 4
    for k in ("time", "fields/u", "fields/v"):
        assert np.array_equal(after[k], full[k]), k
    # and a shorter run length would drop frame 60: refused
    shutil.copy(at20, tmp_path / "again.h5")
    before = md5s(out)
    res = run_cli(["run", "--restart", str(tmp_path / "again.h5"), "--out", str(out),
                   "--set", "time.steps=40"])
    one_error(res, "holds frames to step 60")
    assert md5s(out) == before


# ----------------------------------------------------------------- data loss 2, defect 5

@pytest.mark.parametrize("setting,key", [
    ('output.fields=["u"]', "output.fields"),
    ('output.fields=["u","v","stress"]', "output.fields"),
    ("materials.granite.bulk_modulus=30e9", "materials.granite.bulk_modulus"),
    ("materials.granite.density=5000", "materials.granite.density"),
    ("parts.0.shape.hi=[0.016, 0.192, 0.016]", "parts.0.shape.hi"),
    ("solver.hourglass=0.02", "solver.hourglass"),
    ('probes=[{name="a", position=[0.05, 0.008, 0.008]}]', "probes"),
    ("output.peak_center=[0.1, 0.0]", "output.peak_center"),
])
def test_restart_refuses_changed_physics_and_fields(stopped, setting, key):
    before = md5s(stopped)
    res = run_cli(["run", "--restart", str(stopped / "checkpoint.h5"), "--set", setting])
    one_error(res, f"error: {key}: a restart continues its run")
    assert md5s(stopped) == before


@pytest.mark.mpi
def test_restart_refuses_other_fields_on_two_ranks(stopped):
    before = md5s(stopped)
    res = run_cli(["run", "--restart", str(stopped / "checkpoint.h5"), "--set",
                   'output.fields=["u","v","stress"]'], ranks=2)
    one_error(res, "output.fields")
    assert md5s(stopped) == before


def test_restart_may_change_cadence_and_length(tmp_path):
    out = tmp_path / "o"
    assert run_cli(["run", "elastic_wave", "--out", str(out), *SMALL,
                    "--stop-after", "20"]).returncode == 0
    old = frames(out / "run.h5")
    res = run_cli(["run", "--restart", str(out / "checkpoint.h5"), "--set",
                   "output.checkpoint_every=20", "--set", "solver.progress_every=10",
                   "--set", "time.t_end=1.6e-5", "--set", "solver.max_imbalance=0.1"])
    assert res.returncode == 0, res.stdout + res.stderr
    new = frames(out / "run.h5")
    assert new["frames_written"] == 5
    for k in ("time", "fields/u", "fields/v"):
        assert np.array_equal(new[k][:2], old[k][:2]), k


# ----------------------------------------------------------------- data loss 3: one run per folder

def _hold_lock(folder: Path):
    import fcntl
    import os
    folder.mkdir(parents=True, exist_ok=True)
    fd = os.open(folder / "run.lock", os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    os.write(fd, json.dumps({"pid": os.getpid(), "host": "here", "since": "now"}).encode())
    return fd


def test_a_folder_in_use_is_refused_and_a_stale_lock_taken_over(tmp_path, stopped):
    import os
    out = tmp_path / "o"
    fd = _hold_lock(out)
    try:
        res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL])
        one_error(res, "in use by another mpipd run", f"pid {os.getpid()} on here")
        assert [p.name for p in out.iterdir()] == ["run.lock"]
    finally:
        os.close(fd)                       # as a killed run's: the file stays, unlocked
    res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL])
    assert res.returncode == 0, res.stdout + res.stderr
    assert not (out / "run.lock").exists()          # released and removed at the end
    # a restart into a folder in use
    before = md5s(stopped)
    fd = _hold_lock(stopped)
    try:
        before_lock = md5s(stopped)
        res = run_cli(["run", "--restart", str(stopped / "checkpoint.h5")])
        one_error(res, "in use by another mpipd run")
        assert md5s(stopped) == before_lock
    finally:
        os.close(fd)
        (stopped / "run.lock").unlink()
    assert md5s(stopped) == before


def test_bad_input_leaves_no_folder(tmp_path):
    out = tmp_path / "new"
    res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL, "--set",
                   'probes=[{name="far", position=[0.5, 0.0, 0.0]}]'])
    one_error(res, "probes.0.position")
    assert not out.exists()


@pytest.mark.mpi
def test_two_runs_started_at_once_into_one_folder(tmp_path):
    """Both at once on 2 ranks each: exactly one runs, the other is refused (the
    lock, or the run file it finds under the lock); the file is the winner's."""
    from conftest import BIN, child_env
    out = tmp_path / "o"
    cmds = [["mpirun", "--oversubscribe", "-n", "2", str(BIN / "mpipd"), "run", "elastic_wave",
             "--out", str(out), *SMALL, *extra]
            for extra in ([], ["--set", "materials.granite.density=3000"])]
    ps = [subprocess.Popen(c, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           env=child_env()) for c in cmds]
    res = [(p.wait(timeout=300), *p.communicate()) for p in ps]
    codes = sorted(r[0] for r in res)
    assert codes == [0, 2], res
    loser = next(r for r in res if r[0] == 2)
    lines = {ln for ln in loser[2].splitlines() if ln.startswith("mpipd")}
    assert len(lines) == 1 and ("in use by another mpipd run" in lines.pop()
                                or "exists" in loser[2]), loser[2]
    winner = res.index(next(r for r in res if r[0] == 0))
    with h5py.File(out / "run.h5", "r") as f:
        assert ("density=3000" in str(f.attrs["scene"])) == (winner == 1)
        assert int(f.attrs["frames_written"]) == f["time"].shape[0] == 4
        assert np.isfinite(f["fields/u"][...]).all()
    assert not (out / "run.lock").exists()


# ----------------------------------------------------------------- data loss 4: sizes first

@pytest.fixture
def small_fs(tmp_path):
    """A 20 MB tmpfs (needs root; skipped elsewhere)."""
    import os
    p = tmp_path / "fs"
    p.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=20m", "tmpfs", str(p)],
                      capture_output=True).returncode != 0:
        if os.geteuid() == 0:
            pytest.fail("mount -t tmpfs failed as root")
        pytest.skip("mounting a tmpfs needs root")
    yield p
    subprocess.run(["umount", "-l", str(p)], capture_output=True)


@pytest.mark.parametrize("setting,needles", [
    ("time.t_end=1.2e-3", ("needs about 0.09", "301 frame(s) of 2 field(s) x 6144 points",
                           "--force-size")),
    ("time.steps=999999999999999999", ("needs about", "--force-size")),
    ("time.t_end=1e30", ("needs about", "--force-size")),
    ("time.steps=99999999999999999999", ("time.steps: must be below 2^63",)),
    ("output.every=99999999999999999999", ("output.every: must be below 2^63",)),
    ("parts.0.jitter_seed=9999999999999999999", ("parts.0.jitter_seed: must be below 2^63",)),
])
def test_too_big_for_the_disk_is_refused_before_overwrite_deletes(small_fs, setting, needles):
    """An existing run on a 20 MB file system and --overwrite with a run file of
    88 MB (or a typo'd length): exit 2, one line with the numbers; the old run
    (its log and checkpoint included) byte for byte unchanged."""
    out = small_fs / "o"
    res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL, "--stop-after", "20"])
    assert res.returncode == 0, res.stdout + res.stderr
    before = md5s(out)
    assert "checkpoint.h5" in before and "run.log" in before
    res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL, "--overwrite",
                   "--set", setting])
    one_error(res, *needles)
    assert md5s(out) == before


def test_restart_that_would_outgrow_the_disk_is_refused(small_fs):
    out = small_fs / "o"
    assert run_cli(["run", "elastic_wave", "--out", str(out), *SMALL,
                    "--stop-after", "20"]).returncode == 0
    before = md5s(out)
    res = run_cli(["run", "--restart", str(out / "checkpoint.h5"), "--set", "time.t_end=1.2e-3"])
    one_error(res, "needs about", "--force-size")
    assert md5s(out) == before


def test_model_larger_than_memory_is_refused(tmp_path):
    """The memory check, in-process (no run is started): a host with 1 MB available."""
    import argparse

    from mpipd.cli import UsageError, _check_sizes
    from mpipd.input import scene as sc
    scene, _ = sc.load("elastic_wave", ["parts.0.dx=0.002", "time.steps=10"])
    args = argparse.Namespace(restart=None, overwrite=False, force_size=False)
    with pytest.raises(UsageError, match=r"the model needs about .* on host h .* 0\.001 GB "
                                         r"available there.*--force-size"):
        _check_sizes(scene, 2, [("h", 10**6), ("h", 10**6)], tmp_path / "o", args)
    _check_sizes(scene, 2, [("h", 10**12), ("g", 10**12)], tmp_path / "o", args)
    _check_sizes(scene, 2, [("h", 10**6), ("h", 10**6)], tmp_path / "o",
                 argparse.Namespace(restart=None, overwrite=False, force_size=True))
    assert not (tmp_path / "o").exists()


def test_check_reports_memory_and_run_file_size():
    res = run_cli(["check", "elastic_wave", *SMALL[:-1]])
    assert res.returncode == 0, res.stderr
    assert "memory: the model's arrays" in res.stdout and "available" in res.stdout
    assert "run file: 0.00" in res.stdout and "4 frame(s) x 2 field(s) x 6144 points" in res.stdout


# ----------------------------------------------------------------- mpipd.post (items 8, 9)

@pytest.fixture(scope="module")
def three_frames(tmp_path_factory):
    out = tmp_path_factory.mktemp("pp") / "r"
    res = run_cli(["run", "elastic_wave", "--out", str(out), *SMALL, "--set", "time.steps=40",
                   "--set", 'output.fields=["u","stress_work"]'])
    assert res.returncode == 0, res.stdout + res.stderr
    return out


def post(*args):
    return subprocess.run([sys.executable, "-m", "mpipd.post", *args], capture_output=True,
                          text=True, cwd=ROOT, timeout=120)


@pytest.mark.parametrize("extra,needle", [
    (["--frame", "99"], "--frame 99: the run file holds 3 frame(s)"),
    (["--frame", "-4"], "--frame -4: the run file holds 3 frame(s)"),
    (["--z", "5"], "--z 5 m is outside the body"),
    (["--z", "-0.01"], "--z -0.01 m is outside the body"),
    (["--out", "/nonexistent/dir/x.png"], "no directory /nonexistent/dir"),
])
def test_fracture_refuses_what_it_cannot_plot(three_frames, tmp_path, extra, needle):
    before = md5s(three_frames)
    res = post("fracture", str(three_frames / "run.h5"), "--field", "stress_work",
                      *(extra if "--out" in extra else [*extra, "--out", str(tmp_path / "f.png")]))
    assert res.returncode == 2, res.stdout + res.stderr
    assert "Traceback" not in res.stderr
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("mpipd.post: error: ") and needle in lines[0], \
        res.stderr
    assert not (tmp_path / "f.png").exists() and md5s(three_frames) == before


def test_fracture_in_range_still_plots(three_frames, tmp_path):
    res = post("fracture", str(three_frames / "run.h5"), "--field", "stress_work",
                      "--frame", "-3", "--z", "0.008", "--out", str(tmp_path / "f.png"))
    assert res.returncode == 0, res.stdout + res.stderr
    assert (tmp_path / "f.png").stat().st_size > 0


def test_report_out_on_a_file_is_one_line(three_frames, tmp_path):
    f = tmp_path / "file"
    f.write_text("keep")
    res = post("report", str(three_frames / "run.h5"), "--out", str(f))
    assert res.returncode == 2, res.stdout + res.stderr
    assert "Traceback" not in res.stderr and "exists and is not a directory" in res.stderr
    assert f.read_text() == "keep"
