"""The Python API for notebooks (``mpipd.open``, mpipd/post/api.py) on a small
``blast_demo`` run made once: every value against the file read directly with h5py;
serial without MPI (no mpi4py imported); the same values read by 2 ranks under mpirun;
``import mpipd`` imports none of the reading code; and examples/notebook.py runs on the
run and prints what the file holds."""
import json
import subprocess
import sys

import h5py
import numpy as np
import pytest
from conftest import ROOT, child_env, run_cli, run_mpi_script

#: blast_demo cut to 3 mm thick and 12 mm across, 20 steps with a frame every 4, two
#: probes in the rock (the scene's own probes lie beyond the cut rock)
SCENE = ["run", "blast_demo", "--quiet",
         "--set", "parts.0.shape.z=[0.0, 0.003]", "--set", "parts.1.shape.z=[0.0, 0.003]",
         "--set", "parts.2.shape.z=[0.0, 0.003]", "--set", "parts.2.shape.radius=0.012",
         "--set", "time.t_end=4e-7", "--set", "output.every=4",
         "--set", 'output.fields=["u","damage","pressure","peak_pressure"]',
         "--set", 'probes=[{ name = "A", position = [0.006, 0.0, 0.0015], part = "rock" }, '
                  '{ name = "B", position = [0.0, 0.009, 0.0015], part = "rock" }]']


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    out = tmp_path_factory.mktemp("api") / "demo"
    res = run_cli([*SCENE, "--out", str(out)], timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    return out / "run.h5"


def names(f, key):
    return [n.decode() if isinstance(n, bytes) else str(n)
            for n in f["geometry"][key].attrs["names"]]


def test_import_mpipd_loads_no_reading_code():
    code = ("import sys, mpipd; print(sorted(m for m in ('h5py', 'matplotlib', 'mpi4py', "
            "'mpipd.post', 'mpipd.post.api') if m in sys.modules))")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120, env=child_env())
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "[]"


def test_open_is_serial_without_mpi(run_file):
    """Opening, reading a field and a section import neither mpi4py nor MPI."""
    code = ("import sys, mpipd; run = mpipd.open(sys.argv[1]); run.field('damage'); "
            "run.section(part='rock'); run.probes; run.energy; run.close(); "
            "print('mpi4py' in sys.modules)")
    res = subprocess.run([sys.executable, "-c", code, str(run_file)], capture_output=True,
                         text=True, timeout=120, env=child_env())
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "False"


def test_frames_times_names_and_fields_are_the_files(run_file):
    import mpipd
    with mpipd.open(run_file.parent) as run, h5py.File(run_file, "r") as f:
        k = int(f.attrs["frames_written"])
        assert run.frames == k == 6                       # t = 0 and every 4 of 20 steps
        assert run.n_points == int(f.attrs["n_points"]) == len(run.x)
        np.testing.assert_array_equal(run.times, f["time"][:k])
        assert run.materials == names(f, "material") == ["explosive", "copper", "granite"]
        assert run.parts == names(f, "part") == ["charge", "tube", "rock"]
        assert set(run.fields) == {"u", "damage", "pressure", "peak_pressure"}
        assert run.attrs["scene_name"] == "blast_demo" and run.gid_range == (0, run.n_points)
        np.testing.assert_array_equal(run.x, f["geometry/x"][...])
        np.testing.assert_array_equal(run.part_ids, f["geometry/part"][...])
        np.testing.assert_array_equal(run.material_ids, f["geometry/material"][...])
        for name in ("damage", "pressure", "u"):
            np.testing.assert_array_equal(run.field(name), f["fields"][name][k - 1])
            np.testing.assert_array_equal(run.field(name, frame=2), f["fields"][name][2])
            np.testing.assert_array_equal(run.field(name, frame=slice(None)),
                                          f["fields"][name][:k])
        p = f["fields/pressure"][k - 1]
        assert np.count_nonzero(p)                        # the charge is burning
        rock = f["geometry/part"][...] == 2
        np.testing.assert_array_equal(run.field("pressure", part="rock"), p[rock])
        np.testing.assert_array_equal(run.field("u", frame=slice(1, 3), part="charge"),
                                      f["fields/u"][1:3][:, f["geometry/part"][...] == 0])
        np.testing.assert_array_equal(run.positions("tube"),
                                      f["geometry/x"][...][f["geometry/part"][...] == 1])
        with pytest.raises(KeyError, match="stress"):
            run.field("stress")
        with pytest.raises(IndexError):
            run.field("damage", frame=k)
        with pytest.raises(ValueError, match="charge, tube, rock"):
            run.field("damage", part="granite")


def test_a_section_is_the_level_nearest_the_height(run_file):
    """The section against the same rule applied to the file: the z level (the points'
    own z: this lattice is not jittered) nearest the wanted height among the part's
    levels, and the part's points on it."""
    import mpipd
    with mpipd.open(run_file) as run, h5py.File(run_file, "r") as f:
        assert "z_level" not in f["geometry"]
        x, pid = f["geometry/x"][...], f["geometry/part"][...]
        k = int(f.attrs["frames_written"]) - 1
        # 2.45 mm: nearest the rock's level 2.5 mm, the charge's nearest is 2.6 mm
        for part, z, pids in (("rock", None, [2]), ("charge", 0.00245, [0]),
                              (None, 0.0009, [0, 1, 2])):
            mine = np.isin(pid, pids)
            levels = np.unique(x[mine, 2])
            want = 0.5 * (x[mine, 2].min() + x[mine, 2].max()) if z is None else z
            zl = levels[np.argmin(np.abs(levels - want))]
            sel = mine & (x[:, 2] == zl)
            sec = run.section(z=z, part=part, field="pressure")
            assert len(sec.gid) and sec.z == zl and sec.part == part and sec.frame == k
            assert sec.time == f["time"][k]
            np.testing.assert_array_equal(sec.gid, np.flatnonzero(sel))
            np.testing.assert_array_equal(sec.x, x[sel, 0])
            np.testing.assert_array_equal(sec.y, x[sel, 1])
            np.testing.assert_array_equal(sec.values, f["fields/pressure"][k][sel])
        sec = run.section(part="rock", field="u", frame=1)        # a vector field
        assert sec.values.shape == (len(sec.gid), 3)
        np.testing.assert_array_equal(sec.values, f["fields/u"][1][sec.gid])
        assert run.section().field == "damage"


def test_probes_and_ledger_are_the_files(run_file):
    import mpipd
    with mpipd.open(run_file) as run, h5py.File(run_file, "r") as f:
        assert sorted(run.probes) == ["A", "B"]
        for name, probe in run.probes.items():
            g = f["probes"][name]
            written = np.isfinite(g["t"][...])
            assert written.sum() == 21                    # steps 0..20, one row each
            assert set(probe.keys()) == set(g)
            for q in g:
                np.testing.assert_array_equal(probe[q], g[q][...][written])
            assert probe.gid == g.attrs["gid"] and probe.part == "rock"
            assert probe.material == "granite"
            np.testing.assert_array_equal(probe.x, f["geometry/x"][probe.gid])
            np.testing.assert_array_equal(probe.position, g.attrs["position"])
        ledger = run.energy
        k = int(f.attrs["frames_written"])
        assert list(ledger)[0] == "t" and list(ledger)[-1] == "balance"
        assert set(ledger) == set(f["energy"])
        for term, values in ledger.items():
            np.testing.assert_array_equal(values, f["energy"][term][:k])
        np.testing.assert_array_equal(ledger["t"], run.times)


def test_not_a_run_file_is_one_clear_error(tmp_path):
    import mpipd
    from mpipd.post.reader import RunFileError
    bad = tmp_path / "x.h5"
    with h5py.File(bad, "w") as f:
        f["a"] = 1
    with pytest.raises(RunFileError, match="not an mpipd run file"):
        mpipd.open(bad)


READ_IN_PARALLEL = """
import json, sys
import numpy as np
from mpi4py import MPI
import mpipd
comm = MPI.COMM_WORLD
run = mpipd.open(sys.argv[1], comm=comm)
lo, hi = run.gid_range
parts = comm.gather((lo, hi, run.field("pressure"), run.field("u", frame=3, part="rock")), root=0)
sec = run.section(part="rock", field="pressure")
times, ledger, probes = run.times, run.energy, run.probes
run.close()
if comm.Get_rank() == 0:
    one = mpipd.open(sys.argv[1])
    ref_sec = one.section(part="rock", field="pressure")
    out = {"ranges": [[int(p[0]), int(p[1])] for p in parts],
           "field": bool(np.array_equal(np.concatenate([p[2] for p in parts]),
                                        one.field("pressure"))),
           "part_field": bool(np.array_equal(np.concatenate([p[3] for p in parts]),
                                             one.field("u", frame=3, part="rock"))),
           "section": all(bool(np.array_equal(getattr(sec, a), getattr(ref_sec, a)))
                          for a in ("x", "y", "gid", "values")) and sec.z == ref_sec.z,
           "times": bool(np.array_equal(times, one.times)),
           "ledger": all(bool(np.array_equal(ledger[t], v)) for t, v in one.energy.items()),
           "probes": all(bool(np.array_equal(probes[n]["sigma_rr"], p["sigma_rr"]))
                         for n, p in one.probes.items())}
    print(json.dumps(out))
else:
    print(json.dumps({"section_elsewhere": sec is None}))
"""


def test_two_reading_ranks_give_the_serial_values(run_file, tmp_path):
    script = tmp_path / "read.py"
    script.write_text(READ_IN_PARALLEL)
    res = run_mpi_script(script, 2, str(run_file), timeout=180)
    assert res.returncode == 0, res.stdout + res.stderr
    docs = [json.loads(line) for line in res.stdout.splitlines() if line.startswith("{")]
    ours = [d for d in docs if "ranges" in d]
    assert len(ours) == 1 and {"section_elsewhere": True} in docs, res.stdout
    d = ours[0]
    (a0, b0), (a1, b1) = d["ranges"]
    assert a0 == 0 and b0 == a1 < b1 and b0 > 0                # each rank a slice
    assert all(d[k] for k in ("field", "part_field", "section", "times", "ledger", "probes")), d


def test_the_notebook_example_runs(run_file, tmp_path):
    png = tmp_path / "damage.png"
    res = subprocess.run([sys.executable, str(ROOT / "examples" / "notebook.py"), str(run_file),
                          "--part", "rock", "--out", str(png)], capture_output=True, text=True,
                         timeout=180, cwd=ROOT, env=child_env())
    assert res.returncode == 0, res.stdout + res.stderr
    with h5py.File(run_file, "r") as f:
        k = int(f.attrs["frames_written"])
        balance = np.abs(f["energy/balance"][:k]).max()
        n_rock = int((f["geometry/part"][...] == 2).sum())
        sigma = f["probes/A/sigma_rr"][...]
    out = res.stdout
    assert f"{k} frames" in out and "parts: charge, tube, rock" in out
    assert "materials: explosive, copper, granite" in out
    assert f" of {n_rock} points >= 0.5" in out
    assert f"largest |balance| {balance:.3e}" in out
    assert f"most compressive sigma_rr {np.nanmin(sigma) / 1e6:.4g} MPa" in out
    assert png.is_file() and png.stat().st_size > 1000
