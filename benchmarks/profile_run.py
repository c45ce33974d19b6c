"""Where a run's time goes: N steps of a scene (from step 0) or of a checkpoint (from
its step) under cProfile on every rank, the time of each function of the time loop
summed over its calls (its own time, without its callees'), the mean and largest
over the ranks, as a share of the loop's wall time.

    mpirun -n 2 python benchmarks/profile_run.py --restart runs/X/checkpoint.h5 --steps 100 \\
        --out docs/bench/profile.md
    mpirun -n 2 python benchmarks/profile_run.py blast_paper --steps 100

A numba kernel is a C call that cProfile does not see on its own: its time is the own
time of the thin Python method that calls it (mpipd's two-layer kernels: one kernel
per method), so the table names the method (``Correspondence.gather``, ...).  MPI
calls are mpi4py's builtins (``Sendrecv``, ``Allreduce``, ...): their own time
includes the wait for the other ranks, the load imbalance.  Nothing is written
but ``--out``: no run file, no checkpoint (probes and frames are not taken).
"""
from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def build(args, team):
    from mpipd.input import scene as sc
    from mpipd.output import checkpoint as ck
    from mpipd.solver import Simulation
    if args.restart:
        info = ck.read_scene(args.restart)
        scene = sc.parse(info.scene, str(args.restart), info.overrides + list(args.set))
        sim = Simulation(scene, team)
        ck.restore(sim, args.restart)
        label = f"checkpoint {args.restart} (step {info.step})"
    else:
        source, overrides = sc.expand_case(args.scene, args.set)
        scene, _ = sc.load(source, overrides)
        sim = Simulation(scene, team)
        label = f"scene {args.scene} (step 0)"
    return scene, sim, label


def own_times(prof) -> dict:
    """{function label: (own time, calls)} of a cProfile.Profile."""
    st = pstats.Stats(prof)
    out = {}
    for (file, line, name), (cc, nc, tt, ct, callers) in st.stats.items():
        if file == "~":
            label = name.strip("<>").replace("built-in method ", "").replace("method ", "")
        else:
            mod = Path(file).stem
            label = f"{mod}.{name}"
        t, c = out.get(label, (0.0, 0))
        out[label] = (t + tt, c + nc)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?", help="scene or SCENE:CASE (or --restart)")
    ap.add_argument("--restart", help="a checkpoint to start from")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--warmup", type=int, default=4, help="steps before the profile (compile, caches)")
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--out", help="also write the table (markdown) here")
    args = ap.parse_args(argv)
    if bool(args.scene) == bool(args.restart):
        ap.error("give a SCENE or --restart CHECKPOINT")

    from mpipd.output.writer import git_commit, short_commit
    from mpipd.parallel.team import world
    team = world()
    scene, sim, label = build(args, team)
    for _ in range(args.warmup):
        sim.step()
    bonds = sim.n_bonds_global
    prof = cProfile.Profile()
    team.barrier()
    t0 = time.perf_counter()
    prof.enable()
    for _ in range(args.steps):
        sim.step()
    prof.disable()
    wall = time.perf_counter() - t0
    team.barrier()
    walls = team.gather(wall)
    tables = team.gather(own_times(prof))
    classes = sim.classes.summary(team) if sim.classes.enabled else "single-rate"
    if not team.root:
        return 0
    wall = max(walls)
    names = set().union(*tables)
    rows = []
    for n in names:
        ts = [t.get(n, (0.0, 0))[0] for t in tables]
        calls = max(t.get(n, (0.0, 0))[1] for t in tables)
        rows.append((sum(ts) / len(ts), max(ts), calls, n))
    rows.sort(reverse=True)
    commit = short_commit(git_commit(), 7)       # "-dirty" if the solver's code is not HEAD's
    lines = [f"# Profile: {label}", "",
             f"`mpirun -n {team.size} python benchmarks/profile_run.py "
             f"{'--restart ' + args.restart if args.restart else args.scene} --steps {args.steps}"
             + "".join(f" --set {s}" for s in args.set) + f"` at commit {commit}; "
             f"{team.size} rank(s), steps {sim.step_count - args.steps}–{sim.step_count} "
             f"(after {args.warmup} warm-up steps).", "",
             f"Loop wall time {wall:.1f} s ({wall / args.steps:.3f} s a step, slowest rank; "
             f"per rank: {', '.join(f'{w:.1f}' for w in walls)} s)"
             + (f"; {bonds / 1e6:.1f} M bonds, {bonds * args.steps / wall / 1e6:.2f} M bond-steps/s "
                f"({bonds * args.steps / wall / 1e6 / team.size:.2f} per rank)" if bonds else "")
             + ".", "", f"Step classes at the end: {classes}.", "",
             "Own time of each function (without its callees), summed over its calls:", "",
             "| function | own time, mean over ranks (s) | largest rank (s) | share of the loop | calls (a rank) |",
             "|---|---|---|---|---|"]
    for mean, mx, calls, n in rows[:args.top]:
        lines.append(f"| `{n}` | {mean:.2f} | {mx:.2f} | {100 * mean / wall:.1f} % | {calls} |")
    rest = sum(r[0] for r in rows[args.top:])
    lines.append(f"| everything else ({len(rows) - args.top} functions) | {rest:.2f} | | "
                 f"{100 * rest / wall:.1f} % | |")
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
