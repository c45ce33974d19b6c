"""Bench two checkouts side by side in one session (a refactor's "within x % of before").

    python benchmarks/ab.py OLD_CHECKOUT NEW_CHECKOUT [--cases elastic,jh2,...]
                            [--ranks 1,2] [--size 60] [--steps 20] [--repeat 2]

For each case and rank count, runs benchmarks/case.py of OLD and of NEW
alternately (``repeat`` times each, so drifts of this noisy machine hit both),
and prints per case the best and the median bond-steps/s per core of each, and
NEW/OLD - 1 of the best (the machine's noise only ever slows a run; the medians show
how large it was).
Each checkout is imported with this interpreter (the same venv for both) through
benchmarks/checkout_run.py, which sets the editable install's finder aside (with
PYTHONPATH alone both runs would import the installed tree).
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
from pathlib import Path

LAUNCHER = Path(__file__).resolve().parent / "checkout_run.py"
CASES = "elastic,jh2,blast,blast_mr,jh2_refresh,blast_refresh"


def run_case(checkout: Path, case: str, ranks: int, size: int, steps: int) -> float:
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMP_NUM_THREADS="1")
    cmd = ["mpirun", "--oversubscribe", "-n", str(ranks), sys.executable, str(LAUNCHER),
           str(checkout), str(checkout / "benchmarks" / "case.py"), case, "--size", str(size),
           "--steps", str(steps)]
    res = subprocess.run(cmd, env=env, capture_output=True, text=True)
    m = re.search(r"bond_steps_per_s_per_core=([0-9.eE+-]+)", res.stdout)
    if res.returncode or not m:
        raise RuntimeError(f"{checkout} {case} n={ranks}: {res.stderr.strip()[-400:]}")
    return float(m.group(1))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("old", type=Path)
    ap.add_argument("new", type=Path)
    ap.add_argument("--cases", default=CASES)
    ap.add_argument("--ranks", default="1,2")
    ap.add_argument("--size", type=int, default=60)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--repeat", type=int, default=2)
    a = ap.parse_args()
    print(f"{'case':14s} {'ranks':>5s} {'old best':>9s} {'new best':>9s} {'new/old-1':>9s} "
          f"{'old median':>10s} {'new median':>10s}   (M bond-steps/s per core, {a.repeat} runs each)")
    for case in a.cases.split(","):
        for n in map(int, a.ranks.split(",")):
            old, new = [], []
            for _ in range(a.repeat):
                old.append(run_case(a.old.resolve(), case, n, a.size, a.steps))
                new.append(run_case(a.new.resolve(), case, n, a.size, a.steps))
            o, w = max(old), max(new)
            print(f"{case:14s} {n:5d} {o / 1e6:9.2f} {w / 1e6:9.2f} {w / o - 1:+9.1%} "
                  f"{statistics.median(old) / 1e6:10.2f} {statistics.median(new) / 1e6:10.2f}",
                  flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
