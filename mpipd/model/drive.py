"""Prescribed velocities on regions (``[[boundaries]] kind = "prescribed_velocity"``,
mpipd.input.loads.PrescribedVelocity): the driven points and the work they do.

A driven point is ``fixed`` for the integrator (no force accelerates it,
kernels.integrate); around each step the drive sets its motion instead::

    kick_drift          driven: v = 0, u unchanged (the fixed rule)
    drift               v = V(t + dt/2), u += dt V(t + dt/2)     (before the forces)
    forces f_{n+1}      book the work, below
    kick                driven: v = 0 (the fixed rule)
    hold                v = V(t + dt)                            (the state's v_{n+1})

Energy.  The ledger's held energy counts every point, driven ones included: the
elastic energy (the stress work of every point) changes by minus the work of the
internal forces on all points, the free points' kinetic energy + the integrator
term by plus their share (velocity Verlet's identity, kernels.energy), so what is
left is the driven points' share of the internal work and their kinetic energy::

    boundary += -dt sum_driven V_i (f_i,n + f_i,n+1)/2 . v_i,n+1/2
                + sum_driven m_i (|v_i,n+1|^2 - |v_i,n|^2) / 2

the power of the reaction force (the force the body puts on the driven points,
-V f) integrated by the trapezoid, plus what it costs to accelerate the driven
points themselves: the work the boundary puts into the body, the ledger's
``boundary`` (mpipd.model.ledger).  The driven points' integrator term is 0 (a = 0).

The arrays are per owned point; the numerics are kernels.integrate.drive and
kernels.energy.trapezoid_work.  A restart recomputes the previous forces from the
restored state (Simulation.initialize calls :meth:`start`), as the loads do.
"""
from __future__ import annotations

import numpy as np

from ..kernels import integrate
from ..kernels.energy import trapezoid_work
from ..state import AUX


class Drive:
    """The driven owned points of a scene's prescribed-velocity boundaries (the
    last such boundary that holds a point rules it)."""

    def __init__(self, conditions, x_owned: np.ndarray, rho: np.ndarray, vol: np.ndarray):
        self.conditions = list(conditions)
        which = np.full(len(x_owned), -1, dtype=np.int64)
        for k, bc in enumerate(self.conditions):
            which[bc.mask(x_owned)] = k
        self.idx = np.flatnonzero(which >= 0).astype(np.int64)
        self.which = which[self.idx]
        self.mass = rho[self.idx] * vol[self.idx]
        self.f_old = np.zeros((len(self.idx), 3))
        self.work = 0.0                         # this rank's share (J)

    def register(self, state):
        state.add("drive_idx", "drive", self.idx, rows=AUX)
        state.scalar("drive_work", "drive", lambda: self.work,
                     lambda v: setattr(self, "work", float(v)))

    def velocity(self, t: float) -> np.ndarray:
        """(driven points, 3): each one's prescribed velocity at time t."""
        table = np.array([bc.value(t) for bc in self.conditions]).reshape(-1, 3)
        return np.ascontiguousarray(table[self.which])

    def kinetic(self, t: float) -> float:
        """The driven points' kinetic energy at their prescribed velocity at time t."""
        vt = self.velocity(t)
        return 0.5 * float(np.dot(self.mass, np.einsum("ij,ij->i", vt, vt)))

    def drift(self, u, v, t: float, dt: float):
        """The driven points' half-step velocity V(t + dt/2) and their drift."""
        integrate.drive(u, v, self.idx, self.velocity(t + 0.5 * dt), dt)

    def book(self, f, v, vol, dt: float):
        """After the forces f_{n+1}, v = v_{n+1/2}: the reaction's trapezoidal work
        (its sign: the work the driven points do on the body)."""
        if len(self.idx):
            self.work -= trapezoid_work(self.f_old, np.ascontiguousarray(f[self.idx]),
                                        self.idx, v, vol, dt)

    def hold(self, u, v, t: float, dt: float):
        """The driven points' velocity at the end of the step t..t + dt and the
        change of their kinetic energy over it, which the boundary paid."""
        integrate.drive(u, v, self.idx, self.velocity(t + dt), 0.0)
        if len(self.idx):
            self.work += self.kinetic(t + dt) - self.kinetic(t)

    def start(self, f, u, v, t: float):
        """The state's own velocity V(t) and forces as the trapezoid's previous ones
        (step 0, a restart, a refresh of the forces)."""
        integrate.drive(u, v, self.idx, self.velocity(t), 0.0)
        self.f_old[...] = f[self.idx]
