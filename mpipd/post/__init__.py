"""Parallel-HDF5 analysis of mpipd runs: ``mpirun -n N python -m mpipd.post CMD run.h5``.

Each rank opens the run file with the ``mpio`` driver and reads only its own
contiguous slice of global ids; results are combined with reductions, so no
rank ever holds a whole field.
"""
