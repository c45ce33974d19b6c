"""Time steps of a run from its checkpoint under this tree and under another commit,
alternately, on R ranks: the wall time per step of each, their ratio, and the time of
the correspondence force gathers by multi-rate level and of the reweight at class
changes (the part of a late step that single-rate scenes and ``make bench``, which
starts from rest, do not show).

    python benchmarks/steps_ab.py CHECKPOINT --against COMMIT [--steps 40] [--ranks 2]
                                  [--repeat 2]

``--against`` checks COMMIT out into a temporary git worktree (removed afterwards) and
runs it with this interpreter through benchmarks/checkout_run.py.  Each run restores
the checkpoint, takes ``--warmup`` steps (kernel compilation, caches), then times
``--steps`` steps on every rank; the slowest rank's figures are printed.  Nothing is
written.  A checkpoint with fracture and class changes under way, for example

    mpirun -n 2 mpipd run blast_paper --set parts.2.shape.radius=0.040 \\
        --set probes.5.position=[0.035,0,0.0004] --set probes.6.position=[0.036,0,0.0004] \\
        --set probes.7.position=[0.037,0,0.0004] --set time.t_end=1.6e-5 \\
        --set output.checkpoint_every=200 --out runs/r40

(the paper's specimen cut to r = 40 mm, probes E-G moved inside it: 519,636 points,
60.0 M bonds; its checkpoint at 16 us, about 8 minutes on 2 ranks).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LAUNCHER = ROOT / "benchmarks" / "checkout_run.py"


def inner(checkpoint: str, steps: int, warmup: int) -> None:
    """Under mpirun: restore, warm up, time; rank 0 prints one JSON line."""
    from mpipd.input import scene as sc
    from mpipd.model import correspondence as cm
    from mpipd.output import checkpoint as ck
    from mpipd.parallel.team import world
    from mpipd.solver import Simulation

    team = world()
    info = ck.read_scene(checkpoint)
    scene = sc.parse(info.scene, checkpoint, info.overrides + ["time.t_end=1.0"])
    sim = Simulation(scene, team)
    ck.restore(sim, checkpoint)
    spent = defaultdict(float)
    calls = defaultdict(int)

    def timed(name, method, label):
        def run(self, *a):
            t = time.perf_counter()
            method(self, *a)
            key = label(self)
            spent[key] += time.perf_counter() - t
            calls[key] += 1
        setattr(cm.Correspondence, name, run)

    if hasattr(cm.Correspondence, "reweight"):
        timed("reweight", cm.Correspondence.reweight, lambda s: "reweight")
    timed("gather", cm.Correspondence.gather, lambda s: f"gather level {s.classes.level}")
    for _ in range(warmup):
        sim.step()
    spent.clear()
    calls.clear()
    team.barrier()
    t0 = time.perf_counter()
    for _ in range(steps):
        sim.step()
    wall = time.perf_counter() - t0
    keys = sorted({k for ks in team.gather(sorted(spent)) for k in ks})
    out = {"wall": team.max(wall), "steps": steps, "step": sim.step_count,
           "parts": {k: [team.max(spent.get(k, 0.0)), calls.get(k, 0)] for k in keys}}
    if team.rank == 0:
        print("STEPS_AB " + json.dumps(out), flush=True)


def run(checkout: Path, args) -> dict:
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMP_NUM_THREADS="1")
    cmd = ["mpirun", "--oversubscribe", "-n", str(args.ranks), sys.executable, str(LAUNCHER),
           str(checkout), str(Path(__file__).resolve()), "--inner", args.checkpoint,
           "--steps", str(args.steps), "--warmup", str(args.warmup)]
    res = subprocess.run(cmd, env=env, capture_output=True, text=True)
    for line in res.stdout.splitlines():
        if line.startswith("STEPS_AB "):
            return json.loads(line[len("STEPS_AB "):])
    raise RuntimeError(f"{checkout}: {res.stderr.strip()[-600:]}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("checkpoint")
    ap.add_argument("--against", help="a commit to time beside this tree")
    ap.add_argument("--steps", type=int, default=40)
    ap.add_argument("--warmup", type=int, default=4)
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--inner", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.inner:
        inner(args.checkpoint, args.steps, args.warmup)
        return 0
    trees = {"this": ROOT}
    tmp = None
    if args.against:
        tmp = Path(tempfile.mkdtemp()) / "against"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tmp),
                        args.against], check=True, capture_output=True)
        trees = {args.against: tmp, "this": ROOT}
    try:
        results = defaultdict(list)
        for _ in range(args.repeat):
            for name, tree in trees.items():
                results[name].append(run(tree, args))
    finally:
        if tmp is not None:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tmp)],
                           capture_output=True)
    print(f"{args.checkpoint}: {args.steps} steps from step {results['this'][0]['step'] - args.steps}"
          f" on {args.ranks} rank(s), {args.repeat} run(s) each, alternately; slowest rank")
    per_step = {}
    for name, rs in results.items():
        per_step[name] = statistics.median(r["wall"] / r["steps"] for r in rs)
        print(f"  {name}: {per_step[name]:.3f} s a step (median; runs "
              + ", ".join(f"{r['wall'] / r['steps']:.3f}" for r in rs) + ")")
        best = min(rs, key=lambda r: r["wall"])
        for k, (t, n) in sorted(best["parts"].items()):
            print(f"      {k}: {t / best['steps']:.3f} s a step over {n} calls "
                  f"({t / best['wall']:.1%} of the loop)")
    if args.against:
        print(f"  ratio {args.against} / this: {per_step[args.against] / per_step['this']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
