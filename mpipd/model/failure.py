"""Point failure -> bond breakage, PD damage phi and the damped set (paper §2.4).

Built only when some material of the scene can fail (JH2, or a tension model).
Every step, after the materials and the tension model have marked failed
owned points in ``mode`` (1 JH2 plastic, 2 JH2 tensile, 3 tension model):

1. the halo copies ``mode`` to the ghosts (one uint8 per point);
2. points that failed since the last step — owned or ghost — are looked up in a
   cKDTree of reference positions (built once) for owned candidates within
   (largest horizon + dx_k / 2); only those candidates' bonds are tested
   (mpipd.kernels.breakage), never all bonds;
3. owned points that lost bonds get a new shape tensor (bond-spring fallback
   where too few bonds are left), with F recomputed over the new family at the
   current displacement and the volume factor that keeps J continuous
   (Correspondence.rebuild_shape), and a new damage phi (Eq. 39);  the held
   potentials (hourglass, spring, contact) of the candidates before and of the
   changed points after are booked as ``removed`` in the energy ledger;
4. owned points with phi = 1 join the damped set (Eq. 41).

Each rank breaks only its owned points' bonds, by the same rule from the same
(ghost-copied) flags, so both directions of a bond break on the same step.
"""
from __future__ import annotations

import time

import numpy as np
from scipy.spatial import cKDTree

from ..kernels.breakage import break_bonds, pairs_from_lists, pd_damage
from ..state import LOCAL


class Failure:
    def __init__(self, points, families, halo, corr, damping: float, damp, tl, mode,
                 ledger=None, damp_base=None):
        """``damp`` and ``mode`` are the State's damping coefficients and failure
        flags (mode: local points; written by the materials and the tension model,
        exchanged and acted on here); ``damp_base``: each point's damping when intact
        (absorbing layers; empty or None: 0), which a failed point's keeps if larger."""
        self.points = points
        self.families = families
        self.halo = halo
        self.corr = corr
        n, nl = points.n_owned, points.n_local
        self.mode = mode
        self.done = np.zeros(nl, dtype=np.uint8)
        self.phi = np.zeros(n)
        self.touched = np.zeros(n, dtype=np.uint8)
        self.damping = damping
        self.damp = damp                        # the simulation's damping array (or empty)
        self.damp_base = damp_base if damp_base is not None else np.zeros(0)
        self.tl = tl[:n]                        # only total-Lagrangian points have damage
        self.tree = cKDTree(points.x)
        self.reach = float(points.horizon.max()) if nl else 0.0
        self.ledger = ledger
        self.bonds_broken = 0
        # wall time of update(): the bookkeeping (search, breakage, rebuild, damage),
        # and the flag exchange apart, since on several ranks the exchange is the
        # first wait after the step's work and absorbs the ranks' imbalance
        self.seconds = 0.0
        self.exchange_seconds = 0.0
        #: called with the owned points whose family changed (multi-rate's clock)
        self.on_rebuild = None
        self.refresh_damage()

    def register(self, state):
        """This model's arrays in the State (owner "failure"); the output fields
        ``damage`` (phi) and ``failure_mode``."""
        state.add("done", "failure", self.done, rows=LOCAL)
        state.add("phi", "failure", self.phi, output="damage")
        state.add("touched", "failure", self.touched)
        state.offer("failure_mode", "failure",
                    lambda: self.mode[: self.points.n_owned].astype(np.float64))

    def after_restore(self):
        """Ghost flags, the failed set, damage and the damped set from the restored
        mode and bonds (restart step 2); ``bonds_broken`` is a restored scalar."""
        self.halo.exchange(self.mode)
        self.done[:] = self.mode != 0
        self.refresh_damage()

    def update(self, u) -> int:
        """Exchange failure flags and break bonds (u: the current displacement).
        Returns the newly failed local points."""
        t0 = time.perf_counter()
        self.halo.exchange(self.mode)
        t1 = time.perf_counter()
        self.exchange_seconds += t1 - t0
        new = np.flatnonzero((self.mode != 0) & (self.done == 0))
        if len(new):
            self.done[new] = 1
            p, fam = self.points, self.families
            lists = self.tree.query_ball_point(p.x[new], self.reach + 0.5 * p.dx[new])
            rows, items = pairs_from_lists(lists)
            own = items < p.n_owned
            cand = np.unique(items[own])
            before = self.corr.potentials(cand, u) if self.ledger is not None else None
            self.bonds_broken += break_bonds(new[rows[own]], items[own], p.x, p.gid, p.dx, p.material,
                                             fam.offsets, fam.nbr, fam.broken, self.touched)
            changed = np.flatnonzero(self.touched)
            if self.on_rebuild is not None:
                self.on_rebuild(changed)
            if len(changed):
                self.touched[changed] = 0
                self.corr.rebuild_shape(changed, u)
                if self.ledger is not None:
                    self.ledger.book_jump(before[np.searchsorted(cand, changed)],
                                          self.corr.potentials(changed, u))
                pd_damage(changed, fam.offsets, fam.nbr, fam.broken, p.volume, self.phi)
                if self.damping > 0:
                    self._set_damping(changed)
        self.seconds += time.perf_counter() - t1
        return len(new)

    def refresh_damage(self):
        """phi and the damped set of every owned TL point from the bond states."""
        p, fam = self.points, self.families
        rows = np.flatnonzero(self.tl).astype(np.int64)
        pd_damage(rows, fam.offsets, fam.nbr, fam.broken, p.volume, self.phi)
        if self.damping > 0:
            self._set_damping(rows)

    def _set_damping(self, rows):
        """Eq. 41's damping on the rows with phi = 1, over their intact value."""
        failed = np.where(self.phi[rows] >= 1.0, self.damping, 0.0)
        self.damp[rows] = (np.maximum(self.damp_base[rows], failed) if len(self.damp_base)
                           else failed)

    def counts(self) -> np.ndarray:
        """Owned failed points per mode (index = mode)."""
        return np.bincount(self.mode[: self.points.n_owned], minlength=4)
