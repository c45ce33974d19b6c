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

Importing mpipd never initialises MPI; the CLI and tests pass a communicator in.
It does point numba's kernel cache at a directory keyed by the sources
(mpipd.kernels.cache).
"""
from .kernels.cache import configure as _configure_kernel_cache

__version__ = "0.1.0"

#: numba's cache directory, keyed by the sources (mpipd.kernels.cache)
KERNEL_CACHE = _configure_kernel_cache()
