"""Follow a charge's densest gas point step by step (the delay study's gas spike,
README "What blasting engineers need" and studies/validation/notes.md §10).

    python studies/diagnoses/gas_peak.py blast_bench:short --charge charge2 \\
        --from-us 3.9 --to-us 4.1 [--set KEY=VALUE ...]

Runs the scene in-process on one rank up to ``--to-us`` and prints, at every step
from ``--from-us`` on, the point of the charge with the largest gas pressure: its
pressure, its reference and current distance from the charge's axis, its radial
speed, V/V0, how many of its current neighbours are gas and how many solid (and
which parts), the solids' mean velocity, and tr L split into the gas and the solid
parts of its family (Eq. 46 with each part's N over the whole family's M).
"""
import argparse

import numpy as np
from mpi4py import MPI

from mpipd.input import scene as sc
from mpipd.parallel.team import Team
from mpipd.solver import Simulation


def tr_l_parts(sim, i):
    """(tr L over gas neighbours, over solid neighbours, n gas, solid neighbours)."""
    g, p = sim.gas, sim.points
    y = p.x + sim.u
    nb = g.nbr[g.offsets[i]:g.offsets[i + 1]]
    Y = y[nb] - y[i]
    L = np.linalg.norm(Y, axis=1)
    keep = L < p.horizon[i]
    nb, Y, L = nb[keep], Y[keep], L[keep]
    gas = g.is_gas[nb].astype(bool)
    w = (p.horizon[i] - L) ** 2 * np.where(gas, g.V_w[nb], p.volume[nb])
    Mi = np.linalg.inv(np.einsum("k,ki,kj->ij", w, Y, Y))
    Z = sim.v[nb] - sim.v[i]

    def tr(sel):
        return float(np.trace(np.einsum("k,ki,kj->ij", w[sel], Z[sel], Y[sel]) @ Mi))
    return tr(gas), tr(~gas), int(gas.sum()), nb[~gas]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--charge", required=True, help="the charge's part name")
    ap.add_argument("--from-us", type=float, required=True)
    ap.add_argument("--to-us", type=float, required=True)
    ap.add_argument("--set", action="append", default=[])
    a = ap.parse_args()
    scene, _ = sc.load(a.scene, [f"time.t_end={a.to_us * 1e-6}"] + a.set)
    sim = Simulation(scene, Team(MPI.COMM_SELF))
    sim.initialize()
    g, p = sim.gas, sim.points
    gi = g.gas_idx
    k_part = [q.name for q in scene.parts].index(a.charge)
    axis = np.array(scene.parts[k_part].shape.center[:2])
    mine = p.part[gi] == k_part
    steps = int(round(a.to_us * 1e-6 / scene.time.dt))
    print("step t_us p_GPa r0_mm r_mm v_r V/V0 n_gas n_solid solid_parts solid_v trL_gas trL_solid")
    for _ in range(steps):
        sim.step()
        if sim.t < a.from_us * 1e-6 - 1e-15:
            continue
        pr = np.where(mine, g.gd[gi, 7], 0.0)
        k = int(np.argmax(pr))
        i = gi[k]
        y = p.x[i] + sim.u[i]
        rr = y[:2] - axis
        r = float(np.hypot(*rr))
        r0 = float(np.hypot(*(p.x[i, :2] - axis)))
        tg, ts, ng, solid = tr_l_parts(sim, i)
        sv = sim.v[solid, :2].mean(axis=0) if len(solid) else np.zeros(2)
        print(f"{sim.step_count} {sim.t * 1e6:.2f} {pr[k] / 1e9:.2f} {r0 * 1e3:.2f} {r * 1e3:.2f} "
              f"{sim.v[i, :2] @ rr / max(r, 1e-12):.0f} {g.gd[i, 6] / g.V0[k]:.3f} {ng} "
              f"{len(solid)} {sorted(set(p.part[solid].tolist()))} "
              f"({sv[0]:.0f},{sv[1]:.0f}) {tg:.3g} {ts:.3g}", flush=True)


if __name__ == "__main__":
    main()
