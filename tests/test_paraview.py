"""ParaView opens run.xdmf: a fracture run on 2 ranks, read back through each of
ParaView's XDMF readers by ``pvbatch`` (Debian's ParaView 5.11; ``make test``
installs it, scripts/install_paraview.sh), equals run.h5 at the last frame; and
ParaView draws it: every point a vertex cell in all three readers, Threshold on
damage and Clip give the points they should, and the shipped
scripts/paraview_figure.py renders a picture that is not blank (headless, on an Xvfb
display started here)."""
import os
import select
import shutil
import subprocess
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import run_cli

HERE = Path(__file__).resolve().parent
FIGURE = HERE.parent / "scripts" / "paraview_figure.py"
PVBATCH = shutil.which("pvbatch")
XVFB = shutil.which("Xvfb")
pytestmark = pytest.mark.skipif(
    PVBATCH is None, reason="pvbatch not found (make test installs Debian's paraview "
                            "with scripts/install_paraview.sh)")

FIELDS = ["u", "v", "damage", "stress"]
# 130 steps, a frame every 30: steps 0, 30, ..., 120 and the last, 130 -> 6 frames
RING = ["--set", "parts.0.shape.z=[0.0, 0.006]", "--set", "time.t_end=6.5e-6",
        "--set", "output.every=30", "--set", f"output.fields={FIELDS!r}".replace("'", '"'),
        "--quiet"]
READERS = ("XDMFReader", "Xdmf3ReaderS", "Xdmf3ReaderT")


@pytest.fixture(scope="module")
def ring(tmp_path_factory):
    out = tmp_path_factory.mktemp("paraview")
    res = run_cli(["run", "granite_ring", "--out", str(out), *RING], ranks=2, timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    return out / "run.h5"


def pvbatch_env(home, display=None):
    """A clean environment for pvbatch.  It embeds the system Python (a PYTHONPATH
    to the venv would shadow its numpy), and it is an MPI program that starts as a
    singleton: no launcher variables of an mpirun this pytest may run under.  The
    probes fetch data and render nothing; the picture renders through X on
    ``display`` (Debian's ParaView has no offscreen rendering: without a display
    pvbatch aborts with "bad X server connection")."""
    env = {"PATH": "/usr/local/bin:/usr/bin:/bin", "HOME": str(home), "LANG": "C.UTF-8",
           "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}
    if display is not None:
        env["DISPLAY"] = display
    return env


def pvbatch(args, tmp_path, display=None, timeout=180):
    res = subprocess.run([PVBATCH, *map(str, args)], capture_output=True, text=True,
                         timeout=timeout, cwd=tmp_path, env=pvbatch_env(tmp_path, display))
    log = res.stdout + res.stderr
    assert res.returncode == 0, log
    return log


@pytest.fixture(scope="module")
def display():
    """An X display for pvbatch: an Xvfb of this module's own.  ``-displayfd``: the
    server picks a free display number and writes it when it accepts connections, so
    there is no race for a number nor a guess at the start-up time (``xvfb-run -a``
    lost both, now and then, to the other X servers of a busy machine)."""
    if XVFB is None:        # pvbatch is here (the module runs), so the set-up is broken
        pytest.fail("Xvfb not found beside pvbatch: scripts/install_paraview.sh (make "
                    "paraview, run by make test) installs both")
    r, w = os.pipe()
    proc = subprocess.Popen([XVFB, "-displayfd", str(w), "-nolisten", "tcp",
                             "-screen", "0", "1280x1024x24"], pass_fds=(w,),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(w)
    try:
        ready, _, _ = select.select([r], [], [], 60)
        num = os.read(r, 64).decode().strip() if ready else ""
        assert num.isdigit(), f"Xvfb gave no display number in 60 s (exit {proc.poll()})"
        yield f":{num}"
    finally:
        os.close(r)
        proc.terminate()
        proc.wait(timeout=30)


def test_paraview_reads_every_field_at_the_last_frame(ring, tmp_path):
    out = tmp_path / "paraview.npz"
    res = subprocess.run([PVBATCH, str(HERE / "paraview_probe.py"),
                          str(ring.with_suffix(".xdmf")), str(out)],
                         capture_output=True, text=True, timeout=180, cwd=tmp_path,
                         env=pvbatch_env(tmp_path))
    log = res.stdout + res.stderr
    assert res.returncode == 0, log
    assert "Skipping unrecognized array type" not in log, log
    got = np.load(out)
    with h5py.File(ring, "r") as f:
        n = int(f.attrs["frames_written"])
        times = f["time"][:n]
        x = f["geometry/x"][...]
        want = {k: f["fields"][k][n - 1] for k in FIELDS}
    assert n == 6
    assert (want["damage"] > 0).sum() > 100 and want["damage"].max() == 1.0   # cracks
    assert str(got["default"]) in READERS
    for r in READERS:
        assert len(got[f"{r}.t"]) == n, r
        np.testing.assert_allclose(got[f"{r}.t"], times, rtol=1e-8, atol=0, err_msg=r)
        np.testing.assert_array_equal(got[f"{r}.x"], x, err_msg=r)        # gid order
        for k in FIELDS:
            assert f"{r}.{k}" in got, f"{r} loaded no {k}: {sorted(got.keys())}"
            a = got[f"{r}.{k}"]
            assert a.size == want[k].size, (r, k, a.shape)
            np.testing.assert_array_equal(a.reshape(want[k].shape), want[k], err_msg=f"{r} {k}")
        for c, comp in enumerate(("xx", "yy", "zz", "yz", "xz", "xy")):   # named components
            np.testing.assert_array_equal(got[f"{r}.stress_{comp}"], want["stress"][:, c],
                                          err_msg=f"{r} stress_{comp}")


def test_paraview_draws_every_point_thresholds_and_clips(ring, tmp_path):
    """Every point is a vertex cell in all three readers, in gid order; on the file as
    ``OpenDataFile`` opens it, Threshold on damage and Clip give the points of run.h5
    (before run.xdmf's Polyvertex had its connectivity, the Xdmf 3 readers gave no
    cell: nothing drew, and both filters gave nothing)."""
    out = tmp_path / "draw.npz"
    pvbatch([HERE / "paraview_draw.py", ring.with_suffix(".xdmf"), out], tmp_path)
    got = np.load(out)
    with h5py.File(ring, "r") as f:
        n = int(f.attrs["frames_written"])
        N = int(f.attrs["n_points"])
        damage = f["fields/damage"][n - 1]
        x = f["geometry/x"][...]
    assert str(got["default"]) in READERS
    for r in ("open", *READERS):
        assert got[f"{r}.points"] == N and got[f"{r}.cells"] == N, r
        assert list(got[f"{r}.types"]) in ([1], [2]), r         # VTK_VERTEX / VTK_POLY_VERTEX
        np.testing.assert_array_equal(got[f"{r}.offsets"], np.arange(N + 1), err_msg=r)
        np.testing.assert_array_equal(got[f"{r}.connectivity"], np.arange(N), err_msg=r)
    hot = int((damage >= 0.5).sum())
    assert 100 < hot < N
    assert got["threshold"] == hot and got["threshold_cells"] == hot
    assert got["clip"] in ((x[:, 0] < 0).sum(), (x[:, 0] > 0).sum())
    assert 0 < got["clip"] < N


def scene_pixels(png):
    """The fraction of the picture's left three quarters (the scalar bar is on the
    right) unlike the background (the corner pixel), and the fraction that is the
    warm end of the colour map (damage near 1)."""
    from PIL import Image
    a = np.asarray(Image.open(png).convert("RGB")).astype(int)
    a = a[:, : 3 * a.shape[1] // 4]
    drawn = (np.abs(a - a[0, 0]).sum(axis=-1) > 30).mean()
    warm = ((a[..., 0] > 150) & (a[..., 1] < 90) & (a[..., 2] < 90)).mean()
    return drawn, warm


def test_paraview_figure_renders_the_damage(ring, tmp_path, display):
    """scripts/paraview_figure.py draws the run, thresholded on damage, headless: the
    picture holds the points (a blank view, as before, holds only the scalar bar)."""
    png = tmp_path / "damage.png"
    log = pvbatch([FIGURE, ring.parent, "--out", png, "--threshold", "0.5",
                   "--size", "500", "400"], tmp_path, display)
    with h5py.File(ring, "r") as f:
        N = int(f.attrs["n_points"])
        hot = int((f["fields/damage"][int(f.attrs["frames_written"]) - 1] >= 0.5).sum())
    assert f"{N} points {N} cells" in log and f"damage >= 0.5: {hot} points" in log, log
    drawn, warm = scene_pixels(png)
    assert drawn > 0.05, f"the picture is blank: {drawn:.1%} of it drawn"
    assert warm > 0.001, f"no damaged point drawn: {warm:.2%} of the picture"
