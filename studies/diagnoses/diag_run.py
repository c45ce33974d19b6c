"""What the serial diagnosis scripts share: a run file opened on one rank, with its model.

    run, model = open_run(path, "zone_split.py")
    args, run, model = open_with_option("zone_split.py", "--split-mm", 10.0)

exits with one line naming the script when started on more than one rank.
"""
import argparse
import sys
from pathlib import Path

from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from mpipd.post.model import load_model  # noqa: E402
from mpipd.post.reader import Run  # noqa: E402


def open_run(path, script):
    """(Run, Model) of the run file at ``path``, read serially by ``script``."""
    if MPI.COMM_WORLD.size != 1:
        sys.exit(f"{script} runs on 1 rank")
    run = Run(path, MPI.COMM_WORLD)
    return run, load_model(run)


def open_with_option(script, option, default):
    """Parse ``script``'s command line (a run file and one float ``option``), open the
    run file with :func:`open_run`: (args, Run, Model)."""
    ap = argparse.ArgumentParser(prog=script)
    ap.add_argument("run_file")
    ap.add_argument(option, type=float, default=default)
    args = ap.parse_args()
    return (args, *open_run(args.run_file, script))
