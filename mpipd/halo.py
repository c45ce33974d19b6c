"""Halo exchange: owned values -> the ghost copies on other ranks.

The plan comes from :meth:`mpipd.decomp.Slabs.plan`: for every peer rank, one
contiguous local slice of ghosts to receive and one contiguous slice of owned
points to send.  Arrays are exchanged in place through mpi4py's buffer
interface (``Irecv``/``Isend`` straight into and out of the array slices, no
pickling, no packing), so a ghost is a bitwise copy of its owner's value.

Any C-contiguous array whose first axis is the local point index can be
exchanged: positions and velocities every step, per-point tensors after the
stress update, uint8 failure flags.
"""
from __future__ import annotations

import numpy as np


class Halo:
    def __init__(self, comm, recv, send, n_owned: int, n_local: int):
        self.comm = comm
        self.recv = [(q, a, b) for q, a, b in recv if b > a]
        self.send = [(q, a, b) for q, a, b in send if b > a]
        self.n_owned = n_owned
        self.n_local = n_local
        self.peers = sorted({q for q, _, _ in self.recv} | {q for q, _, _ in self.send})
        self._verify()

    def _verify(self):
        """Check once that every peer sends exactly what this rank expects to receive."""
        rank = self.comm.Get_rank()
        size = self.comm.Get_size()
        expect = [0] * size
        for q, a, b in self.send:
            expect[q] = b - a
        got = self.comm.alltoall(expect)
        want = [0] * size
        for q, a, b in self.recv:
            want[q] = b - a
        if got != want:
            raise RuntimeError(f"rank {rank}: halo plan mismatch: peers send {got}, "
                               f"this rank expects {want}")

    def exchange(self, *arrays: np.ndarray) -> None:
        """Copy owned values of every array into the ghost rows on the other ranks."""
        from mpi4py import MPI
        reqs = []
        for t, arr in enumerate(arrays):
            if arr.shape[0] != self.n_local or not arr.flags.c_contiguous:
                raise ValueError("halo: arrays must be C-contiguous with n_local rows")
            for q, a, b in self.recv:
                reqs.append(self.comm.Irecv(arr[a:b], source=q, tag=t))
        for t, arr in enumerate(arrays):
            for q, a, b in self.send:
                reqs.append(self.comm.Isend(arr[a:b], dest=q, tag=t))
        MPI.Request.Waitall(reqs)

    @property
    def n_ghost(self) -> int:
        return self.n_local - self.n_owned
