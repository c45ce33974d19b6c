"""The parallel layer: the only code that knows about ranks.

``team``    the communicator and its reductions (``Team``), MPI start-up and abort
``decomp``  slab decomposition by z layer, owned and ghost points of a rank
``halo``    the halo exchange (the only place ghost data moves)
"""
