"""The multi-rate family factor against measured critical steps (docs/multirate.md,
The family factor): how far a cut family shortens the stable step, and what each
``family_factor`` of the class rule says about it.

    python studies/multirate/family_factor.py [--out FILE] [--side N]

A free granite block (JH2, 0.8 mm, horizon 3 dx, N^3 points, blast_paper's hourglass
coefficient) with bonds broken in a known pattern: none, a planar crack through the
middle, two crossed cracks, and a central ball (radius L/4) with 30-95 % of its bonds
broken (a hash of the pair: the same bonds both ways).  For each, the smallest factor
over the block of each rule (``mpipd.model.multirate.FAMILY_FACTORS``), and the
critical step measured single-rate: white-noise velocities, 600 steps at dt = f dt_c
(dt_c: ``mpipd.model.stability.critical_dt``), stable if the total energy stays within 1 % and
no runaway is detected; f bisected between 0.05 and 2.2 to 1/32 of the bracket.
The margin of a rule: the measured critical step over the largest step the class rule
gives the cut block's worst point at blast_paper's safety 0.5 (0.5 x factor x dt_c;
above 1: stable).  One rank, about 5 minutes.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from tables import emit  # noqa: E402

DX = 8e-4
CASES = ("intact", "plane crack", "crossed cracks", "ball 30 %", "ball 60 %", "ball 80 %",
         "ball 90 %", "ball 95 %")
STEPS = 600
#: blast_paper's multi-rate safety factor (the margins' reference)
SAFETY = 0.5


def scene(side: int, f: float):
    """The block at dt = f dt_c; and dt_c."""
    from mpipd.input.scene import Scene
    from mpipd.input.schema import build
    from mpipd.model.stability import critical_dt
    L = side * DX
    d = {"scene": {"name": "family_factor"}, "time": {"dt": 1e-9, "steps": STEPS},
         "materials": {"granite": {"model": "jh2"}},
         "parts": [{"name": "block", "material": "granite", "dx": DX, "horizon_factor": 3.0,
                    "shape": {"kind": "box", "lo": [0, 0, 0], "hi": [L, L, L]}}],
         "solver": {"hourglass": 0.01}, "initial": []}
    dtc = critical_dt(build(Scene, d))
    d["time"]["dt"] = f * dtc
    return build(Scene, d), dtc


def cut(sim, case: str, side: int) -> int:
    """Break the bonds of ``case`` (both ways) and rebuild the shape tensors."""
    p, fam = sim.points, sim.families
    n = p.n_owned
    L = side * DX
    i = np.repeat(np.arange(n), np.diff(fam.offsets))
    j = fam.nbr
    xi, xj = p.x[i], p.x[j]
    if case == "intact":
        b = np.zeros(len(j), bool)
    elif case == "plane crack":
        b = (xi[:, 0] < L / 2) != (xj[:, 0] < L / 2)
    elif case == "crossed cracks":
        b = ((xi[:, 0] < L / 2) != (xj[:, 0] < L / 2)) | ((xi[:, 1] < L / 2) != (xj[:, 1] < L / 2))
    else:
        share = float(case.split()[1]) / 100.0
        c = np.full(3, L / 2)
        inside = (np.linalg.norm(xi - c, axis=1) < L / 4) | (np.linalg.norm(xj - c, axis=1) < L / 4)
        lo, hi = np.minimum(p.gid[i], p.gid[j]), np.maximum(p.gid[i], p.gid[j])
        b = inside & ((lo * 1000003 + hi * 7919) % 10007 < share * 10007)
    fam.broken[b] = 1
    sim.corr.rebuild_shape()
    return int(b.sum())


def factors(sim) -> dict:
    """The smallest factor of each rule over the block's intact correspondence points."""
    from mpipd.model.multirate import FAMILY_FACTORS
    cl = sim.classes
    out = {}
    for kind in FAMILY_FACTORS:
        cl.factor_kind = kind
        cl.kfac = None
        out[kind] = float(cl.family_factor(sim.corr, sim.halo).min())
    return out


def stable(side: int, case: str, f: float, team) -> bool:
    from mpipd.solver import Simulation, Unstable
    sc, _ = scene(side, f)
    sim = Simulation(sc, team)
    cut(sim, case, side)
    sim.initialize()
    n = sim.points.n_owned
    rng = np.random.default_rng(1)
    sim.v[:n] = 1e-3 * rng.standard_normal((n, 3))
    sim.v[:n] -= sim.v[:n].mean(axis=0)
    e0 = sim.energies().total
    try:
        for _ in range(STEPS):
            sim.step()
        e = sim.energies().total
    except Unstable:
        return False
    return bool(np.isfinite(e) and abs(e / e0 - 1.0) < 0.01)


def critical(side: int, case: str, team, lo=0.05, hi=2.2, rounds=5):
    """The bracket (lo, hi) of the critical f: stable at lo, unstable at hi."""
    if not stable(side, case, lo, team):
        return 0.0, lo
    if stable(side, case, hi, team):
        return hi, np.inf
    for _ in range(rounds):
        mid = 0.5 * (lo + hi)
        if stable(side, case, mid, team):
            lo = mid
        else:
            hi = mid
    return lo, hi


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", help="also write the table (markdown) here")
    ap.add_argument("--side", type=int, default=14, help="points along each edge (14)")
    args = ap.parse_args(argv)
    from mpi4py import MPI

    from mpipd.parallel.team import Team
    from mpipd.solver import Simulation
    team = Team(MPI.COMM_SELF)
    t0 = time.perf_counter()
    rows = []
    for case in CASES:
        sim = Simulation(scene(args.side, 1.0)[0], team)
        broken = cut(sim, case, args.side)
        fac = factors(sim)
        lo, hi = critical(args.side, case, team)
        rows.append((case, broken, fac, lo, hi))
        print(f"{case}: {broken} bonds broken, factors {fac}, critical f in [{lo:.3f}, {hi:.3f})",
              flush=True)
    ref_lo, ref_hi = rows[0][3], rows[0][4]
    kinds = list(rows[0][2])
    lines = [f"Critical step of a free {args.side}^3 granite block (JH2, dx 0.8 mm, horizon 3 dx) "
             f"with cut families, single-rate, in units of dt_c = mpipd.check.critical_dt "
             f"(`python studies/multirate/family_factor.py --side {args.side}`, "
             f"{time.perf_counter() - t0:.0f} s on one rank).  Factor: the smallest over the "
             f"block.  Ratio: the cut block's critical step over the intact block's.  Margin: "
             f"the measured critical step (its lower bracket) over the class rule's largest "
             f"step for the worst point at safety {SAFETY} ({SAFETY} x factor x dt_c; above 1 "
             f"is stable).",
             "", "| bonds broken | count | " + " | ".join(f"factor, {k}" for k in kinds)
             + " | critical dt / dt_c | ratio to intact | "
             + " | ".join(f"margin, {k}" for k in kinds) + " |",
             "|---|---|" + "---|" * (2 * len(kinds) + 2)]
    for case, broken, fac, lo, hi in rows:
        ratio = (f"{lo / ref_hi:.2f}-{hi / ref_lo:.2f}" if np.isfinite(hi)
                 else f"> {lo / ref_hi:.2f}")
        crit = f"{lo:.3f}-{hi:.3f}" if np.isfinite(hi) else f"> {lo:.3f}"
        lines.append(f"| {case} | {broken} | " + " | ".join(f"{fac[k]:.3f}" for k in kinds)
                     + f" | {crit} | {ratio} | "
                     + " | ".join(f"{lo / (SAFETY * fac[k]):.1f}" for k in kinds) + " |")
    emit(lines, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
