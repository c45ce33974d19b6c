"""benchmarks/profile_run.py: the own time of the time loop's functions, per rank."""
import subprocess
import sys

from conftest import ROOT, child_env


def test_the_profile_names_the_kernels_and_adds_up(tmp_path):
    out = tmp_path / "p.md"
    res = subprocess.run(["mpirun", "--oversubscribe", "-n", "2", sys.executable,
                          str(ROOT / "benchmarks" / "profile_run.py"), "elastic_wave",
                          "--steps", "6", "--warmup", "1", "--top", "8", "--out", str(out)],
                         capture_output=True, text=True, timeout=300, env=child_env())
    assert res.returncode == 0, res.stdout + res.stderr
    text = out.read_text()
    assert "2 rank(s), steps 1–7" in text
    rows = [ln for ln in text.splitlines() if ln.startswith("| `")]
    assert len(rows) == 8
    assert any("nosb." in r for r in rows)               # a numba kernel, by its own name
    shares = [float(ln.split("|")[4].strip(" %")) for ln in text.splitlines()
              if ln.startswith("| `") or ln.startswith("| everything else")]
    assert 50.0 < sum(shares) <= 100.5                  # own times add up to the loop
