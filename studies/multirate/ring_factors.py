"""The JH2 ring of tests/test_multirate.py::test_state_following_classes_and_the_ledger
under each buffer and each family factor (docs/multirate.md, The family factor): the
ledger's largest balance at the coarse boundaries, the share of single-rate's bond
states evaluated, the failed points and the classes at the end.

    python studies/multirate/ring_factors.py [--out FILE] [--safety S ...] [--windows W ...]

At the test's safety 0.9 by default; ``--safety`` takes one or more others (blast_paper's
0.5).  ``--windows`` runs the default family factor with each fracture window (coarse
steps; 0: no fracture rule) instead of each factor at the default window.  One rank,
seconds per case.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from tables import emit  # noqa: E402

#: the test's scene overrides (granite_ring, refresh after breakage; the test's safety 0.9)
OVER = ["parts.0.dx=0.0015", "time.dt=6.25e-8", "time.t_end=6e-6", "output.every=40",
        "solver.refresh_after_break=true"]


def run(buffer: str, factor: str, safety: float, window: int = 2):
    from mpi4py import MPI

    from mpipd.input import scene as sc
    from mpipd.parallel.team import Team
    from mpipd.solver import Simulation
    over = OVER + [f'time.multirate={{max_ratio=4, safety={safety}, buffer="{buffer}", '
                   f'family_factor="{factor}", fracture_window={window}}}']
    scene, _ = sc.load("granite_ring", over)
    sim = Simulation(scene, Team(MPI.COMM_SELF))
    n = sim.points.n_owned
    worst = 0.0
    while sim.step_count < scene.time.n_steps:
        sim.step()
        if sim.at_boundary and sim.step_count % 40 == 0:
            worst = max(worst, abs(sim.energies().balance))
    k = np.bincount(sim.classes.klass[:n], minlength=3)
    return worst, sim.classes.evaluated_share(sim.team), int(np.count_nonzero(sim.mode[:n])), k


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", help="also write the table (markdown) here")
    ap.add_argument("--safety", type=float, nargs="+", default=[0.9])
    ap.add_argument("--windows", type=int, nargs="+", help="fracture windows (default factor)")
    args = ap.parse_args(argv)
    from mpipd.input.scene import BUFFERS, FAMILY_FACTORS, Multirate
    cmd = "python studies/multirate/ring_factors.py" + (
        "" if args.safety == [0.9] else " --safety " + " ".join(f"{s:g}" for s in args.safety)) + (
        " --windows " + " ".join(map(str, args.windows)) if args.windows else "")
    default = Multirate()
    cases = ([(default.family_factor, w) for w in args.windows] if args.windows
             else [(f, default.fracture_window) for f in FAMILY_FACTORS])
    lines = ["granite_ring (3780 points, JH2, tension failure, contact, viscosity), max_ratio 4, "
             f"96 steps (`{cmd}`).", "",
             "| safety | buffer | family factor | fracture window | largest ledger balance | "
             "bond states evaluated | failed points | classes 0 / 1 / 2 at the end |",
             "|---|---|---|---|---|---|---|---|"]
    for safety in args.safety:
        for buffer in BUFFERS:
            for factor, window in cases:
                bal, share, failed, k = run(buffer, factor, safety, window)
                lines.append(f"| {safety:g} | {buffer} | {factor} | {window} | {bal:.2e} | "
                             f"{share:.3f} | {failed} | {' / '.join(str(int(x)) for x in k)} |")
                print(lines[-1], flush=True)
    emit(lines, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
