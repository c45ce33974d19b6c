"""The closed form behind `make diagnoses` (studies/diagnoses/wave_speed.py): the
cylindrical cavity under a pressure history, checked against two limits computed
here — causality (nothing before (r - a)/c_P) and the quasi-static Lamé field
sigma_rr = -p a^2 / r^2 for a slow load."""
import importlib.util
import math

import numpy as np
import pytest
from conftest import ROOT

spec = importlib.util.spec_from_file_location(
    "wave_speed", ROOT / "studies" / "diagnoses" / "wave_speed.py")
ws = importlib.util.module_from_spec(spec)
spec.loader.exec_module(ws)

RHO, K, G = 2660.0, 21.9e9, 25.7e9
C_P = math.sqrt((K + 4 * G / 3) / RHO)
A = 3.2e-3


class Pulse:
    def __init__(self, p0, alpha, beta):
        self.p0, self.alpha, self.beta = p0, alpha, beta

    def value(self, t):
        return self.p0 * (math.exp(-self.alpha * t) - math.exp(-self.beta * t))


def test_nothing_arrives_before_the_p_wave():
    t = np.arange(600) * 2e-8
    load = Pulse(3e8, 2e5, 2e6)
    for r in (2 * A, 4 * A, 8 * A):
        y, c = ws.closed_form(t, r, A, load, RHO, K, G)
        assert c == pytest.approx(C_P, rel=1e-12)
        before = t < (r - A) / C_P - 0.1e-6
        assert np.abs(y[before]).max() < 2e-3 * y.max()
        assert y.max() > 0


def test_a_slow_load_gives_the_lame_field():
    """p rises over ~1 ms, 1000 transit times a/c_P: sigma_rr(r) -> -p(t) a^2/r^2."""
    t = np.arange(4000) * 5e-7
    load = Pulse(1e8, 2e2, 2e3)
    for r in (1.5 * A, 3 * A):
        y, _ = ws.closed_form(t, r, A, load, RHO, K, G)
        p = np.array([load.value(x) for x in t])
        k = slice(1000, 4000)
        assert y[k] == pytest.approx(p[k] * (A / r) ** 2, rel=2e-2, abs=1e-3 * p.max())


def test_potentials_where_totals_are_the_ledgers_terms(tmp_path):
    """studies/diagnoses/potentials_where.py on a fracturing run's checkpoint, read
    on another rank count (2 against the run's 1): its table's per-(material, code)
    rows add up to its "all" row, count every point once, and its totals are the
    ledger's hourglass and spring terms at the checkpoint's step as the run booked
    them in run.h5 (a frame falls on that step)."""
    import re

    import h5py
    from conftest import run_cli, run_mpi_script

    out = tmp_path / "run"
    res = run_cli(["run", "granite_ring", "--out", str(out), "--quiet",
                   "--set", "parts.0.shape.z=[0.0, 0.006]", "--set", "time.t_end=1.2e-5",
                   "--set", "output.every=40", "--stop-after", "200"], ranks=1)
    assert res.returncode == 0, res.stderr
    with h5py.File(out / "run.h5", "r") as f:
        k = int(f.attrs["frames_written"]) - 1
        assert round(f["time"][k] / f.attrs["dt"]) == 200
        hg, sp = f["energy/hourglass"][k], f["energy/spring"][k]
        n_points = int(f.attrs["n_points"])
    res = run_mpi_script(ROOT / "studies" / "diagnoses" / "potentials_where.py", 2,
                         str(out / "checkpoint.h5"))
    assert res.returncode == 0, res.stderr
    assert "step 200" in res.stdout
    rows = re.findall(r"^\| (\w+) \| ?(\d*) ?\| (\d+) \| ([^|]+) \| ([^|]+) \|$", res.stdout, re.M)
    parts = [r for r in rows if r[0] != "all"]
    (whole,) = [r for r in rows if r[0] == "all"]
    assert len(parts) >= 2                      # fracture put points on a fallback
    assert sum(int(r[2]) for r in parts) == int(whole[2]) == n_points
    for col, booked in ((3, hg), (4, sp)):
        assert sum(float(r[col]) for r in parts) == pytest.approx(float(whole[col]), rel=1e-3)
        assert float(whole[col]) == pytest.approx(booked, rel=1e-3, abs=1e-9)
    assert hg > 0


def test_zone_split_reads_a_failed_annulus_as_area_over_dx():
    """studies/diagnoses/zone_split.py on a hand-built section: a square lattice at
    0.3 mm inside r = 10 mm and 0.8 mm beyond (the seamless band's), the annulus 3.2-10
    mm failed through and nothing else.  Its share of zone 1 is counted here as failed
    points x dx over the zone's area, and it is within the lattice's rounding of
    area(annulus) / (dx area(zone 1)); the part beyond 10 mm adds nothing, and the two
    shares add up to crack_density's zone."""
    spec = importlib.util.spec_from_file_location(
        "zone_split", ROOT / "studies" / "diagnoses" / "zone_split.py")
    zs = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(zs)
    rw, ro, rs = 3.2e-3, 72e-3, 10e-3
    fine = np.arange(-rs, rs + 1e-9, 0.3e-3)
    coarse = np.arange(-ro, ro + 1e-9, 0.8e-3)
    xf, yf = (a.ravel() for a in np.meshgrid(fine, fine))
    xc, yc = (a.ravel() for a in np.meshgrid(coarse, coarse))
    kf, kc = np.hypot(xf, yf) < rs, np.hypot(xc, yc) >= rs
    x, y = np.concatenate([xf[kf], xc[kc]]), np.concatenate([yf[kf], yc[kc]])
    dx = np.concatenate([np.full(kf.sum(), 0.3e-3), np.full(kc.sum(), 0.8e-3)])
    r = np.hypot(x, y)
    failed = (r >= rw) & (r < rs)
    whole, parts, masks = zs.split_density(x, y, failed, (0.0, 0.0), dx, rw, ro, rs)
    e1 = rw + (ro - rw) / 3
    area1 = np.pi * (e1 ** 2 - rw ** 2)
    by_hand = np.count_nonzero(failed) * 0.3 / (area1 * 1e6)     # mm / mm^2
    assert parts[0][0]["density_mm_per_mm2"] == pytest.approx(by_hand, rel=1e-12)
    assert by_hand == pytest.approx(np.pi * (rs ** 2 - rw ** 2) / (0.3e-3 * area1) * 1e-3, rel=0.03)
    assert parts[1][0]["density_mm_per_mm2"] == 0.0
    for k in range(3):
        assert (parts[0][k]["density_mm_per_mm2"] + parts[1][k]["density_mm_per_mm2"]
                == pytest.approx(whole[k]["density_mm_per_mm2"], rel=1e-12))
    assert np.count_nonzero(masks[0][0]) == np.count_nonzero(kf & (np.hypot(xf, yf) >= rw))
