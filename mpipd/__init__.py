"""mpipd — MPI-parallel, slab-decomposed non-ordinary state-based peridynamics.

Where things live:

``scene``           scene schema: TOML -> validated frozen dataclasses
``geometry``        lattice fill of shapes, the layer table
``decomp``          slab decomposition, owned and ghost points of a rank
``halo``            halo exchange (the only place ghost data moves)
``families``        CSR neighbour families sorted by global id
``kernels/``        numba kernels (nosb, rotation, integrate, linalg)
``correspondence``  the correspondence machinery shared by every material
``materials/``      elastic, jh2, tension, j2 (copper), jwl (explosive) behind one interface
``failure``         point failure -> bond breakage, PD damage, damped set
``gas``             the explosive as updated-Lagrangian points (detonation, JWL)
``loads``           initial conditions, boundary conditions, body-force loads
``probes``          named points recorded every step
``solver``          step pipeline and time loop
``output``          parallel HDF5 + XDMF
``checkpoint``      checkpoint/restart by global id (any rank count)
``report``          ``mpipd check``: sizes, memory, stable time step, EOS warnings
``cli``             ``mpipd run | check | scenes``

Importing mpipd never initialises MPI; the CLI and tests pass a communicator in.
"""
__version__ = "0.1.0"
