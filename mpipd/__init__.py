"""mpipd — MPI-parallel, slab-decomposed non-ordinary state-based peridynamics.

Where things live:

``scene``           scene schema: TOML -> validated frozen dataclasses
``geometry``        lattice fill of shapes, the layer table
``decomp``          slab decomposition, owned and ghost points of a rank
``halo``            halo exchange (the only place ghost data moves)
``families``        CSR neighbour families sorted by global id
``kernels/``        numba kernels (nosb, rotation, integrate, linalg)
``correspondence``  the correspondence machinery shared by every material
``materials/``      constitutive models behind one small interface
``loads``           initial and boundary conditions
``solver``          step pipeline and time loop
``output``          parallel HDF5 + XDMF
``cli``             ``mpipd run | check | scenes``

Importing mpipd never initialises MPI; the CLI and tests pass a communicator in.
"""
__version__ = "0.1.0"
