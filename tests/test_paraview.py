"""ParaView opens run.xdmf: a fracture run on 2 ranks, read back through each of
ParaView's XDMF readers by ``pvbatch`` (Debian's ParaView 5.11; ``make test``
installs it, scripts/install_paraview.sh), equals run.h5 at the last frame."""
import shutil
import subprocess
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import run_cli

HERE = Path(__file__).resolve().parent
PVBATCH = shutil.which("pvbatch")
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


def pvbatch_env(home):
    """A clean environment for pvbatch.  It embeds the system Python (a PYTHONPATH
    to the venv would shadow its numpy), and it is an MPI program that starts as a
    singleton: no launcher variables of an mpirun this pytest may run under.  Headless
    needs nothing more: the probe fetches data and renders nothing."""
    return {"PATH": "/usr/local/bin:/usr/bin:/bin", "HOME": str(home), "LANG": "C.UTF-8",
            "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}


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
