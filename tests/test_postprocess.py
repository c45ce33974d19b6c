"""postprocess under mpirun: the wave speed read back from a 2-rank run file, by
1 and by 2 reading ranks, against the closed-form speeds; the summary against
values read directly with h5py."""
import math
import subprocess
import sys

import h5py
import numpy as np
import pytest
from conftest import ROOT, child_env, run_cli

RHO, K, G = 2660.0, 21.9e9, 25.7e9
C_P = math.sqrt((K + 4 * G / 3) / RHO)
C_BAR = math.sqrt(9 * K * G / (3 * K + G) / RHO)


def post(ranks, *args):
    cmd = ["mpirun", "--oversubscribe", "-n", str(ranks), sys.executable, "-m", "postprocess",
           *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120, cwd=ROOT,
                          env=child_env())


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    out = tmp_path_factory.mktemp("pp") / "wave"
    res = run_cli(["run", "elastic_wave", "--out", str(out), "--quiet",
                   "--set", "parts.0.dx=0.002", "--set", "time.dt=2e-7",
                   "--set", "time.t_end=4.4e-5", "--set", "initial.0.half_width=0.04",
                   "--set", "output.every=2", "--set", 'output.fields=["v"]'], ranks=2)
    assert res.returncode == 0, res.stderr
    return out / "run.h5"


def test_wave_speed_from_file(run_file):
    outs = []
    for n in (1, 2):
        res = post(n, "wave-speed", str(run_file), "--stations", "0.08,0.12,0.16")
        assert res.returncode == 0, res.stderr
        outs.append(res.stdout)
    assert outs[0] == outs[1]                      # the reading decomposition does not matter
    speed = float(outs[1].split("wave speed")[1].split()[0])
    assert abs(speed - C_P) / C_P < 0.03 and abs(speed - C_BAR) / C_BAR < 0.03


def test_summary_matches_direct_read(run_file):
    res = post(2, "summary", str(run_file))
    assert res.returncode == 0, res.stderr
    with h5py.File(run_file, "r") as f:
        n, frames = f.attrs["n_points"], f.attrs["frames_written"]
        peak = np.sqrt((f["fields/v"][...] ** 2).sum(axis=2)).max(axis=1)
    assert f"points {n}  frames {frames}" in res.stdout
    printed = [float(p) for p in res.stdout.split("(m/s):")[1].split()]
    np.testing.assert_allclose(printed, peak, rtol=1e-3)


def test_bad_input_is_a_clear_error(run_file):
    res = post(1, "summary", str(run_file) + ".nope")
    assert res.returncode == 2 and "cannot open" in res.stderr
    res = post(2, "wave-speed", str(run_file), "--stations", "0.5")      # beyond the bar
    assert res.returncode == 2 and "no points near station" in res.stderr


def test_fracture_png(tmp_path):
    out = tmp_path / "ring"
    res = run_cli(["run", "granite_ring", "--out", str(out), "--quiet",
                   "--set", "parts.0.dx=0.002", "--set", "time.t_end=6e-6"], ranks=2)
    assert res.returncode == 0, res.stderr
    import matplotlib.image as mpimg
    imgs = []
    for n in (1, 2):
        png = tmp_path / f"f{n}.png"
        res = post(n, "fracture", str(out / "run.h5"), "--out", str(png))
        assert res.returncode == 0 and "wrote" in res.stdout, res.stderr
        imgs.append(mpimg.imread(png))
    assert imgs[0].shape[0] > 300 and np.array_equal(imgs[0], imgs[1])
    res = post(1, "fracture", str(out / "run.h5"), "--field", "u")
    assert res.returncode == 2 and "not a scalar" in res.stderr
