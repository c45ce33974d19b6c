"""Open a run file collectively and give each rank its slice of global ids."""
from __future__ import annotations

import h5py
import numpy as np


class Run:
    """A run file opened by every rank of ``comm``; ``lo:hi`` is this rank's gid slice."""

    def __init__(self, path, comm):
        self.comm = comm
        self.f = h5py.File(path, "r", driver="mpio", comm=comm)
        self.n_points = int(self.f.attrs["n_points"])
        self.frames = int(self.f.attrs["frames_written"])
        r, n = comm.Get_rank(), comm.Get_size()
        self.lo = self.n_points * r // n
        self.hi = self.n_points * (r + 1) // n

    def geometry(self, name: str) -> np.ndarray:
        return self.f["geometry"][name][self.lo:self.hi]

    def field(self, name: str, frame=slice(None)) -> np.ndarray:
        if name not in self.f["fields"]:
            raise KeyError(f"the run has no field {name!r} "
                           f"(it has: {', '.join(self.f['fields'])})")
        return self.f["fields"][name][frame, self.lo:self.hi]

    @property
    def time(self) -> np.ndarray:
        return self.f["time"][: self.frames]

    def energy(self, name: str) -> np.ndarray:
        return self.f["energy"][name][: self.frames]

    def close(self):
        self.f.close()
