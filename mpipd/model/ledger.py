"""The energy ledger: every energy a run moves, booked per frame (DESIGN §8b).

Terms (J, global sums over the owned points of every rank)::

    held        kinetic      sum m |v|^2 / 2
                integrator   -(dt^2 / 8) sum m |a|^2: velocity Verlet's shadow term —
                             kinetic + integrator changes by exactly the trapezoidal
                             work of all forces (kernels.energy)
                elastic      sum V e_el over intact points: recoverable, each material
                             from its own state (JH2: J S:S/4G + the EOS potential; J2:
                             J (p^2/2K + S:S/4G)); a hypoelastic solid, which has no
                             potential and no dissipation, holds its stress work W
                hourglass    Eq. 15's energy (kernels.energy; a state function)
                spring       the bond-spring fallback's bonds
                contact      the contact penalty of broken bonds in compression (Eq. 40)
                gas          sum V0 e: the explosive's internal energy (unreacted included)
                gas_contact  the gas-solid contact's potential (mpipd.materials.jwl.GasContact;
                             0 without one)
                gas_wall     the work done against the gas wall (mpipd.materials.jwl.GasWall:
                             minus the trapezoidal work of its forces); its stored
                             energy, of either sign as its force is not a potential
                             one; 0 without one
    dissipated  plastic      sum over intact points V (W - e_el): plastic flow, damage
                             and the bulking pressure's work (W = the stress work)
                removed      sum over failed or detached (K singular) points V W, plus
                             the hourglass and spring energy lost or gained
                             discontinuously when bonds broke or a point switched
                             to/from the fallback (booked before/after the change)
                contact_onset  minus the contact penalty that bonds breaking while
                             compressed put in at once (<= 0: energy the contact model
                             adds; booked before/after, like ``removed``)
                viscous      minus the work of the artificial viscosity (trapezoid)
                damping      removed by the damping of phi = 1 points (Eq. 41)
                gas_damping  removed by the gas damping (§2.6)
                gas_viscous  taken out by the gas's bulk viscosity q (mpipd.kernels.ul:
                             the trapezoidal work of its part of the gas force)
                absorbed     taken out by absorbing layers (mpipd.input.loads.Absorbing):
                             the damping work of the points in a layer (a layer point
                             that fails books its Eq. 41 damping here too)
                interface    minus the work of the ghost-force correction (trapezoid;
                             not a potential force, so of either sign)
                multirate    the jump of the integrator term where the step classes
                             changed at a coarse boundary (mpipd.model.multirate): the
                             forces are gathered again with the new weights, and
                             velocity Verlet with a changed step is not
                             energy-conserving across the change; of either sign
                             (it includes, on such a boundary, the jump of the
                             refresh after breakage, which is booked in
                             ``removed`` elsewhere); 0 in a single-rate run
    in          initial      held at step 0
                external     work of the loads (trapezoid)
                boundary     work of the prescribed-velocity boundaries
                             (mpipd.model.drive: the power of the reaction force
                             on the driven points by the trapezoid, plus their
                             kinetic energy's change)
    balance     (initial + external + boundary - held - dissipated) / scale,
                scale = max(|initial|, |external|, |boundary|, |held|, |dissipated|)

Every force the step applies is in exactly one of these: the correspondence
force (its work is the stress work W, to O(dt^2)), hourglass, spring,
contact and gas contact (potentials), gas (its work leaves e by the trapezoidal energy
equation), viscosity, gas viscosity, damping, interface (their work), loads
(external); the driven points' share of them is the boundary's (boundary).
So |balance| is the time-discretisation error, of order (omega dt)^2, plus
one-step errors where forces switch (a failure, a break): a term left out
shows as a balance of its own size.

Impossible values are errors: a held term that must be >= 0 below -tol
(kinetic, elastic, hourglass, spring, contact, gas, gas_contact) or a dissipation below
-tol (plastic, removed, viscous, damping, gas_damping, gas_viscous, absorbed), tol = BALANCE_TOL x
scale, are listed by :func:`impossible`.
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..kernels import energy as kern
from ..kernels.layout import INTACT, SPRING_K
from ..state import AUX, LAST

HELD = ("kinetic", "integrator", "elastic", "hourglass", "spring", "contact", "gas",
        "gas_contact", "gas_wall")
DISSIPATED = ("plastic", "removed", "contact_onset", "viscous", "damping", "gas_damping",
              "gas_viscous", "absorbed", "interface", "multirate")
#: the datasets of /energy in a run file, in this order
TERMS = ("t",) + HELD + DISSIPATED + ("external", "boundary", "initial", "balance")
#: terms that cannot be negative (beyond round-off and O(dt^2) noise)
NON_NEGATIVE = ("kinetic", "elastic", "hourglass", "spring", "contact", "gas", "gas_contact",
                "plastic",
                "removed", "viscous", "damping", "gas_damping", "gas_viscous", "absorbed")
#: |balance| and the negative excursions that :func:`impossible` tolerates
BALANCE_TOL = 1e-3


@dataclass
class Energies:
    """One ledger reading (J); see the module docstring for the terms."""
    kinetic: float = 0.0
    integrator: float = 0.0
    elastic: float = 0.0
    hourglass: float = 0.0
    spring: float = 0.0
    contact: float = 0.0
    gas: float = 0.0
    gas_contact: float = 0.0
    gas_wall: float = 0.0
    plastic: float = 0.0
    removed: float = 0.0
    contact_onset: float = 0.0
    viscous: float = 0.0
    damping: float = 0.0
    gas_damping: float = 0.0
    gas_viscous: float = 0.0
    absorbed: float = 0.0
    interface: float = 0.0
    multirate: float = 0.0
    external: float = 0.0
    boundary: float = 0.0
    initial: float = 0.0

    @property
    def held(self) -> float:
        return sum(getattr(self, k) for k in HELD)

    @property
    def dissipated(self) -> float:
        return sum(getattr(self, k) for k in DISSIPATED)

    @property
    def total(self) -> float:
        """The energy held (mechanical + gas); it changes only by external work and
        dissipation."""
        return self.held

    @property
    def scale(self) -> float:
        return max(abs(self.initial), abs(self.external), abs(self.boundary),
                   abs(self.held), abs(self.dissipated), 1e-300)

    @property
    def balance(self) -> float:
        """Relative closure error (initial + external + boundary - held - dissipated)
        / scale."""
        return (self.initial + self.external + self.boundary - self.held
                - self.dissipated) / self.scale

    @classmethod
    def from_record(cls, group, frame: int = -1) -> "Energies":
        """The reading of one frame of a run file's ``/energy`` group (h5py); a term
        the file predates (``multirate``, ``absorbed``, ``gas_viscous``, ``gas_contact``, ``boundary``)
        reads 0."""
        return cls(**{f.name: float(group[f.name][frame]) if f.name in group else 0.0
                      for f in fields(cls)})

    def as_dict(self) -> dict:
        d = {f.name: getattr(self, f.name) for f in fields(self)}
        d["balance"] = self.balance
        return d


def impossible(e: Energies, tol: float = BALANCE_TOL) -> list[str]:
    """Terms that are negative beyond tol x scale (each one a line)."""
    lim = -tol * e.scale
    return [f"{k} = {getattr(e, k):.6g} J < 0" for k in NON_NEGATIVE if getattr(e, k) < lim]


class Ledger:
    """The accumulated terms of one rank (the held terms are read from the state).

    ``edamp`` (per unit mass, owned points) is filled by kernels.integrate.kick_drift;
    ``fv`` (the viscous force density of this step) by the force gather; the
    previous step's viscous and interface forces are kept for the trapezoid.
    """

    def __init__(self, n_owned: int, damped: bool, viscous: bool, n_interface: int,
                 layer=None):
        self.edamp = np.zeros(n_owned if damped else 0)
        #: owned points in an absorbing layer (their damping work is ``absorbed``)
        self.layer = np.zeros(0, np.int64) if layer is None else np.asarray(layer, np.int64)
        self.fv = np.zeros((n_owned if viscous else 0, 3))
        self.fv_old = np.zeros_like(self.fv)
        self.fc_old = np.zeros((n_interface, 3))
        self.rows = np.arange(n_owned, dtype=np.int64)
        self.viscous_work = 0.0          # this rank's share (J)
        self.interface_work = 0.0
        self.jumps = 0.0                 # hourglass + spring energy removed by discontinuities
        self.contact_jumps = 0.0         # contact energy removed (< 0: added) by them
        self.reclass = 0.0               # integrator jumps where the step classes changed
        self.initial = None              # global, set once at step 0

    def register(self, state, interface):
        """The ledger's per-point memory (owner "ledger") and its accumulated sums
        (global scalars) in the State, under the checkpoint names of before."""
        own = "ledger"
        state.add("ledger_edamp", own, self.edamp, checkpoint=len(self.edamp) > 0)
        state.add("ledger_fv", own, self.fv)
        state.add("ledger_fv_old", own, self.fv_old, checkpoint=len(self.fv_old) > 0,
                  restore=LAST)
        state.add("ledger_rows", own, self.rows, rows=AUX)
        state.add("ledger_layer", own, self.layer, rows=AUX)
        if interface is not None:
            state.add("ledger_fc_old", own, self.fc_old, rows=interface.idx, checkpoint=True,
                      restore=LAST)
        else:
            state.add("ledger_fc_old", own, self.fc_old, rows=AUX)     # empty
        for name in ("viscous_work", "interface_work", "jumps", "contact_jumps", "reclass"):
            state.scalar(f"ledger_{name}", own, (lambda k=name: getattr(self, k)),
                         (lambda v, k=name: setattr(self, k, float(v))))
        state.scalar("ledger_initial", own, lambda: self.initial,
                     lambda v: setattr(self, "initial", float(v)), reduce="same")

    def start(self, interface):
        """The forces of the initial state become the 'previous' forces."""
        self.fv_old[...] = self.fv
        if interface is not None:
            self.fc_old[...] = interface.fc

    def book_work(self, v, vol, dt, interface):
        """After the forces of step n+1, before the second half kick (v = v_{n+1/2})."""
        if len(self.fv):
            self.viscous_work += kern.trapezoid_work(self.fv_old, self.fv, self.rows, v, vol, dt)
        if interface is not None and len(interface.idx):
            self.interface_work += kern.trapezoid_work(self.fc_old, interface.fc,
                                                       interface.idx, v, vol, dt)

    def book_jump(self, before: np.ndarray, after: np.ndarray):
        """Held potentials (rows: points; columns: hourglass, spring, contact) just
        before and after a discontinuous change: the difference is removed."""
        d = before.sum(axis=0) - after.sum(axis=0)
        self.jumps += float(d[0] + d[1])
        self.contact_jumps += float(d[2])

    @staticmethod
    def integrator(sim) -> float:
        """This rank's integrator term -(dt^2/8) sum m |a|^2."""
        n = sim.points.n_owned
        return kern.integrator_term(sim.a, sim.rho, sim.points.volume[:n], sim.dt)

    def local(self, sim) -> np.ndarray:
        """This rank's terms, in the order of :class:`Energies`' fields."""
        p, c = sim.points, sim.corr
        n = p.n_owned
        vol = p.volume[:n]
        m = sim.rho * vol
        mode = sim.mode
        ke = 0.5 * float(np.dot(m, np.einsum("ij,ij->i", sim.v[:n], sim.v[:n])))
        integ = self.integrator(sim)
        eel = c.elastic_energy(mode)
        gone = (mode[:n] != INTACT) | (c.spring == SPRING_K)
        keep = ~gone
        elastic = float(np.dot(vol[keep], eel[keep]))
        plastic = float(np.dot(vol[keep], c.W[keep] - eel[keep]))
        removed = float(np.dot(vol[gone], c.W[gone])) + self.jumps
        pot = c.potentials(self.rows, sim.u).sum(axis=0)
        gas = sim.gas.energy() if sim.gas is not None else 0.0
        gas_viscous = sim.gas.viscous_work if sim.gas is not None else 0.0
        gas_contact = sim.gas.contact_energy() if sim.gas is not None else 0.0
        gas_wall = sim.gas.wall_energy() if sim.gas is not None else 0.0
        damping = gas_damping = absorbed = 0.0
        if len(self.edamp):
            ed = m * self.edamp
            if sim.gas is not None:
                gas_damping = float(ed[sim.gas.gas_idx].sum())
            absorbed = float(ed[self.layer].sum())
            damping = float(ed.sum()) - gas_damping - absorbed
        return np.array([ke, integ, elastic, pot[0], pot[1], pot[2], gas, gas_contact,
                         gas_wall, plastic, removed,
                         self.contact_jumps, -self.viscous_work, damping, gas_damping,
                         gas_viscous, absorbed,
                         -self.interface_work, self.reclass, sim.external_work,
                         sim.drive.work if getattr(sim, "drive", None) is not None else 0.0])

    def read(self, sim) -> Energies:
        tot = sim.team.sum(self.local(sim))
        e = Energies(*map(float, tot))
        if self.initial is None:
            self.initial = e.held
        e.initial = self.initial
        return e
