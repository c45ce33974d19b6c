"""One benchmark case, run under mpirun by benchmarks/run.py.

Prints (rank 0) one line:

    bench <case> ranks=<n> points=<N> bonds=<B> steps=<S> wall_s=<t>
          bond_steps_per_s_per_core=<x> bytes_per_bond=<m> ...

bond-steps = bonds x steps (bonds counted per family entry, each pair twice, as
the peers count them); wall_s is the time loop only (set-up and the first,
JIT-warming steps excluded), the slowest rank's; per core = divided by ranks.
"""
import argparse
import resource
import time

from mpi4py import MPI

from mpipd.input.scene import OUTPUT_FIELDS, Scene
from mpipd.input.schema import build
from mpipd.parallel.team import Team
from mpipd.solver import Simulation

PEAKS = ("peak_pressure", "peak_sigma_rr", "peak_speed")


def elastic_block(n: int, steps: int) -> dict:
    """n^3 granite block, dx = 1 mm, horizon 3 dx, Gaussian-ish velocity pulse."""
    dx = 1e-3
    L = n * dx
    return {
        "scene": {"name": "bench_elastic"},
        "time": {"dt": 5e-8, "steps": steps},
        "materials": {"granite": {"model": "elastic", "density": 2660.0,
                                  "bulk_modulus": 21.9e9, "shear_modulus": 25.7e9}},
        "parts": [{"name": "block", "material": "granite", "dx": dx,
                   "shape": {"kind": "box", "lo": [0, 0, 0], "hi": [L, L, L]}}],
        "initial": [{"kind": "velocity_pulse", "axis": "z", "center": L / 2,
                     "half_width": L / 8, "velocity": [0.0, 0.0, 1.0]}],
    }


def jh2_block(n: int, steps: int) -> dict:
    """n^3 granite block with Table 1 JH2 + tension failure, breakage, contact,
    damping and viscosity; a 10 x 10 x 3 mm patch of the top face struck inward at
    40 m/s crushes the rock under it and cracks around it: a local failure zone
    (a few per cent of the points per 100 steps, the regime the issue's
    bookkeeping target is set for)."""
    d = elastic_block(n, steps)
    L = n * 1e-3
    d["scene"]["name"] = "bench_jh2"
    d["materials"] = {"granite": {"model": "jh2",
                                  "tension": {"sigma_st": -6.9e6, "c1": 0.33, "rate0": 0.4}}}
    d["solver"] = {"hourglass": 0.01, "contact": True, "damping": 2e5,
                   "viscosity": {"cq": 8.0, "cl": 0.1}}
    c = L / 2
    d["initial"] = [{"kind": "uniform_velocity",
                     "region": {"lo": [c - 5e-3, c - 5e-3, L - 3e-3], "hi": [c + 5e-3, c + 5e-3, L]},
                     "velocity": [0.0, 0.0, -40.0]}]
    return d


def blast_slice(n: int, steps: int) -> dict:
    """A single-hole slice: explosive (r < 3.2 mm), copper tube (0.6 mm), JH2 granite
    with the tension model out to n/3 mm (20 mm for n = 60), 10 mm thick, dx 0.5 mm
    throughout; detonated from z = 0 (the gas is ~2.6% of the points)."""
    R = n / 3 * 1e-3
    z = [0.0, 0.010]
    return {
        "scene": {"name": "bench_blast"},
        "time": {"dt": 1.5e-8, "steps": steps},
        "materials": {
            "explosive": {"model": "jwl", "damping": 1e4, "interacts_with": ["copper"]},
            "copper": {"model": "j2"},
            "granite": {"model": "jh2",
                        "tension": {"sigma_st": -6.9e6, "c1": 0.33, "rate0": 0.4}}},
        "parts": [
            {"name": "charge", "material": "explosive", "dx": 5e-4,
             "shape": {"kind": "cylinder", "center": [0, 0], "radius": 0.0032, "z": z}},
            {"name": "tube", "material": "copper", "dx": 5e-4,
             "shape": {"kind": "annulus", "center": [0, 0], "inner_radius": 0.0032,
                       "radius": 0.0038, "z": z}},
            {"name": "rock", "material": "granite", "dx": 5e-4,
             "shape": {"kind": "annulus", "center": [0, 0], "inner_radius": 0.0038,
                       "radius": R, "z": z}}],
        "solver": {"hourglass": 0.01, "contact": True, "damping": 2e5,
                   "viscosity": {"cq": 8.0, "cl": 0.1}},
        # the built-in blast scenes keep the per-step peaks: so does the bench
        "output": {"fields": ["u", "v"] + [k for k in PEAKS if k in OUTPUT_FIELDS]},
    }


def blast_paper_slice(n: int, steps: int) -> dict:
    """The same slice at the paper's three resolutions: explosive 0.4 / 1.5 mm,
    copper 0.3 / 1.0 mm, rock 0.8 / 2.4 mm (dx / horizon), dual horizons with the
    interface correction; rock out to n/1.5 mm (40 mm for n = 60), 10 mm thick."""
    d = blast_slice(n, steps)
    d["scene"]["name"] = "bench_blast_paper_dx"
    d["time"]["dt"] = 2e-8
    charge, tube, rock = d["parts"]
    charge.update(dx=4e-4, horizon_factor=3.75)
    charge["shape"]["radius"] = 0.0026
    tube.update(dx=3e-4, horizon_factor=1.0 / 0.3)
    tube["shape"].update(inner_radius=0.0026, radius=0.0032)
    rock.update(dx=8e-4)
    rock["shape"].update(inner_radius=0.0032, radius=n / 1.5 * 1e-3)
    return d


def multirate_pair(case, ratio=4, safety=0.5):
    """``case`` twice, single-rate and with multi-rate classes (mpipd.model.multirate):
    run by :func:`main` back to back in one process, reported as wall time per
    simulated microsecond and their ratio."""
    def make(n: int, steps: int, multirate: bool = False) -> dict:
        d = case(n, steps)
        d["output"]["every"] = 4 * ratio           # frames on coarse steps (none are written)
        if multirate:
            d["time"]["multirate"] = {"max_ratio": ratio, "safety": safety}
        return d
    make.__doc__ = (f"{case.__name__}, single-rate and multi-rate (max_ratio {ratio}, "
                    f"safety {safety})")
    make.pair = ratio
    return make


def refreshed(case):
    """The case with solver.refresh_after_break on (a second force evaluation on
    steps where bonds broke): its price beside the plain case."""
    def make(n: int, steps: int) -> dict:
        d = case(n, steps)
        d["scene"]["name"] += "_refresh"
        d["solver"]["refresh_after_break"] = True
        return d
    make.__doc__ = f"{case.__name__} with refresh_after_break = true"
    return make


def rockmass(case):
    """The case as a rock mass (README, "The rock mass"): its rock jittered by 0.2 dx
    and with Weibull strength (m = 6) on sigma_st and T — the price of both beside
    the plain case."""
    def make(n: int, steps: int) -> dict:
        d = case(n, steps)
        d["scene"]["name"] += "_rockmass"
        d["parts"][-1]["jitter"] = 0.2
        d["materials"]["granite"]["heterogeneity"] = {
            "distribution": "weibull", "modulus": 6.0, "seed": 1, "applies_to": ["tension", "T"]}
        return d
    make.__doc__ = f"{case.__name__} as a rock mass"
    return make


CASES = {"elastic": elastic_block, "jh2": jh2_block, "blast": blast_slice,
         "blast_mr": blast_paper_slice, "jh2_refresh": refreshed(jh2_block),
         "blast_refresh": refreshed(blast_slice),
         "blast_paper_slice": multirate_pair(blast_paper_slice),
         "jh2_rockmass": rockmass(jh2_block)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("case", choices=sorted(CASES))
    ap.add_argument("--size", type=int, default=60, help="points per block edge")
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--warmup", type=int, default=2)
    args = ap.parse_args()
    team = Team(MPI.COMM_WORLD)
    if hasattr(CASES[args.case], "pair"):
        return pair(args, team)
    scene = build(Scene, CASES[args.case](args.size, args.steps + args.warmup))
    t0 = time.perf_counter()
    sim = Simulation(scene, team)
    setup = team.max(time.perf_counter() - t0)
    for _ in range(args.warmup):
        sim.step()
    team.barrier()
    failed0 = int(sim.failure_counts()[1:].sum())
    book0 = sim.failure.seconds if sim.failure else 0.0
    flags0 = sim.failure.exchange_seconds if sim.failure else 0.0
    if sim.gas is not None:
        sim.gas.search_seconds = 0.0
    t0 = time.perf_counter()
    for _ in range(args.steps):
        sim.step()
    wall = team.max(time.perf_counter() - t0)
    extra = ""
    if sim.gas is not None:
        share = team.max(sim.gas.search_seconds) / wall
        extra += (f" gas_points_pct={100.0 * team.sum(len(sim.gas.gas_idx)) / sim.n_global:.2f}"
                  f" gas_research_share={share:.3f}")
    if sim.failure is not None:
        book = team.max(sim.failure.seconds - book0)
        flags = team.max(sim.failure.exchange_seconds - flags0)
        failed = int(sim.failure_counts()[1:].sum())
        per100 = (failed - failed0) / sim.n_global * 100.0 / args.steps * 100.0
        extra += (f" failed_pct_per_100_steps={per100:.3f} failed_total={failed}"
                  f" bonds_broken={sim.bonds_broken()} breakage_share={book / wall:.3f}"
                  f" flag_exchange_share={flags / wall:.3f}")
    if sim.interface is not None:               # the ghost-force correction's own cost
        ic = sim.interface
        t1 = time.perf_counter()
        for _ in range(args.steps):
            ic.apply(sim.corr.fd, sim.corr.F, sim.f, sim.classes.klass, sim.classes.level)
        share = team.max(time.perf_counter() - t1) / wall
        extra += (f" interface_points_pct={100.0 * team.sum(len(ic.idx)) / sim.n_global:.2f}"
                  f" interface_share={share:.4f}")
    mem = sim.memory()
    bpb = team.max(mem["bytes_per_bond"])
    bpp = team.max(mem["bytes_per_point"])
    rss = team.max(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
    B = sim.n_bonds_global
    if team.root:
        rate = B * args.steps / wall / team.size
        print(f"bench {args.case} ranks={team.size} points={sim.n_global} bonds={B} "
              f"steps={args.steps} wall_s={wall:.3f} bond_steps_per_s_per_core={rate:.4g} "
              f"bytes_per_bond={bpb:.2f} bytes_per_point={bpp:.1f} peak_rss_mib={rss:.0f} "
              f"setup_s={setup:.2f}{extra}", flush=True)


def pair(args, team):
    """Single-rate, then multi-rate, of one case in one process (the same JIT cache
    and machine state): wall time of the time loop per simulated microsecond, the
    ratio, and the multi-rate run's classes.  Steps and warm-up are rounded up to
    whole coarse steps."""
    make = CASES[args.case]
    r = make.pair
    steps = -(-args.steps // r) * r
    warm = -(-max(args.warmup, 1) // r) * r
    out = {}
    for mr in (False, True):
        scene = build(Scene, make(args.size, steps + warm, multirate=mr))
        sim = Simulation(scene, team)
        for _ in range(warm):
            sim.step()
        team.barrier()
        t0 = time.perf_counter()
        for _ in range(steps):
            sim.step()
        wall = team.max(time.perf_counter() - t0)
        out[mr] = wall / (steps * scene.time.dt * 1e6)
        if mr:
            cl = sim.classes
            per = team.sum(cl.counts(cl.fam_bonds))
            classes = " ".join(f"class{k}_points={per[k, 0]} class{k}_bonds={per[k, 1]}"
                               for k in range(len(per)))
            from mpipd.model.multirate import projected_cost
            cost = projected_cost(per[:, 1])
    if team.root:
        print(f"bench {args.case} ranks={team.size} points={sim.n_global} "
              f"bonds={sim.n_bonds_global} steps={steps} dt={scene.time.dt:.3g} "
              f"single_rate_wall_s_per_us={out[False]:.3f} "
              f"multirate_wall_s_per_us={out[True]:.3f} speedup={out[False] / out[True]:.3f} "
              f"max_ratio={r} projected_speedup={1 / cost:.3f} {classes}", flush=True)


if __name__ == "__main__":
    main()
