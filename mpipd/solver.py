"""Assemble the step pipeline a scene needs and run the time loop.

:class:`Simulation` is built on every rank from the same validated scene and
the run's :class:`mpipd.parallel.team.Team`:

1. layer table -> slab decomposition -> this rank's owned + ghost points only
   (the explosive gas: all of it, as ghosts; the solids it reaches beyond the
   halo come as remote rows, mpipd.parallel.near);
2. halo plan, families (CSR, gid-sorted), material groups, correspondence state;
3. initial and boundary conditions, initial forces.

One step (velocity Verlet, DESIGN §4), over the scene's models
(:class:`mpipd.model.base.Model`: the correspondence solids, then each further
model family the scene's materials name, :data:`FAMILY_MODELS`)::

    kick_drift                      v += dt/2 a; u += dt v   (owned)
    drive.drift                     driven points: v, u from the prescribed velocity
    halo: u, v                      owned -> ghosts
    model.update                    F, Fdot, R, V, d, sigma; the gas's pressure (owned)
    model.force_data                B, h; the gas's A, V, p (owned)
    halo: every model's force data  owned -> ghosts (one call)
    model.gather                    f_i from own + ghost data (owned)
    kick                            a = f / rho; v += dt/2 a
    drive.hold                      driven points: v = the prescribed velocity

No MPI call appears here except through the halo and the team.
"""
from __future__ import annotations

import time as _time

import numpy as np

from .input.geometry import LayerTable
from .input.joints import cut_joints
from .input.loads import PrescribedVelocity, refuse_empty, regions
from .input.probes import place
from .kernels import integrate, runaway
from .kernels.layout import N_MODES, SPRING_K
from .model.base import Model
from .model.correspondence import Correspondence
from .model.drive import Drive
from .model.failure import Failure
from .model.families import build_families
from .model.gas import Gas
from .model.interface import InterfaceCorrection
from .model.interface import needed as interface_needed
from .model.ledger import Energies, Ledger, impossible
from .model.multirate import StepClasses
from .model.stability import part_critical_dt
from .output.peaks import Peaks
from .output.probes import Probes
from .parallel.decomp import decompose, halo_width, local_points, replicated_parts
from .parallel.halo import Halo
from .state import AUX, LAST, LOCAL, State

#: model family (``Material.family``) -> the model its points are, beyond the
#: correspondence solids ("tl", always built: it holds every point's kinematics);
#: built as ``cls(scene, points, team, slabs)`` when some part is of such a material
FAMILY_MODELS: dict[str, type[Model]] = {"ul": Gas}


class Unstable(RuntimeError):
    """Non-finite values appeared; the message names the step, field, gid and position."""


class Simulation:
    def __init__(self, scene, team):
        self.scene = scene
        self.team = team
        self.dt = scene.time.dt
        self.dt_stable = float(part_critical_dt(scene).min())    # stability.critical_dt
        table = LayerTable.from_parts(scene.parts, scene.material_ids)
        gas_parts = scene.gas_parts
        # the gas is held whole on every rank (the solids it acts on: mpipd.parallel.near)
        self.slabs = decompose(table, team.size, halo_width(scene), replicated_parts(scene))
        self.n_global = table.n_points
        self.gid_range = self.slabs.gid_range(team.rank)
        p = self.points = local_points(scene, self.slabs, team.rank)
        recv, send = self.slabs.plan(team.rank)
        self.halo = Halo(team.comm, recv, send, p.n_owned, p.n_local)
        self.tl = ~np.isin(p.part, gas_parts)           # total-Lagrangian points (not gas)
        self.families = build_families(p.x, p.gid, p.horizon, p.n_owned,
                                       tl=self.tl if gas_parts else None)
        self.n_bonds_global = team.sum(self.families.n_bonds)
        # pre-existing joints: their crossing bonds start broken (before K is built)
        self.joint_bonds = team.sum(cut_joints(scene.joints, scene.parts, p, self.families,
                                               self.tl)) if scene.joints else 0

        n = p.n_owned
        names = list(scene.materials)
        st = self.state = State(n, p.n_local)
        p.register(st)
        st.add("tl", "solver", self.tl, rows=LOCAL)
        self.families.register(st)
        self.rho = st.add("rho", "solver", np.array([scene.materials[m].density
                                                     for m in names])[p.material[:n]])
        self.u = st.add("u", "solver", np.zeros((p.n_local, 3)), rows=LOCAL, exchanged=True,
                        checkpoint=True, output="u")
        self.v = st.add("v", "solver", np.zeros((p.n_local, 3)), rows=LOCAL, exchanged=True,
                        checkpoint=True, output="v")
        self.a = st.add("a", "solver", np.zeros((n, 3)), checkpoint=True, restore=LAST)
        self.f = st.add("f", "solver", np.zeros((n, 3)))
        self.fixed = st.add("fixed", "solver", np.zeros(n, dtype=np.uint8))
        # failure flags (0 intact, layout.MODE_*): set by the materials and the tension
        # model, exchanged and acted on by Failure, read by the interface correction
        self.mode = st.add("mode", "solver", np.zeros(p.n_local, np.uint8), rows=LOCAL,
                           exchanged=scene.can_fail, checkpoint=True)
        # a region (initial or boundary) with no point of the body is bad input
        refuse_empty(scene, [team.sum(int(np.count_nonzero(c.selects(p.x[:n]))))
                             for _, c in regions(scene)])
        for bc in scene.boundaries:
            self.fixed |= bc.mask(p.x[:n]).astype(np.uint8)
        for ic in scene.initial:
            ic.apply(p.x[:n], self.v[:n])
        self.v[:n][self.fixed.astype(bool)] = 0.0
        # prescribed velocities (fixed for the integrator; the drive moves them)
        driven = [bc for bc in scene.boundaries if isinstance(bc, PrescribedVelocity)]
        self.drive = Drive(driven, p.x[:n], self.rho, p.volume[:n]) if driven else None
        if self.drive is not None:
            self.drive.register(st)

        sv = scene.solver
        # step classes (multi-rate; all 0 in a single-rate scene)
        self.classes = StepClasses(scene, p, self.families, team)
        self.classes.register(st)
        dt_ratio = scene.time.dt / part_critical_dt(scene)[p.part[:n]]
        self.corr = Correspondence(p, self.families, scene.materials, names, sv.hourglass,
                                   self.mode, self.classes, dt_ratio, contact=sv.contact,
                                   viscosity=sv.viscosity, tl=self.tl)
        self.corr.register(st)
        self.corr.rebuild_shape()
        self.corr.floor_switches = 0            # the start's fallback points are no switches
        # the ghost-force correction exists only where dx or the horizon changes
        tl_parts = [q for k, q in enumerate(scene.parts) if k not in gas_parts]
        self.interface = (InterfaceCorrection(p, self.families, self.halo, self.corr, self.tl,
                                              tl_parts)
                          if interface_needed(scene, tl_parts) else None)
        if self.interface is not None:
            self.interface.register(st)
            self.corr.attach_interface(self.interface)      # a post-gather step of corr
        # damping (Eq. 41 for phi = 1, the gas's own, absorbing layers), only if some
        # is asked for; ``damp_base``: the absorbing layers' (solids only)
        layers = [bc for _, bc in scene.absorbing_layers]
        needs_damp = (sv.damping > 0 and scene.can_fail) or bool(gas_parts) or bool(layers)
        self.damp = st.add("damp", "solver", np.zeros(n if needs_damp else 0))
        self.damp_base = st.add("damp_base", "solver", np.zeros(n if layers else 0))
        if layers:
            c_p = np.array([scene.materials[m].p_wave_speed for m in names])[p.material[:n]]
            for bc in layers:
                np.maximum(self.damp_base, bc.damping(p.x[:n], c_p), out=self.damp_base)
            self.damp_base[~self.tl[:n]] = 0.0
            self.damp[:] = self.damp_base
        # failure and bond breakage exist only if some material can fail
        self.ledger = Ledger(n, damped=len(self.damp) > 0, viscous=sv.viscosity is not None,
                             n_interface=len(self.interface.idx) if self.interface else 0,
                             layer=np.flatnonzero(self.damp_base > 0))
        self.ledger.register(st, self.interface)
        self.failure = (Failure(p, self.families, self.halo, self.corr, sv.damping, self.damp,
                                self.tl, self.mode, self.ledger, self.damp_base)
                        if scene.can_fail else None)
        if self.failure is not None:
            self.failure.register(st)
            if self.classes.enabled:            # multi-rate's breakage clock
                self.failure.on_rebuild = self.classes.touch
        # the models of the further families the scene's parts use (the explosive gas)
        self.models: list[Model] = [self.corr]
        used = {scene.materials[q.material].family for q in scene.parts}
        for family, cls in FAMILY_MODELS.items():
            if family in used:
                model = cls(scene, p, team, self.slabs)
                model.register(st)
                self.models.append(model)
        self.gas = next((m for m in self.models if isinstance(m, Gas)), None)
        if self.gas is not None:                # the gas's own damping (paper §2.6)
            self.damp[self.gas.gas_idx] = self.gas.mat.damping
        # time-dependent body forces (none: no arrays, no calls)
        self.loads = [ld.prepare(scene.parts, p) for ld in scene.loads]
        self._b_prev = [np.zeros_like(pl.g) for pl in self.loads]
        for k, pl in enumerate(self.loads):
            st.add(f"load{k}_idx", "loads", pl.idx, rows=AUX)
            st.add(f"load{k}_g", "loads", pl.g, rows=pl.idx)
            st.add(f"load{k}_b", "loads", get=lambda k=k: self._b_prev[k], rows=pl.idx)
        self.external_work = 0.0
        st.scalar("external_work", "loads", lambda: self.external_work, self._set_work)
        st.scalar("bonds_broken", "failure", self.bonds_broken_here, self._set_broken)
        self.step_count = 0
        self.t = 0.0
        self.peaks = Peaks(self, scene.output)
        self.peaks.register(st)
        self.classify()                         # the reference state's classes
        self.initialize()
        self.probes = (Probes(scene.probes, place(scene.probes, scene, p, team), self.dt, p,
                              team, self.corr, self.v, self.mode, self.classes.klass,
                              gas=self.gas) if scene.probes else None)
        self.energies()                         # the ledger's initial energy (step 0)

    def initialize(self):
        """F from the current (initial) displacement and the forces it gives.

        At step 0 the state's stored energy becomes its stress work: a material
        whose pressure is a function of the volume (JH2's EOS) holds the energy
        of an initial displacement from the start (W_0 = e_el(J_0)), so the
        ledger's initial energy includes it."""
        if getattr(self, "gas", None) is not None:
            self.gas.y = None                   # positions come from u, not a past update
        self.classes.level = self.classes.top   # a coarse boundary: every state is current
        self.halo.exchange(self.u, self.v)
        if self.classes.enabled:
            self.classes.snapshot(self.u)
        self.corr.deform(self.u, self.v)
        if self.step_count == 0:
            self.corr.initial_volume()
            self.corr.W[:] = 0.0
            self.corr.W[:] = self.corr.elastic_energy(self.mode)
        for m in self.models:
            m.commit()
        self.compute_forces()
        self.apply_loads(self.t, 0.0)
        integrate.kick(self.v, self.f, self.rho, 0.0, self.fixed, self.a)
        if self.drive is not None:
            self.drive.start(self.f, self.u, self.v, self.t)
        self.ledger.start(self.interface)
        self.peaks.sample(self)

    # ------------------------------------------------------------------ pipeline
    def compute_forces(self):
        """Every model's force data of owned points -> one halo call -> each model's
        internal force density gathered into f, in the models' order."""
        moved = []
        for m in self.models:
            moved.extend(m.force_data(self.u, self.ledger))
        self.halo.exchange(*moved)
        for m in self.models:
            m.gather(self.u, self.v, self.f, self.ledger.fv)

    def _refresh_forces(self, dt: float, reclassified: bool = False):
        """Forces of the state after this step's breakage (Solver.refresh_after_break)
        or with the step classes' new weights, for the next half kick.  The
        integrator term -(dt^2/8) sum m |a|^2 jumps with a; the ledger books the
        jump like any other discontinuity: in ``multirate`` when the classes
        changed at this boundary, else in ``removed``."""
        before = self.ledger.integrator(self)
        # the owned v are now v_{n+1}: the ghosts must hold the same (the viscosity
        # reads v_j - v_i), or the forces would depend on the decomposition
        self.halo.exchange(self.v)
        self.compute_forces()
        if self.loads:
            self.apply_loads(self.t + dt, 0.0)
        integrate.kick(self.v, self.f, self.rho, 0.0, self.fixed, self.a)
        if self.drive is not None:
            self.drive.start(self.f, self.u, self.v, self.t + dt)
        self.ledger.start(self.interface)
        jump = before - self.ledger.integrator(self)
        if reclassified:
            self.ledger.reclass += jump
        else:
            self.ledger.jumps += jump

    def hold_classes(self, kbase):
        """Hold the owned points' step classes at ``kbase`` (StepClasses.hold) and
        recompute the forces with them (at step 0: a verification device)."""
        self.classes.hold(kbase, self.halo)
        self.corr.regroup()
        self.initialize()

    def _reweight(self):
        """The next half kick's forces with the step classes that just changed: the
        correspondence forces are gathered again (old and new weights) only where a
        family holds a changed class, and a follows there.  The jump of the
        integrator term is the ledger's ``multirate`` entry."""
        before = self.ledger.integrator(self)
        self.halo.exchange(self.v)              # v_{n+1} on the ghosts too (as _refresh_forces)
        rows = self.classes.reweighted_rows()
        self.corr.reweight(rows, self.u, self.v, self.f, self.ledger.fv, self.classes.previous)
        integrate.accelerations(self.f, self.rho, self.fixed, rows, self.a)
        if self.drive is not None:
            self.drive.start(self.f, self.u, self.v, self.t + self.dt)
        self.ledger.start(self.interface)
        self.ledger.reclass += before - self.ledger.integrator(self)

    def classify(self) -> bool:
        """New step classes from the current state (a coarse boundary; multi-rate
        only); True, on every rank, if any point's class changed."""
        if not self.classes.enabled:
            return False
        changed = bool(self.team.max(int(self.classes.classify(self.corr, self.halo,
                                                                self.step_count + 1))))
        if changed:
            self.corr.regroup()
            self.classes.changes += 1
        return changed

    def apply_loads(self, t: float, dt: float):
        """Add the loads' body forces at time t to f; accumulate their work over the
        step just taken, dt * V * (b_old + b_new)/2 . v_{n+1/2} (trapezoidal)."""
        V = self.points.volume
        for k, pl in enumerate(self.loads):
            b = pl.load.value(t) * pl.g
            self.f[pl.idx] += b
            if dt:
                vh = self.v[pl.idx]
                self.external_work += dt * float(
                    np.sum(V[pl.idx] * np.einsum("ij,ij->i", 0.5 * (self._b_prev[k] + b), vh)))
            self._b_prev[k] = b

    def update(self, dt: float):
        """Everything between the two half kicks: kinematics, stress, forces."""
        self.halo.exchange(self.u, self.v)
        if self.classes.enabled:
            self.classes.snapshot(self.u)
        for m in self.models:                       # stress; the gas: Eqs. 45–48, detonation
            m.update(self.u, self.v, dt, self.t + dt)
        self.compute_forces()
        if self.loads:
            self.apply_loads(self.t + dt, dt)
        for m in self.models:
            m.commit()

    def step(self):
        """One fine step.  With step classes (mpipd.model.multirate) only the states
        whose class acts at this step's level are updated and gathered; failure
        and breakage act every step (a coarse point's tension check sees its last
        state again, which it passed then), new classes at coarse boundaries."""
        dt = self.dt
        cl = self.classes
        cl.set_level(self.step_count + 1)
        integrate.kick_drift(self.u, self.v, self.a, dt, self.fixed, self.damp,
                             self.ledger.edamp)
        if self.drive is not None:
            self.drive.drift(self.u, self.v, self.t, dt)
        self.update(dt)
        self.ledger.book_work(self.v, self.points.volume, dt, self.interface)
        if self.drive is not None:
            self.drive.book(self.f, self.v, self.points.volume, dt)
        integrate.kick(self.v, self.f, self.rho, dt, self.fixed, self.a)
        if self.drive is not None:
            self.drive.hold(self.u, self.v, self.t, dt)
        self.peaks.sample(self)
        refresh = False
        if self.failure is not None:                # paper §2.7 steps 11–12, every step
            self.corr.check_tension(self.mode)
            new = self.failure.update(self.u)
            if new and self.interface is not None:
                self.interface.retire(self.mode)
            refresh = bool(self.scene.solver.refresh_after_break and self.team.max(int(new > 0)))
        changed = cl.boundary(self.step_count + 1) and self.classify()
        if refresh:
            self._refresh_forces(dt, reclassified=changed)
        elif changed:
            self._reweight()
        cl.previous = cl.klass                  # the old classes are no longer needed
        self.step_count += 1
        self.t = self.step_count * dt

    @property
    def at_boundary(self) -> bool:
        """Is the current step a coarse-step boundary (every state current)?"""
        return self.classes.boundary(self.step_count)

    # ------------------------------------------------------------------ diagnostics
    def energies(self) -> Energies:
        """The energy ledger now (global; mpipd.model.ledger)."""
        e = self.ledger.read(self)
        if not np.isfinite(e.held + e.dissipated):
            self.check_finite()
            raise Unstable(f"non-finite energy at step {self.step_count} (t = {self.t:.4e} s): "
                           "the run went unstable; compare dt with `mpipd check`")
        return e

    def check_finite(self):
        """Raise :class:`Unstable` on every rank if any owned u, v or stress is NaN/Inf,
        or a family pair moves apart or together by more than its reference
        distance in one step (|v_j - v_i| dt > |xi|, kernels.runaway: an
        instability that the failure models keep finite by zeroing stresses;
        Galilean-invariant, so a body in rigid motion at any speed passes), naming the first bad point (lowest
        gid) over all ranks.  The ghosts' v are refreshed first, so the test sees
        the same velocities on any number of ranks."""
        n = self.points.n_owned
        bad = None
        self.halo.exchange(self.v)
        fam = self.families
        g = runaway.first_runaway(fam.offsets, fam.nbr, self.points.x, self.v,
                                  self.points.gid, self.dt)
        fast = np.flatnonzero(self.points.gid[:n] == g) if g >= 0 else np.empty(0, np.int64)
        for name, rows in (
                ("u", np.flatnonzero(~np.all(np.isfinite(self.u[:n]), axis=1))),
                ("v", np.flatnonzero(~np.all(np.isfinite(self.v[:n]), axis=1))),
                ("stress", np.flatnonzero(~np.all(np.isfinite(self.corr.sigma), axis=1))),
                ("relative speed |v_j - v_i| dt > |xi|", fast)):
            if len(rows):
                i = rows[0]
                cand = (int(self.points.gid[i]), name, tuple(self.points.x[i]))
                bad = cand if bad is None or cand[0] < bad[0] else bad
        found = [b for b in self.team.gather(bad) if b is not None]
        if found:
            gid, name, x = min(found)
            what = f"non-finite {name}" if name in ("u", "v", "stress") else name
            raise Unstable(f"{what} at step {self.step_count} (t = {self.t:.4e} s), "
                           f"first at gid {gid}, x = ({x[0]:.4g}, {x[1]:.4g}, {x[2]:.4g}) m; "
                           "compare dt with `mpipd check`")
        self.check_soft()

    def soft_points(self) -> tuple[int, int]:
        """(intact solid points on the bond springs by the stable-step test alone,
        intact solid points), over all ranks: an intact point (failure mode 0, not
        gas) whose shape tensor is invertible but whose lambda_min(K) fell below its
        floor (mpipd.model.correspondence.stable_floor, ``count_floor``)."""
        n = self.points.n_owned
        intact = (self.mode[:n] == 0) & self.tl[:n]
        soft = intact & (self.corr.spring == SPRING_K) & (self.corr.lam > 0.0)
        return (self.team.sum(int(np.count_nonzero(soft))),
                self.team.sum(int(np.count_nonzero(intact))))

    def check_soft(self):
        """Raise :class:`Unstable` on every rank if more than :data:`MAX_SOFT_SHARE` of
        the intact solid points have left the correspondence force for the bond
        springs by the stable-step test (:meth:`soft_points`).

        At a stable dt the floor is (dt / dt_c)^2 lambda_min(K^0), which an intact
        point reaches only after its family lost most of its stiffness, next to a
        crack; beyond the stable estimate (``--force``) the floor is lambda_min(K^0)
        and the point falls back at its first broken bond.  A run in which this
        spreads through the body is no longer the correspondence model: its
        points carry the springs' force and no material stress (the failure
        models and this fallback keep the run finite, so the NaN and runaway
        tests do not fire, and it would end as "fracture").  Only beyond the stable
        estimate (``--force``): below it a fracturing body may leave few intact points,
        all of them beside cracks (a JH2 block released from compression: 56 of its 56
        remaining intact points), which is the fallback doing its work.  Measured
        (granite_ring, 1 rank): at its own dt no intact point ever falls back; at
        1.1, 1.5 and 2 x the stable estimate 11-12 % of the intact points have at
        step 1, and 80-96 % by t = 15 us."""
        if self.failure is None:            # nothing breaks: no family loses stiffness
            return
        if self.dt <= self.dt_stable:       # the floor is (dt / dt_c)^2 lambda_min(K^0):
            return                          # a point falls back only next to a crack
        soft, intact = self.soft_points()
        if soft > MAX_SOFT_SHARE * max(intact, 1):
            over = self.dt / self.dt_stable
            raise Unstable(
                f"{soft} of the {intact} intact solid points ({soft / intact:.0%}) left "
                f"the correspondence force for the bond springs at step {self.step_count} "
                f"(t = {self.t:.4e} s), their families too soft for dt (the stable-step "
                "test, mpipd.model.correspondence.stable_floor; more than "
                f"{MAX_SOFT_SHARE:.0%} is no longer the model: a blow-up held finite by "
                "the fallback, not fracture); dt = "
                f"{self.dt:.4e} s is {over:.2f} x the stable estimate; compare dt with "
                "`mpipd check`")

    def check_ledger(self, e):
        """Raise :class:`Unstable` on every rank if the ledger reading ``e`` (global)
        has |balance| > b, or a term that cannot be negative below -b x its scale
        (mpipd.model.ledger.impossible), b = the scene's ``solver.max_imbalance``:
        energy that no term books, so the run's numbers from here on cannot be
        trusted.  b = 0 never raises."""
        bound = self.scene.solver.max_imbalance
        if not bound:
            return
        bad = ([f"balance {e.balance:+.3e}"] if abs(e.balance) > bound else []) + \
            impossible(e, bound)
        if bad:
            raise Unstable(f"energy ledger broken at step {self.step_count} "
                           f"(t = {self.t:.4e} s): {'; '.join(bad)}, beyond "
                           f"solver.max_imbalance = {bound:g} of the ledger's scale "
                           f"{e.scale:.4g} J; compare dt with `mpipd check`; where bonds "
                           "break, solver.refresh_after_break = true removes velocity "
                           "Verlet's breakage error (README, the energy ledger)")

    def geometry_fields(self) -> dict:
        """Per-point fields of the reference state the run file keeps under
        /geometry (owned rows): the strength factors of a heterogeneous material."""
        sf = self.corr.strength_factors()
        return {} if sf is None else {"strength_factor": sf}

    def bonds_broken(self) -> int:
        return self.team.sum(self.failure.bonds_broken) if self.failure else 0

    def bonds_broken_here(self) -> int:
        """This rank's share of the broken-bond count (a restart gives it all to rank 0)."""
        return self.failure.bonds_broken if self.failure else 0

    def _set_broken(self, value):
        if self.failure is not None:
            self.failure.bonds_broken = int(value)

    def _set_work(self, value):
        self.external_work = float(value)

    def after_restore(self):
        """Rebuild, from a restored state, what follows from it: the gas's pair-weight
        ghosts, the shape tensors, the failure flags' ghosts, damage and damped set
        (mpipd.output.checkpoint.restore, step 2)."""
        self.classes.after_restore(self.halo)
        self.corr.regroup()
        for m in self.models:
            m.after_restore(self.halo)
        if self.failure is not None:
            self.failure.after_restore()
            if self.interface is not None:  # retired where bonds broke or families failed
                self.interface.retire(self.mode)

    def failure_counts(self) -> np.ndarray:
        """Failed owned points per mode over all ranks (index = mode, 0 = intact)."""
        if self.failure is None:
            return np.array([self.n_global] + [0] * (N_MODES - 1))
        return self.team.sum(self.failure.counts())

    def spring_points(self) -> int:
        return self.team.sum(self.corr.n_spring)

    def memory(self) -> dict:
        """Bytes held by this rank: the State's registered arrays (per-bond, the rest,
        per owner) and the failure model's reference-position search tree."""
        m = self.state.memory()
        bond, point = m["bond_bytes"], m["point_bytes"]
        tree = 0
        if self.failure is not None:                # the reference-position search tree
            tree = self.failure.tree.data.nbytes + self.failure.tree.indices.nbytes
        nb = max(1, self.families.n_bonds)
        return {"bond_bytes": bond, "point_bytes": point, "tree_bytes": tree,
                "bytes_per_bond": bond / nb,
                "bytes_per_point": (point + tree) / max(1, self.points.n_local),
                "by_owner": m["by_owner"]}

    # ------------------------------------------------------------------ time loop
    def run(self, n_steps: int, writer=None, every: int = 0, progress=None,
            checkpointer=None) -> float:
        """Advance to step ``n_steps`` (from the current step: a restart continues),
        writing a frame every ``every`` steps and at the last step, and
        checkpointing as ``checkpointer`` says.  Returns the loop's wall time."""
        if self.probes is not None and self.step_count == 0:
            self.probes.sample(self.step_count, self.t)
        if writer is not None and self.step_count == 0:
            writer.frame(self)
        t0 = _time.perf_counter()
        first = self.step_count
        while self.step_count < n_steps:
            self.step()
            if self.probes is not None:
                self.probes.sample(self.step_count, self.t)
            last = self.step_count == n_steps
            frame = writer is not None and every and (self.step_count % every == 0 or last)
            if frame and not self.at_boundary:
                raise RuntimeError(f"frame at step {self.step_count}, not a coarse-step "
                                   "boundary (the scene check keeps frames on them)")
            if frame or self.step_count % FINITE_CHECK_EVERY == 0:
                self._or_stop(self.check_finite, checkpointer)
            if frame:
                e = writer.frame(self)              # the frame that broke it is kept
                self._or_stop(lambda: self.check_ledger(e), checkpointer)
                self.classes.frame_written(self.step_count)
            if not self.at_boundary:        # states of coarse classes are mid-step
                continue
            if progress is not None:
                e = progress(self, self.step_count - first, n_steps - first,
                             _time.perf_counter() - t0)
                if e is not None:
                    self._or_stop(lambda: self.check_ledger(e), checkpointer)
            if checkpointer is not None and not last and checkpointer.after_step():
                break
        return _time.perf_counter() - t0

    @staticmethod
    def _or_stop(check, checkpointer):
        """Run a check; if it raises :class:`Unstable`, leave the state in
        checkpoint_failed.h5 for a look first."""
        try:
            check()
        except Unstable:
            if checkpointer is not None:
                checkpointer.write_final()
            raise


#: steps between NaN/Inf checks of the owned fields (also at every frame)
FINITE_CHECK_EVERY = 10
#: the share of the intact solid points that may be on the bond springs by the
#: stable-step test before the run is stopped as unstable (Simulation.check_soft)
MAX_SOFT_SHARE = 0.05


class Progress:
    """One line on rank 0 every ``every`` steps (or about every ``seconds``): step,
    simulated time, wall time, ETA, throughput, failed points and energy.  Rank 0
    decides when a line is due and tells the others, since the line needs global sums.
    A call returns the ledger reading it printed (on every rank), or None when no
    line was due."""

    def __init__(self, team, every: int = 0, seconds: float = 2.0, log=None):
        self.team = team
        self.every = every
        self.seconds = seconds
        self.log = log or (lambda msg: print(msg, flush=True))
        self._last = 0.0

    def __call__(self, sim, done: int, total: int, wall: float):
        if self.every:
            due = done % self.every == 0 or done == total
        else:
            due = self.team.bcast(wall - self._last >= self.seconds or done == total)
        if not due:
            return
        self._last = wall
        failed = int(sim.failure_counts()[1:].sum()) if sim.failure is not None else 0
        e = sim.energies()
        if self.team.root:
            self._line(sim, done, total, wall, failed, e)
        return e

    def _line(self, sim, done, total, wall, failed, e):
        rate = sim.n_bonds_global * done / max(wall, 1e-12)
        eta = wall / done * (total - done)
        self.log(f"step {sim.step_count:>7d}/{sim.step_count - done + total:<7d} "
                 f"t={sim.t * 1e6:9.4f} us  wall={wall:8.1f} s  eta={eta:8.1f} s  "
                 f"{rate / 1e6:8.2f} M bond-steps/s ({rate / self.team.size / 1e6:.2f} per rank)  "
                 f"failed={failed}  E={e.held:.5g} J  balance={e.balance:+.2e}")
