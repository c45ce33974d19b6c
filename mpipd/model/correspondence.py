"""The correspondence machinery, once for every material.

:class:`Correspondence` owns the per-point kinematic state of the owned points
— K^-1, F (this and last step), Fdot, rotation R, left stretch V, unrotated
stress, stress work, volume factor — and the per-point force data and spring reference
maps of all local points.  It
calls the kernels of :mod:`mpipd.kernels.nosb` and
:mod:`mpipd.kernels.rotation`; materials only see the unrotated rate of
deformation ``d`` and update the unrotated stress of their own points.

It is the "tl" model family (:class:`mpipd.model.base.Model`); its step
(DESIGN §4, steps 4–8)::

    update(u, v, dt)    deform: F, Fdot                  Eqs. 5, 13
                        rotate: R, V, d, J (c det F)     Eqs. 6–14
                        update_stress: materials, work   Eq. 19 / 36
    force_data(u, ledger) B = P K^-1 - h F, h              Eqs. 2, 3, 15
    (halo exchange of fd and G)
    gather(u, v, f, fv) internal force density           Eq. 1
                        then the ghost-force correction  (mpipd.model.interface)
    commit()            F_old <- F

The explosive's points ("ul" family) are rows here too (code NOT_TL in
``spring``): they carry no material group, no bond and no force data.
"""
from __future__ import annotations

import numpy as np

from ..kernels import energy, integrate, nosb, rotation
from ..kernels.layout import CORRESPONDENCE, FD_WIDTH, FD_WIDTH_VISCOUS, INTACT, MODE_HELD, NOT_TL, SPRING_F, SPRING_K
from ..kernels.viscosity import viscosity_data
from ..materials.base import STATE_OUTPUTS
from ..state import AUX, BOND, LAST, LOCAL, REBUILT
from .base import Model
from .stability import micromodulus

#: a point whose det K <= RCOND (tr K / 3)^3 uses the bond-spring fallback
RCOND = 1e-8


def stable_floor(lam0: np.ndarray, dt_ratio: np.ndarray) -> np.ndarray:
    """The smallest lambda_min(K_i) at which point i keeps its correspondence force,

        floor_i = min(1, dt / dt_c,i)^2 lambda_min(K_i^0),

    from ``lam0`` = lambda_min(K_i^0) over the point's family at the start of the run
    (its reference family less the bonds that start broken: joints) and ``dt_ratio``
    = dt / dt_c,i, dt the finest step (every step class's) and dt_c,i the critical step
    of the point's part at rest (mpipd.model.stability.part_critical_dt).

    Point i's force state is omega P K^-1 xi with P linear in F = N K^-1, so the
    largest eigenvalue of its element's stiffness grows as 1 / lambda_min(K_i), and
    the stable step of the central difference, 2 / omega_max, shrinks as
    sqrt(lambda_min(K_i)): dt_i = dt_c,i sqrt(lambda_min(K_i) / lambda_min(K_i^0)) (the
    "shape_tensor" family factor of mpipd.model.multirate).  A point that lost bonds
    until dt_i < dt cannot be stepped stably by any class: with a near-singular K
    (a few bonds left, nearly coplanar) its correspondence force blew up a jittered
    rock (studies/validation/notes.md §26) although det K passed the RCOND test.  It
    takes the bond springs instead, the paper's fallback for a family too poor for
    K (§2.1).  A point with its family at rest has dt_i = dt_c,i >= dt (``mpipd run``
    holds dt to the estimate; beyond it, ``--force``, the floor is lambda_min(K^0)
    itself), so no point starts on the springs by this rule.  The reference is the
    family at the start, not the whole reference family: a face a joint cuts is then
    treated as the part's free surface is (stable at dt_c, though its K is as soft);
    with the whole family as reference the fragment bench's cubes cut by joints, at
    0.55 dt_c, started with 1728 of 97,336 points (the 8 around each joint crossing) on
    the springs (studies/validation/notes.md §31).  A crack's face, formed in the run, is
    still measured against the intact family.  The estimate errs on the safe side
    (multirate's measurements: a point with 95 % of its bonds broken has 0.001 of dt_c
    by it, 0.10-0.15 measured); but in such a ball (tests/test_multirate.py,
    _crushed_block) the points it takes off are the unstable ones: held at 4 dt, the
    ball's energy grew 1.6e5-fold in 800 steps without the rule and stays within 1e-7
    with it (84 points on the springs; studies/validation/notes.md §28)."""
    r = np.minimum(np.asarray(dt_ratio, float), 1.0)
    return r * r * np.maximum(lam0, 0.0)


class MaterialGroup:
    """The owned points of one material and that material's history arrays
    (compact: entry k belongs to point idx[k])."""

    def __init__(self, material, idx: np.ndarray, mid: int, gid: np.ndarray):
        """``gid``: the global ids of the points ``idx`` (a heterogeneous material's
        strength factors are drawn from them, mpipd.materials.heterogeneity)."""
        self.material = material
        self.mid = mid                          # the material's id (points.material)
        self.idx = idx.astype(np.int64)
        self.state = material.new_state(len(idx))
        h = getattr(material, "heterogeneity", None)
        if h is not None:                       # a history array: gathered by class
            self.state["strength_factor"] = h.factors(gid)
        #: entries of each step class (mpipd.model.multirate); None: all, class 0
        self.by_class = [None]

    def regroup(self, klass):
        """The entries of each step class, from the points' classes."""
        k = klass[self.idx]
        if not k.any():
            self.by_class = [None]
        else:
            self.by_class = [np.flatnonzero(k == c) for c in range(int(k.max()) + 1)]

    def update(self, d, J, dt, sigma, mode, level=0):
        """The material's stress update of the entries whose class acts at ``level``,
        each class with its own step 2^k dt (a class's history rows are gathered,
        updated and put back; all of them at once in a single-rate run)."""
        for k, pos in enumerate(self.by_class[:level + 1]):
            if pos is None:
                self.material.update(self.idx, d, J, dt, sigma, mode, self.state)
                continue
            if not len(pos):
                continue
            sub = {key: arr[pos] for key, arr in self.state.items()}
            self.material.update(self.idx[pos], d, J, dt * (1 << k), sigma, mode, sub)
            for key, arr in sub.items():
                self.state[key][pos] = arr

    def check_tension(self, sigma, d, mode, level=0) -> int:
        """The material's tension failure model on the entries whose class acts at
        ``level``: the others' stress and rate are those of their last update,
        checked (and passed) then."""
        t = getattr(self.material, "tension", None)
        if t is None:
            return 0
        factor = self.material.strength_factor(self.state, "tension")
        n = 0
        for pos in self.by_class[:level + 1]:
            if pos is None:
                return t.apply(self.idx, sigma, d, mode, factor)
            if len(pos):
                n += t.apply(self.idx[pos], sigma, d, mode, factor[pos] if len(factor) else factor)
        return n


class Correspondence(Model):
    name = "correspondence"

    def __init__(self, points, families, materials: dict, material_names, hourglass: float,
                 mode, classes, dt_ratio, contact: bool = False, viscosity=None, tl=None):
        """``mode``: the State's failure flags (the materials and the tension model
        set them; failed points carry no stress).  ``classes``: the step classes
        (mpipd.model.multirate.StepClasses; its ``level`` says which points' states
        the next update and gather evaluate).  ``dt_ratio``: dt over each owned
        point's critical step at rest (:func:`stable_floor`)."""
        n, nl = points.n_owned, points.n_local
        self.points = points
        self.classes = classes
        self.families = families
        self.mode = mode
        mats = [materials[m] for m in material_names]
        self.materials = mats                   # by material id, on every rank
        self.groups = []                        # the solids with points on this rank
        for mid, mat in enumerate(mats):
            idx = np.nonzero(points.material[:n] == mid)[0]
            if len(idx) and mat.family == "tl":
                self.groups.append(MaterialGroup(mat, idx, mid, points.gid[idx]))
        self.interface = None                   # the ghost-force correction, if any
        # both ends' influence omega(|xi|) of every bond (reference geometry: once)
        self.omega_i = np.empty(len(families.nbr))
        self.omega_j = np.empty(len(families.nbr))
        self.rinv = np.empty(len(families.nbr))          # 1 / |xi|
        nosb.bond_influence(points.x, points.horizon, points.influence, families.offsets,
                            families.nbr, self.omega_i, self.omega_j, self.rinv)
        # (n, 3, 3) C-contiguous: a point's tensor is 9 adjacent numbers in every kernel
        # (np.array of a broadcast keeps the broadcast's strides, point index fastest)
        def eye(rows):
            return np.tile(np.eye(3), (rows, 1, 1))
        self.Kinv = np.zeros((n, 3, 3))
        self.trK = np.zeros(n)
        self.spring = np.zeros(n, dtype=np.uint8)
        self.F = eye(n)
        self.F_old = eye(n)
        self.Fdot = np.zeros((n, 3, 3))
        self.R = eye(n)
        self.V = eye(n)
        self.sigma = np.zeros((n, 6))           # unrotated Cauchy stress, Voigt
        self.d = np.zeros((n, 6))               # unrotated rate of deformation, Voigt
        self.J = np.ones(n)                     # det F at mid-step (stress power, viscosity)
        self.J_end = np.ones(n)                 # c det F at the end of the step (materials)
        self.Jfac = np.ones(n)                  # volume factor c (rebuild_shape)
        #: 1 where the last rotate found no continuum kinematics (kernels.rotation):
        #: the point keeps its material state (:meth:`hold`)
        self.held = np.zeros(n, np.uint8)
        self.toggled = np.zeros(n, np.int64)    # points that switched to/from SPRING_F
        self.W = np.zeros(n)                    # strain energy per reference volume
        self.gamma = np.zeros(n)                # sum_j omega V_j (Eq. 43)
        self.contact = bool(contact)
        self.viscosity = viscosity
        # force data of owned + ghost points: B (9), h, fallback flag [, viscosity (2)]
        self.fd = np.zeros((nl, FD_WIDTH_VISCOUS if viscosity is not None else FD_WIDTH))
        #: spring reference map of owned + ghost points (kernels.nosb): a point on the
        #: bond springs measures its bonds' stretch from |G xi|; set when it switches in
        self.G = eye(nl)
        self.dil = np.zeros(n if viscosity is not None else 0)
        if viscosity is not None:
            rho = np.array([m.density for m in mats])[points.material[:n]]
            K = np.array([m.bulk_modulus for m in mats])[points.material[:n]]
            self.visc_l = viscosity.cl * rho * np.sqrt(K / rho)        # C_l rho0 c0
            self.visc_q = viscosity.cq * rho                           # C_q rho0
        self.hg_modulus = np.array([hourglass * m.hourglass_modulus if m.family == "tl" else 0.0
                                    for m in mats])[
            points.material[:n]]
        # bond-spring constant 18 k / (pi delta^4) of every local point
        bulk = np.array([m.bulk_modulus for m in mats])[points.material]
        self.cbb = micromodulus(bulk, points.horizon)
        self.n_spring = 0
        # points outside the total-Lagrangian model (the gas): code NOT_TL, never counted
        self.not_tl = np.flatnonzero(~tl[:n]) if tl is not None else np.zeros(0, np.int64)
        self.lam = np.zeros(n)                  # lambda_min(K) now, 0 if K is singular
        lam0 = np.zeros(n)
        self.reference_kinv(lam0, families.broken)         # the start: joints cut
        #: the smallest lambda_min(K) of each owned point on the correspondence force
        self.floor = stable_floor(lam0, dt_ratio)
        #: owned points this invocation moved from the correspondence force to the
        #: springs by the stable-step test alone (the run log's figure)
        self.floor_switches = 0

    def register(self, state):
        """This model's arrays in the State (owner "correspondence"), each solid
        material's history as ``state<material id>/<name>`` on every rank (an empty
        subset where a rank has no point of that material), and the output fields
        computed from them."""
        own, mode = self.name, self.mode
        add = state.add
        for name in ("Kinv", "trK", "Fdot", "J", "toggled", "gamma", "dil", "hg_modulus", "lam",
                     "floor", "held"):
            add(name, own, getattr(self, name))
        # with step classes a point keeps its last rate and volume between its updates:
        # the tension check (every step) and the ledger read them, so a restart needs them
        for name in ("d", "J_end"):
            add(name, own, getattr(self, name), checkpoint=self.classes.enabled)
        add("spring", own, self.spring, checkpoint=True, restore=REBUILT)
        # exchanged with fd; restored after the rebuild of K, which would take F for it
        add("spring_map", own, self.G, rows=LOCAL, exchanged=True, checkpoint=True,
            restore=REBUILT)
        add("F", own, self.F)
        add("F_old", own, self.F_old, checkpoint=True, restore=LAST)
        for name in ("R", "V", "sigma", "Jfac"):
            add(name, own, getattr(self, name), checkpoint=True)
        add("W", own, self.W, checkpoint=True, output="stress_work")
        add("fd", own, self.fd, rows=LOCAL, exchanged=True)
        add("omega_i", own, self.omega_i, rows=BOND)
        add("omega_j", own, self.omega_j, rows=BOND)
        add("rinv", own, self.rinv, rows=BOND)
        add("cbb", own, self.cbb, rows=LOCAL)
        add("not_tl", own, self.not_tl, rows=AUX)
        if self.viscosity is not None:
            add("visc_l", own, self.visc_l)
            add("visc_q", own, self.visc_q)
        here = {g.mid: g for g in self.groups}
        for mid, mat in enumerate(self.materials):
            if mat.family != "tl":
                continue
            g = here.get(mid)
            rows = g.idx if g is not None else np.zeros(0, np.int64)
            hist = g.state if g is not None else mat.new_state(0)
            owner = f"material {mid} ({mat.registry_name})"
            if g is not None:
                add(f"group{mid}_idx", owner, g.idx, rows=AUX)
                # its entries of each step class (MaterialGroup.regroup; None: all)
                for k in range(self.classes.top + 1):
                    add(f"group{mid}_class{k}", owner, rows=AUX,
                        get=lambda g=g, k=k: g.by_class[k] if k < len(g.by_class) else None)
            for key, arr in hist.items():
                add(f"state{mid}/{key}", owner, arr, rows=rows, checkpoint=True,
                    output=STATE_OUTPUTS.get(key))
        state.offer("stress", own, self.cauchy_stress)
        state.offer("elastic_energy", own, lambda: self.elastic_energy(mode))

    def strength_factors(self) -> np.ndarray | None:
        """The owned points' strength factors (mpipd.materials.heterogeneity; 1 for a
        homogeneous material), or None when no material of the scene has one."""
        if not any(getattr(m, "heterogeneity", None) is not None for m in self.materials):
            return None
        out = np.ones(self.points.n_owned)
        for g in self.groups:
            if "strength_factor" in g.state:
                out[g.idx] = g.state["strength_factor"]
        return out

    def attach_interface(self, correction):
        """The ghost-force correction (mpipd.model.interface) becomes the last part
        of :meth:`gather`."""
        self.interface = correction

    def after_restore(self, halo=None):
        """Shape tensors from the restored bonds (restart step 2); the points the
        stable-step test puts on the springs there were on them at the checkpoint."""
        self.rebuild_shape()
        self.floor_switches = 0

    # ---------------------------------------------------------------- steps
    def rebuild_shape(self, which: np.ndarray | None = None, u=None) -> int:
        """K^-1 of the given owned points (default: all).  Returns the number of
        owned points on the bond-spring fallback afterwards.

        Given the current displacement ``u`` (a rebuild after bonds broke), the
        points' F is recomputed over their new families at that u, F' = N'(u) K'^-1,
        and the volume factor keeps the volume ratio continuous:

            c <- c det F / det F'      (so c' det F' = c det F),

        F and F_old become F' (the next rotation increment then compares F's
        of one family).  A point of a coarse class between its updates
        (multi-rate) is rebuilt at the positions of its last update, where its F
        and F_old are (mpipd.model.multirate.StepClasses.u_at_update), so that its
        next update's increment is taken over one family.  Without it J = det F jumps when a family turns
        one-sided (a JH2 point went 133 MPa -> 18 GPa through K3 mu^3 with no
        work done) and the pressure then does work that nothing put in.

        A point that this rebuild moves from the correspondence force to the
        springs takes its F of before (its last regular F) as its spring reference
        map G (kernels.nosb).
        """
        p, fam = self.points, self.families
        if which is None:
            which = np.arange(p.n_owned, dtype=np.int64)
        before = self.spring[which] == CORRESPONDENCE
        nosb.shape_tensors(p.x, p.volume, p.horizon, p.influence, fam.offsets, fam.nbr,
                           fam.broken, self.Kinv, self.trK, self.gamma, self.lam, self.spring,
                           RCOND, self.floor, which)
        self.spring[self.not_tl] = NOT_TL
        to_springs = before & (self.spring[which] == SPRING_K)
        self.G[which[to_springs]] = self.F[which[to_springs]]
        # switched by the stable-step test alone (K invertible, below the floor)
        self.floor_switches += int(np.count_nonzero(to_springs & (self.lam[which] > 0.0)))
        if u is not None and len(which):
            Fn = np.empty((len(which), 3, 3))
            cl = self.classes
            kw = cl.klass[which]
            for k in np.unique(kw):
                # a point between its updates (coarse class, multi-rate): F' at the
                # positions of its last update, where its F and F_old are
                sel = np.flatnonzero(kw == k) if len(np.unique(kw)) > 1 else slice(None)
                Fk = np.empty((len(which[sel]), 3, 3))
                nosb.gradients_of(which[sel], p.x, cl.u_at_update(int(k) if k > cl.level else 0, u),
                                  p.volume, p.horizon, p.influence, fam.offsets, fam.nbr,
                                  fam.broken, self.Kinv, self.spring, Fk)
                Fn[sel] = Fk
            j_old = np.linalg.det(self.F[which])
            j_new = np.linalg.det(Fn)
            ok = before & (self.spring[which] == CORRESPONDENCE) & (j_old > 0) & (j_new > 0)
            self.Jfac[which[ok]] *= j_old[ok] / j_new[ok]
            self.F[which] = Fn
            self.F_old[which] = Fn
        self.n_spring = self.count_spring()
        return self.n_spring

    def reference_kinv(self, lam: np.ndarray | None = None,
                       broken: np.ndarray | None = None) -> np.ndarray:
        """K^-1 (Eq. 4) of every owned point over its whole reference family (no bond
        broken; or, given ``broken``, less those bonds), zero where K cannot be
        inverted, without touching the model's state; lambda_min of that K into
        ``lam``, if given."""
        p, fam = self.points, self.families
        n = p.n_owned
        Kinv = np.zeros((n, 3, 3))
        spring = np.zeros(n, np.uint8)
        nosb.shape_tensors(p.x, p.volume, p.horizon, p.influence, fam.offsets, fam.nbr,
                           np.zeros_like(fam.broken) if broken is None else broken, Kinv,
                           np.zeros(n), np.zeros(n), np.zeros(n) if lam is None else lam,
                           spring, RCOND, np.zeros(n), np.arange(n, dtype=np.int64))
        return Kinv

    def count_spring(self) -> int:
        """Owned total-Lagrangian points on the bond-spring fallback."""
        return int(np.count_nonzero((self.spring == SPRING_K) | (self.spring == SPRING_F)))

    def count_floor(self) -> int:
        """Owned points on the bond-spring fallback by the stable-step test alone (K
        invertible, lambda_min(K) below the floor: :func:`stable_floor`)."""
        return int(np.count_nonzero((self.spring == SPRING_K) & (self.lam > 0.0)))

    def update(self, u, v, dt: float, t: float):
        """F and Fdot, then rotation, stretch and d, then the materials' stress."""
        self.deform(u, v)
        self.rotate(dt)
        self.update_stress(dt, self.mode)

    def deform(self, u, v):
        p, fam, cl = self.points, self.families, self.classes
        nosb.deformation_gradients(p.x, u, v, p.volume, self.omega_i, self.rinv, fam.offsets, fam.nbr,
                                   fam.broken, self.Kinv, self.spring, self.F, self.Fdot,
                                   self.dil, cl.klass, cl.level)

    def initial_volume(self):
        """J_end = c det F of the current F (the start of a run, before any step)."""
        J = np.linalg.det(self.F)
        ok = ((self.spring == CORRESPONDENCE) | (self.spring == SPRING_F)) & (J > 0)
        self.J_end[:] = np.where(ok, self.Jfac * J, 1.0)

    def rotate(self, dt: float):
        cl = self.classes
        rotation.rotate_stretch(self.F_old, self.F, self.Fdot, self.R, self.V, dt,
                                self.spring, self.d, self.J, self.J_end, self.Jfac,
                                cl.klass, cl.level, self.held)

    def hold(self, mode: np.ndarray) -> np.ndarray:
        """Mark the intact points the last rotate held (on the bond springs, or with no
        valid F this step) MODE_HELD in ``mode`` and return them; :meth:`release` undoes it.

        Such a point's d = 0 and J = 1 are placeholders (kernels.rotation), not its
        state: put through a material update they would reset JH2's compression to 0
        (p collapses to the bulking term) and its rate terms to their static values,
        and the tension model would then fail the point from the switch itself.  The
        paper's fallback (§2.1) replaces the point's force, not its material: held
        out of both calls as a failed point is, it keeps its stress, damage and
        history until it leaves the springs or fails by breakage."""
        rows = np.flatnonzero(self.held)
        rows = rows[mode[rows] == INTACT]
        mode[rows] = MODE_HELD
        return rows

    @staticmethod
    def release(mode: np.ndarray, rows: np.ndarray):
        mode[rows] = INTACT

    def update_stress(self, dt: float, mode: np.ndarray):
        """Materials advance the stress; ``mode`` (failure flags) may be set by them.
        Points on the bond springs keep their material state (:meth:`hold`)."""
        k, level = self.classes.klass, self.classes.level
        integrate.stress_power(self.sigma, self.d, self.J, 0.5 * dt, self.spring, self.W, k, level)
        rows = self.hold(mode)
        try:
            for g in self.groups:
                g.update(self.d, self.J_end, dt, self.sigma, mode, level)
        finally:
            self.release(mode, rows)
        integrate.stress_power(self.sigma, self.d, self.J, 0.5 * dt, self.spring, self.W, k, level)

    def check_tension(self, mode: np.ndarray) -> int:
        """Tension failure model (Eqs. 37–38) of the materials that have one, at the
        points whose state was updated at this step's level (points on the bond
        springs are not checked: :meth:`hold`)."""
        level = self.classes.level
        rows = self.hold(mode)
        try:
            return sum(g.check_tension(self.sigma, self.d, mode, level) for g in self.groups)
        finally:
            self.release(mode, rows)

    def force_data(self, u, ledger=None) -> tuple:
        """Force data of the owned points (returned for the halo).  A point that
        switched to or from the singular-F fallback (SPRING_F) in this call changes
        its held potentials discontinuously: the ledger books before - after."""
        cl = self.classes
        n_bad, n_tog = nosb.force_data(self.F, self.F_old, self.R, self.sigma, self.Kinv,
                                       self.trK, self.spring, self.hg_modulus, self.Jfac,
                                       self.fd, self.G, self.toggled, cl.klass, cl.level)
        if self.viscosity is not None:
            viscosity_data(self.dil, self.gamma, self.J, self.trK, self.spring,
                           self.visc_l, self.visc_q, self.fd)
        if n_bad or n_tog:
            self.n_spring = self.count_spring()
        if n_tog and ledger is not None:
            self._book_toggles(self.toggled[:n_tog], u, ledger)
        return (self.fd, self.G)

    def _book_toggles(self, rows, u, ledger):
        """Potentials of ``rows`` under their other fallback code (before the
        switch) and under the current one: the jump the switch made."""
        now = self.spring[rows].copy()
        self.spring[rows] = np.where(now == SPRING_F, CORRESPONDENCE, SPRING_F).astype(np.uint8)
        before = self.potentials(rows, u)
        self.spring[rows] = now
        ledger.book_jump(before, self.potentials(rows, u))

    def gather(self, u, v, f, fv):
        """Internal force density into f, the viscous share also into fv (if any);
        then the ghost-force correction f_i -= P_i g_i where there is one."""
        p, fam, cl = self.points, self.families, self.classes
        nosb.gather_forces(p.x, u, v, p.volume, p.horizon, self.omega_i, self.omega_j, self.rinv,
                           fam.offsets, fam.nbr, fam.broken, self.fd, self.G, self.cbb,
                           self.contact, f, fv, cl.klass, cl.kmin, cl.level)
        if self.interface is not None:
            self.interface.apply(self.fd, self.F, f, cl.klass, cl.level)

    def reweight(self, rows, u, v, f, fv, previous):
        """The forces of the owned ``rows`` after the step classes changed at a coarse
        boundary (every state current, force data and its ghosts unchanged): f
        (and fv) += gather(new weights) - gather(old weights) there, in one pass over
        the bonds whose weights changed (nosb.gather_reweight), so the gas's, the
        loads' and the other points' forces stay as they are.  The interface
        correction's force fc is left with the new weights."""
        p, fam, cl = self.points, self.families, self.classes
        g = np.empty((len(rows), 3))
        gv = np.empty((len(rows), 3) if len(fv) else (0, 3))
        nosb.gather_reweight(p.x, u, v, p.volume, p.horizon, self.omega_i, self.omega_j,
                             self.rinv, fam.offsets, fam.nbr, fam.broken, self.fd, self.G, self.cbb,
                             self.contact, rows, previous, cl.klass, cl.top, g, gv)
        f[rows] += g
        if len(fv):
            fv[rows] += gv
        if self.interface is not None:
            n = p.n_owned
            out = []
            for klass in (previous, cl.klass):
                h = np.zeros((n, 3))
                self.interface.apply(self.fd, self.F, h, klass, cl.top)
                out.append(h[rows])
            f[rows] += out[1] - out[0]

    def commit(self):
        """F_old <- F of the points updated at this level."""
        rows = self.classes.rows(self.classes.level)
        if rows is None:
            self.F_old[...] = self.F
        else:
            self.F_old[rows] = self.F[rows]

    def regroup(self):
        """The material groups' class entries after the classes changed."""
        for g in self.groups:
            g.regroup(self.classes.klass)

    # ---------------------------------------------------------------- diagnostics
    def cauchy_stress(self) -> np.ndarray:
        """Rotated Cauchy stress sigma = R S R^T of owned points, Voigt order."""
        S = np.empty((len(self.sigma), 3, 3))
        s = self.sigma
        S[:, 0, 0], S[:, 1, 1], S[:, 2, 2] = s[:, 0], s[:, 1], s[:, 2]
        S[:, 1, 2] = S[:, 2, 1] = s[:, 3]
        S[:, 0, 2] = S[:, 2, 0] = s[:, 4]
        S[:, 0, 1] = S[:, 1, 0] = s[:, 5]
        T = np.einsum("nij,njk,nlk->nil", self.R, S, self.R)
        return np.stack([T[:, 0, 0], T[:, 1, 1], T[:, 2, 2],
                         T[:, 1, 2], T[:, 0, 2], T[:, 0, 1]], axis=1)

    def cauchy_stress_of(self, i: int) -> np.ndarray:
        """Rotated Cauchy stress of one owned point, Voigt order."""
        s = self.sigma[i]
        S = np.array([[s[0], s[5], s[4]], [s[5], s[1], s[3]], [s[4], s[3], s[2]]])
        T = self.R[i] @ S @ self.R[i].T
        return np.array([T[0, 0], T[1, 1], T[2, 2], T[1, 2], T[0, 2], T[0, 1]])

    def elastic_energy(self, mode) -> np.ndarray:
        """Recoverable energy per reference volume of every owned point (J/m^3),
        from each material's own state (0 for failed points and the gas)."""
        out = np.zeros(self.points.n_owned)
        for g in self.groups:
            g.material.elastic_energy(g.idx, self.sigma, self.J_end, mode, g.state, self.W,
                                      out)
        return out

    def potentials(self, rows: np.ndarray, u) -> np.ndarray:
        """(hourglass, spring, contact) energy (J) owned by each of the owned points
        ``rows``, at displacement u with the current bonds, F, K and fallback codes
        (kernels.energy)."""
        p, fam = self.points, self.families
        out = np.empty((len(rows), 3))
        energy.point_potentials(rows, p.x, u, p.volume, p.horizon, p.influence, fam.offsets,
                                fam.nbr, fam.broken, self.F, self.G, self.hg_modulus, self.trK,
                                self.spring, self.cbb, self.contact, out)
        return out

    def hourglass_energy(self, u) -> float:
        rows = np.arange(self.points.n_owned, dtype=np.int64)
        return float(self.potentials(rows, u)[:, 0].sum())
