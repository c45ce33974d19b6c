"""Fragments (mpipd.post.fragments, mpipd.post.sieve): a block cut by joints into
known pieces, the same fragments on 1, 2 and 3 ranks, and fits that recover a
sampled distribution.  Expected values are computed here from the geometry."""
import csv
import json
import math

import numpy as np
import pytest
from conftest import child_env, run_cli

from mpipd.post.sieve import fit_rosin_rammler, fit_swebrec, passing, percentile

DX = 1e-3
RHO = 2660.0
BLOCK = f"""
[scene]
name = "cut_block"
[time]
dt = 1.0e-7
steps = 0
[materials.granite]
model = "elastic"
density = {RHO}
bulk_modulus = 21.9e9
shear_modulus = 25.7e9
[[parts]]
name = "block"
material = "granite"
dx = {DX}
shape = {{ kind = "box", lo = [0.0, 0.0, 0.0], hi = [0.010, 0.008, 0.006] }}
[solver]
contact = true
[[joints]]                    # between the lattice planes x = 2.5 and 3.5 mm
point = [0.0032, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
[[joints]]                    # between y = 3.5 and 4.5 mm
point = [0.0, 0.004, 0.0]
normal = [0.0, -1.0, 0.0]
[output]
every = 1
fields = ["u"]
"""


def fragments(tmp_path, run, ranks, *extra):
    import subprocess
    import sys
    out = tmp_path / f"frag{ranks}"
    cmd = ["mpirun", "--oversubscribe", "-n", str(ranks), sys.executable, "-m", "mpipd.post",
           "fragments", str(run), "--out", str(out), "--min-points", "1", *extra]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=child_env())
    assert res.returncode == 0, res.stdout + res.stderr
    return out


@pytest.fixture(scope="module")
def cut_block(tmp_path_factory):
    d = tmp_path_factory.mktemp("cut")
    (d / "block.toml").write_text(BLOCK)
    res = run_cli(["run", str(d / "block.toml"), "--out", str(d / "run"), "--quiet"])
    assert res.returncode == 0, res.stdout + res.stderr
    return d, d / "run" / "run.h5"


def test_a_block_cut_by_two_joints_gives_its_four_pieces(cut_block):
    d, run = cut_block
    out = fragments(d, run, 1)
    rows = list(csv.DictReader(open(out / "fragments.csv")))
    # pieces of (3 or 7) x (4 or 4) x 6 points, each point a 1 mm cube
    want = sorted([(nx * ny * 6, nx, ny) for nx in (3, 7) for ny in (4, 4)], reverse=True)
    assert len(rows) == 4
    for row, (n, nx, ny) in zip(rows, want):
        assert int(row["points"]) == n
        assert float(row["mass_kg"]) == pytest.approx(n * RHO * DX ** 3, rel=1e-12)
        # second moments of a box L1 x L2 x L3 (the points' cubes included): L^2 / 12
        L = sorted([nx * DX, ny * DX, 6 * DX], reverse=True)
        lam = [float(row[k]) for k in ("l1_m2", "l2_m2", "l3_m2")]
        np.testing.assert_allclose(lam, [v * v / 12 for v in L], rtol=1e-9)
        assert float(row["sieve_m"]) == pytest.approx(2 * math.sqrt(5 * L[1] ** 2 / 12), rel=1e-9)
        assert float(row["d_eq_m"]) == pytest.approx((6 * n * DX ** 3 / math.pi) ** (1 / 3))
    cx = sorted(float(r["cx_m"]) for r in rows)
    np.testing.assert_allclose(cx, [1.5e-3, 1.5e-3, 6.5e-3, 6.5e-3], atol=1e-12)
    doc = json.loads((out / "fragments.json").read_text())
    assert doc["fragments"] == 4 and doc["fines_mass_fraction"] == 0.0


def test_same_fragments_on_1_2_3_ranks(cut_block):
    d, run = cut_block
    ref = (fragments(d, run, 1) / "fragments.csv").read_bytes()
    for n in (2, 3):                     # 3 ranks: slabs of 2 layers, thinner than the halo
        assert (fragments(d, run, n) / "fragments.csv").read_bytes() == ref


def test_rock_bridges_hold_a_partly_open_joint_together(tmp_path):
    text = BLOCK.replace('normal = [1.0, 0.0, 0.0]\n',
                         'normal = [1.0, 0.0, 0.0]\npersistence = 0.5\npatch = 0.002\n')
    (tmp_path / "b.toml").write_text(text)
    assert run_cli(["run", str(tmp_path / "b.toml"), "--out", str(tmp_path / "r"),
                    "--quiet"]).returncode == 0
    rows = list(csv.DictReader(open(fragments(tmp_path, tmp_path / "r" / "run.h5", 2)
                                    / "fragments.csv")))
    assert len(rows) == 2                 # only the y joint separates: 10 x 4 x 6 each
    assert [int(r["points"]) for r in rows] == [240, 240]


# ------------------------------------------------------------------ the curve
def test_percentiles_of_a_hand_built_curve():
    x, P = passing(np.array([4.0, 1.0, 2.0, 8.0]), np.array([1.0, 1.0, 1.0, 1.0]))
    assert list(x) == [1, 2, 4, 8] and list(P) == [0.25, 0.5, 0.75, 1.0]
    assert percentile(x, P, 0.5) == pytest.approx(2.0)
    # 0.6 lies 2/5 of the way from P = 0.5 (x = 2) to 0.75 (x = 4), in ln x
    assert percentile(x, P, 0.6) == pytest.approx(2.0 * 2.0 ** 0.4)
    assert percentile(x, P, 0.1) == 1.0


def test_fits_recover_sampled_distributions():
    """Equal-mass fragments whose sizes are drawn from a known curve: the mass
    passing curve is then that curve's empirical CDF."""
    rng = np.random.default_rng(5)
    u = rng.random(4000)
    x50, n = 0.012, 1.4
    size = x50 * (-np.log1p(-u) / math.log(2.0)) ** (1 / n)        # inverse Rosin-Rammler
    rr = fit_rosin_rammler(*passing(size, np.ones_like(size)))
    assert rr["x50"] == pytest.approx(x50, rel=0.03) and rr["n"] == pytest.approx(n, rel=0.04)
    assert rr["r2"] > 0.999
    xmax, b = 0.05, 2.2
    size = xmax * (x50 / xmax) ** (((1 - u) / u) ** (1 / b))          # inverse Swebrec
    sw = fit_swebrec(*passing(size, np.ones_like(size)))
    assert sw["x50"] == pytest.approx(x50, rel=0.03) and sw["b"] == pytest.approx(b, rel=0.08)
    assert sw["xmax"] == pytest.approx(xmax, rel=0.1) and sw["r2"] > 0.999


# ------------------------------------------------------------------ bad input
def test_bad_input_is_one_line(tmp_path, cut_block):
    import subprocess
    import sys
    d, run = cut_block
    res = run_cli(["run", "elastic_wave", "--out", str(tmp_path / "w"), "--quiet",
                   "--set", "time.steps=2", "--set", "output.every=1"])
    assert res.returncode == 0
    for args, needle in (([str(tmp_path / "w" / "run.h5")], "no /bonds record"),
                         ([str(run), "--frame", "5"], "--frame 5"),
                         ([str(run), "--parts", "rock"], "no part 'rock'"),
                         ([str(run), "--damage-threshold", "0.5"], "needs the damage field")):
        res = subprocess.run([sys.executable, "-m", "mpipd.post", "fragments", *args,
                              "--out", str(tmp_path / "f")], capture_output=True, text=True,
                             timeout=120, env=child_env())
        lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
        assert res.returncode == 2 and len(lines) == 1 and needle in lines[0], res.stderr
        assert not (tmp_path / "f").exists()


def test_damage_rule_breaks_bonds_between_two_damaged_points():
    """--damage-threshold: a bond counts as broken where both ends exceed it; bonds
    already broken stay broken (checked against a loop over the hand-built bonds)."""
    from mpipd.model.families import build_families
    from mpipd.post.fragments import _break_damaged
    rng = np.random.default_rng(5)
    x = rng.random((120, 3))
    fam = build_families(x, np.arange(120), np.full(120, 0.3), 90)
    damage = rng.random(120)
    before = (rng.random(fam.n_bonds) < 0.1).astype(np.uint8)
    fam.broken[:] = before
    _break_damaged(fam.offsets, fam.nbr, damage, 0.6, fam.broken)
    for i in range(90):
        for k in range(fam.offsets[i], fam.offsets[i + 1]):
            j = fam.nbr[k]
            assert fam.broken[k] == (before[k] or (damage[i] > 0.6 and damage[j] > 0.6))
