"""postprocess report / compare: every measure on synthetic run files with known
answers (in-process, one reading rank), the same numbers on 1 and 2 reading
ranks, clear errors for foreign and truncated files, and the whole report on a
short `blast_demo` run under mpirun -n 2."""
import json
import math
import shutil
import subprocess
import sys

import h5py
import numpy as np
import pytest
from conftest import ROOT, child_env, run_cli

DX, R_WALL, R_OUT, NZ = 1e-3, 3e-3, 30e-3, 4
C_WAVE, N_ATT, C_ATT = 4000.0, 0.8, 300e6          # synthetic wave: speed, attenuation
DT = 1e-8

SCENE = f"""
[scene]
name = "synthetic"
[time]
dt = {DT}
steps = 1000
[materials.explosive]
model = "jwl"
[materials.granite]
model = "jh2"
tension = {{ sigma_st = -6.9e6, c1 = 0.33, rate0 = 0.4 }}
[[parts]]
name = "charge"
material = "explosive"
dx = {DX}
shape = {{ kind = "cylinder", center = [0.0, 0.0], radius = 0.002, z = [0.0, {NZ * DX}] }}
[[parts]]
name = "rock"
material = "granite"
dx = {DX}
shape = {{ kind = "annulus", center = [0.0, 0.0], inner_radius = {R_WALL}, radius = {R_OUT}, z = [0.0, {NZ * DX}] }}
[output]
every = 250
fields = ["v", "damage", "failure_mode", "pressure", "strain_energy"]
"""
PROBES = {"A": 6.8, "B": 10.8, "C": 22.0, "D": 26.0, "P1": 0.8, "P2": 1.6, "P3": 4.8}


def lattice():
    """Points of the scene in gid order (z, material, part, y, x), like mpipd.geometry."""
    from mpipd.geometry import Annulus, Cylinder
    cyl = Cylinder(center=(0.0, 0.0), radius=0.002, z=(0.0, NZ * DX))
    ann = Annulus(center=(0.0, 0.0), radius=R_OUT, z=(0.0, NZ * DX), inner_radius=R_WALL)
    xs, part = [], []
    for z in ann.z_levels(DX):
        for p, shape in ((0, cyl), (1, ann)):
            x, y = shape.cross_section(DX)
            xs.append(np.column_stack([x, y, np.full(len(x), z)]))
            part.append(np.full(len(x), p))
    return np.concatenate(xs), np.concatenate(part)


def gaussian(t, t0, width):
    return np.exp(-((t - t0) / width) ** 2)


def write_run(path, failed=None, v_rock=1.0, w_rock=2.0, frames=5):
    """An mpipd-layout run file.  ``failed``: boolean mask (last frame damage = 1);
    v = (v_rock * k, 0, 0) m/s and W = w_rock * k J/m3 on the rock at frame k;
    explosive pressure 1e8 * (k + 1) * (1 + z/mm) Pa; probes carry a Gaussian pulse
    of peak C d^-n (d in mm) arriving at d / C_WAVE."""
    x, part = lattice()
    N = len(x)
    rock = part == 1
    failed = np.zeros(N, bool) if failed is None else failed
    steps = 1000
    t = np.arange(steps + 1) * DT
    tf = np.linspace(0, steps * DT, frames)
    with h5py.File(path, "w") as f:
        f.attrs.update(n_points=N, frames_written=frames, scene=SCENE, scene_name="synthetic",
                       ranks=1, dt=DT, steps=steps, git_commit="test", mpipd_version="test")
        g = f.create_group("geometry")
        g["x"] = x
        g["volume"] = np.full(N, DX ** 3)
        g["material"] = part.astype("i4")
        g["material"].attrs["names"] = ["explosive", "granite"]
        g["part"] = part.astype("i4")
        g["part"].attrs["names"] = ["charge", "rock"]
        f["time"] = tf
        fl = f.create_group("fields")
        k = np.arange(frames)[:, None]
        dmg = np.zeros((frames, N))
        dmg[-1, failed] = 1.0
        fl["damage"] = dmg
        fl["failure_mode"] = np.where(dmg > 0, 3.0, 0.0)
        v = np.zeros((frames, N, 3))
        v[:, rock, 0] = v_rock * k
        fl["v"] = v
        fl["strain_energy"] = np.where(rock[None, :], w_rock * k, 0.0)
        fl["pressure"] = np.where(rock[None, :], 0.0, 1e8 * (k + 1) * (1 + x[None, :, 2] * 1e3))
        e = f.create_group("energy")
        for name in ("t", "kinetic", "strain", "hourglass", "gas", "total", "external"):
            e[name] = np.zeros(frames)
        r = np.hypot(x[:, 0], x[:, 1])
        for name, d_mm in PROBES.items():
            want = np.array([R_WALL + d_mm * 1e-3, 0.0, 0.5 * NZ * DX])
            gid = int(np.argmin(np.where(rock, np.linalg.norm(x - want, axis=1), np.inf)))
            d = r[gid] - R_WALL
            pulse = gaussian(t, 1e-6 + d / C_WAVE, 0.4e-6)
            pg = f.create_group(f"probes/{name}")
            pg.attrs["gid"] = gid
            pg.attrs["position"] = want
            pg["t"] = t
            pg["sigma_rr"] = -C_ATT * (d * 1e3) ** -N_ATT * pulse
            pg["v_r"] = 5.0 * (d * 1e3) ** -1.2 * pulse
            yielding = name != "P3"
            pg["p"] = 50e6 * pulse
            pg["s"] = 100e6 * pulse
            pg["strength"] = np.where(yielding, 100e6, 500e6) * np.ones_like(t)
    return x, part


def analyse(path):
    from mpi4py import MPI

    from postprocess.analysis import analyse as run_analysis
    from postprocess.model import load_model
    from postprocess.reader import Run
    run = Run(path, MPI.COMM_SELF)
    try:
        model = load_model(run)
        metrics, _ = run_analysis(run, model)
    finally:
        run.close()
    return metrics, model


def test_geometry_from_the_stored_scene(tmp_path):
    write_run(tmp_path / "run.h5")
    _, m = analyse(tmp_path / "run.h5")
    assert (m.r_wall, m.r_out, m.dx, m.center) == (R_WALL, R_OUT, DX, (0.0, 0.0))
    assert m.part_names[m.rock] == "rock" and m.part_names[m.charge] == "charge"
    assert m.jh2 is not None and m.density == {0: 1320.0, 1: 2660.0} and not m.notes


def test_crack_density_of_hand_placed_cracks(tmp_path):
    """Zones 3-12, 12-21, 21-30 mm.  Zone 1: a ring of failed points |r - 7.5 mm| < dx/2
    (length ~ 2 pi 7.5 mm); zone 2: one radial line along the +x row y = dx/2, which
    holds the 9 points x = 12.5 ... 20.5 mm: 9 mm of crack."""
    x, part = lattice()
    r = np.hypot(x[:, 0], x[:, 1])
    ring = (part == 1) & (np.abs(r - 7.5e-3) < 0.5 * DX)
    line = (part == 1) & (np.abs(x[:, 1] - 0.5 * DX) < 1e-9) & (x[:, 0] > 12e-3) & (r < 21e-3)
    write_run(tmp_path / "run.h5", failed=ring | line)
    m, _ = analyse(tmp_path / "run.h5")
    fr = m["fracture"]
    assert fr["criterion"] == "damage phi = 1" and len(fr["sections"]) == 3
    area = [math.pi * (b ** 2 - a ** 2) for a, b in ((3, 12), (12, 21), (21, 30))]   # mm^2
    n_ring = int(ring.sum()) // NZ
    for sec in fr["sections"].values():
        z1, z2, z3 = sec["zones"]
        assert z1["failed_points"] == n_ring and z2["failed_points"] == 9
        assert z1["density_mm_per_mm2"] == pytest.approx(n_ring * 1.0 / area[0], rel=1e-12)
        assert z2["density_mm_per_mm2"] == pytest.approx(9.0 / area[1], rel=1e-12)
        assert z3["density_mm_per_mm2"] == 0.0
        # the lattice ring is a digital circle: its length is 2 pi R within 15 %
        assert n_ring == pytest.approx(2 * math.pi * 7.5, rel=0.15)
    assert fr["mean_density_mm_per_mm2"][1] == pytest.approx(9.0 / area[1], rel=1e-12)


def test_radial_cracks_and_crushed_zone(tmp_path):
    """Six rays from the wall to the boundary (0, 60, ... 300 deg), a short ray at 30 deg,
    a chip at the boundary at 150 deg not connected inward, and a crushed disc r < 6 mm:
    six major cracks, crushed zone 3 mm = one borehole radius beyond the wall."""
    x, part = lattice()
    r = np.hypot(x[:, 0], x[:, 1])
    th = np.arctan2(x[:, 1], x[:, 0])
    rock = part == 1

    def ray(deg, r0, r1):
        a = np.radians(deg)
        along = x[:, 0] * np.cos(a) + x[:, 1] * np.sin(a)
        perp = np.abs(-x[:, 0] * np.sin(a) + x[:, 1] * np.cos(a))
        return rock & (perp < 0.75 * DX) & (along > 0) & (r >= r0) & (r <= r1)
    failed = rock & (r < 6e-3)
    for deg in range(0, 360, 60):
        failed |= ray(deg, 0, R_OUT)
    failed |= ray(30, 0, 15e-3)
    failed |= rock & (r > 27.5e-3) & (np.abs(np.degrees(th) - 150) < 4)
    write_run(tmp_path / "run.h5", failed=failed)
    m, _ = analyse(tmp_path / "run.h5")
    for sec in m["fracture"]["sections"].values():
        rc = sec["radial_cracks"]
        assert rc["count"] == 6 and rc["boundary_arcs"] == 7
        np.testing.assert_allclose(rc["angles_deg"], [0, 60, 120, 180, 240, 300], atol=2.0)
        assert sec["crushed_zone"]["extent_mm"] == pytest.approx(3.0)
    assert m["fracture"]["major_radial_cracks"] == 6
    assert m["fracture"]["crushed_extent_borehole_radii"] == pytest.approx(1.0)
    row = {r["key"]: r for r in m["targets"]}
    assert row["major_radial_cracks"]["verdict"] == "within"
    assert row["crushed_zone"]["verdict"] == "within"


def test_wave_speed_attenuation_and_ppv_from_probes(tmp_path):
    """A pulse of peak C d^-0.8 travelling at 4000 m/s gives back the speed and the
    exponent; the PPV law d^-1.2 gives beta = 1.2."""
    write_run(tmp_path / "run.h5")
    m, _ = analyse(tmp_path / "run.h5")
    rs = m["radial_stress"]
    assert [p["name"] for p in rs["points"]] == ["A", "B", "C", "D"]
    assert rs["fit"]["n"] == pytest.approx(N_ATT, abs=1e-4)
    assert rs["fit"]["C"] == pytest.approx(C_ATT / 1e6, rel=1e-3)
    a = rs["points"][0]
    assert a["peak_MPa"] == pytest.approx(C_ATT / 1e6 * a["d_mm"] ** -N_ATT, rel=1e-4)
    assert m["wave_speed"]["speed_m_s"] == pytest.approx(C_WAVE, rel=1e-3)
    assert m["ppv"]["fit"]["n"] == pytest.approx(1.2, abs=1e-4)
    assert m["ppv"]["source"].startswith("probes")
    row = {r["key"]: r for r in m["targets"]}
    assert row["attenuation_n"]["verdict"] == "within"          # 0.8 within 0.798 +- 0.1
    assert row["wave_speed"]["verdict"] == "outside"            # 4000 < 0.95 * 4270


def test_energy_paths_and_pressures(tmp_path):
    x, part = lattice()
    write_run(tmp_path / "run.h5", v_rock=2.0, w_rock=3.0)
    m, _ = analyse(tmp_path / "run.h5")
    n_rock = int((part == 1).sum())
    V = DX ** 3
    k = np.arange(5)
    want = n_rock * V * (0.5 * 2660.0 * (2.0 * k) ** 2 + 3.0 * k)
    np.testing.assert_allclose(m["energy"]["total_J"], want, rtol=1e-12)
    ps = {p["name"]: p for p in m["pressure_stress"]["points"]}
    assert ps["P1"]["yielded"] and ps["P2"]["yielded"] and not ps["P3"]["yielded"]
    assert ps["P1"]["s_at_yield_MPa"] == pytest.approx(99.0, abs=1.0)
    gas = m["gas_pressure"]
    zmax = (NZ - 0.5)                                           # mm, top level
    assert gas["peak_MPa"] == pytest.approx(100 * 5 * (1 + zmax))
    prof = m["gas_profiles"][-1]
    np.testing.assert_allclose(prof["p_MPa"], 100 * 5 * (1 + np.array(prof["z_mm"])))
    assert m["failure_modes"]["intact"] == int((part == 1).sum())


def post(ranks, *args, timeout=120):
    cmd = ["mpirun", "--oversubscribe", "-n", str(ranks), sys.executable, "-m", "postprocess",
           *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=ROOT,
                          env=child_env())


def test_foreign_and_truncated_files_are_one_line_errors(tmp_path):
    good = tmp_path / "run.h5"
    write_run(good)
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f["data"] = np.arange(10)
    cut = tmp_path / "cut.h5"
    raw = good.read_bytes()
    cut.write_bytes(raw[: len(raw) // 2])
    text = tmp_path / "text.h5"
    text.write_text("not hdf5\n")
    for bad, what in ((foreign, "not an mpipd run file"), (cut, "cannot open"),
                      (text, "cannot open"), (tmp_path / "none.h5", "cannot open")):
        res = subprocess.run([sys.executable, "-m", "postprocess", "report", str(bad)],
                             capture_output=True, text=True, timeout=60, cwd=ROOT, env=child_env())
        assert res.returncode == 2, (bad, res.stderr)
        lines = res.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("postprocess: error:") and what in lines[0]
        if bad not in (foreign, cut):
            continue
        res = post(2, "report", str(bad), "--out", str(tmp_path / "rep"))
        assert res.returncode == 2, (bad, res.stderr)
        ours = [ln for ln in res.stderr.splitlines() if ln.startswith("postprocess")]
        assert len(ours) == 1 and what in ours[0] and "Traceback" not in res.stderr
    assert not (tmp_path / "rep").exists()
    res = subprocess.run([sys.executable, "-m", "postprocess", "compare", str(good), str(foreign),
                          "--out", str(tmp_path / "cmp")], capture_output=True, text=True,
                         timeout=60, cwd=ROOT, env=child_env())
    assert res.returncode == 2 and "not an mpipd run file" in res.stderr


def test_compare_puts_runs_side_by_side(tmp_path):
    """Two synthetic runs (a crushed disc of 5 and of 8 mm) in one table and one figure."""
    x, part = lattice()
    r = np.hypot(x[:, 0], x[:, 1])
    for name, rc in (("small", 5e-3), ("large", 8e-3)):
        (tmp_path / name).mkdir()
        write_run(tmp_path / name / "run.h5", failed=(part == 1) & (r < rc))
    res = post(2, "compare", str(tmp_path / "small" / "run.h5"), str(tmp_path / "large" / "run.h5"),
               "--out", str(tmp_path / "cmp"))
    assert res.returncode == 0, res.stderr
    for f in ("compare.md", "compare.json", "compare_fracture.png", "compare_energy.png",
              "compare_peak_stress.png"):
        assert (tmp_path / "cmp" / f).stat().st_size > 1000
    doc = json.loads((tmp_path / "cmp" / "compare.json").read_text())
    assert [r["label"] for r in doc["runs"]] == ["synthetic (small)", "synthetic (large)"]
    ext = [r["fracture"]["crushed_extent_mm"] for r in doc["runs"]]
    assert ext == [2.0, 5.0]
    md = (tmp_path / "cmp" / "compare.md").read_text()
    assert "| synthetic (small) | synthetic (large) |" in md


# --------------------------------------------------------------------- end to end

FIGURES = ("fig07_explosive_pressure", "fig07_pressure_plane", "fig09_fracture_faces",
           "fig11_fracture_sections", "fig12_crack_density", "fig13_failure_modes",
           "fig15_pressure_stress", "fig16a_radial_stress", "fig16b_wave_speed",
           "fig17_peak_radial_stress", "fig18_ppv", "fig20_rock_energy")


def demo_scene():
    from mpipd.scene import builtin_scenes
    return "blast_demo" if "blast_demo" in builtin_scenes() else "blast_slice"


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo") / "demo"
    res = run_cli(["run", demo_scene(), "--out", str(out), "--quiet",
                   "--set", "time.t_end=3.8e-6", "--set", "output.every=38"], ranks=2)
    assert res.returncode == 0, res.stderr
    return out / "run.h5"


def test_report_on_blast_demo_under_mpirun(demo_run, tmp_path):
    docs = []
    for n in (2, 1):
        out = tmp_path / f"rep{n}"
        res = post(n, "report", str(demo_run), "--out", str(out))
        assert res.returncode == 0, res.stderr
        assert "wrote" in res.stdout
        docs.append((out / "report.json").read_text())
    assert docs[0] == docs[1]                        # the same numbers on 2 and on 1 rank
    doc = json.loads(docs[0])
    if demo_scene() == "blast_demo":                 # it has A-C and P1-P3: every figure
        assert sorted(doc["figures"]) == sorted(FIGURES), doc["figures_not_made"]
    for name in doc["figures"].values():
        assert (tmp_path / "rep2" / name).stat().st_size > 10_000
    md = (tmp_path / "rep2" / "report.md").read_text()
    assert "| quantity | this run |" in md and len(doc["targets"]) == 15
    assert all(r["verdict"].split(":")[0] in ("within", "outside", "not available")
               for r in doc["targets"])
    shutil.rmtree(tmp_path / "rep1")
