"""Ghost-force correction where the resolution changes (dual horizons).

Families are the union of each point's horizon and the points whose horizon
reaches it, and the pair force is the dual-horizon one (Ren et al. 2016,
2017; :mod:`mpipd.kernels.nosb`), so momentum is conserved.  Dual horizons
alone do not pass the patch test, though: under a uniform first Piola stress
P the force density on point i is

    f_i = P g_i,   g_i = sum_j (omega_i K_i^-1 + omega_j K_j^-1) xi_ij V_j,

and g_i, zero by symmetry inside a uniform lattice, is of order 1/dx within
two horizons of a change of spacing, horizon or influence function (a
coarse/fine interface, the zones of a graded part, two parts with different
``influence``).  That is a ghost force: a uniform strain across the
interface is not in equilibrium.

The correction (this module) acts on points whose g_i can feel a change of
resolution (a family member of another dx, horizon or influence function, or
one that has one):

* in full where the ball of twice the point's reach lies inside the
  total-Lagrangian body — there the uniform-stress force is pure artefact;
* in the x-y plane where that ball leaves the body only through z faces shared
  by every part near the point (the body is a prism there: thin slices, the
  faces of a specimen).  A flat z face's own traction in a single-resolution
  lattice is along z (mirror symmetry in x and y about the point), so only the
  x and y components of g_i are ghost force; the z component stays;
* not at all where an x-y free surface lies inside the ball (the paper's tube
  wall, thinner than the rock's horizon): there the surface's traction and the
  interface's ghost force share the same points and cannot be told apart — the
  uncorrected forces already carry the face's exact traction and centroid
  (tested); the scene can move the step away instead (``Part.band``).

At a point corrected in full the force becomes

    f_i = sum_j omega_j V_j (P_j - P_i) K_j^-1 xi_ij   (+ hourglass, contact, viscosity)

(i's own terms cancel exactly),

which is zero for uniform P and reproduces div P for a linear P.  It is not
the gradient of an energy, and it does not conserve momentum exactly: the
energy and momentum error it makes are measured in the tests and the README.

g_i is computed once from the reference configuration (it is geometric).
A point that loses a bond, or whose family holds a failed point, has a
different geometry from then on: its correction is switched off for good
(decided from bond states and the exchanged failure flags, so the same on
any number of ranks and after a restart).
"""
from __future__ import annotations

import numpy as np

from ..input.geometry import balls_inside, prisms_inside
from ..kernels import interface as kern
from ..kernels.layout import CORRESPONDENCE, KINV_FLAG, KINV_WIDTH
from ..state import AUX

#: |g_i| dx_i above this is a ghost force (round-off in a uniform lattice is ~1e-14)
G_TOL = 1e-12


def needed(scene, tl_parts) -> bool:
    """A correction exists only if the total-Lagrangian parts differ in dx, horizon
    or influence function."""
    return (scene.solver.interface_correction
            and len({(p.dx, p.horizon, p.influence) for p in tl_parts}) > 1)


class InterfaceCorrection:
    def __init__(self, points, families, halo, corr, tl, tl_parts):
        p, fam = points, families
        n = p.n_owned
        # K^-1 and a no-K flag for every local point (ghosts from their owners)
        kinv = np.zeros((p.n_local, KINV_WIDTH))
        kinv[:n, :9] = corr.Kinv.reshape(n, 9)
        kinv[:n, KINV_FLAG] = (corr.spring != CORRESPONDENCE).astype(float)
        kinv[n:, KINV_FLAG] = 1.0
        halo.exchange(kinv)
        near = self._near_interface(p, fam, halo)
        cand = np.flatnonzero(tl[:n] & (corr.spring == CORRESPONDENCE) & near).astype(np.int64)
        g = np.zeros((len(cand), 3))
        kern.interface_vectors(p.x, p.volume, p.horizon, p.influence, fam.offsets, fam.nbr,
                               fam.broken, kinv, cand, g)
        sel = np.linalg.norm(g, axis=1) * p.dx[cand] > G_TOL
        cand, g = cand[sel], g[sel]
        reach = self._reach(p.horizon, fam, cand)
        full = balls_inside(tl_parts, p.x[cand], 2.0 * reach)
        planar = ~full & prisms_inside(tl_parts, p.x[cand], 2.0 * reach)
        g[planar, 2] = 0.0                     # a z face's traction stays
        keep = (full | planar) & (np.linalg.norm(g, axis=1) * p.dx[cand] > G_TOL)
        self.idx = cand[keep]
        K = np.linalg.inv(corr.Kinv[self.idx])
        self.q = np.ascontiguousarray(np.einsum("nij,nj->ni", K, g[keep]))   # K_i g_i
        #: owned points corrected in full, in the plane only, and left with their ghost
        #: force (an interface within two reaches of an x-y free surface)
        self.counts = (int((keep & full).sum()), int((keep & planar).sum()),
                       int((~(full | planar)).sum()))
        self.active = np.ones(len(self.idx), dtype=np.uint8)
        self.families = fam
        self.fc = np.zeros((len(self.idx), 3))       # this step's correction force density

    @staticmethod
    def _near_interface(p, fam, halo) -> np.ndarray:
        """Owned points whose g_i can feel a change of dx, horizon or influence
        function: a family member of another one, or a family member that has one."""
        n = p.n_owned
        mixed = np.zeros(p.n_local, dtype=np.uint8)
        kern.mixed_families(p.dx, p.horizon, p.influence, fam.offsets, fam.nbr, n, mixed)
        halo.exchange(mixed)
        near = np.zeros(n, dtype=np.uint8)
        kern.spread(mixed, fam.offsets, fam.nbr, n, near)
        return near.astype(bool)

    @staticmethod
    def _reach(horizon, fam, idx) -> np.ndarray:
        """Farthest interaction of each point: its own horizon or a neighbour's."""
        out = np.empty(len(idx))
        kern.family_reach(horizon, fam.offsets, fam.nbr, idx, out)
        return out

    def register(self, state):
        """The corrected points and their data in the State (owner "interface")."""
        own = "interface"
        state.add("interface_idx", own, self.idx, rows=AUX)
        for name in ("q", "active", "fc"):
            state.add(f"interface_{name}", own, getattr(self, name), rows=self.idx)

    def apply(self, fd, F, f, klass, level):
        """f_i -= P_i g_i at the active corrected points whose step class acts at
        ``level`` (with its weight, kernels.classes)."""
        kern.subtract_ghost_force(fd, F, self.idx, self.q, self.active, f, self.fc, klass, level)

    def retire(self, mode) -> int:
        """Switch off the correction where bonds broke or a family member failed."""
        fam = self.families
        return kern.retire(self.idx, self.active, fam.offsets, fam.nbr, fam.broken, mode)

    @property
    def n_active(self) -> int:
        return int(np.count_nonzero(self.active))
