"""Tests under mpirun -n 1, 2 and 3 (oversubscribed), each with a timeout."""
import xml.etree.ElementTree as ET
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import run_cli, run_mpi_script

HERE = Path(__file__).resolve().parent
SMALL = ["--set", "parts.0.dx=0.002", "--set", "time.dt=2e-7", "--set", "time.t_end=1.2e-5",
         "--set", "output.every=20", "--set", 'output.fields=["u","v","stress"]', "--quiet"]


@pytest.mark.parametrize("ranks,dx", [(2, 1e-3), (3, 1e-3), (3, 2e-3)])
def test_halo_exchange_is_bitwise(ranks, dx):
    # dx = 2 mm on 3 ranks: slabs thinner than the halo -> multi-hop exchange
    res = run_mpi_script(HERE / "mpi_halo_check.py", ranks, str(dx), timeout=120)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "halo ok=True" in res.stdout


def test_exception_on_one_rank_aborts_the_job():
    res = run_mpi_script(HERE / "mpi_abort_check.py", 2, timeout=60)
    assert res.returncode != 0
    assert "deliberate failure on rank 1" in res.stderr


def run_on_1_2_3(base, scene, args):
    """Run ``scene`` on 1, 2 and 3 ranks; returns {ranks: run.h5}."""
    out = {}
    for n in (1, 2, 3):
        d = base / f"n{n}"
        res = run_cli(["run", scene, "--out", str(d), *args], ranks=n, timeout=600)
        assert res.returncode == 0, res.stdout + res.stderr
        out[n] = d / "run.h5"
    return out


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    return run_on_1_2_3(tmp_path_factory.mktemp("runs"), "elastic_wave", SMALL)


def test_decomposition_invariance_bitwise(runs):
    with h5py.File(runs[1], "r") as f1:
        ref = {k: f1[k][...] for k in ("fields/u", "fields/v", "fields/stress", "geometry/x")}
        assert f1.attrs["frames_written"] == 4
    for n in (2, 3):
        with h5py.File(runs[n], "r") as f:
            assert f.attrs["ranks"] == n
            for k, a in ref.items():
                assert np.array_equal(f[k][...], a), f"{k} differs between 1 and {n} ranks"
    assert np.abs(ref["fields/v"][-1]).max() > 0.1          # the wave really ran


def test_output_layout_and_xdmf(runs):
    with h5py.File(runs[2], "r") as f:
        N = f.attrs["n_points"]
        assert f["geometry/x"].shape == (N, 3)
        assert f["fields/u"].shape == (4, N, 3)
        assert f["fields/stress"].shape == (4, N, 6)
        assert "elastic_wave" in f.attrs["scene"]
        assert f.attrs["mpipd_version"]
        t = f["time"][...]
        np.testing.assert_allclose(np.diff(t), 20 * 2e-7, rtol=1e-9)
        e = f["energy/kinetic"][...] + f["energy/elastic"][...] + f["energy/hourglass"][...]
        assert e[0] > 0 and np.abs(e - e[0]).max() < 0.01 * e[0]
        assert np.abs(f["energy/balance"][...]).max() < 1e-6      # the ledger closes
    xdmf = runs[2].with_suffix(".xdmf").read_text()
    root = ET.fromstring(xdmf)                                # well-formed XML
    grids = root.findall("./Domain/Grid/Grid")
    assert len(grids) == 4
    names = {a.get("Name") for a in grids[-1].findall("Attribute")}
    assert names == {"u", "v", "stress", *(f"stress_{c}" for c in ("xx", "yy", "zz", "yz", "xz",
                                                                   "xy")),
                     "volume", "material", "part"}          # /geometry, at every frame
    part = next(a for a in grids[3].findall("Attribute") if a.get("Name") == "part")
    item = part.find("DataItem")
    assert item.get("NumberType") == "Int" and item.text == "run.h5:/geometry/part"
    # frame 3 of u: a HyperSlab for libxdmf2 (children) that Xdmf 3 reads from its text
    # (tests/test_paraview.py opens it with ParaView's readers)
    item = next(a for a in grids[3].findall("Attribute") if a.get("Name") == "u").find("DataItem")
    assert item.get("Type") == "HyperSlab" and item.get("ItemType") is None
    assert item.get("Dimensions") == f"{N} 3" and item.get("Format") == "HDF"
    assert item.text.strip() == f"run.h5:/fields/u|3 0 0:1 1 1:1 {N} 3:4 {N} 3"
    sel, src = item.findall("DataItem")
    assert sel.get("Dimensions") == "3 3" and sel.text.split() == ["3", "0", "0", "1", "1", "1",
                                                                   "1", str(N), "3"]
    assert src.get("Dimensions") == f"4 {N} 3" and src.text == "run.h5:/fields/u"


FRACTURE = ["--set", "parts.0.shape.z=[0.0, 0.006]", "--set", "time.t_end=8e-6",
            "--set", "output.every=40", "--quiet",
            "--set", 'output.fields=["u","v","damage","failure_mode","jh2_damage","pressure"]']


@pytest.fixture(scope="module")
def fracture_runs(tmp_path_factory):
    return run_on_1_2_3(tmp_path_factory.mktemp("frac"), "granite_ring", FRACTURE)


def test_fracture_identical_on_1_2_3_ranks(fracture_runs):
    """Same failed set, same broken bonds (the run file's /bonds, every frame's broken
    gid pairs), bit-identical fields (3 ranks: multi-hop halo)."""
    keys = ("fields/u", "fields/v", "fields/damage", "fields/failure_mode", "fields/jh2_damage",
            "fields/pressure", "bonds/broken", "bonds/offsets") + tuple(f"probes/{p}/{q}" for p in ("near", "far")
                                       for q in ("t", "sigma_rr", "v_r", "p", "s", "strength"))
    with h5py.File(fracture_runs[1], "r") as f1:
        ref = {k: f1[k][...] for k in keys}
        broken = f1.attrs["bonds_broken"]
        modes = f1.attrs["failed_points_by_mode"]
    assert broken > 1000 and modes[1] > 0 and modes[3] > 0     # crushing and tension cracks
    # probes: one row per step, and v_r agrees with the v field at a frame (step 40)
    with h5py.File(fracture_runs[1], "r") as f1:
        g = f1["probes/near"]
        assert len(g["t"]) == 161 and not np.isnan(g["v_r"][...]).any()
        gid = g.attrs["gid"]
        x = f1["geometry/x"][gid]
        v = f1["fields/v"][1, gid]
        want = (v[0] * x[0] + v[1] * x[1]) / np.hypot(x[0], x[1])
        assert abs(g["v_r"][40] - want) <= 1e-12 * abs(want)
    for n in (2, 3):
        with h5py.File(fracture_runs[n], "r") as f:
            assert f.attrs["bonds_broken"] == broken
            assert np.array_equal(f.attrs["failed_points_by_mode"], modes)
            for k, a in ref.items():
                assert np.array_equal(f[k][...], a), f"{k} differs between 1 and {n} ranks"


ROCKMASS = FRACTURE + [
    "--set", 'materials.granite.heterogeneity={distribution="weibull", modulus=6.0, seed=2, '
             'applies_to=["tension", "T"]}',
    "--set", "parts.0.jitter=0.2", "--set", "parts.0.jitter_seed=3",
    "--set", "joints=[{point=[0.0, 0.0, 0.0], normal=[1.0, 2.0, 0.5], radius=0.012}, "
             "{point=[0.0, 0.0, 0.0021], normal=[0.0, 0.0, 1.0], persistence=0.6, patch=0.002}]"]


@pytest.fixture(scope="module")
def rockmass_runs(tmp_path_factory):
    """granite_ring as a rock mass: Weibull strength, jitter (through the slab cuts) and
    two joints, one across every slab boundary and one along z."""
    return run_on_1_2_3(tmp_path_factory.mktemp("rockmass"), "granite_ring", ROCKMASS)


def test_rockmass_identical_on_1_2_3_ranks(rockmass_runs, fracture_runs):
    keys = ("geometry/x", "geometry/strength_factor", "fields/u", "fields/v", "fields/damage",
            "fields/failure_mode", "probes/near/sigma_rr", "probes/near/strength",
            "bonds/broken", "bonds/offsets")
    with h5py.File(rockmass_runs[1], "r") as f1:
        ref = {k: f1[k][...] for k in keys}
        broken, joint = f1.attrs["bonds_broken"], f1.attrs["joint_bonds"]
    with h5py.File(fracture_runs[1], "r") as f:            # the rock mass is not the lattice
        assert not np.array_equal(f["geometry/x"][...], ref["geometry/x"])
        assert f.attrs["joint_bonds"] == 0
    assert broken > 1000 and joint > 1000
    assert ref["fields/damage"][0].max() > 0.2             # the joints show at t = 0
    assert 0.17 < ref["geometry/strength_factor"].std() < 0.22     # m = 6: cv 0.194
    # the mpipd.post reader cuts the jittered points by their lattice levels
    from mpi4py import MPI

    from mpipd.post.reader import Run
    run = Run(rockmass_runs[1], MPI.COMM_SELF)
    try:
        np.testing.assert_allclose(np.unique(run.z_level), (np.arange(6) + 0.5) * 1e-3,
                                   rtol=0, atol=1e-15)
        assert run.n_levels == 6 and len(np.unique(run.geometry("x")[:, 2])) > 1000
    finally:
        run.close()
    for n in (2, 3):
        with h5py.File(rockmass_runs[n], "r") as f:
            assert f.attrs["bonds_broken"] == broken and f.attrs["joint_bonds"] == joint
            for k in keys:
                assert np.array_equal(f[k][...], ref[k]), f"{k} differs between 1 and {n} ranks"


@pytest.fixture(scope="module")
def multirate_runs(tmp_path_factory):
    """granite_ring with multi-rate classes (rock class 2, the crushed zone finer) and
    the forces recomputed after breakage (the ghosts' velocities once made that
    path depend on the decomposition; tests/test_restart.py covers the other one,
    the re-gather after a class change)."""
    return run_on_1_2_3(tmp_path_factory.mktemp("mr"), "granite_ring",
                        FRACTURE + ["--set", "time.multirate={max_ratio=4, safety=1.0}",
                                    "--set", "solver.refresh_after_break=true"])


def test_multirate_identical_on_1_2_3_ranks(multirate_runs, fracture_runs):
    keys = ("fields/u", "fields/v", "fields/damage", "fields/failure_mode", "fields/pressure",
            "energy/multirate", "probes/near/sigma_rr", "probes/far/v_r")
    with h5py.File(multirate_runs[1], "r") as f1:
        ref = {k: f1[k][...] for k in keys}
        broken = f1.attrs["bonds_broken"]
    with h5py.File(fracture_runs[1], "r") as f:          # multi-rate is not single-rate
        assert not np.array_equal(f["fields/u"][...], ref["fields/u"])
    assert broken > 1000 and ref["energy/multirate"][-1] != 0.0
    for n in (2, 3):
        with h5py.File(multirate_runs[n], "r") as f:
            assert f.attrs["bonds_broken"] == broken
            for k in keys:
                if k.startswith("energy/"):     # global sums: reduction order (1e-12 J)
                    np.testing.assert_allclose(f[k][...], ref[k], rtol=0, atol=1e-12)
                else:
                    assert np.array_equal(f[k][...], ref[k]), f"{k} differs between 1 and {n} ranks"


@pytest.mark.parametrize("ranks", [2, 3])
def test_remote_solids_are_exactly_those_the_gas_reaches(ranks):
    """mpi_near_check.py: gas moved up to a column away from its owners' slabs; each
    rank's remote solid rows are exactly the solids it lacks within the gas reach of
    its own gas, with their owners' positions, velocities, volumes and gids."""
    res = run_mpi_script(HERE / "mpi_near_check.py", ranks, timeout=180)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "near ok=True" in res.stdout
