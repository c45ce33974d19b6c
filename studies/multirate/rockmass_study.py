"""The rock mass's effect on the fracture pattern (issue 18, item 4): blast_demo on
the cubic lattice, with jitter, with Weibull strength and with both, over seeds.

    python studies/multirate/rockmass_study.py --out runs/rockmass [--seeds 1 2 3] \\
        [--mpirun mpirun] [--table studies/model/rockmass_blast_demo.md]

Runs (2 ranks each, ``--overwrite``): ``lattice_0`` (the built-in scene: no seed to
vary) and ``jitter_S``, ``weibull_S``, ``rockmass_S`` for each seed S (the named
cases blast_demo:jitter, :weibull, :rockmass with parts.2.jitter_seed = S and the
heterogeneity's seed = S), then ``mpipd.post report`` of each, then the table
(benchmarks/multirate_compare.py --bands --stats): every run's row, and each
group's mean ± standard deviation and range of the report's targets (crack density
per zone against the experiment's ranges, radial cracks, crushed zone, ...) and of
the lattice-bias measure (a4, a8 and the major radial cracks, mean over sections).
About 2 minutes a run on this machine's 2 cores.
"""
from __future__ import annotations

import argparse
import shlex
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(HERE))
import multirate_compare  # noqa: E402

BIN = Path(sys.executable).parent

#: case -> the overrides that pick seed S
SEEDED = {"jitter": ["parts.2.jitter_seed={s}"],
          "weibull": ["materials.granite.heterogeneity.seed={s}"],
          "rockmass": ["parts.2.jitter_seed={s}", "materials.granite.heterogeneity.seed={s}"]}


def runs(seeds) -> list[tuple[str, str, list[str]]]:
    """(label, scene, overrides) of the study."""
    out = [("lattice_0", "blast_demo", [])]
    for case, over in SEEDED.items():
        out += [(f"{case}_{s}", f"blast_demo:{case}", [o.format(s=s) for o in over])
                for s in seeds]
    return out


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="runs/rockmass")
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--mpirun", default="mpirun")
    ap.add_argument("--ranks", type=int, default=2,
                    help="ranks per run (the results do not depend on it)")
    ap.add_argument("--table", default="studies/model/rockmass_blast_demo.md")
    ap.add_argument("--reuse", action="store_true",
                    help="keep runs whose report exists (resume a study)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    items = runs(args.seeds)
    for label, scene, over in items:
        d = out / label
        if args.reuse and (d / "report" / "report.json").exists():
            continue
        sets = [a for o in over for a in ("--set", o)]
        cmd = [*shlex.split(args.mpirun), "-n", str(args.ranks), str(BIN / "mpipd"), "run", scene,
               "--out", str(d),
               "--overwrite", "--quiet", *sets]
        print(" ".join(cmd), flush=True)
        subprocess.run(cmd, check=True)
        subprocess.run([*shlex.split(args.mpirun), "-n", str(args.ranks), sys.executable, "-m",
                        "mpipd.post", "report",
                        str(d / "run.h5"), "--out", str(d / "report")], check=True,
                       stdout=subprocess.DEVNULL)
    title = ("# The rock mass on blast_demo: lattice, jitter, Weibull strength, both "
             f"(seeds {', '.join(map(str, args.seeds))})\n\n"
             "Made by `python studies/multirate/rockmass_study.py` (README: The rock mass).")
    return multirate_compare.main(["--out", args.table, "--bands",
                                   "lattice,jitter,weibull,rockmass", "--stats",
                                   "--title", title,
                                   *[f"{label}={out / label}" for label, _, _ in items]])


if __name__ == "__main__":
    sys.exit(main())
