"""Compiled kernels: module-level ``numba.njit(cache=True)`` functions that take
only arrays and scalars.  One concern per module:

``linalg``     3x3 helpers (determinant, inverse, products) on small arrays
``index``      the family ranges and neighbour indices every bond loop reads with
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

#: numba options of the bond loops (:mod:`.nosb`'s deformation gradients and force
#: gathers): LLVM may fuse a multiply and an add into one fused multiply-add
#: ("contract" alone: no reassociation, no assumption about NaN or infinity).  The
#: fusion is decided when the kernel is compiled, so every rank runs the same machine
#: code on the same operands in the same order and the results stay bit-identical
#: across decompositions; they differ from unfused code by rounding.
BOND_LOOP = {"cache": True, "fastmath": {"contract"}}
