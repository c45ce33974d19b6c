"""Where a checkpoint's hourglass and bond-spring energy sit.

Diagnosis of studies/validation/notes.md §39 (a ledger broken by energy that springs
held when they switched in).  Builds the checkpoint's scene, restores the
checkpoint (mpipd.output.checkpoint.restore), and sums the ledger's own per-point
potentials (mpipd.model.correspondence.Correspondence.potentials: hourglass and
spring energy owned by each point, kernels.energy) by material and by fallback code
(mpipd.kernels.layout: 0 correspondence, 1 springs as K is singular or too soft for
dt, 2 springs as F is singular this step), then lists the largest spring-energy
holders:

    mpirun -n 2 python studies/diagnoses/potentials_where.py CHECKPOINT [--top 10]

The totals are the ledger's ``hourglass`` and ``spring`` terms at the checkpoint's
step (the same function computes both).  Collective; rank 0 prints.
"""
import argparse
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from mpipd.input import scene as sc  # noqa: E402
from mpipd.output import checkpoint as ck  # noqa: E402
from mpipd.parallel.team import Team  # noqa: E402
from mpipd.solver import Simulation  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("checkpoint")
    ap.add_argument("--top", type=int, default=10)
    args = ap.parse_args()
    team = Team(MPI.COMM_WORLD)
    info = ck.read_scene(args.checkpoint)
    scene = sc.parse(info.scene, args.checkpoint, info.overrides)
    sim = Simulation(scene, team)
    ck.restore(sim, args.checkpoint)
    p, n = sim.points, sim.points.n_owned
    pot = sim.corr.potentials(np.arange(n, dtype=np.int64), sim.u)
    mat, code = p.material[:n], sim.corr.spring[:n]
    groups = [(int(m), int(c), int(s.sum()), float(pot[s, 0].sum()), float(pot[s, 1].sum()))
              for m in np.unique(mat) for c in np.unique(code)
              for s in [(mat == m) & (code == c)] if s.any()]
    top = [(float(pot[i, 1]), int(p.gid[i]), int(mat[i]), int(code[i]),
            (p.x[i] * 1e3).tolist(), float(np.linalg.norm(sim.u[i]) * 1e3))
           for i in np.argsort(-pot[:, 1])[:args.top]]
    groups, top = team.comm.gather(groups, root=0), team.comm.gather(top, root=0)
    if not team.root:
        return 0
    names = {i: name for name, i in scene.material_ids.items()}
    acc = defaultdict(lambda: [0, 0.0, 0.0])
    for g in groups:
        for m, c, cnt, hg, sp in g:
            a = acc[(m, c)]
            a[0] += cnt
            a[1] += hg
            a[2] += sp
    print(f"{args.checkpoint}: step {info.step}")
    print("| material | fallback code | points | hourglass (J) | spring (J) |")
    print("|---|---|---|---|---|")
    for (m, c), (cnt, hg, sp) in sorted(acc.items()):
        print(f"| {names[m]} | {c} | {cnt} | {hg:.4g} | {sp:.4g} |")
    print(f"| all | | {sum(a[0] for a in acc.values())} | "
          f"{sum(a[1] for a in acc.values()):.4g} | {sum(a[2] for a in acc.values()):.4g} |")
    print("\nlargest spring energies:")
    for e, gid, m, c, x, u in sorted(sum(top, []), reverse=True)[:args.top]:
        print(f"  {e:10.4g} J  gid {gid}  {names[m]}  code {c}  x = "
              f"({x[0]:.2f}, {x[1]:.2f}, {x[2]:.2f}) mm  |u| = {u:.3f} mm")
    return 0


if __name__ == "__main__":
    sys.exit(main())
