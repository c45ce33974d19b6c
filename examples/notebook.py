"""Reading a run from Python, as in a notebook: ``mpipd.open`` and NumPy arrays.

    python examples/notebook.py runs/demo/run.h5 [--part rock] [--out damage.png]

Make the run first (``make demo`` writes runs/demo/run.h5).  Each block below is a
notebook cell: the run's frames and names, the damage of the last frame, a section
through the rock, the probes' peak radial stress and the energy ledger's closure.
Serial: no ``mpirun`` and no communicator (``mpipd.open(path, comm=...)`` reads in
parallel under MPI).
"""
import argparse

import numpy as np

import mpipd

ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
ap.add_argument("run", nargs="?", default="runs/demo/run.h5", help="a run.h5 or its folder")
ap.add_argument("--part", default=None, help="the part of the section (default: the last part)")
ap.add_argument("--out", default=None, help="draw the section's damage into this PNG")
args = ap.parse_args()

# --- the run: frames, times, named materials and parts
run = mpipd.open(args.run)
print(run)
print(f"{run.frames} frames, t = {run.times[0] * 1e6:.3g} .. {run.times[-1] * 1e6:.3g} us")
print("materials:", ", ".join(run.materials))
print("parts:", ", ".join(run.parts))

# --- a field at the last frame, per part
part = args.part or run.parts[-1]
if "damage" in run.fields:
    for name in run.parts:
        phi = run.field("damage", frame=-1, part=name)
        print(f"damage of {name}: {np.count_nonzero(phi >= 0.5)} of {phi.size} points >= 0.5")

    # --- a section through one part: the z level nearest the part's middle
    sec = run.section(part=part)
    print(f"section of {part} at z = {sec.z * 1e3:.3g} mm, t = {sec.time * 1e6:.3g} us: "
          f"{sec.values.size} points, mean damage {sec.values.mean():.3f}")
    if args.out:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5, 4.4), dpi=100)
        im = ax.scatter(sec.x * 1e3, sec.y * 1e3, c=sec.values, s=4, marker="s",
                        cmap="inferno", vmin=0, vmax=1)
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        fig.colorbar(im, ax=ax, label="damage")
        fig.savefig(args.out)
        print(f"wrote {args.out}")

# --- the probes: one array a quantity, one row a step
for name, probe in run.probes.items():
    print(f"probe {name} ({probe.part}, gid {probe.gid}): {probe['t'].size} steps, "
          f"most compressive sigma_rr {probe['sigma_rr'].min() / 1e6:.4g} MPa")

# --- the energy ledger: one array a term, one row a frame
ledger = run.energy
print("ledger terms:", ", ".join(ledger))
print(f"largest |balance| {np.abs(ledger['balance']).max():.3e}")
run.close()
