"""What each part of the multi-rate class rule costs at a checkpoint: the points and
bonds per class, and the bond states a fine step evaluates against single-rate
(``projected_cost``), under the rule as the scene states it and with one part of the
rule changed at a time (docs/multirate.md, The class rule).

    python studies/multirate/class_rules.py CHECKPOINT [KEY=VALUE ...] [--out FILE]

Runs on one rank: it restores the checkpoint, takes ``max_ratio`` steps to the next
coarse boundary (so the state the rule reads is current), then recomputes every owned
point's base class from that state with ``StepClasses.base_classes``'s formula and
spreads it with each buffer.  Nothing of the run is written.  The variants:

* the rule (the scene's buffer) and the other buffer;
* no buffer (every point at its own base class);
* without the fracture rule (a family that lost bonds in the last coarse steps);
* the fracture rule at class 1 instead of 0, and over 1 coarse step (2 if the scene's
  window is 1) instead of the scene's ``fracture_window``;
* the other family factor (row sum or shape tensor), and none.
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


def restore(path, overrides):
    from mpi4py import MPI

    from mpipd.input import scene as sc
    from mpipd.output import checkpoint as ck
    from mpipd.parallel.team import Team
    from mpipd.solver import Simulation
    info = ck.read_scene(path)
    scene = sc.parse(info.scene, str(path), info.overrides + list(overrides))
    sim = Simulation(scene, Team(MPI.COMM_SELF))
    ck.restore(sim, path)
    for _ in range(sim.classes.ratio):
        sim.step()
    return sim


def base_classes(sim, kappa=True, fracture=True, fracture_class=None):
    """StepClasses.base_classes at the current state, with the family factor on or off
    and the fracture rule on (at ``fracture_class``, None: the scene's) or off."""
    C = sim.classes
    return C.base_classes(sim.corr, sim.halo, C.step, kappa=kappa, fracture=fracture,
                          fracture_class=fracture_class)


def other_factor(sim, kind):
    """base_classes with the family factor ``kind`` (its factors from scratch), then
    the scene's again."""
    C = sim.classes
    scene_kind = C.factor_kind
    C.factor_kind, C.kfac = kind, None
    try:
        return base_classes(sim)
    finally:
        C.factor_kind, C.kfac = scene_kind, None


def other_window(sim, window):
    """base_classes with the fracture rule over ``window`` coarse steps, then the
    scene's window again."""
    C = sim.classes
    scene_window, C.window = C.window, window
    try:
        return base_classes(sim)
    finally:
        C.window = scene_window


def spread(sim, kb, buffer):
    """The classes after the buffer ("full", "graded" or None) on one rank."""
    from mpipd.model.multirate import buffered
    C = sim.classes
    if buffer is None:
        return kb
    a = np.full(sim.points.n_local, C.top, np.uint8)
    a[:C.n_owned] = kb
    return buffered(sim.families, a, C.top, buffer == "graded", C.all_rows,
                    np.empty(C.n_owned, np.uint8))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("checkpoint")
    ap.add_argument("set", nargs="*", metavar="KEY=VALUE", help="scene overrides")
    ap.add_argument("--out", help="also write the table (markdown) here")
    args = ap.parse_args(argv)

    from mpipd.model.multirate import projected_cost
    sim = restore(args.checkpoint, args.set)
    C = sim.classes
    if not C.enabled:
        print("the scene is single-rate: no classes", file=sys.stderr)
        return 2
    n = C.n_owned
    bonds = C.fam_bonds
    mr = sim.scene.time.multirate
    other = "full" if mr.buffer == "graded" else "graded"
    fc = mr.fracture_class
    rule = base_classes(sim)
    window = 2 if C.window == 1 else 1
    kind = "shape_tensor" if mr.family_factor == "row_sum" else "row_sum"
    rows = [
        (f"the rule (buffer {mr.buffer}, fracture class {fc} over {C.window} coarse steps, "
         f"family factor {mr.family_factor})",
         rule, mr.buffer),
        (f"buffer {other}", rule, other),
        ("no buffer", rule, None),
        ("no fracture rule", base_classes(sim, fracture=False), mr.buffer),
        (f"fracture class {1 if fc == 0 else 0}", base_classes(sim, fracture_class=1 if fc == 0 else 0),
         mr.buffer),
        (f"fracture window {window} coarse step(s)", other_window(sim, window), mr.buffer),
        (f"family factor {kind}", other_factor(sim, kind), mr.buffer),
        ("no family factor kappa", base_classes(sim, kappa=False), mr.buffer),
    ]
    failed = int(np.count_nonzero(sim.mode[:n]))
    lines = [f"Classes at {args.checkpoint} (step {C.step}, {sim.t * 1e6:.2f} us): {n} points, "
             f"{failed} failed, {int(bonds.sum())} bonds; max_ratio {C.ratio}, safety {C.safety}.",
             "", "| rule | points per class | bonds per class (M) | bond states evaluated |",
             "|---|---|---|---|"]
    for name, kb, buffer in rows:
        k = spread(sim, kb, buffer)
        pts = np.bincount(k, minlength=C.top + 1)
        per = np.bincount(k, weights=bonds, minlength=C.top + 1)
        lines.append(f"| {name} | {' / '.join(str(int(x)) for x in pts)} | "
                     f"{' / '.join(f'{x / 1e6:.2f}' for x in per)} | {projected_cost(per):.3f} |")
    emit(lines, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
