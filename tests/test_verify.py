"""The quick subset of `make verify` (benchmarks/verify.py --quick): every
verification problem at its two coarsest resolutions on 1 rank and the coarsest on
2 ranks, against answers computed independently of the solver.  Checks the outputs
and that the errors sit where `make verify` measured them."""
import json
import subprocess
import sys
import time

import pytest
from conftest import ROOT, child_env


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("verify")
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "verify.py"), "--quick",
                          "--out", str(out)], capture_output=True, text=True, timeout=600,
                         env=child_env(), cwd=ROOT)
    took = time.perf_counter() - t0
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    data = json.loads((out / "results.json").read_text())
    return out, data["rows"], took, res.stdout


def rows(data, problem, ranks=1):
    got = sorted((r for r in data if r["problem"] == problem and r["ranks"] == ranks),
                 key=lambda r: -r["dx"])
    assert got, problem
    return got


def test_outputs_written(quick):
    """The outputs exist.  Its wall time is printed by verify.py, not asserted: a
    time bound fails on a shared machine (93 s against a bound of 90 s beside a
    long run, 2026-12-03), and speed is `make bench`'s to measure."""
    out, data, took, stdout = quick
    for name in ("table.md", "table.csv", "results.json", "error_vs_time.png"):
        assert (out / name).stat().st_size > 0
    assert (out / "error_vs_time.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    table = (out / "table.md").read_text()
    assert table.startswith("| problem | resolution | points | ranks | wall s | error | order")
    assert "2-rank errors equal the 1-rank ones" in stdout


def test_two_ranks_give_the_one_rank_errors(quick):
    _, data, _, _ = quick
    one = {(r["problem"], r["dx"]): r["error"] for r in data if r["ranks"] == 1}
    two = [r for r in data if r["ranks"] == 2]
    assert len(two) >= 5
    for r in two:
        assert r["error"] == pytest.approx(one[(r["problem"], r["dx"])], rel=1e-9, abs=1e-15)


def test_wave_speed_converges_at_second_order(quick):
    a, b = rows(quick[1], "P-wave speed")
    assert a["error"] < 0.05 and b["error"] < 0.025
    assert 1.6 < b["order"] < 2.4


def test_lame_stresses(quick):
    for r in rows(quick[1], "Lame cylinder"):
        assert r["error"] < 0.05 and r["band_max"] < 0.25
        assert r["ke_end_over_peak"] < 1e-5            # the transient has settled


def test_energy(quick):
    for r in rows(quick[1], "energy, max deviation"):
        assert r["error"] < 1e-2
    for r in rows(quick[1], "energy drift / 1000 steps"):
        assert abs(r["value"]) < 1e-3


def test_jh2_point_first_order(quick):
    a, b = rows(quick[1], "JH2 point, uniaxial strain")
    assert a["error"] < 0.03 and 0.9 < b["order"] < 1.1
    assert -0.0047 < a["eps_yield"] < -0.0044 and b["failed"] == 0


def test_detonation(quick):
    for r in rows(quick[1], "detonation front"):
        assert abs(r["value"] - 6690.0) / 6690.0 < 0.01      # front speed
        assert 1.0 < r["lag_dx"] < 1.6                       # half the 3 dx burn ramp
    for r in rows(quick[1], "JWL isentrope (dx refined)"):
        assert r["error"] < 0.01
    a, b = rows(quick[1], "JWL isentrope (dt refined, dx 0.8 mm)")
    assert 0.8 < b["order"] < 1.2                            # first order in dt
