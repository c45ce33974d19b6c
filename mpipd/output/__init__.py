"""Output: what a run writes and how it is resumed.

``writer``      the run file (parallel HDF5, gid-indexed) and its XDMF
``probes``      named points recorded every step
``peaks``       per-point running peaks over every step
``checkpoint``  checkpoint/restart by global id (any rank count)
``rundir``      a run's directory: its own files, locks, restart matching
"""
