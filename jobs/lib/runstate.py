"""State of an mpipd run folder, for the job chains in jobs/ (serial, no MPI).

    python jobs/lib/runstate.py OUT

prints one line ``STATE STEP STEPS``:

    done     STEPS STEPS   run.h5 holds its last frame (written at the last step)
    partial  STEP  STEPS   not finished; OUT/checkpoint.h5 is at STEP
    started  0     STEPS   run.h5 exists, not finished, and no checkpoint
    none     0     0       no run.h5 yet

STEPS is 0 when run.h5 is missing or unreadable.  A run is finished when the
frame counter equals the number of frames the file was sized for: mpipd writes
the last frame at the last step, and a checkpoint is never written at the last
step, so ``checkpoint.h5`` is always behind a finished run.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")    # parallel file systems


def state(out: Path) -> tuple[str, int, int]:
    import h5py
    run, ck = out / "run.h5", out / "checkpoint.h5"
    steps, finished = 0, False
    if run.exists():
        try:
            with h5py.File(run, "r") as f:
                steps = int(f.attrs["steps"])
                finished = int(f.attrs["frames_written"]) == f["time"].shape[0]
        except (OSError, KeyError, ValueError):
            pass                     # unreadable: not finished
    if finished:
        return "done", steps, steps
    if ck.exists():
        try:
            with h5py.File(ck, "r") as f:
                return "partial", int(f.attrs["step"]), steps
        except (OSError, KeyError, ValueError):
            pass
    return ("started" if run.exists() else "none"), 0, steps


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    print(*state(Path(argv[0])))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
