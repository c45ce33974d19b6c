"""The communicator, passed in — never a global.

:class:`Team` wraps an mpi4py communicator with the few collective verbs the
solver needs (reductions, broadcast, abort).  Nothing here initialises MPI at
import; :func:`world` imports ``mpi4py.MPI`` only when called.
"""
from __future__ import annotations

import numpy as np


class Team:
    """The ranks of one run and their collective operations."""

    def __init__(self, comm):
        self.comm = comm
        self.rank = comm.Get_rank()
        self.size = comm.Get_size()

    @property
    def root(self) -> bool:
        return self.rank == 0

    def _op(self, name):
        from mpi4py import MPI
        return getattr(MPI, name)

    def _reduce(self, x, name):
        """``name`` (SUM, MAX, MIN) over the ranks of a number (a Python object reduction)
        or of a NumPy array (elementwise, into an array of its dtype)."""
        if np.isscalar(x):
            return self.comm.allreduce(x, op=self._op(name))
        out = np.empty_like(x)
        self.comm.Allreduce(np.ascontiguousarray(x), out, op=self._op(name))
        return out

    def sum(self, x):
        """Global sum of a number or of a NumPy array (elementwise)."""
        return self._reduce(x, "SUM")

    def max(self, x):
        """Global maximum of a number or of a NumPy array (elementwise)."""
        return self._reduce(x, "MAX")

    def min(self, x):
        """Global minimum of a number or of a NumPy array (elementwise)."""
        return self._reduce(x, "MIN")

    def gather(self, x):
        """Small per-rank values to every rank (a list indexed by rank)."""
        return self.comm.allgather(x)

    def bcast(self, x):
        return self.comm.bcast(x, root=0)

    def barrier(self):
        self.comm.Barrier()

    def abort(self, code: int = 1):
        self.comm.Abort(code)


class Fatal(RuntimeError):
    """An error with a known cause (disk full, ...): :func:`abort_on_error` prints
    it as one line ``mpipd: error: <what>`` instead of a traceback, and exits with
    ``exit_code``."""
    exit_code = 1


def abort_on_error(team: Team, fn, *args):
    """Run ``fn(*args)``; if it raises on any rank, print the traceback (one line
    for a :class:`Fatal`) and abort the whole MPI job (a plain exit would leave the
    other ranks waiting forever)."""
    import sys
    import traceback
    try:
        return fn(*args)
    except SystemExit:
        raise
    except Fatal as e:
        import os
        sys.stderr.write(f"mpipd: error: {e}\n")
        sys.stderr.flush()
        sys.stdout.flush()
        if team.size > 1:
            team.abort(e.exit_code)
        # files may be left open by the failure: leave now, before the interpreter's
        # teardown closes them after MPI_Finalize (HDF5 crashes there)
        os._exit(e.exit_code)
    except BaseException:
        sys.stderr.write(f"mpipd: rank {team.rank} failed:\n{traceback.format_exc()}")
        sys.stderr.flush()
        if team.size > 1:
            team.abort(1)
        return 1


def world() -> Team:
    from mpi4py import MPI
    return Team(MPI.COMM_WORLD)
