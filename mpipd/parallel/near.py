"""The solids near the gas: a halo that follows the gas instead of the slabs.

The explosive gas is held whole on every rank (:func:`mpipd.parallel.decomp.replicated_parts`),
but the solids it acts on (its ``interacts_with`` materials) are held only as their
slabs and static ghosts are.  A gas point moves far from its owner's slab, so its
owner may lack solid points within its horizon.  This object gives them to it:

* ``plan`` (collective): each rank r picks, for every peer q, the points of the
  solids that r owns, that q does not hold (beyond q's static halo) and that lie
  within ``reach`` of some gas point q owns, at the current positions.  Every rank
  holds every gas point, so r decides this alone; only the counts, gids and
  volumes travel.  The points a rank receives are its *remote* rows, appended
  after its local points: local index n_local + k, by source rank, then gid.
* ``exchange`` (collective): the current positions and velocities of the remote
  rows, from their owners, every step.

With ``reach`` = gas horizon + Verlet skin and a new plan whenever the gas's
Verlet list is rebuilt (mpipd.model.gas: any gas or solid point moved half the
skin, on any rank), every solid point within a gas horizon of a gas point is on
that gas point's owner until the next plan, so the gas's families, and every sum
over them (in gid order), are those of the one-rank run.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..kernels.search import near_cells


class NearHalo:
    def __init__(self, comm, n_local: int, sources: np.ndarray, lacks: dict[int, np.ndarray],
                 gas: np.ndarray, gas_owner: np.ndarray, volume: np.ndarray, gid: np.ndarray):
        """``sources``: this rank's owned solid points the gas may act on (local
        indices); ``lacks[q]``: mask over ``sources``, True where peer q does not
        hold the point; ``gas`` the local indices of every gas point and
        ``gas_owner`` their owning ranks; ``volume``, ``gid``: of the local points."""
        self.comm = comm
        self.rank = comm.Get_rank()
        self.n_local = n_local
        self.sources = sources
        self.lacks = lacks
        self.gas = gas
        self.gas_owner = gas_owner
        self.volume = volume
        self.gid = gid
        self.send: list[tuple[int, np.ndarray]] = []     # (peer, owned local indices)
        self.recv: list[tuple[int, int, int]] = []       # (peer, start, stop) remote rows
        self.n_remote = 0
        self.remote_gid = np.zeros(0, np.int64)
        self.remote_volume = np.zeros(0)
        self.plans = 0

    def _near(self, y, q: int, reach: float) -> np.ndarray:
        """This rank's source points that q lacks within ``reach`` of q's gas."""
        cand = self.sources[self.lacks[q]]
        g = self.gas[self.gas_owner == q]
        if not len(cand) or not len(g):
            return np.zeros(0, np.int64)
        cand = near_cells(y, cand, g, reach)
        if not len(cand):
            return cand
        d, _ = cKDTree(y[g]).query(y[cand], distance_upper_bound=reach)
        return cand[d < reach]

    def plan(self, y: np.ndarray, reach: float) -> int:
        """New send and receive lists at the current positions ``y`` (local rows);
        the remote rows' gids and volumes.  Returns the number of remote rows."""
        from mpi4py import MPI
        size = self.comm.Get_size()
        self.plans += 1
        self.send = []
        counts = [0] * size
        for q in range(size):
            if q != self.rank and q in self.lacks:
                idx = self._near(y, q, reach)
                if len(idx):
                    self.send.append((q, idx))
                    counts[q] = len(idx)
        got = self.comm.alltoall(counts)
        self.recv, start = [], self.n_local
        for q in range(size):
            if got[q]:
                self.recv.append((q, start, start + got[q]))
                start += got[q]
        self.n_remote = start - self.n_local
        self.remote_gid = np.zeros(self.n_remote, np.int64)
        self.remote_volume = np.zeros(self.n_remote)
        reqs, keep = [], []
        for q, a, b in self.recv:
            a, b = a - self.n_local, b - self.n_local
            reqs.append(self.comm.Irecv(self.remote_gid[a:b], source=q, tag=0))
            reqs.append(self.comm.Irecv(self.remote_volume[a:b], source=q, tag=1))
        for q, idx in self.send:
            keep += [np.ascontiguousarray(self.gid[idx], dtype=np.int64),
                     np.ascontiguousarray(self.volume[idx])]
            reqs.append(self.comm.Isend(keep[-2], dest=q, tag=0))
            reqs.append(self.comm.Isend(keep[-1], dest=q, tag=1))
        MPI.Request.Waitall(reqs)
        return self.n_remote

    def exchange(self, *arrays: np.ndarray) -> None:
        """Fill the remote rows (n_local..) of each array (C-contiguous, at least
        n_local + n_remote rows) from the owners' local rows."""
        if not self.send and not self.recv:
            return
        from mpi4py import MPI
        reqs, keep = [], []
        for t, arr in enumerate(arrays):
            for q, a, b in self.recv:
                reqs.append(self.comm.Irecv(arr[a:b], source=q, tag=10 + t))
        for t, arr in enumerate(arrays):
            for q, idx in self.send:
                keep.append(np.ascontiguousarray(arr[idx]))
                reqs.append(self.comm.Isend(keep[-1], dest=q, tag=10 + t))
        MPI.Request.Waitall(reqs)
