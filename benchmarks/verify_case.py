"""Verification problems for `make verify` (benchmarks/verify.py runs this under mpirun).

    mpirun -n R python benchmarks/verify_case.py PROBLEM[,PROBLEM...] [--res 0,1] [--quick]

prints, on rank 0, one line per resolution:  ``VERIFY {json}``  with the problem,
the resolution, the point count, the ranks, the wall time of the case (model
set-up plus time loop, the slowest rank's; the interpreter start and a small
untimed warm-up that loads the numba kernels are excluded) and the error
measure against an answer computed independently of the solver.

The problems live in the package ``benchmarks/problems/``, one module a problem
(``wave``, ``lame``, ``energy``, ``jh2_point``, ``detonation`` with ``isentrope_dt``;
shared helpers in ``common``); its docstring lists them.  This file is the command
line only.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/: the package

from problems import PROBLEMS  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("problems", help="comma-separated: " + ", ".join(sorted(PROBLEMS)))
    ap.add_argument("--res", default=None, help="comma-separated resolution indices")
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    keys = args.problems.split(",")
    for key in keys:
        if key not in PROBLEMS:
            ap.error(f"unknown problem {key!r}")
    from mpi4py import MPI

    from mpipd.parallel.team import Team
    team = Team(MPI.COMM_WORLD)
    for key in keys:
        prob = PROBLEMS[key]()
        if team.size > 1 and getattr(prob, "serial_only", False):
            continue
        table = prob.QUICK if args.quick else prob.RESOLUTIONS
        idx = range(len(table)) if args.res is None else map(int, args.res.split(","))
        prob.run(team, table[0], steps=2)          # untimed: loads the numba kernels
        for k in idx:
            out = prob.run(team, table[k])
            rows = out if isinstance(out, list) else [out]
            if team.root:
                for r in rows:
                    r.setdefault("problem", prob.name)
                    r.setdefault("measure", getattr(prob, "measure", ""))
                    r["key"] = key
                    r["ranks"] = team.size
                    print("VERIFY " + json.dumps(r), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
