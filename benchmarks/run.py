"""`make bench`: every benchmark case on 1 and 2 ranks, the restore's memory and time
(benchmarks/restart_bench.py), then the LAMMPS peer if installed.

Usage: python benchmarks/run.py [--size N] [--steps S] [--ranks 1,2] [--no-peer]
"""
import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
PEER = HERE.parent.parent / "shared" / "peers" / "lammps" / "run.sh"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=60, help="block edge in points (60 -> 216k)")
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--ranks", default="1,2")
    ap.add_argument("--cases", default="elastic,jh2,blast,blast_mr,jh2_refresh,blast_refresh,"
                                       "blast_paper_slice,jh2_rockmass")
    ap.add_argument("--no-peer", action="store_true")
    args = ap.parse_args()
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMP_NUM_THREADS="1")
    status = 0
    for case in args.cases.split(","):
        for n in map(int, args.ranks.split(",")):
            cmd = ["mpirun", "--oversubscribe", "-n", str(n), sys.executable,
                   str(HERE / "case.py"), case, "--size", str(args.size),
                   "--steps", str(args.steps)]
            res = subprocess.run(cmd, env=env, capture_output=True, text=True)
            sys.stdout.write(res.stdout)
            if res.returncode:
                sys.stderr.write(res.stderr)
                status = 1
    for n in map(int, args.ranks.split(",")):     # the restore's memory and time
        where = HERE.parent / "runs" / "restart_bench" / f"ranks{n}"
        base = ["mpirun", "--oversubscribe", "-n", str(n), sys.executable,
                str(HERE / "restart_bench.py")]
        for phase in ("write", "restore"):
            res = subprocess.run(base + [phase, "--size", str(args.size), "--dir", str(where)],
                                 env=env, capture_output=True, text=True)
            sys.stdout.write(res.stdout)
            if res.returncode:
                sys.stderr.write(res.stderr)
                status = 1
                break
        shutil.rmtree(where, ignore_errors=True)
    if args.no_peer:
        return status
    if shutil.which("lmp") and PEER.exists():
        for n in map(int, args.ranks.split(",")):
            res = subprocess.run(["bash", str(PEER), str(n), str(args.size), str(args.steps),
                                  "lps"], env=env, capture_output=True, text=True)
            line = [ln for ln in res.stdout.splitlines() if ln.startswith("lammps")]
            print(f"peer {line[-1] if line else 'failed: ' + res.stderr.strip()[-300:]}")
    else:
        print("peer lammps: not run (needs Debian's `lammps` and ../shared/peers/lammps)")
    return status


if __name__ == "__main__":
    sys.exit(main())
