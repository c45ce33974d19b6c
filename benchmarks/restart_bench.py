"""`make bench`: what a restore costs in memory and time, beside what the model holds.

    mpirun -n N python benchmarks/restart_bench.py write   --size S --broken F --dir D
    mpirun -n N python benchmarks/restart_bench.py restore --size S --dir D

``write`` builds ``benchmarks/case.py``'s jh2 block of S^3 points, breaks the fraction F
of its bonds (each bond from both ends: a pair breaks when a hash of its two gids says
so, the same on every rank count) and writes a checkpoint to D.  ``restore`` builds the
same block in a fresh process, reads its peak resident memory (VmHWM), resets the peak
(``/proc/self/clear_refs``), restores the checkpoint and reads the peak again.  Rank 0
prints one line, the slowest or largest rank's figures:

    bench restart ranks=<n> points=<N> bonds=<B> broken_pairs=<P> build_peak_mib=<a>
          rss_built_mib=<b> restore_peak_mib=<c> restore_extra_mib=<c - b> restore_s=<t>

``restore_extra_mib`` is what the restore needs above the built model: the per-bond
temporaries of the broken-bond marking once made it 12.4 GB per rank at
``blast_paper:dx0.7``'s 283 M bonds (notes §37).
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parent))
from case import jh2_block  # noqa: E402

from mpipd.input.scene import Scene  # noqa: E402
from mpipd.input.schema import build  # noqa: E402
from mpipd.kernels.hashrng import uniform  # noqa: E402
from mpipd.output import checkpoint  # noqa: E402
from mpipd.parallel.team import Team  # noqa: E402
from mpipd.solver import Simulation  # noqa: E402


def status_mib(key: str) -> float:
    """A memory figure of this process from /proc/self/status (VmHWM, VmRSS), MiB."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(key + ":"):
            return int(line.split()[1]) / 1024.0
    return float("nan")


def reset_peak():
    """Set VmHWM to the current RSS (Linux >= 4.0: write 5 to clear_refs)."""
    Path("/proc/self/clear_refs").write_text("5")


def break_bonds(sim, fraction: float):
    """Break the bonds whose gid pair draws below ``fraction`` (both directed copies:
    mpipd.kernels.hashrng keyed by lo * N + hi, the same on every rank count)."""
    fam, gid = sim.families, sim.points.gid
    rows = np.repeat(np.arange(len(fam.offsets) - 1), np.diff(fam.offsets))
    a, b = gid[rows], gid[fam.nbr]
    keys = np.minimum(a, b).astype(np.int64) * sim.n_global + np.maximum(a, b)
    fam.broken[:] = (uniform(0, 0, keys) < fraction).astype(np.uint8)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("phase", choices=("write", "restore"))
    ap.add_argument("--size", type=int, default=60)
    ap.add_argument("--broken", type=float, default=0.3)
    ap.add_argument("--dir", required=True)
    args = ap.parse_args()
    team = Team(MPI.COMM_WORLD)
    path = Path(args.dir) / "checkpoint.h5"
    scene = build(Scene, jh2_block(args.size, 10))
    sim = Simulation(scene, team)
    if args.phase == "write":
        if team.root:
            path.parent.mkdir(parents=True, exist_ok=True)
        team.barrier()
        break_bonds(sim, args.broken)
        checkpoint.write(sim, path, "")
        return 0
    build_peak = team.max(status_mib("VmHWM"))
    rss_built = status_mib("VmRSS")
    reset_peak()
    team.barrier()
    t0 = time.perf_counter()
    checkpoint.restore(sim, path)
    wall = team.max(time.perf_counter() - t0)
    peak = status_mib("VmHWM")
    extra = team.max(peak - rss_built)
    rss_built, peak = team.max(rss_built), team.max(peak)
    pairs = team.sum(int(np.count_nonzero(sim.families.broken)))
    if team.root:
        print(f"bench restart ranks={team.size} points={sim.n_global} "
              f"bonds={sim.n_bonds_global} broken_pairs={pairs} "
              f"build_peak_mib={build_peak:.0f} rss_built_mib={rss_built:.0f} "
              f"restore_peak_mib={peak:.0f} restore_extra_mib={extra:.0f} "
              f"restore_s={wall:.2f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
