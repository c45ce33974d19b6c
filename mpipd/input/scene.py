"""Scenes: TOML files in SI units, validated into frozen dataclasses.

A scene has these tables (see ``mpipd/scenes/elastic_wave.toml``)::

    [scene]       name, description
    [time]        dt (s) and exactly one of steps / t_end (s); optionally
                  multirate = { max_ratio = 4, safety = 0.5 } (mpipd.model.multirate)
    [materials.NAME]  model = "elastic", density, bulk_modulus, shear_modulus
    [[parts]]     name, material, dx (m), horizon_factor (default 3.0),
                  shape = { kind = "box" | "cylinder" | "annulus", ... },
                  influence = "quadratic" (default) | "constant" | "inverse",
                  jitter = 0.2, jitter_seed = 1 (lattice jitter, mpipd.input.geometry)
    [solver]      hourglass (Eq. 15 coefficient, default 0.01), progress_every,
                  max_imbalance (the ledger bound that stops a run, default 1e-2), ...
    [[initial]]   kind = "velocity_pulse" | "uniform_velocity" | "gaussian_velocity", ...
    [[boundaries]] kind = "fixed", region = { lo, hi } | "prescribed_velocity", region,
                  velocity, ramp | "absorbing", face, at, thickness, reflection
    [[loads]]     kind = "borehole_pressure", center, radius, p0/alpha/beta or times/pressures
    [[probes]]    name, position, center (radial axis), part (snap to that part's
                  points only): recorded every step
    [[joints]]    point, normal, radius, spacing, persistence, patch, seed, parts, box:
                  pre-existing joints whose crossing bonds start broken (mpipd.input.joints)
    [output]      every (steps), fields

Horizon.  A part's horizon is delta = horizon_factor * dx * (1 + HORIZON_TOL)
with HORIZON_TOL = 1e-3: the family is every point with |xi| < delta, so with the
default factor 3 the lattice shell at exactly |xi| = 3 dx is included (122
neighbours in the bulk, like the peer codes' 3.015 dx) robustly against
round-off, while the influence function omega = (delta - |xi|)^2 stays the
paper's.

Influence function.  A part's ``influence`` picks omega for its points'
side of every bond (mpipd.kernels.influence): "quadratic" (delta - |xi|)^2, the
paper's and the default; "constant" 1, Peridigm's default; "inverse"
delta / |xi|.  Graded rings and an inner band inherit it.

Bad input raises :class:`mpipd.input.schema.SceneError` with one line naming the key.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import tomllib

from ..kernels.influence import CODES as INFLUENCE
from ..materials import MATERIALS
from .geometry import SHAPES
from .joints import Joint
from .loads import BOUNDARIES, INITIAL, LOADS, Absorbing
from .probes import Probe, part_matches
from .schema import SceneError, build, fail, join, non_negative, positive, tagged

HORIZON_TOL = 1e-3


def check_horizon_factor(obj, path):
    """A horizon delta = horizon_factor * dx * (1 + HORIZON_TOL) of at least dx:
    horizon_factor >= 1 (NaN refused), the one check of a part's and an inner band's
    ``horizon_factor`` (SceneError naming ``<path>.horizon_factor``)."""
    if not obj.horizon_factor >= 1.0:
        fail(join(path, "horizon_factor"),
             f"horizon must be at least dx (factor >= 1, got {obj.horizon_factor})")

#: per-point fields that ``[output] fields`` may name: components and what the scene needs
OUTPUT_FIELDS = {
    "u": (3, None), "v": (3, None), "stress": (6, None),
    "stress_work": (1, None),            # W: stress work per reference volume (J/m^3)
    "elastic_energy": (1, None),         # recoverable part of W (J/m^3; 0 once failed)
    "peak_pressure": (1, None), "peak_sigma_rr": (1, None), "peak_speed": (1, None),  # peaks
    "damage": (1, "failure"),            # PD damage phi (Eq. 39)
    "failure_mode": (1, "failure"),      # 0 intact, 1 JH2 D >= 1, 2 JH2 p* < -T*, 3 tension model
    "jh2_damage": (1, "jh2"), "pressure": (1, "pressure"), "plastic_strain": (1, "plastic"),
    "strain_rate": (1, "jh2"),
    "gas_force": (1, "gas"),             # 1 where a gas point carried a force (kernels.ul.well_posed)
}


@dataclass(frozen=True)
class Meta:
    name: str = "unnamed"
    description: str = ""


@dataclass(frozen=True)
class Multirate:
    """Multi-rate integration (mpipd.model.multirate): every point takes steps of
    2^k dt, k from its material's stable step at its current state times
    ``safety``, up to ``max_ratio`` dt (the coarse step: failure, breakage,
    frames and checkpoints happen every ``max_ratio`` steps).  ``buffer``: how a
    point's class follows its family's, "full" (no coarser than any point it pushes)
    or "graded" (at most one class coarser: a step ratio of 2 across any bond);
    ``fracture_class``: the class a point whose family lost bonds in the last
    ``fracture_window`` coarse steps takes at most (a window of 0: no such rule);
    ``family_factor``: how a point's stable step follows the
    bonds it and its neighbours lost, "row_sum" (the Gershgorin row sum at the point
    against its own at rest), "row_sum_part" (against the largest of its part at rest;
    safety at most PART_SAFETY) or "shape_tensor" (lambda_min of its own K)
    (docs/multirate.md, The class rule)."""
    max_ratio: int = 4
    safety: float = 0.5
    buffer: str = "graded"
    fracture_class: int = 0
    fracture_window: int = 2
    family_factor: str = "row_sum"

    def check(self, path):
        if self.max_ratio not in MAX_RATIOS:
            fail(join(path, "max_ratio"), "max_ratio must be one of "
                 + ", ".join(map(str, MAX_RATIOS)) + f" (a power of two up to {MAX_RATIOS[-1]}, "
                 f"the ratios the verification covers); got {self.max_ratio}")
        if not 0.0 < self.safety <= 1.0:
            fail(join(path, "safety"), f"safety must be in (0, 1] (got {self.safety})")
        if self.buffer not in BUFFERS:
            fail(join(path, "buffer"), "buffer must be one of "
                 + ", ".join(f'"{b}"' for b in BUFFERS) + f" (got {self.buffer!r})")
        if self.family_factor not in FAMILY_FACTORS:
            fail(join(path, "family_factor"), "family_factor must be one of "
                 + ", ".join(f'"{b}"' for b in FAMILY_FACTORS) + f" (got {self.family_factor!r})")
        if self.family_factor == "row_sum_part" and self.safety > PART_SAFETY:
            fail(join(path, "safety"), f'family_factor = "row_sum_part" needs safety <= '
                 f"{PART_SAFETY} (its step for a 95 %-crushed family is 1.5x the measured one, "
                 f"studies/multirate/multirate_family_factor.md; got {self.safety})")
        top = self.max_ratio.bit_length() - 1
        if not 0 <= self.fracture_class <= top:
            fail(join(path, "fracture_class"), f"fracture_class must be a class 0..{top} of "
                 f"max_ratio = {self.max_ratio} (got {self.fracture_class})")
        if not 0 <= self.fracture_window <= MAX_FRACTURE_WINDOW:
            fail(join(path, "fracture_window"), f"fracture_window must be a number of coarse "
                 f"steps 0..{MAX_FRACTURE_WINDOW} (got {self.fracture_window})")


#: the coarse/fine step ratios multi-rate integration accepts (verified in make verify)
MAX_RATIOS = (1, 2, 4, 8)
#: the longest fracture window (coarse steps) a scene may ask for
MAX_FRACTURE_WINDOW = 8
#: how a point's class follows its family's (mpipd.model.multirate.StepClasses._spread)
BUFFERS = ("full", "graded")
#: how a point's stable step follows its family (mpipd.model.multirate.FAMILY_FACTORS)
FAMILY_FACTORS = ("row_sum", "row_sum_part", "shape_tensor")
#: the largest safety of the "row_sum_part" family factor: the granite block's measured
#: critical step over its step is 1.6 at 0.5 with 95 % of a ball's bonds broken
#: (studies/multirate/family_factor.py), below 1 above 0.8; granite_ring at 0.9 fails more points
PART_SAFETY = 0.5


@dataclass(frozen=True)
class Time:
    dt: float
    steps: int | None = None
    t_end: float | None = None
    multirate: Multirate | None = None

    def check(self, path):
        positive(self, path, "dt")
        if (self.steps is None) == (self.t_end is None):
            fail(join(path, "steps"), "give exactly one of steps and t_end")
        if self.steps is not None and self.steps < 0:
            fail(join(path, "steps"), f"must be >= 0 (got {self.steps})")
        if self.t_end is not None:
            non_negative(self, path, "t_end")

    @property
    def n_steps(self) -> int:
        if self.steps is not None:
            return self.steps
        return int(math.ceil(self.t_end / self.dt - 1e-9))


@dataclass(frozen=True)
class Grade:
    """Radial grading of a cylinder or annulus part (paper §3.4, "adaptive
    meshing"): ``zones`` concentric rings of equal width whose dx grows linearly
    from the part's ``dx`` (innermost ring) to ``dx_outer`` (outermost), each
    with horizon ``horizon_factor`` * its dx.  The rings are parts of their own
    (named ``<part>.0``, ``<part>.1``, ...), joined by dual horizons and the
    interface correction."""
    dx_outer: float
    zones: int = 5

    def check(self, path):
        positive(self, path, "dx_outer")
        if self.zones < 2:
            fail(join(path, "zones"), f"needs at least 2 zones (got {self.zones})")


@dataclass(frozen=True)
class Band:
    """An inner ring of an annulus part at a resolution of its own, ``width`` wide.

    Given the neighbour's ``dx`` and ``horizon_factor`` (the paper's copper tube:
    0.3 mm, 3.3333333), the tube and the band share one lattice and one horizon,
    so their interface is seamless, and the step to the part's own dx moves
    ``width`` out — far enough from the bore (two reaches of the coarse side plus
    the coarse horizon) and it is corrected in full.  Named ``<part>.band``."""
    dx: float
    width: float
    horizon_factor: float = 3.0

    def check(self, path):
        positive(self, path, "dx")
        positive(self, path, "width")
        check_horizon_factor(self, path)


@dataclass(frozen=True)
class Initiation:
    """When and where a charge (a part of the explosive) is lit, at ``time`` (s):
    from the face z = ``z``, the detonation running along +z (``direction`` 1) or
    -z (-1), so that a point at reference height z' is lit at
    time + (z' - z) direction / vod; or from a ``point`` (x, y, z), a primer, the
    front running out from it in every direction, so that a point at reference
    position x' is lit at time + |x' - point| / vod (a charge along any axis,
    :class:`mpipd.input.geometry.Rod`).  mpipd.model.gas.lighting_times.  A
    charge without one follows its material's initiation_z and direction at
    time 0.  ``never = true``: a charge that is not lit at all (unlit gas all run,
    e.g. a thrown charge); without it, a charge none of whose points is lit before
    the run's end, or whose plane or point lies outside it, is bad input
    (mpipd.model.gas.check_charges)."""
    z: float = 0.0
    time: float = 0.0
    direction: float = 1.0
    point: tuple[float, float, float] | None = None
    never: bool = False

    def check(self, path):
        non_negative(self, path, "time")
        if self.direction not in (1.0, -1.0):
            fail(join(path, "direction"), "must be 1 or -1")
        if self.point is not None and (self.z != 0.0 or self.direction != 1.0):
            fail(join(path, "point"), "give either point or z and direction, not both")
        if self.never and (self.point is not None or self.z != 0.0 or self.time != 0.0
                           or self.direction != 1.0):
            fail(join(path, "never"), "a charge that is never lit takes no z, time, "
                                      "direction or point")

    def times(self, x, vod):
        """Lighting times of reference positions ``x`` (n, 3) (class docstring;
        infinite for a charge that is never lit)."""
        if self.never:
            return np.full(len(x), np.inf)
        if self.point is not None:
            return self.time + np.linalg.norm(x - np.asarray(self.point), axis=1) / vod
        return self.time + (x[:, 2] - self.z) * self.direction / vod


@dataclass(frozen=True)
class Part:
    name: str
    material: str
    dx: float
    shape: Any = tagged(SHAPES)
    horizon_factor: float = 3.0
    grade: Grade | None = None
    band: Band | None = None
    influence: str = "quadratic"
    jitter: float = 0.0               # lattice jitter, fraction of dx (mpipd.input.geometry)
    jitter_seed: int = 1
    initiation: Initiation | None = None    # a charge's own initiation (explosive parts)

    def check(self, path):
        positive(self, path, "dx")
        if not 0.0 <= self.jitter < 0.5:
            fail(join(path, "jitter"), f"must be in [0, 0.5): the offset on each axis is at "
                                       f"most jitter * dx (got {self.jitter})")
        non_negative(self, path, "jitter_seed")
        if self.influence not in INFLUENCE:
            fail(join(path, "influence"), f"unknown influence function {self.influence!r} "
                                          f"(known: {', '.join(INFLUENCE)})")
        check_horizon_factor(self, path)
        if self.grade is not None and not hasattr(self.shape, "radius"):
            fail(join(path, "grade"), "grading needs a cylinder or annulus shape")
        if self.band is not None:
            r0 = getattr(self.shape, "inner_radius", None)
            if r0 is None:
                fail(join(path, "band"), "an inner band needs an annulus shape")
            if not self.band.width < self.shape.radius - r0:
                fail(join(join(path, "band"), "width"),
                     f"must be less than the annulus's width {self.shape.radius - r0:g}")

    def zones(self) -> list["Part"]:
        """The part itself, or its inner band and graded rings as separate plain parts."""
        if self.band is not None:
            b, sh = self.band, self.shape
            edge = sh.inner_radius + b.width
            ring = SHAPES.get("annulus")(center=sh.center, radius=edge, z=sh.z,
                                         inner_radius=sh.inner_radius)
            rest = SHAPES.get("annulus")(center=sh.center, radius=sh.radius, z=sh.z,
                                         inner_radius=edge)
            inner = replace(self, name=f"{self.name}.band", dx=b.dx,
                            horizon_factor=b.horizon_factor, shape=ring, grade=None, band=None)
            return [inner] + replace(self, shape=rest, band=None).zones()
        g = self.grade
        if g is None:
            return [self]
        sh = self.shape
        r0 = getattr(sh, "inner_radius", 0.0)
        edges = r0 + (sh.radius - r0) * np.arange(g.zones + 1) / g.zones
        out = []
        for k in range(g.zones):
            dx = self.dx + (g.dx_outer - self.dx) * k / (g.zones - 1)
            if edges[k] > 0.0:
                ring = SHAPES.get("annulus")(center=sh.center, radius=float(edges[k + 1]),
                                             z=sh.z, inner_radius=float(edges[k]))
            else:
                ring = SHAPES.get("cylinder")(center=sh.center, radius=float(edges[k + 1]),
                                              z=sh.z)
            out.append(replace(self, name=f"{self.name}.{k}", dx=float(dx), shape=ring,
                               grade=None, band=None))
        return out

    @property
    def horizon(self) -> float:
        return self.horizon_factor * self.dx * (1.0 + HORIZON_TOL)


@dataclass(frozen=True)
class Viscosity:
    """Artificial viscosity (Eqs. 42–44): quadratic ``cq`` and linear ``cl`` coefficients."""
    cq: float = 8.0
    cl: float = 0.1

    def check(self, path):
        non_negative(self, path, "cq", "cl")


@dataclass(frozen=True)
class Solver:
    """Numerical switches.  ``damping`` is c of Eq. 41 in 1/s for points with
    phi = 1 (the paper's 0.2 per microsecond is 2e5 1/s); 0 switches it off.
    ``contact`` turns on Eq. 40 on broken bonds; ``viscosity`` Eqs. 42–44.
    ``interface_correction`` removes the ghost force where dx or the horizon
    changes (mpipd.model.interface); it only exists in scenes whose parts differ.
    ``refresh_after_break`` recomputes the forces after a step in which bonds
    broke, so the next half kick uses the broken state's forces: velocity Verlet
    otherwise applies the pre-break force for one more half step, a first-order
    error at each breakage (it shows in the energy ledger's balance); it costs a
    second force evaluation on such steps.  ``max_imbalance`` stops a run (exit 3,
    the state in checkpoint_failed.h5) at the first frame or progress line whose
    energy ledger passes it: |balance|, or a term that cannot be negative below
    -max_imbalance x the ledger's scale (mpipd.solver.Simulation.check_ledger);
    0 never stops.  The report calls anything beyond 1e-3 an error
    (mpipd.model.ledger.BALANCE_TOL); the default stops at ten times that, where
    the run's numbers can no longer be booked."""
    hourglass: float = 0.01
    progress_every: int = 0           # steps between progress lines; 0 = about every 2 s
    contact: bool = False
    damping: float = 0.0
    viscosity: Viscosity | None = None
    interface_correction: bool = True
    refresh_after_break: bool = False
    max_imbalance: float = 1e-2

    def check(self, path):
        non_negative(self, path, "hourglass", "progress_every", "damping", "max_imbalance")


@dataclass(frozen=True)
class Output:
    """``every`` (steps between frames), ``fields``, ``checkpoint_every``, and
    ``peak_center``: the (x, y) of the z axis about which ``peak_sigma_rr`` is
    radial (mpipd.output.peaks)."""
    every: int = 10
    fields: tuple[str, ...] = ("u", "v")
    checkpoint_every: int = 0         # steps between checkpoints; 0 = only on signal/stop
    peak_center: tuple[float, float] = (0.0, 0.0)

    def check(self, path):
        positive(self, path, "every")
        non_negative(self, path, "checkpoint_every")
        for i, f in enumerate(self.fields):
            if f == "strain_energy":
                fail(join(join(path, "fields"), i), "'strain_energy' is now 'stress_work' "
                     "(total stress work); 'elastic_energy' is its recoverable part")
            if f not in OUTPUT_FIELDS:
                fail(join(join(path, "fields"), i),
                     f"unknown field {f!r} (known: {', '.join(OUTPUT_FIELDS)})")
        if len(set(self.fields)) != len(self.fields):
            fail(join(path, "fields"), "a field is listed twice")


@dataclass(frozen=True)
class Scene:
    time: Time
    parts: tuple[Part, ...]
    materials: dict = tagged(MATERIALS, dict)
    scene: Meta = field(default_factory=Meta)
    solver: Solver = field(default_factory=Solver)
    initial: tuple = tagged(INITIAL, list, default=())
    boundaries: tuple = tagged(BOUNDARIES, list, default=())
    loads: tuple = tagged(LOADS, list, default=())
    probes: tuple[Probe, ...] = ()
    joints: tuple[Joint, ...] = ()
    output: Output = field(default_factory=Output)

    def __post_init__(self):
        # a graded part becomes its rings (Grade): everything downstream sees plain parts
        if any(p.grade is not None or p.band is not None for p in self.parts):
            object.__setattr__(self, "parts", tuple(z for p in self.parts for z in p.zones()))

    def check(self, path):
        if not self.parts:
            fail("parts", "a scene needs at least one part")
        if not self.materials:
            fail("materials", "a scene needs at least one material")
        names = set()
        for i, p in enumerate(self.parts):
            if p.material not in self.materials:
                fail(f"parts.{i}.material",
                     f"no material {p.material!r} (defined: {', '.join(self.materials)})")
            if p.name in names:
                fail(f"parts.{i}.name", f"duplicate part name {p.name!r}")
            if p.influence != "quadratic" and p.material in self.gas_materials:
                fail(f"parts.{i}.influence", "the explosive gas (updated-Lagrangian) always "
                                              "uses the quadratic influence function")
            names.add(p.name)
        gas = self.gas_materials
        for i, p in enumerate(self.parts):
            if p.initiation is not None and p.material not in gas:
                fail(f"parts.{i}.initiation", f"only a charge (a part of an explosive, jwl, "
                                               f"material) is initiated; {p.material!r} is not")
        if len(gas) > 1:
            fail("materials", f"one explosive (jwl) material at most (got {', '.join(gas)})")
        for m in gas:
            for a in self.materials[m].interacts_with:
                if a not in self.materials or a == m:
                    fail(f"materials.{m}.interacts_with", f"no other material {a!r}")
        for i, ld in enumerate(self.loads):
            if hasattr(ld, "check_parts"):          # loads placed on the geometry
                ld.check_parts(self.parts, f"loads.{i}")
        for i, jt in enumerate(self.joints):
            jt.check_parts(self.parts, f"joints.{i}")
        gas = set(self.gas_materials)
        solids = {p.material for p in self.parts} - gas
        for i, bc in self.absorbing_layers:
            for m in sorted(solids):
                cd = float(bc.c_max(self.materials[m].p_wave_speed)) * self.time.dt
                if cd > 2.0:
                    fail(f"boundaries.{i}.thickness",
                         f"the layer's damping at the face, c_max dt = {cd:.3g} for {m!r}, "
                         f"exceeds 2 (the damped update then reverses velocities): "
                         f"make the layer thicker or the reflection larger")
        if self.joints and not self.solver.contact:
            fail("solver.contact", "joints need contact (true): the faces of a joint "
                                   "would otherwise pass through each other")
        seen = set()
        for i, pr in enumerate(self.probes):
            if pr.name in seen or not pr.name.isidentifier():
                fail(f"probes.{i}.name", f"probe names must be unique identifiers ({pr.name!r})")
            seen.add(pr.name)
            if pr.part is not None and not any(part_matches(pr.part, p.name)
                                               for p in self.parts):
                known = ", ".join(p.name for p in self.parts)
                fail(f"probes.{i}.part", f"no part {pr.part!r} (parts: {known})")
        mr = self.time.multirate
        if mr is not None and mr.max_ratio > 1:
            r = mr.max_ratio
            for where, n in (("time.steps", self.time.n_steps), ("output.every", self.output.every),
                             ("output.checkpoint_every", self.output.checkpoint_every)):
                if n % r:
                    fail(where, f"must be a multiple of time.multirate.max_ratio = {r} "
                                f"(got {n}): states are all current only at coarse steps")
        needs = {"failure": self.can_fail, "jh2": self.has_model("jh2"),
                 "plastic": self.has_model("jh2") or self.has_model("j2"),
                 "pressure": self.has_model("jh2") or self.has_model("jwl"),
                 "gas": self.has_model("jwl")}
        for i, f in enumerate(self.output.fields):
            need = OUTPUT_FIELDS[f][1]
            if need is not None and not needs[need]:
                what = {"failure": "a material that can fail (jh2, or a tension model)",
                    "jh2": "a jh2 material", "plastic": "a jh2 or j2 material",
                    "pressure": "a jh2 or jwl material", "gas": "a jwl material"}[need]
                fail(f"output.fields.{i}", f"{f!r} needs {what}")

    @property
    def name(self) -> str:
        return self.scene.name

    @property
    def material_ids(self) -> dict[str, int]:
        """Material name -> id, in the order the scene defines them."""
        return {m: k for k, m in enumerate(self.materials)}

    @property
    def gas_materials(self) -> list[str]:
        """The materials whose points are the updated-Lagrangian gas (family "ul"),
        in scene order: the one place that tells the gas from the solids."""
        return [m for m, mat in self.materials.items() if mat.family == "ul"]

    @property
    def absorbing_layers(self) -> list[tuple[int, object]]:
        """(index in ``boundaries``, layer) of the absorbing layers
        (mpipd.input.loads.Absorbing): the one place that tells them apart."""
        return [(i, bc) for i, bc in enumerate(self.boundaries) if isinstance(bc, Absorbing)]

    @property
    def gas_parts(self) -> list[int]:
        """Indices of the parts made of a gas material."""
        gas = set(self.gas_materials)
        return [k for k, q in enumerate(self.parts) if q.material in gas]

    @property
    def can_fail(self) -> bool:
        used = {p.material for p in self.parts}
        return any(self.materials[m].can_fail for m in used)

    def has_model(self, name: str) -> bool:
        used = {p.material for p in self.parts}
        return any(self.materials[m].registry_name == name for m in used)

    @property
    def max_horizon(self) -> float:
        return max(p.horizon for p in self.parts)

    @property
    def max_dx(self) -> float:
        return max(p.dx for p in self.parts)


# --------------------------------------------------------------------------- loading

def scenes_dir() -> Path:
    """The folder of the built-in scenes (``mpipd/input/scenes`` in the package)."""
    return Path(str(resources.files("mpipd.input") / "scenes"))


def cases_dir() -> Path:
    """The folder of the built-in scenes' named cases, one ``<scene>.toml`` a scene."""
    return scenes_dir() / "cases"


def builtin_scenes() -> dict[str, Path]:
    """Built-in scene name -> file."""
    root = scenes_dir()
    return {p.stem: p for p in root.iterdir() if p.name.endswith(".toml")}


def resolve(source: str) -> Path:
    """A scene argument is a path to a TOML file or the name of a built-in scene."""
    p = Path(source)
    if p.is_file():
        return p
    builtins = builtin_scenes()
    if source in builtins:
        return builtins[source]
    if p.exists():
        fail("scene", f"{source} is not a file")
    fail("scene", f"no file or built-in scene named {source!r} "
                  f"(built-in: {', '.join(sorted(builtins))})")


def parse_override(text: str) -> tuple[list, Any]:
    """``key.path=value`` -> (path components, value).  The value is read as a
    TOML value (``3``, ``1e-3``, ``[0, 0, 1]``, ``"box"``, ``true``); anything
    that is not valid TOML is taken as a plain string."""
    if "=" not in text:
        fail("--set", f"expected key.path=value, got {text!r}")
    key, raw = text.split("=", 1)
    key = key.strip()
    if not key:
        fail("--set", f"empty key in {text!r}")
    try:
        value = tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    path = [int(k) if k.isdigit() else k for k in key.split(".")]
    return path, value


def apply_override(raw: dict, path: list, value) -> None:
    node = raw
    shown = ""
    for k in path[:-1]:
        shown = join(shown, k)
        if isinstance(node, list):
            if not isinstance(k, int) or not 0 <= k < len(node):
                fail(shown, f"--set: no entry {k!r} here (array of {len(node)})")
            node = node[k]
        elif isinstance(node, dict):
            node = node.setdefault(k, {})
        else:
            fail(shown, "--set: not a table")
    last = path[-1]
    if isinstance(node, list):
        if not isinstance(last, int) or not 0 <= last < len(node):
            fail(join(shown, last), f"--set: no entry here (array of {len(node)})")
        node[last] = value
    elif isinstance(node, dict):
        node[str(last)] = value
    else:
        fail(shown, "--set: not a table")


def parse(text: str, origin: str = "scene", overrides=()) -> Scene:
    """Validate TOML text (plus ``key.path=value`` overrides) into a :class:`Scene`."""
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        fail(origin, f"not a valid TOML file: {e}")
    for o in overrides:
        path, value = parse_override(o)
        apply_override(raw, path, value)
        for other in EXCLUSIVE.get(tuple(path), ()):     # the later setting wins
            raw.get(other[0], {}).pop(other[1], None)
    return build(Scene, raw)


#: keys of which a scene gives one: an override of one removes the others
EXCLUSIVE = {("time", "steps"): (("time", "t_end"),),
             ("time", "t_end"): (("time", "steps"),)}


@dataclass(frozen=True)
class Case:
    """A named case of a built-in scene: a list of ``--set`` overrides."""
    set: tuple[str, ...]
    description: str = ""
    study: str = ""


def cases(scene_name: str) -> dict[str, Case]:
    """The named cases of a built-in scene (``mpipd/input/scenes/cases/<scene>.toml``)."""
    f = cases_dir() / f"{scene_name}.toml"
    if not f.is_file():
        return {}
    raw = tomllib.loads(f.read_text())
    return {name: build(Case, table, f"cases.{name}") for name, table in raw.items()}


def expand_case(source: str, overrides=()) -> tuple[str, list[str]]:
    """``SCENE:CASE`` -> (SCENE, the case's overrides + ``overrides``); the run is
    named ``SCENE-CASE``.  Anything else comes back unchanged."""
    if ":" not in source or Path(source).is_file():
        return source, list(overrides)
    base, name = source.rsplit(":", 1)
    if base not in builtin_scenes():      # a path with a ':' in it: resolve says what is missing
        return source, list(overrides)
    known = cases(base)
    if name not in known:
        fail("scene", f"no case {name!r} of {base!r} "
                      f"(cases: {', '.join(known) if known else 'none'})")
    return base, [*known[name].set, f'scene.name="{base}-{name}"', *overrides]


def load(source: str, overrides=()) -> tuple[Scene, str]:
    """Load a scene from a path, a built-in name or ``built-in:case``.
    Returns (scene, TOML text of the base scene)."""
    source, overrides = expand_case(source, overrides)
    path = resolve(source)
    try:
        text = path.read_text(encoding="utf-8-sig")     # a UTF-8 BOM is no TOML statement
    except (OSError, UnicodeDecodeError) as e:
        fail(str(source), f"cannot read: {e}")
    return parse(text, str(source), overrides), text


__all__ = ["Scene", "SceneError", "load", "parse", "builtin_scenes", "cases", "expand_case",
           "HORIZON_TOL"]
