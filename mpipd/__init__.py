"""mpipd — MPI-parallel, slab-decomposed non-ordinary state-based peridynamics.

Where things live (docs/architecture.md has the step pipeline and who owns
which array):

``input/``      scene TOML -> validated frozen dataclasses; shapes, loads, built-in scenes
``parallel/``   the team (MPI), slab decomposition, halo exchange
``model/``      families, correspondence machinery, failure, interface, gas, energy ledger
``materials/``  elastic, jh2, tension, j2 (copper), jwl (explosive) behind one registry
``kernels/``    the numba kernels the model's objects call
``output/``     run file (parallel HDF5 + XDMF), probes, running peaks, checkpoints, run dirs
``solver``      the step pipeline and time loop
``check``       ``mpipd check``: sizes, memory, stable time step, EOS warnings
``cli``         ``mpipd run | check | scenes``
``post/``       reading run files after a run: ``python -m mpipd.post`` (report, figures)

``mpipd.open(path)`` reads a run file from Python (mpipd.post.api), serially; it
imports the reading code (h5py) when called, not when mpipd is imported.

Importing mpipd never initialises MPI; the CLI and tests pass a communicator in.
It does point numba's kernel cache at a directory keyed by the sources
(mpipd.kernels.cache), and turns numba's colouring of error messages off: with it,
numba's colorama writes a colour reset (ESC[0m, no newline) to a terminal stdout at
exit, and under mpirun every rank's stdout is a pseudo-terminal, so the fragment landed
inside other ranks' lines (a run log's line, a verification row's JSON).
"""
import os

os.environ.setdefault("NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING", "1")   # before numba

from .kernels.cache import configure as _configure_kernel_cache  # noqa: E402

__version__ = "0.1.0"

#: numba's cache directory, keyed by the sources (mpipd.kernels.cache)
KERNEL_CACHE = _configure_kernel_cache()


def open(path, comm=None):
    """Open a run file (``run.h5`` or its folder) for reading from Python:
    a :class:`mpipd.post.api.RunFile` with the frames, times, material and part names,
    fields, sections, probes and energy ledger as NumPy arrays.  Serial without
    ``comm`` (no MPI); with an mpi4py communicator every rank reads its own slice.
    The reading code (h5py) is imported on the first call, not by ``import mpipd``."""
    from .post.api import open as _open
    return _open(path, comm)
