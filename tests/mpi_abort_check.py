"""Run under mpirun -n 2: rank 1 raises while rank 0 waits in a collective.
Without the abort the job would hang; with it, mpirun exits non-zero at once."""
from mpi4py import MPI

from mpipd.parallel.team import Team, abort_on_error

team = Team(MPI.COMM_WORLD)


def work():
    if team.rank == 1:
        raise RuntimeError("deliberate failure on rank 1")
    team.barrier()
    return 0


abort_on_error(team, work)
