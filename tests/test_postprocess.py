"""postprocess under mpirun: the wave speed read back from a 2-rank run file, by
1 and by 2 reading ranks, against the closed-form speeds; the summary against
values read directly with h5py.  And, serially, the formulas postprocess shares
(the peak time of fits, the reductions of Team, the JH2 envelopes of jh2)."""
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
    cmd = ["mpirun", "--oversubscribe", "-n", str(ranks), sys.executable, "-m", "mpipd.post",
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


def test_wave_speed_refuses_a_peak_at_the_first_frame(run_file):
    res = post(2, "wave-speed", str(run_file), "--stations", "0.0,0.1")   # the bump at t = 0
    assert res.returncode == 2
    assert ("mpipd.post: error: the peak is at the first or last frame: the run is too "
            "short or the station too far") in res.stderr


def test_peak_time_vertex_and_edges():
    from mpipd.post.fits import peak_time
    t = np.arange(8) * 0.5
    # samples of y = 1 - (t - 1.6)^2: the vertex exactly, with the largest sample's value
    y = 1.0 - (t - 1.6) ** 2
    tp, yp, interior = peak_time(t, y)
    assert interior and tp == pytest.approx(1.6, rel=1e-14) and yp == y[3]
    tp, _, interior = peak_time(t, 1.0 - (t - 1.4) ** 2)     # shifted to the left side
    assert interior and tp == pytest.approx(1.4, rel=1e-14)
    # a peak at either end: the sample itself, flagged (wave-speed refuses it)
    assert peak_time(t, -t) == (0.0, 0.0, False)
    assert peak_time(t, t) == (3.5, 3.5, False)
    # two equal largest samples: the first, shifted half a step to the vertex between
    assert peak_time(t, np.array([0, 1, 2, 2, 1, 0, 0, 0.0])) == (1.25, 2.0, True)
    # a NaN (a row never written) is not a peak
    assert peak_time(t, np.array([np.nan, 1, 3, 1, 0, 0, 0, 0.0])) == (1.0, 3.0, True)


def test_team_reductions_of_numbers_and_arrays(team):
    """The reductions the run reader uses (Run.max/min/sum_int/max_array/sum_array):
    numbers stay numbers, arrays are reduced elementwise in their dtype."""
    assert team.max(2.5) == 2.5 and team.min(-1) == -1 and team.sum(3) == 3
    a = np.array([1.0, -2.0, 3.0])
    for f in (team.max, team.min, team.sum):
        out = f(a)
        assert isinstance(out, np.ndarray) and out.dtype == a.dtype
        np.testing.assert_array_equal(out, a)
    n = np.array([4, 5], dtype=np.int64)
    assert team.sum(n).dtype == np.int64


def test_jh2_envelope_of_the_pressure_stress_figure():
    """probe_metrics.jh2_envelope: sigma_HEL times Eqs. 21 and 23 (Table 1 granite),
    at edot* = 1 by default: 433.16 MPa intact and 49.14 MPa fractured at p = 200 MPa
    (1.2 GPa * 1.9 (254/3700)^0.62 and 1.2 GPa * 0.25 (200/3700)^0.62)."""
    from mpipd.materials.jh2 import JH2
    from mpipd.post.probe_metrics import jh2_envelope
    m = JH2()
    si, sf = jh2_envelope(m, np.array([-m.T, 0.0, 200e6]))
    assert si[0] == 0.0 and sf[0] == 0.0 and sf[1] == 0.0
    assert si[2] == pytest.approx(433.158e6, rel=1e-5)
    assert sf[2] == pytest.approx(49.1445e6, rel=1e-5)
    si1, sf1 = jh2_envelope(m, np.array([200e6]), strain_rate=1000.0)
    rate = 1.0 + 0.005 * math.log(1000.0)
    assert si1[0] == pytest.approx(si[2] * rate, rel=1e-14)
    assert sf1[0] == pytest.approx(sf[2] * rate, rel=1e-14)
