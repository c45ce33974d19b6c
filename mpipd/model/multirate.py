"""Multi-rate (subcycled) explicit integration: every point's step class.

Scheme: an asynchronous variational integrator (Lew, Marsden, Ortiz & West
2003, ARMA 167; 2004, IJNME 60) on power-of-two step classes, the
peridynamic form of LS-DYNA's element subcycling.  Each point's force state
(its stress through Eq. 2, its hourglass penalty, its viscosity, its side of a
bond spring, the ghost-force correction at it) is one "element": it acts on
the point and on its family.  An element of class k is evaluated every
dt_k = 2^k dt at the current positions and gives every point of its star the
impulse dt_k f_k; between impulses every point drifts at constant velocity,
so every position is known exactly at every fine step and nothing is
interpolated.  Written as velocity Verlet with the fine dt, that is the
ordinary step with the force

    f_i^s = sum over the elements e acting at fine step s of 2^k_e f_e,i

(kernels.classes.weight), so the solver's loop, its kicks and the energy
ledger's identities are unchanged.  Properties (the sources above; Fong,
Darve & Lew 2008, JCP 227, for the stability analysis):

* linear momentum is conserved exactly: every bond's two impulses have the
  same weight (a force state's impulses sum to zero; a broken pair's contact
  takes the pair's finer class), so each impulse exchange sums to zero;
  angular momentum as in the single-rate model;
* each element is stable under its own Courant limit, dt_k below the critical
  step of its material at its current state; AVIs have resonances when a
  coarse step is a multiple of a fine half-period, dense but very weak in solids;
* classes are synchronised every ``max_ratio`` fine steps (the coarse step):
  there all states are current, and failure, breakage, the tension check,
  frames, checkpoints and progress lines happen only there.

Class rule (at every coarse boundary, identical on any number of ranks: a
function of each point's own state, then of its family by halo exchange):

    dt_i = dt_c,i * lambda_i * kappa_i * c_p,i / c_i(state)   (the stable step now;
                                                          dt_c,i: stability.stable_dt
                                                          of the point's part; c_p,i its
                                                          reference P-wave speed)
    r_i  = safety * dt_i / dt
    base = floor(log2 r_i), clipped to 0..log2(max_ratio), 0 for the gas
    k_i  = min over i's family (bonds broken or not) of base_j    (the buffer, "full")
    k_i  = min(base_i, min over i's family of base_j + 1)        (the buffer, "graded")

c_i(state) is the material's P-wave speed at the larger of its compression now
and the compression extrapolated over two coarse steps at its current rate
(``Material.p_wave_speed_at``: JH2's EOS stiffens steeply, a crushed-zone point
must take the fine class before it gets there), and lambda_i = min(1, smallest
principal stretch of V_i) (``kernels.classes.min_stretch``): dt_c,i is the transit
of the reference spacing, and a point thinned to lambda of it in one direction
has its wave cross the spacing in lambda times the time (Courant-Friedrichs-Lewy
on the current configuration).  That is exact for an isochoric thinning, the
plastic flow of a metal (the density and c are unchanged; a 1-D element of length
lambda L with A = A0 / lambda has the stiffness k0 / lambda^2, so omega_max and
1/dt_crit scale with 1/lambda); under compression c(state) and lambda both count
it, which errs on the safe side.  kappa_i follows the bonds lost around the point
(``StepClasses.family_factor``, the scene's ``family_factor``):

* "row_sum" (the default): kappa_i = min(1, sqrt(R_i^0 / R_i)), R_i the Gershgorin row
  sum of the correspondence stiffness at point i over the elements that hold it
  (``kernels.classes.row_sums``; R_i^0 over the whole reference families).  The
  largest eigenvalue of M^-1 K is at most the largest row sum (Gershgorin), and the
  stable step of the central difference is 2 / omega_max, so a point whose row sum
  grew by R_i / R_i^0 needs its step shortened by at most sqrt of it.  It counts every
  element a point takes impulses from, its own and its neighbours', each with the
  bonds it still has; a free surface and a crack face look alike (each relative to
  its own reference).  Measured (studies/multirate/family_factor.py,
  studies/multirate/multirate_family_factor.md): a granite block with a planar crack, two crossed
  cracks or a ball with 30 % of its bonds broken keeps the intact block's critical
  step; balls with 60-95 % broken lose 13-90 % of it, about what the row sum says
  (at 95 %: 0.10-0.15 of it measured, 0.15 said: an estimate, not a bound; the
  safety factor covers the rest, a margin of 2.5 at safety 0.5).
* "row_sum_part": the same row sum against the largest R^0 of i's part at rest (all
  ranks): at rest the rule steps the part's stiffest points (edges and corners, cut by
  the surface) at dt_c, stable to 1.75 dt_c as measured on the block; a crack face no
  stiffer than they are keeps its step (measured: factor 1 for cracks and 30 % balls,
  as the critical step; 1.4-2.3x the measured step for balls 80-95 % broken, hence
  the scene's bound safety <= 0.5, a margin of 1.6 there).
* "shape_tensor": kappa_i = min(1, sqrt(lambda_min(K_i) / lambda_min(K_i^0))) of the
  point's own element (the force state omega P K^-1 xi, P linear in F = N K^-1: the
  element's largest eigenvalue scales with 1 / lambda_min(K)).  It errs on the safe
  side by far (a crack face: 0.68 where the step is unchanged; 95 % of a ball's bonds
  broken: 0.001 where 0.10-0.15 is measured) and holds most of a fractured specimen
  in the finer classes.

Both are 1 off the correspondence force (the gas, the bond-spring fallback) and at a
point that failed (its own stress no longer follows its material), as the smallest
stretch is, and are recomputed where a family changed (bonds broke) and, for the
row sum, around it.  A copper tube driven to 2.4 x its radius is
thinned to lambda = 0.25 (studies/validation/notes.md §13).  A point whose dt_i is
below dt itself cannot be helped by any class (class 0 is dt): the boundary
counts it (``over``), and the run log and the error of an unstable run name the
worst such point; the scene's remedy is a smaller dt with a larger max_ratio
(the same coarse step).  Coarsening needs
``HYSTERESIS`` x the margin (no class flicker at a threshold), but never more
than half the point's own margin at rest (``coarsening_margin``): a point whose
ratio at rest lies less than HYSTERESIS above its class's threshold (the 0.8 mm
granite of blast_paper: 4.35 against 4) would otherwise never return to it once
refined.  Refining is immediate.  The full buffer makes every element's class no
coarser than any point it pushes; the graded one (the default) lets it be one class
coarser, a step ratio of 2 across a bond, the 2:1 grading of subcycled and adaptive
meshes: each element still steps within its own stable estimate, the condition of the
AVI stability analysis (Fong et al. 2008), while the layer beside every fine point no
longer steps at the finest class (docs/multirate.md).  A point whose family lost bonds
in the last ``fracture_window`` coarse steps (the scene's, 2 by default; 0: no such
rule) takes at most ``fracture_class``.  When a class changes, the forces at the
boundary are gathered again with the new weights (the second half kick of velocity
Verlet with a changed step), and the jump of the integrator term this makes is booked
in the ledger's ``multirate`` entry.
"""
from __future__ import annotations

import numpy as np

from ..kernels.classes import around, element_sums, family_min, largest_eigenvalue, level_at, min_stretch, row_sums
from ..kernels.layout import CORRESPONDENCE, INTACT, NOT_TL, SPRING_F
from ..state import AUX, LOCAL

#: coarsening needs the class's margin times this (refinement: 1)
HYSTERESIS = 1.25


class StepClasses:
    """Step class of every local point (owned first, ghosts after), the coarse-step
    bookkeeping and the rows each level updates.  Single-rate scenes hold all
    classes at 0 and every level at 0 (the kernels then give the single-rate numbers)."""

    name = "multirate"

    def __init__(self, scene, points, families, team=None):
        """``team``: the ranks (the part-wide reference of the \"row_sum_part\" factor)."""
        mr = scene.time.multirate
        self.team = team
        self.n_parts = len(scene.parts)
        self.ratio = mr.max_ratio if mr is not None else 1
        self.safety = mr.safety if mr is not None else 1.0
        #: the buffer: a class no coarser than any pushed point's ("full") or at most one
        #: class coarser ("graded"); the class a fracturing family takes at most
        self.graded = mr is not None and mr.buffer == "graded"
        self.factor_kind = mr.family_factor if mr is not None else "row_sum"
        self.fracture_class = mr.fracture_class if mr is not None else 0
        self.window = mr.fracture_window if mr is not None else 0
        self.top = self.ratio.bit_length() - 1
        self.dt = scene.time.dt
        n, nl = points.n_owned, points.n_local
        self.n_owned = n
        self.families = families
        self.klass = np.zeros(nl, np.uint8)             # k of owned + ghosts
        self.kbase = np.full(nl, self.top, np.uint8)    # before the buffer
        self.kmin = np.zeros(n, np.uint8)               # min k over the closed family
        #: the step at which each owned point's family last changed (bonds broke)
        self.touched = np.full(n if self.ratio > 1 else 0, -(1 << 40), np.int64)
        self.level = self.top
        self.step = 0
        self._rows = {}
        self._held = None
        self.previous = self.klass                     # the classes before the last change
        # this invocation's figures (the run log): bond states evaluated, steps,
        # coarse boundaries, and those where a class changed (the forces' change gathered)
        self.bonds_by_class = [0.0] * (self.top + 1)
        self.evaluated = 0.0
        self.steps = self.boundaries = self.changes = 0
        #: u (owned + ghosts) at the last update of each coarse class 1..top: a point
        #: whose family changes between its updates rebuilds F at those positions
        self.u_then = np.zeros((self.top, nl, 3))
        #: the stable steps dt_i below dt (this rank, this invocation): coarse steps
        #: with one, the first such step, the smallest dt_i / dt of each material
        self.over_steps = 0
        self.over_first = -1
        self.over_worst = {}                            # material id -> (dt_i / dt, gid)
        self.over_now = 0                               # points over dt at the last boundary
        #: the three figures above as they stood at the last frame written (its step
        #: last): a failure's line separates them from the steps of the blow-up itself
        self.over_framed = None
        #: family_factor: its reference (1/lambda_min(K^0), or R^0), the factor kept, the
        #: rows to recompute; the row sum's element data (owned and ghosts) and R now
        self.kref = self.kfac = self.stale = None
        self.elem = self.rnow = self.changed = None
        #: owned rows whose closed family holds a class that changed at the last boundary
        self.reweighted = np.zeros(0, np.int64)
        #: do klass and kmin follow from kbase (a spread, or a restore, since)?
        self.spread = False
        #: the owned points with ghosts in their families (what :meth:`rows_around`
        #: reads besides the changed families) and its output buffer, made at first use
        self.edge = np.zeros(0, np.int64)
        self.near = np.zeros(0, np.uint8)
        #: every owned row (multi-rate only)
        self.all_rows = np.arange(n if self.enabled else 0, dtype=np.int64)
        #: each owned point's critical step, P-wave speed at rest and coarsening margin
        self.dtc = self.cp0 = self.hyst = None
        if self.enabled:
            from .stability import part_critical_dt
            cp = np.array([scene.materials[q.material].p_wave_speed for q in scene.parts])
            self.dtc = part_critical_dt(scene)[points.part[:n]]
            self.cp0 = cp[points.part[:n]]
            self.hyst = coarsening_margin(self.safety * self.dtc / self.dt, self.top)

    @property
    def fam_bonds(self) -> np.ndarray:
        """Bonds of each owned point's family (a temporary)."""
        return np.diff(self.families.offsets)

    @property
    def enabled(self) -> bool:
        return self.ratio > 1

    def register(self, state):
        """The classes (checkpointed: the hysteresis needs the last base class, and a
        restart must go on with the classes it stopped with)."""
        state.add("step_class", self.name, self.klass, rows=LOCAL, exchanged=self.enabled,
                  checkpoint=True)
        state.add("step_class_base", self.name, self.kbase, rows=LOCAL,
                  exchanged=self.enabled, checkpoint=True)
        state.add("step_class_min", self.name, self.kmin)
        state.add("step_class_touched", self.name, self.touched, checkpoint=self.enabled)
        state.add("step_class_u", self.name, self.u_then.reshape(-1, 3), rows=AUX)
        # the rows of the last class change, every owned row, and the slab-edge rows
        # with their buffer (rebuilt from the classes and families: no checkpoint)
        state.add("step_class_reweighted", self.name, get=lambda: self.reweighted, rows=AUX)
        state.add("step_class_rows", self.name, self.all_rows, rows=AUX)
        state.add("step_class_edge", self.name, get=lambda: self.edge, rows=AUX)
        state.add("step_class_near", self.name, get=lambda: self.near, rows=AUX)
        # the owned rows of each class up to a level (made at first use, per level)
        for k in range(self.top):
            state.add(f"step_class_rows{k}", self.name, get=lambda k=k: self._rows.get(k),
                      rows=AUX)
        # each point's critical step, P-wave speed at rest and coarsening margin (from
        # the scene), and the family factor's reference, factor, stale flags and the
        # row sum's element data and change flags (made at first use, rebuilt after a
        # restart): None where multi-rate is off
        for name in ("dtc", "cp0", "hyst", "kref", "kfac", "stale", "rnow"):
            state.add(f"step_class_{name}", self.name, get=lambda name=name: getattr(self, name))
        for name in ("elem", "changed"):
            state.add(f"step_class_{name}", self.name, get=lambda name=name: getattr(self, name),
                      rows=LOCAL, exchanged=self.enabled)

    # ---------------------------------------------------------------- the schedule
    def boundary(self, step: int) -> bool:
        """Is the end of step ``step`` a coarse-step boundary (all classes current)?"""
        return step % self.ratio == 0

    def set_level(self, step: int):
        """The level of the force evaluation at the end of step ``step``."""
        self.level = level_at(step, self.ratio)
        self.step = step
        self.evaluated += sum(self.bonds_by_class[:self.level + 1])
        self.steps += 1

    def snapshot(self, u):
        """Keep u as the positions of the classes updated at this level (after the
        halo exchange of u; every class at a coarse boundary)."""
        for k in range(1, min(self.level, self.top) + 1):
            self.u_then[k - 1] = u

    def u_at_update(self, k: int, u):
        """u at the last update of class k (the current u for class 0)."""
        return u if k == 0 else self.u_then[k - 1]

    def rows(self, level: int) -> np.ndarray | None:
        """Owned rows whose class acts at ``level``; None for all of them."""
        if level >= self.top:
            return None
        r = self._rows.get(level)
        if r is None:
            r = self._rows[level] = np.flatnonzero(self.klass[:self.n_owned] <= level)
        return r

    # ---------------------------------------------------------------- the classes
    def hold(self, kbase, halo):
        """Hold the owned points' base classes at ``kbase`` from now on instead of
        taking them from the state: a verification device that puts a class
        boundary where nothing else changes (tests/test_multirate.py,
        benchmarks/problems/wave_multirate.py).  The caller regroups the
        materials and recomputes the forces (Simulation.hold_classes)."""
        self._held = np.asarray(kbase, np.uint8).copy()
        self.kbase[:self.n_owned] = self._held
        self._spread(halo)

    def touch(self, rows):
        """The families of the owned ``rows`` changed in the current step (bonds broke;
        Failure.on_rebuild)."""
        if len(rows):
            self.touched[rows] = self.step
            if self.kfac is not None:
                self.stale[rows] = True

    def family_factor(self, corr, halo) -> np.ndarray:
        """kappa_i of every owned point (module docstring; the scene's ``family_factor``),
        1 off the correspondence force and once failed.  Kept per point and recomputed where a family
        changed (:meth:`touch`) and, for the row sum, around it.  Collective (halo)."""
        n = self.n_owned
        first = self.kfac is None                       # first use, or after a restart
        if first:
            self.kfac = np.ones(n)
            self.stale = np.ones(n, bool)
        FAMILY_FACTORS[self.factor_kind](self, corr, halo, first)
        self.stale[:] = False
        on = (corr.spring[:n] == CORRESPONDENCE) & (corr.mode[:n] == INTACT)
        return np.where(on, self.kfac, 1.0)

    def base_classes(self, corr, halo, step: int = 0, kappa: bool = True, fracture: bool = True,
                     fracture_class: int | None = None) -> np.ndarray:
        """Each owned point's class from its own material and state (module docstring).
        A study of the rule (studies/multirate/class_rules.py) may leave out the family factor
        (``kappa``) or the fracture rule (``fracture``), or change ``fracture_class``
        (None: the scene's)."""
        n = self.n_owned
        if self._held is not None:
            return self._held
        r = np.zeros(n)                                 # the gas, and any point in no group: 0
        now = np.full(n, np.inf)                        # dt_i / dt at the state now
        horizon = 2.0 * self.ratio * self.dt
        kap = self.family_factor(corr, halo) if kappa else np.ones(n)
        for g in corr.groups:
            idx = g.idx
            mu = 1.0 / corr.J_end[idx] - 1.0
            d = corr.d[idx]
            rate = -(d[:, 0] + d[:, 1] + d[:, 2]) * (1.0 + mu)
            mu_ahead = mu + np.maximum(rate, 0.0) * horizon
            c_now = g.material.p_wave_speed_at(mu)
            c = np.maximum(c_now, g.material.p_wave_speed_at(mu_ahead))
            lam = np.empty(len(idx))
            min_stretch(corr.V, idx, corr.spring, corr.mode, lam)
            lam *= kap[idx]
            now[idx] = self.dtc[idx] * lam * self.cp0[idx] / c_now / self.dt
            r[idx] = self.safety * now[idx] * c_now / c
        self._count_over(now, corr.points.material[:n], corr.points.gid, step)
        with np.errstate(divide="ignore"):
            down = np.floor(np.log2(np.maximum(r, 1e-300)))
            up = np.floor(np.log2(np.maximum(r / self.hyst, 1e-300)))
        down = np.clip(down, 0, self.top).astype(np.uint8)
        up = np.clip(up, 0, self.top).astype(np.uint8)
        k = np.minimum(down, np.maximum(self.kbase[:n], up))
        # fracturing: a family that changed (bonds broke) within the last fracture_window
        # coarse steps takes at most the fracture class (the finest by default)
        if fracture and self.window > 0:
            recent = step - self.touched <= self.window * self.ratio
            fc = self.fracture_class if fracture_class is None else fracture_class
            k[recent] = np.minimum(k[recent], fc)
        return k

    def _count_over(self, ratio, material, gid, step: int):
        """Book the owned points whose stable step now, dt_i = ratio * dt, is below dt
        (the extrapolated compression of the class rule aside: what holds now)."""
        over = np.flatnonzero(ratio < 1.0)
        self.over_now = len(over)
        if not len(over):
            return
        self.over_steps += 1
        if self.over_first < 0:
            self.over_first = step
        for m in np.unique(material[over]):
            sel = over[material[over] == m]
            w = sel[np.argmin(ratio[sel])]
            if ratio[w] < self.over_worst.get(int(m), (np.inf,))[0]:
                self.over_worst[int(m)] = (float(ratio[w]), int(gid[w]))

    def frame_written(self, step: int):
        """Keep this rank's over-dt figures as they stand at a frame (step ``step``):
        a failure's line reports the smallest stable steps up to that state apart
        from those of the steps after it, where an instability may set them."""
        self.over_framed = (self.over_steps, self.over_first, dict(self.over_worst), step)

    def over_line(self, team, names, failed: bool = False) -> str | None:
        """One line (collective) on the points whose stable step fell below dt in this
        invocation, or None if none did: since when, how often, and the smallest
        dt_i / dt of each material (``names``: by material id) with its point.  After
        a failure (``failed``) the smallest are given up to the last frame written
        and, apart, over the steps after it: a blow-up's own steps (an inverted F)
        take dt_i to 0 and would otherwise stand for the whole run."""
        got = team.gather((self.over_steps, self.over_first, self.over_worst))
        kept = team.gather(self.over_framed) if failed else None
        hit = [g for g in got if g[0]]
        if not hit:
            return None
        first = min(g[1] for g in hit)
        each = ": " + _smallest(hit, names)
        if failed and kept and all(k is not None for k in kept):
            step = kept[0][3]
            before = [k for k in kept if k[0]]
            each = (f" up to the last frame (step {step}): "
                    f"{_smallest(before, names) if before else 'none below dt'}; "
                    f"with the steps after it, to the failure{each}")
        return (f"the step dt = {self.dt:.4g} s was above the stable step now of some points "
                f"(their P-wave speed at their compression over their smallest principal "
                f"stretch, mpipd.model.multirate) from step {first} on, at up to "
                f"{max(g[0] for g in hit)} coarse steps; smallest{each}. A smaller "
                f"time.dt with a larger max_ratio keeps the coarse step")

    def classify(self, corr, halo, step: int) -> bool:
        """New classes from the current state (at a coarse boundary); True if any
        owned point's class changed (reduce over ranks)."""
        if not self.enabled:
            return False
        n = self.n_owned
        self.previous = self.klass.copy()
        # the last spread's base classes, if klass and kmin follow from them (not
        # before the first spread: klass starts at 0, kbase at the top class)
        before = self.kbase.copy() if self.spread else None
        self.kbase[:n] = self.base_classes(corr, halo, step)
        self._spread(halo, before)
        self.boundaries += 1
        return bool(np.any(self.klass[:n] != self.previous[:n]))

    def reweighted_rows(self) -> np.ndarray:
        """Owned points whose closed family holds a point whose class changed at the
        last boundary (ghosts included): the forces there change with the weights."""
        return self.reweighted

    def rows_around(self, flag) -> np.ndarray:
        """The owned points whose closed family holds a point flagged in ``flag``
        (owned and ghosts; kernels.classes.around)."""
        n, fam = self.n_owned, self.families
        if len(self.near) != n:
            self.near = np.zeros(n, np.uint8)
            inner = (np.arange(len(self.klass)) < n).astype(np.uint8)
            family_min(fam.offsets, fam.nbr, inner, np.arange(n, dtype=np.int64), self.near)
            self.edge = np.flatnonzero(self.near == 0)
        flag = flag.astype(np.uint8)
        around(fam.offsets, fam.nbr, flag, np.flatnonzero(flag[:n]), self.edge, n, self.near)
        return np.flatnonzero(self.near)

    def _spread(self, halo, before=None):
        """The buffer and the receivers' levels, from the owned base classes:
        k_i = min over i's family of base_j ("full"), or of min(base_i, base_j + 1)
        ("graded"); kmin_i = min over i's closed family of k_j.  With ``before``, the
        base classes (owned and ghosts) of the last spread, only the points whose
        closed family holds a changed base class, and then a changed class, are
        taken again: the same classes as the whole pass, at the cost of the changes."""
        n, fam = self.n_owned, self.families
        halo.exchange(self.kbase)
        rows = self.all_rows if before is None else self.rows_around(self.kbase != before)
        buffered(fam, self.kbase, self.top, self.graded, rows, self.klass[:n])
        halo.exchange(self.klass)
        if before is None:
            family_min(fam.offsets, fam.nbr, self.klass, self.all_rows, self.kmin)
        else:
            self.reweighted = self.rows_around(self.klass != self.previous)
            family_min(fam.offsets, fam.nbr, self.klass, self.reweighted, self.kmin)
        self._recount()
        self.spread = True

    def _recount(self):
        self._rows = {}
        k = self.klass[:self.n_owned]
        self.bonds_by_class = np.bincount(k, weights=self.fam_bonds,
                                          minlength=self.top + 1).tolist()

    def after_restore(self, halo):
        """Ghost classes and receivers from the restored owned classes; the family
        factors are taken again from the restored shape tensors at the next boundary."""
        self.kfac = None
        if self.enabled:
            fam = self.families
            halo.exchange(self.klass, self.kbase)
            family_min(fam.offsets, fam.nbr, self.klass, self.all_rows, self.kmin)
            self._recount()
            self.spread = True

    # ---------------------------------------------------------------- figures
    def summary(self, team) -> str:
        """One line for the run log: the classes now, the share of the single-rate
        bond work this invocation evaluated, and how often the classes changed."""
        per = team.sum(self.counts(self.fam_bonds))
        share = self.evaluated_share(team)
        cls = ", ".join(f"class {k} (dt x {2 ** k}) {per[k, 0]} points / {per[k, 1]} bonds"
                        for k in range(self.top + 1))
        buffer = "graded" if self.graded else "full"
        return (f"multi-rate (max_ratio {self.ratio}, safety {self.safety:g}, {buffer} buffer, "
                f"fracture class {self.fracture_class} over {self.window} coarse steps, "
                f"family factor {self.factor_kind}): now {cls}; "
                f"bond states evaluated {share:.3f} of single-rate's; classes changed at "
                f"{self.changes} of {self.boundaries} coarse steps (a change of the forces gathered at each)")

    def evaluated_share(self, team) -> float:
        """The bond states this invocation evaluated over those single-rate steps
        would have (collective): sum over steps of the bonds of the acting classes,
        over steps x all bonds; 1 single-rate."""
        if not self.enabled:
            return 1.0
        ev = team.sum(np.array([self.evaluated, float(self.steps)]))
        total = team.sum(np.array([float(self.fam_bonds.sum())]))[0]
        return float(ev[0] / max(ev[1] / team.size * total, 1.0))

    def counts(self, n_bonds_of: np.ndarray) -> np.ndarray:
        """(points, bonds) of this rank's owned points per class, shape (top+1, 2)."""
        k = self.klass[:self.n_owned]
        out = np.zeros((self.top + 1, 2), np.int64)
        for c in range(self.top + 1):
            sel = k == c
            out[c] = (int(sel.sum()), int(n_bonds_of[sel].sum()))
        return out


def _smallest(got, names) -> str:
    """"copper 0.500 dt at gid 17; ..." from the ranks' (steps, first, worst by
    material) of StepClasses.over_line: each material's smallest dt_i / dt."""
    worst = {}
    for g in got:
        for m, w in g[2].items():
            worst[m] = min(worst.get(m, w), w)
    return "; ".join(f"{names[m]} {w[0]:.3f} dt at gid {w[1]}" for m, w in sorted(worst.items()))


def shape_tensor_factor(cl, corr, halo, first: bool):
    """kappa_i = min(1, sqrt(lambda_min(K_i) / lambda_min(K_i^0))) at the stale rows of
    ``cl`` (StepClasses), from the point's own shape tensor (module docstring)."""
    n = cl.n_owned
    if first:
        cl.kref = np.empty(n)
        largest_eigenvalue(corr.reference_kinv(), cl.kref)          # 1 / lambda_min(K^0)
    rows = np.flatnonzero(cl.stale)
    if len(rows):
        e = np.empty(len(rows))
        largest_eigenvalue(corr.Kinv[rows], e)                      # 1 / lambda_min(K)
        cl.kfac[rows] = _square_root_ratio(cl.kref[rows], e)


def row_sum_factor(cl, corr, halo, first: bool, part_max: bool = False):
    """kappa_i = min(1, sqrt(R_i^0 / R_i)) (module docstring): the elements of the
    stale rows of ``cl`` (StepClasses) again (kernels.classes.element_sums), their
    data to the ghosts, and R again at every owned point whose closed family holds a
    changed element (kernels.classes.row_sums).  ``part_max``: R_i^0 is replaced by
    the largest R^0 over i's part (all ranks), the "row_sum_part" factor.
    Collective (halo, and the team for ``part_max``)."""
    p, fam = corr.points, cl.families
    n, nl = p.n_owned, p.n_local
    if first:
        owned = np.arange(n, dtype=np.int64)
        whole = np.zeros_like(fam.broken)
        kref = corr.reference_kinv()
        on = ((corr.spring[:n] != NOT_TL) & kref.any(axis=(1, 2))).astype(np.uint8)
        cl.elem = np.zeros((nl, 11))
        element_sums(p.x, p.volume, corr.omega_i, fam.offsets, fam.nbr, whole, kref, on,
                     owned, cl.elem)
        halo.exchange(cl.elem)
        cl.kref = np.zeros(n)
        row_sums(p.x, p.volume, corr.omega_j, fam.offsets, fam.nbr, whole, cl.elem, owned,
                 cl.kref)
        cl.rnow = cl.kref.copy()
        if part_max:                                    # R^0 of the part's stiffest point
            top = np.zeros(cl.n_parts)
            np.maximum.at(top, p.part[:n], cl.kref)
            if cl.team is not None:
                top = cl.team.max(top)
            cl.kref = top[p.part[:n]]
        cl.changed = np.zeros(nl, np.uint8)
    rows = np.flatnonzero(cl.stale)
    s = corr.spring[:n]
    on = ((s == CORRESPONDENCE) | (s == SPRING_F)).astype(np.uint8)   # K invertible
    element_sums(p.x, p.volume, corr.omega_i, fam.offsets, fam.nbr, fam.broken, corr.Kinv,
                 on, rows, cl.elem)
    cl.changed[:] = 0
    cl.changed[rows] = 1
    halo.exchange(cl.elem, cl.changed)
    redo = cl.rows_around(cl.changed)
    if len(redo):
        row_sums(p.x, p.volume, corr.omega_j, fam.offsets, fam.nbr, fam.broken, cl.elem,
                 redo, cl.rnow)
        cl.kfac[redo] = _square_root_ratio(cl.kref[redo], cl.rnow[redo])


def _square_root_ratio(ref, now) -> np.ndarray:
    """min(1, sqrt(ref / now)) where now > 0, else 1: a family factor from a stiffness
    measure at rest and now (both factors of FAMILY_FACTORS)."""
    f = np.ones(len(now))
    ok = now > 0.0
    f[ok] = np.sqrt(ref[ok] / now[ok])
    return np.minimum(1.0, f)


def part_row_sum_factor(cl, corr, halo, first: bool):
    """kappa_i = min(1, sqrt(max over i's part of R^0 / R_i)) (module docstring)."""
    row_sum_factor(cl, corr, halo, first, part_max=True)


#: the scene's ``family_factor`` (mpipd.input.scene.FAMILY_FACTORS)
FAMILY_FACTORS = {"row_sum": row_sum_factor, "row_sum_part": part_row_sum_factor,
                  "shape_tensor": shape_tensor_factor}


def buffered(families, kbase, top: int, graded: bool, rows, out) -> np.ndarray:
    """out[i] (the owned points i in ``rows``) = the class after the buffer from the
    base classes ``kbase`` of the owned points and ghosts: min over i's family of
    base_j (full), or min(base_i, min over i's family of base_j + 1) (graded)."""
    if graded:
        up = np.minimum(kbase.astype(np.int16) + 1, top).astype(np.uint8)
        family_min(families.offsets, families.nbr, up, rows, out)
        out[rows] = np.minimum(out[rows], kbase[rows])
    else:
        family_min(families.offsets, families.nbr, kbase, rows, out)
    return out


def coarsening_margin(rest, top: int) -> np.ndarray:
    """The factor above a class's threshold 2^k that a point's ratio r must reach to
    coarsen into class k: HYSTERESIS, or half the point's margin at rest if that is
    smaller,  h = clip((1 + m) / 2, 1, HYSTERESIS)  with m = r_rest / 2^k_rest and
    k_rest = clip(floor(log2 r_rest), 0, top) the class the point takes at rest
    (``rest``: r_rest of each point, its ratio at rest).  A point at rest is then
    always back in its class at rest."""
    rest = np.asarray(rest, float)
    with np.errstate(divide="ignore"):
        k = np.clip(np.floor(np.log2(np.maximum(rest, 1e-300))), 0, top)
    return np.clip(0.5 * (1.0 + rest / 2.0 ** k), 1.0, HYSTERESIS)


def projected_cost(bonds_per_class) -> float:
    """Bond evaluations per fine step relative to single-rate: sum_k B_k / 2^k / sum B."""
    b = np.asarray(bonds_per_class, float)
    tot = b.sum()
    return float(sum(b[k] / 2 ** k for k in range(len(b))) / tot) if tot else 1.0
