"""Compiled kernels: module-level ``numba.njit(cache=True)`` functions that take
only arrays and scalars.  One concern per module:

``linalg``     3x3 helpers (determinant, inverse, products) on small arrays
``influence``  the influence functions omega (quadratic, constant, inverse) and
               their per-point codes
``nosb``       shape tensor K, deformation gradient F and its rate, force data,
               the force gather (correspondence force state + hourglass penalty
               + bond-spring fallback)
``rotation``   Flanagan–Taylor rotation / left-stretch update, unrotated d
``integrate``  velocity-Verlet kicks and drifts, energies

Python objects in :mod:`mpipd.model.correspondence` and :mod:`mpipd.solver` gather the
arrays and call these; nothing here knows about MPI or scenes.
"""
