"""What the analysis needs to know about the modelled specimen (paper Fig. 6).

The borehole axis ``center`` (x, y), the borehole-wall radius ``r_wall`` (the
rock part's inner radius: the copper tube sits inside the borehole), the outer
radius ``r_out``, the rock's thickness ``z0..z1`` and lattice spacing ``dx``,
the rock's horizon, the densities and the JH2 parameters are read from the scene text stored in the
run file (``attrs['scene']``, parsed with :func:`mpipd.input.scene.parse` together with
the ``--set`` overrides recorded after ``# overrides (--set)``).  If the scene
cannot be parsed, or the rock is not an annulus, they fall back to the geometry:

    r_wall = min r - dx/2,   r_out = max r + dx/2,   dx = V^(1/3)

over the rock points (exact for the lattice of ``mpipd.input.geometry``: cell centres
at half-integer multiples of dx).  Which fallback was used is in ``notes``.

The rock is the part named ``rock``; else the part of a ``jh2`` material; else
the largest part.  A rock split into zones (``<rock>.band``, ``<rock>.0``, ...;
:meth:`mpipd.input.scene.Part.zones`) is all of them: ``rock_ids`` lists every zone,
R_b is the innermost zone's inner radius, R_o the outermost zone's radius and
``wall_dx`` the innermost zone's dx (the wall layer is r < R_b + wall_dx);
``rock`` is the reference zone (the one named ``rock``, or the first): the sections
are named by its z levels and every other zone joins them at its own nearest level
(:mod:`mpipd.post.sections`); ``zone_dx`` and ``zone_horizon`` give each zone's dx and
horizon (from the scene; else dx = V^(1/3) of the zone's points and 3 dx).
The charge is the part of a ``jwl`` material (or ``charge``); ``explosive`` is its
material (JWL constants, Table 2) when the scene parses.
``peak_center`` is the axis of the run's ``peak_sigma_rr`` field (the scene's
``[output] peak_center``, default (0, 0)).

``tubes`` are the tubes that hold a charge (paper Fig. 6: the copper tube inside the
borehole), from the parsed scene only: a part that is an annulus, not a zone of the
rock and not of a ``jwl`` material, around a ``jwl`` part that is a cylinder on the
same axis (within the tube's dx) no wider than the tube's inner radius + its dx.
Each is ``{"part", "name", "center", "r_in", "r_out", "z", "dx", "charges"}``
(``charges``: the part indices of the charges it holds).  No scene, no tube.

``charges`` are every charge of the scene, one a part of a ``jwl`` material:
``{"part", "name", "material", "center", "radius", "z", "dx", "p_CJ", "tube"}``
(``radius``: the cylinder's, the hole it fills; ``p_CJ``: the Chapman-Jouguet pressure
of its JWL constants times its ``pressure_factor``, Pa; ``tube``: the name of the tube
holding it, or None).  Without a parsed scene there is no charge geometry: no charge.

:func:`paper_geometry` says whether the scene is the paper's specimen (Fig. 6): a
cylinder of rock (an annulus, every zone) with one charge on its axis, held by a tube.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

OVERRIDES_MARK = "# overrides (--set)"


def split_scene_text(text: str) -> tuple[str, list[str]]:
    """The stored scene text and the ``--set`` overrides listed after the mark."""
    if OVERRIDES_MARK not in text:
        return text, []
    head, tail = text.split(OVERRIDES_MARK, 1)
    sets = [ln[1:].strip() for ln in tail.splitlines() if ln.startswith("#") and "=" in ln]
    return head, sets


@dataclass
class Model:
    label: str
    scene_name: str
    center: tuple[float, float]
    r_wall: float
    r_out: float
    z0: float
    z1: float
    dx: float
    rock: int                                   # part index of the rock
    charge: int | None                          # part index of the explosive (or None)
    part_names: list[str]
    material_names: list[str]
    density: dict = field(default_factory=dict)  # material id -> kg/m^3
    jh2: object = None                           # the rock's JH2 material (or None)
    pressure_factor: float | None = None
    horizon: float | None = None                 # the rock's horizon (m); None -> 3 dx
    rock_ids: tuple = ()                         # part indices of every zone of the rock
    zone_dx: dict = field(default_factory=dict)       # zone part index -> its dx (m)
    zone_horizon: dict = field(default_factory=dict)  # zone part index -> its horizon (m)
    wall_dx: float | None = None                 # dx of the rock's innermost zone
    explosive: object = None                     # the charge's JWL material (or None)
    peak_center: tuple = (0.0, 0.0)              # axis of the peak_sigma_rr field
    part_material: dict = field(default_factory=dict)   # part index -> material name
    explosive_materials: tuple = ()              # names of the jwl materials (the gas)
    probe_parts: dict = field(default_factory=dict)     # probe name -> its scene ``part``
    tubes: list = field(default_factory=list)    # the tubes holding a charge (docstring)
    charges: list = field(default_factory=list)  # every charge (module docstring)
    rock_is_annulus: bool = False                # every zone of the rock is an annulus
    rock_material: str | None = None             # the rock's material name (scene)
    rock_base: str = "rock"                      # the rock's part name without its zone
    scene_parts: list = field(default_factory=list)     # the scene's part names, in order
    overrides: list = field(default_factory=list)
    notes: list = field(default_factory=list)

    @property
    def thickness(self) -> float:
        return self.z1 - self.z0

    @property
    def zone_ids(self) -> tuple:
        """Every zone of the rock (the reference zone alone if it is not split)."""
        return tuple(self.rock_ids or (self.rock,))

    def dx_of(self, zone: int) -> float:
        return float(self.zone_dx.get(zone, self.dx))

    def horizon_of(self, zone: int) -> float:
        h = self.horizon if self.horizon is not None else 3.0 * self.dx
        return float(self.zone_horizon.get(zone, h))

    def is_rock(self, pid: np.ndarray) -> np.ndarray:
        """Mask of the points (part indices ``pid``) in any zone of the rock."""
        return np.isin(pid, np.asarray(self.rock_ids or (self.rock,)))

    def radius(self, x: np.ndarray) -> np.ndarray:
        return np.hypot(x[:, 0] - self.center[0], x[:, 1] - self.center[1])

    def summary(self) -> dict:
        return {"scene": self.scene_name, "center_m": list(self.center), "r_wall_m": self.r_wall,
                "r_out_m": self.r_out, "z_m": [self.z0, self.z1], "dx_m": self.dx,
                "horizon_m": self.horizon,
                "rock_part": self.part_names[self.rock],
                "rock_zones": [self.part_names[k] for k in self.rock_ids],
                "wall_dx_m": self.wall_dx,
                "charge_part": None if self.charge is None else self.part_names[self.charge],
                "pressure_factor": self.pressure_factor,
                "gas_acts_on": (None if self.explosive is None
                                else list(getattr(self.explosive, "interacts_with", ()))),
                "overrides": self.overrides,
                "notes": self.notes}


def _parse_scene(run, notes):
    text = run.attr("scene")
    if not text:
        notes.append("the run file stores no scene text: geometry from the points")
        return None, []
    body, sets = split_scene_text(str(text))
    try:
        from mpipd.input.scene import parse
        return parse(body, "stored scene", sets), sets
    except Exception as e:                                  # noqa: BLE001 (SceneError, ImportError)
        notes.append(f"the stored scene does not parse ({' '.join(str(e).split())}): "
                     "geometry from the points")
        return None, sets


def zone_of(name: str, part: str) -> bool:
    """Is ``name`` the part ``part`` or one of its zones (``part.band``, ``part.0``, ...)?"""
    return name == part or name.startswith(part + ".")


def base_name(name: str) -> str:
    """The part a zone belongs to: ``rock.band`` / ``rock.3`` -> ``rock``."""
    head, _, tail = name.rpartition(".")
    return head if head and (tail == "band" or tail.isdigit()) else name


def _pick(names, models, want_name, want_model):
    if want_name in names:
        return names.index(want_name)
    for k, m in enumerate(models):
        if m == want_model:
            return k
    return None


def load_model(run, label: str | None = None) -> Model:
    """Collective: every rank gets the same :class:`Model`."""
    notes: list[str] = []
    parts = run.names("part")
    mats = run.names("material")
    scene, sets = _parse_scene(run, notes)
    part_mat = {}
    models = [None] * len(parts)
    if scene is not None:
        sparts = {p.name: p for p in scene.parts}
        for k, name in enumerate(parts):
            if name in sparts:
                part_mat[k] = sparts[name].material
                models[k] = scene.materials[sparts[name].material].registry_name
    # point counts per part decide when names and models do not
    pid = run.geometry("part")
    counts = run.sum_array(np.bincount(pid, minlength=len(parts)).astype(np.int64))
    rock = _pick(parts, models, "rock", "jh2")
    if rock is None:
        rock = int(np.argmax(counts))
        notes.append(f"no part named 'rock' or of a jh2 material: the largest part "
                     f"{parts[rock]!r} is taken as the rock")
    charge = _pick(parts, models, "charge", "jwl")
    rock_base = base_name(parts[rock])
    rock_ids = tuple(k for k, n in enumerate(parts) if zone_of(n, rock_base)) or (rock,)
    x = run.geometry("x")
    sel = np.isin(pid, rock_ids)
    vol = run.geometry("volume")[pid == rock]
    xr = x[sel]
    dx_geo = float(np.cbrt(run.max(float(vol.max()) if len(vol) else 0.0)))
    shape, zones = None, []
    sparts = {p.name: p for p in scene.parts} if scene is not None else {}
    if parts[rock] in sparts:
        spart = sparts[parts[rock]]
        shape = spart.shape
        dx = spart.dx
        horizon = spart.horizon
        zones = [sparts[parts[k]] for k in rock_ids if parts[k] in sparts]
    else:
        dx = dx_geo
        horizon = 3.0 * dx
        notes.append("the rock's horizon is not known from the scene: 3 dx assumed")
    wall_dx = dx
    if shape is not None and all(hasattr(z.shape, "inner_radius") for z in zones):
        inner = min(zones, key=lambda z: z.shape.inner_radius)
        center = (float(shape.center[0]), float(shape.center[1]))
        r_wall = float(inner.shape.inner_radius)
        r_out = float(max(z.shape.radius for z in zones))
        z0, z1 = float(shape.z[0]), float(shape.z[1])
        wall_dx = float(inner.dx)
        if len(zones) > 1:
            notes.append(f"the rock is {len(zones)} zones ({', '.join(z.name for z in zones)}): "
                         f"sections take each zone at its level nearest {parts[rock]!r}'s, "
                         "a failed point counts its own zone's dx")
    else:
        if shape is not None:
            notes.append(f"the rock part is a {type(shape).__name__.lower()}, not an annulus: "
                         "borehole radius from the points")
        lo = [run.min(float(xr[:, k].min()) if len(xr) else np.inf) for k in range(3)]
        hi = [run.max(float(xr[:, k].max()) if len(xr) else -np.inf) for k in range(3)]
        center = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]))
        r = np.hypot(xr[:, 0] - center[0], xr[:, 1] - center[1])
        r_wall = run.min(float(r.min()) if len(r) else np.inf) - 0.5 * dx
        r_out = run.max(float(r.max()) if len(r) else 0.0) + 0.5 * dx
        z0, z1 = lo[2] - 0.5 * dx, hi[2] + 0.5 * dx
    zone_dx, zone_horizon = {}, {}
    for k in rock_ids:
        if parts[k] in sparts:
            zp = sparts[parts[k]]
            zone_dx[k], zone_horizon[k] = float(zp.dx), float(zp.horizon)
        else:
            v = run.geometry("volume")[pid == k]
            zone_dx[k] = float(np.cbrt(run.max(float(v.max()) if len(v) else 0.0)))
            zone_horizon[k] = 3.0 * zone_dx[k]
    density, jh2, pf, explosive, probe_parts = {}, None, None, None, {}
    explosives = (tuple(n for n, m in scene.materials.items() if m.registry_name == "jwl")
                  if scene is not None else ("explosive",))
    peak_center = (0.0, 0.0)
    if scene is not None:
        peak_center = tuple(float(c) for c in getattr(scene.output, "peak_center", (0.0, 0.0)))
        probe_parts = {pr.name: getattr(pr, "part", None) for pr in scene.probes}
        for mid, name in enumerate(mats):
            if name in scene.materials:
                density[mid] = float(scene.materials[name].density)
        rock_mat = scene.materials.get(part_mat.get(rock))
        if rock_mat is not None and rock_mat.registry_name == "jh2":
            jh2 = rock_mat
        if charge is not None and part_mat.get(charge) in scene.materials:
            explosive = scene.materials[part_mat[charge]]
            pf = getattr(explosive, "pressure_factor", None)
    tubes = _tubes(parts, sparts, models, rock_ids)
    charges = _charges(parts, sparts, models, scene, tubes) if scene is not None else []
    annulus = bool(shape is not None and zones
                   and all(hasattr(z.shape, "inner_radius") for z in zones))
    name = str(run.attr("scene_name", scene.name if scene is not None else "unknown"))
    return Model(label=label or name, scene_name=name, center=center, r_wall=r_wall,
                 r_out=r_out, z0=z0, z1=z1, dx=float(dx), rock=rock, charge=charge,
                 part_names=parts, material_names=mats, density=density, jh2=jh2,
                 pressure_factor=pf, horizon=float(horizon), overrides=sets, notes=notes,
                 rock_ids=rock_ids, zone_dx=zone_dx, zone_horizon=zone_horizon,
                 wall_dx=float(wall_dx), explosive=explosive,
                 peak_center=peak_center, part_material=part_mat, probe_parts=probe_parts,
                 explosive_materials=explosives, tubes=tubes, charges=charges,
                 rock_is_annulus=annulus, rock_material=part_mat.get(rock),
                 rock_base=rock_base,
                 scene_parts=[p.name for p in scene.parts] if scene is not None else [])


def paper_geometry(model) -> tuple[bool, str]:
    """Is the scene the paper's specimen (Fig. 6)?  A cylinder of rock (every zone an
    annulus), exactly one charge, on the rock's axis (within the rock's dx), held by a
    tube.  Returns the answer and why (the first condition that fails, or the match)."""
    if not model.rock_is_annulus:
        return False, "the rock is not a cylinder around a borehole (an annulus)"
    if len(model.charges) != 1:
        return False, f"the scene has {len(model.charges)} charges, not one"
    c = model.charges[0]
    off = float(np.hypot(c["center"][0] - model.center[0], c["center"][1] - model.center[1]))
    if off > model.dx:
        return False, f"the charge is {off * 1e3:.3g} mm off the rock's axis"
    if c["tube"] is None:
        return False, "no tube holds the charge"
    return True, (f"a cylinder of rock ({model.part_names[model.rock]!r}) with one charge "
                  f"({c['name']!r}) on its axis in a tube ({c['tube']!r})")


def _charges(parts, sparts, models, scene, tubes) -> list[dict]:
    """Every charge of the parsed scene (module docstring)."""
    out = []
    held = {c: t["name"] for t in tubes for c in t["charges"]}
    for k, n in enumerate(parts):
        sp = sparts.get(n)
        if sp is None or models[k] != "jwl":
            continue
        sh, mat = sp.shape, scene.materials[sp.material]
        center = (tuple(float(v) for v in sh.center[:2]) if hasattr(sh, "center") else None)
        radius = float(sh.radius) if hasattr(sh, "radius") else None
        z = (float(sh.z[0]), float(sh.z[1])) if hasattr(sh, "z") else None
        p_cj = None
        if hasattr(mat, "chapman_jouguet"):
            p_cj = float(mat.chapman_jouguet()["p"]) * float(getattr(mat, "pressure_factor", 1.0))
        out.append({"part": k, "name": n, "material": sp.material, "center": center,
                    "radius": radius, "z": z, "dx": float(sp.dx), "p_CJ": p_cj,
                    "tube": held.get(k)})
    return out


def _tubes(parts, sparts, models, rock_ids) -> list[dict]:
    """The tubes that hold a charge (module docstring), from the scene's parts."""
    out = []
    charges = [(k, sparts[n]) for k, n in enumerate(parts) if models[k] == "jwl" and n in sparts]
    for k, n in enumerate(parts):
        sp = sparts.get(n)
        if sp is None or k in rock_ids or models[k] == "jwl" or not hasattr(sp.shape, "inner_radius"):
            continue
        sh, dx = sp.shape, float(sp.dx)
        held = [c for c, cp in charges
                if not hasattr(cp.shape, "inner_radius") and hasattr(cp.shape, "radius")
                and hasattr(cp.shape, "center")
                and np.hypot(cp.shape.center[0] - sh.center[0],
                             cp.shape.center[1] - sh.center[1]) <= dx
                and cp.shape.radius <= sh.inner_radius + dx]
        if held:
            out.append({"part": k, "name": n, "center": (float(sh.center[0]), float(sh.center[1])),
                        "r_in": float(sh.inner_radius), "r_out": float(sh.radius),
                        "z": (float(sh.z[0]), float(sh.z[1])), "dx": dx, "charges": held})
    return out

