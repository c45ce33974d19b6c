"""Gas containment per saved frame of run files (issue 60, item 3): the report's
measure (mpipd.post.tube: gas points outside the tube's current inner surface
within its length, and beyond its ends), with the ledger's balance and gas_wall
term, one line per frame.

    mpirun -n 1 .venv/bin/python studies/model/wall_containment.py RUN.h5 [RUN.h5 ...]
"""
import sys

import h5py
import numpy as np
from mpi4py import MPI

from mpipd.post import tube
from mpipd.post.model import load_model
from mpipd.post.reader import Run


def main(paths):
    for path in paths:
        run = Run(path, MPI.COMM_WORLD)
        model = load_model(run)
        x, pid = run.geometry("x"), run.geometry("part")
        held = tube.Containment(run, model, x, pid)
        for k in range(run.frames):
            held.frame(k, run.field("u", k))
        res = held.result()
        with h5py.File(path, "r") as f:
            en = f["energy"]
            bal = en["balance"][...]
            gw = en["gas_wall"][...] if "gas_wall" in en else np.zeros_like(bal)
        print(f"# {path}: largest outside {res['max_outside']}, beyond the ends "
              f"{res['max_beyond_ends']}, |balance| <= {np.abs(bal).max():.3g}")
        print("  t_us  outside  beyond  balance  gas_wall_J")
        for k, t in enumerate(res["t_us"]):
            e = min(k, len(bal) - 1)
            print(f"{t:6.2f} {res['outside'][k]:8d} {res['beyond_ends'][k]:7d} "
                  f"{bal[e]:+.2e} {gw[e]:.4g}")


if __name__ == "__main__":
    main(sys.argv[1:])
