"""The model: what one step computes on a rank's points.

``families``        CSR neighbour families sorted by global id
``correspondence``  K, F, rotation, force state and hourglass, once for every material
``failure``         point failure -> bond breakage, PD damage, damped set
``interface``       the ghost-force correction where dx or the horizon changes
``gas``             the explosive as updated-Lagrangian points (detonation, JWL)
``ledger``          the energy ledger (what went in, is held, was dissipated)
"""
