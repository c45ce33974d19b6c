"""Halo exchange: owned values -> the ghost copies on other ranks.

The plan comes from :meth:`mpipd.parallel.decomp.Slabs.plan`: for every peer rank, one
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
        """``recv``: (peer, start, stop) ranges; ``send``: (peer, start, stop) ranges
        or (peer, index array) lists (the replicated gas), in the order the peer
        posts its receives from this rank."""
        self.comm = comm
        self.recv = [(q, a, b) for q, a, b in recv if b > a]
        self.send = []
        for e in send:
            if len(e) == 3 and e[2] > e[1]:
                self.send.append((e[0], slice(e[1], e[2]), e[2] - e[1]))
            elif len(e) == 2 and len(e[1]):
                self.send.append((e[0], np.asarray(e[1]), len(e[1])))
        self.n_owned = n_owned
        self.n_local = n_local
        self.peers = sorted({e[0] for e in self.recv} | {e[0] for e in self.send})
        self._verify()

    def _verify(self):
        """Check once that every peer sends exactly what this rank expects to receive."""
        rank = self.comm.Get_rank()
        size = self.comm.Get_size()
        expect = [0] * size
        for q, _, n in self.send:
            expect[q] += n
        got = self.comm.alltoall(expect)
        want = [0] * size
        for q, a, b in self.recv:
            want[q] += b - a
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
        keep = []                                   # packed buffers live until Waitall
        for t, arr in enumerate(arrays):
            for q, sel, _ in self.send:
                buf = arr[sel] if isinstance(sel, slice) else np.ascontiguousarray(arr[sel])
                keep.append(buf)
                reqs.append(self.comm.Isend(buf, dest=q, tag=t))
        MPI.Request.Waitall(reqs)
