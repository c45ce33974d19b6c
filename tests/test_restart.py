"""Checkpoint/restart: stop a fracturing run, continue on the same and on a
different number of ranks, and get the uninterrupted run's fields bit for bit.
The stop (step 230) falls in a step where bonds break, so the checkpoint must
carry the previous F (from the shape tensors before that breakage)."""
import json
import re
import shutil

import h5py
import numpy as np
import pytest
from conftest import restart_matches, run_cli

from mpipd.input import scene as sc
from mpipd.output import checkpoint as ck
from mpipd.solver import Simulation

ARGS = ["--set", "parts.0.shape.z=[0.0, 0.006]", "--set", "time.t_end=1.2e-5",
        "--set", "output.every=40", "--quiet",
        "--set", 'output.fields=["u","v","damage","failure_mode","jh2_damage","stress"]']
KEYS = ("fields/u", "fields/v", "fields/damage", "fields/failure_mode", "fields/jh2_damage",
        "fields/stress", "time", "probes/near/sigma_rr", "probes/far/strength", "probes/far/t")


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    out = tmp_path_factory.mktemp("ref") / "run"
    res = run_cli(["run", "granite_ring", "--out", str(out), *ARGS], ranks=1)
    assert res.returncode == 0, res.stderr
    with h5py.File(out / "run.h5", "r") as f:
        return {k: f[k][...] for k in KEYS} | {"broken": f.attrs["bonds_broken"],
                                               "probe_lines": probe_lines(res.stdout)}


def probe_lines(stdout):
    """The run log's probe peaks ('mpipd: probe near: peak radial stress ...')."""
    return [ln for ln in stdout.splitlines() if ln.startswith("mpipd: probe ")]


def test_restart_same_and_different_rank_count(tmp_path, reference):
    a = tmp_path / "a"
    res = run_cli(["run", "granite_ring", "--out", str(a), "--stop-after", "230", *ARGS], ranks=2)
    assert res.returncode == 0, res.stderr
    assert "stopped at step 230" in res.stdout and (a / "checkpoint.h5").exists()
    # a stopped invocation reports its stable-step switches too (none in this ring)
    assert "stopped at step 230 of 240; 0 stable-step switch(es)" in res.stdout
    shutil.copytree(a, tmp_path / "b")
    for d, n in ((a, 2), (tmp_path / "b", 3)):
        res = run_cli(["run", "--restart", str(d / "checkpoint.h5"), "--quiet"], ranks=n)
        assert res.returncode == 0, res.stdout + res.stderr
        # the peaks cover the whole run, not the steps since the restart (the near
        # probe's peak falls before step 230)
        assert probe_lines(res.stdout) == reference["probe_lines"]
        assert len(reference["probe_lines"]) == 2
        with h5py.File(d / "run.h5", "r") as f:
            assert f.attrs["bonds_broken"] == reference["broken"]
            # each invocation's record, written collectively with one value on every
            # rank (ranks' own wall times once gave a corrupt JSON string)
            segs = json.loads(f.attrs["segments"])
            assert [(s["from_step"], s["to_step"], s["ranks"]) for s in segs] == \
                [(0, 230, 2), (230, int(f.attrs["steps"]), n)]
            assert all(s["wall_s"] > 0 and s["bond_steps_per_s"] > 0 for s in segs)
            assert all(s["bond_states_evaluated"] == 1.0 for s in segs)     # single-rate
            for k in KEYS:
                assert np.array_equal(f[k][...], reference[k]), f"{k} differs after restart on {n}"


MR = ["--set", "time.multirate={max_ratio=4, safety=1.0}"]


def test_multirate_restart_on_another_rank_count(tmp_path):
    """Multi-rate: stopped at a coarse boundary on 2 ranks, continued on 3, the same
    fields as the uninterrupted run on 1 rank (the classes are checkpointed)."""
    ref = tmp_path / "ref"
    res = run_cli(["run", "granite_ring", "--out", str(ref), *ARGS, *MR], ranks=1)
    assert res.returncode == 0, res.stderr
    logged = float(re.search(r"bond states evaluated ([0-9.]+) of single-rate", res.stdout)[1])
    a = tmp_path / "a"
    res = run_cli(["run", "granite_ring", "--out", str(a), "--stop-after", "232", *ARGS, *MR],
                  ranks=2)
    assert res.returncode == 0, res.stderr
    assert "stopped at step 232" in res.stdout
    res = run_cli(["run", "--restart", str(a / "checkpoint.h5"), "--quiet"], ranks=3)
    assert res.returncode == 0, res.stdout + res.stderr
    with h5py.File(ref / "run.h5", "r") as f0, h5py.File(a / "run.h5", "r") as f1:
        assert f1.attrs["bonds_broken"] == f0.attrs["bonds_broken"]
        # the share of single-rate's bond states each invocation evaluated, in its record
        (seg,) = json.loads(f0.attrs["segments"])
        assert 0.0 < seg["bond_states_evaluated"] < 1.0
        assert seg["bond_states_evaluated"] == pytest.approx(logged, abs=6e-4)
        assert all(0.0 < s["bond_states_evaluated"] < 1.0 for s in json.loads(f1.attrs["segments"]))
        for k in KEYS:
            assert np.array_equal(f1[k][...], f0[k][...]), f"{k} differs after restart"


def test_bad_checkpoint_is_a_clear_error(tmp_path):
    bad = tmp_path / "checkpoint.h5"
    bad.write_bytes(b"not hdf5")
    res = run_cli(["run", "--restart", str(bad)])
    assert res.returncode == 2 and "cannot read checkpoint" in res.stderr
    res = run_cli(["run", "granite_ring", "--restart", str(bad)])
    assert res.returncode == 2 and "either SCENE or --restart" in res.stderr


def test_signal_flag_checkpoints_and_stops(team, tmp_path):
    scene, text = sc.load("granite_ring", ["parts.0.dx=0.002"])
    sim = Simulation(scene, team)
    cp = ck.Checkpointer(sim, tmp_path / "c.h5", text, poll=5)
    for _ in range(4):
        sim.step()
        assert not cp.after_step()
    cp.signalled = True                      # what the SIGTERM/SIGUSR1 handler sets
    sim.step()
    assert cp.after_step() and (tmp_path / "c.h5").exists()
    assert ck.read_scene(tmp_path / "c.h5").step == 5


def test_dt_above_stable_is_refused_unless_forced(tmp_path):
    out = tmp_path / "o"
    res = run_cli(["run", "elastic_wave", "--out", str(out), "--set", "time.dt=1e-6"])
    assert res.returncode == 2 and "--force" in res.stderr and not out.exists()
    res = run_cli(["run", "elastic_wave", "--out", str(out), "--force", "--quiet",
                   "--set", "time.dt=1e-6", "--set", "time.t_end=2e-6",
                   "--set", "parts.0.dx=0.004"])
    assert res.returncode == 0 and "warning" in res.stdout


def test_blow_up_is_stopped_with_its_first_bad_point(tmp_path):
    """dt forced to 3x the stable step: the run stops on all ranks, names the step,
    field, gid and position, and leaves a checkpoint for inspection."""
    out = tmp_path / "o"
    res = run_cli(["run", "elastic_wave", "--out", str(out), "--force", "--quiet",
                   "--set", "parts.0.dx=0.004", "--set", "time.dt=2.6e-6",
                   "--set", "time.t_end=1e-3"], ranks=2, timeout=120)
    assert res.returncode == 3, res.stdout + res.stderr
    msg = [ln for ln in res.stderr.splitlines() if ln.startswith("mpipd: error")]
    assert len(msg) == 1 and "gid" in msg[0] and "x = (" in msg[0]
    assert "non-finite" in msg[0] or "|v_j - v_i| dt > |xi|" in msg[0]
    assert (out / "checkpoint_failed.h5").exists()
    assert msg[0].split("error: ")[1] in (out / "run.log").read_text()


SLAB = """
[scene]
name = "slab_break"
[time]
dt = 2.0e-8
steps = 60
[materials.granite]
model = "jh2"
tension = { sigma_st = -6.9e6 }
[[parts]]
name = "b"
material = "granite"
dx = 1.0e-3
shape = { kind = "box", lo = [0, 0, 0], hi = [0.008, 0.008, 0.012] }
[[initial]]
kind = "uniform_velocity"
region = { lo = [0, 0, 0.009], hi = [0.008, 0.008, 0.012] }
velocity = [0.0, 0.0, 40.0]
[output]
every = 20
fields = ["u", "v", "damage"]
"""


def test_checkpoint_when_one_rank_has_no_broken_bond(tmp_path):
    """The top slab breaks, the bottom one has no broken bond: the checkpoint's
    broken-bond list is written without a collective call (h5py skips empty
    writes, so a collective one hung the other ranks: found on blast_paper at
    step 100), and the restart continues the run bit for bit."""
    scene = tmp_path / "slab.toml"
    scene.write_text(SLAB)
    ref, a = tmp_path / "ref", tmp_path / "a"
    res = run_cli(["run", str(scene), "--out", str(ref), "--quiet"], ranks=3, timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    res = run_cli(["run", str(scene), "--out", str(a), "--stop-after", "40", "--quiet"],
                  ranks=3, timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    with h5py.File(a / "checkpoint.h5", "r") as f:
        gi = f["broken"][:, 0]
        assert len(gi) > 0
    # the bottom third of the gids (z < 4 mm, rank 0's slab) holds no broken bond
    n = 8 * 8 * 12
    assert gi.min() >= n // 3
    restart_matches(a / "checkpoint.h5", ref / "run.h5", ("fields/u", "fields/v", "fields/damage"),
                    ranks=2)


PLATE = """
[scene]
name = "plate_under_block"
[time]
dt = 1.0e-8
steps = 40
[materials.rock]
model = "elastic"
density = 2660.0
bulk_modulus = 21.9e9
shear_modulus = 25.7e9
[materials.metal]
model = "j2"
[[parts]]
name = "block"
material = "rock"
dx = 1.0e-3
shape = { kind = "box", lo = [0.0, 0.0, 0.003], hi = [0.008, 0.008, 0.012] }
[[parts]]
name = "plate"
material = "metal"
dx = 1.0e-3
shape = { kind = "box", lo = [0.0, 0.0, 0.0], hi = [0.008, 0.008, 0.003] }
[[initial]]
kind = "uniform_velocity"
velocity = [0.0, 0.0, 150.0]
region = { lo = [0.0, 0.0, 0.0], hi = [0.008, 0.008, 0.002] }
[output]
every = 20
checkpoint_every = 20
fields = ["u", "v", "stress"]
"""


def test_checkpoint_when_one_rank_has_no_point_of_a_material(tmp_path):
    """The J2 plate lies in the bottom quarter (z < 3 mm), so on 2 ranks the top slab
    has no J2 point.  Material history is saved by material id, the same datasets on
    every rank (by the rank-local group index, the ranks created different datasets
    collectively: the checkpoint at step 20 hung).  Half the plate is thrown at the rest
    at 150 m/s, so the J2 history is not zero; the restart on 3 ranks gives the
    uninterrupted 1-rank run bit for bit, and the saved history is that run's."""
    scene = tmp_path / "plate.toml"
    scene.write_text(PLATE)
    ref, a = tmp_path / "ref", tmp_path / "a"
    res = run_cli(["run", str(scene), "--out", str(ref), "--quiet"], ranks=1, timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    res = run_cli(["run", str(scene), "--out", str(a), "--stop-after", "20", "--quiet"],
                  ranks=2, timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    with h5py.File(a / "checkpoint.h5", "r") as f:
        hist = {k: f[f"points/state1/{k}"][...] for k in f["points/state1"]}
    assert hist and any(np.any(v != 0) for v in hist.values()), "no J2 history to test"
    res = run_cli(["run", "--restart", str(a / "checkpoint.h5"), "--quiet"], ranks=3,
                  timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    with h5py.File(a / "run.h5", "r") as f, h5py.File(ref / "run.h5", "r") as g:
        for k in ("fields/u", "fields/v", "fields/stress"):
            assert np.array_equal(f[k][...], g[k][...]), k
        rock = g["geometry/material"][...] == 0 if "geometry/material" in g else None
    if rock is not None:
        for v in hist.values():
            assert not np.any(v[rock] != 0)              # the rock's rows stay zero
