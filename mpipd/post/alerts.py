"""Warnings a user cannot miss, from a run file: printed in a block at the end of
``mpipd run`` and at the top of the report.  Each names the option that addresses it.

* **Gas pressure.**  A charge whose peak gas pressure (the ``peak_pressure`` field over
  its points at the last frame, over every step; else the file's
  ``peak_gas_pressure`` attribute against the largest p_CJ) exceeds PRESSURE_FACTOR
  (1.5) x its p_CJ (the Chapman-Jouguet pressure of its own JWL constants, times its
  ``pressure_factor``): a steady detonation reaches p_CJ at most, so the gas is being
  compressed by the solid it touches.
* **Gas carrying no force.**  More than NO_FORCE_SHARE (half) of the gas points carry
  no force (``gas_force`` = 0: no gas neighbourhood, or a family collapsing in a
  step) at the last frame; the first saved frame from which that holds to the end is
  named.  Without the field, the count the caller passes (the run's own at its end).
* **Gas leaving its tube or hole.**  A charge held by a tube: gas points outside the
  tube's current inner surface (:mod:`mpipd.post.tube`) at any saved frame.  A charge
  in a hole: gas points of that charge more than one rock spacing beyond the hole's
  wall (radius from the charge's axis > its radius + the rock's dx, current
  positions, within the rock's thickness), or more than one rock spacing beyond the
  rock's faces (out of the hole's open ends), at any saved frame.
* **Lattice bias.**  On a section through the rock, the failed points around a charge
  show the lattice's four-fold symmetry: a_4 (:mod:`mpipd.post.lattice_bias`) at least
  LATTICE_NOISE (3) times its noise level (a chance of about 1e-3 for failure that does
  not depend on the angle) and at least LATTICE_A4 (0.25: the failed fraction varies by
  +-50 % or more with the angle, a modulation of amplitude 2 a_4).

Each warning is ``{"kind", "message", "fix"}``.  :func:`collect` is collective.
"""
from __future__ import annotations

import numpy as np

from . import charges as ch
from . import sections as secs
from . import tube as tb

PRESSURE_FACTOR = 1.5
NO_FORCE_SHARE = 0.5
LATTICE_NOISE = 3.0
LATTICE_A4 = 0.25


def _gas_mask(run, model) -> np.ndarray:
    pid = run.geometry("part")
    return np.isin(pid, [c["part"] for c in model.charges])


def pressure(run, model) -> list[dict]:
    out = []
    cs = [c for c in model.charges if c["p_CJ"]]
    if not cs:
        return out
    pid = run.geometry("part")
    if run.has_field("peak_pressure"):
        p = run.field("peak_pressure", run.frames - 1)
        peaks = {c["name"]: run.max(float(p[pid == c["part"]].max()) if (pid == c["part"]).any()
                                    else -np.inf) for c in cs}
        limits = {c["name"]: c["p_CJ"] for c in cs}
        source = "peak_pressure field"
    elif run.attr("peak_gas_pressure") is not None:
        peaks = {"the gas": float(run.attr("peak_gas_pressure"))}
        limits = {"the gas": max(c["p_CJ"] for c in cs)}
        source = "the run file's peak_gas_pressure attribute"
    else:
        return out
    for name, peak in peaks.items():
        lim = limits[name]
        if np.isfinite(peak) and peak > PRESSURE_FACTOR * lim:
            out.append({"kind": "gas pressure",
                        "message": f"peak gas pressure of {name} {peak / 1e9:.4g} GPa is "
                                   f"{peak / lim:.2f} x its p_CJ {lim / 1e9:.4g} GPa (over "
                                   f"{PRESSURE_FACTOR:g} x; {source}): a detonation reaches "
                                   "p_CJ at most, the gas is being squeezed by the solid "
                                   "it touches",
                        "fix": _wall_fix(model, _held_by(model))})
    return out


def no_force(run, model, end=None) -> list[dict]:
    gas = _gas_mask(run, model)
    n = run.sum_int(int(gas.sum()))
    if not n:
        return []
    if run.has_field("gas_force"):
        share = []
        for k in range(run.frames):
            f = run.field("gas_force", k)
            share.append(run.sum_int(int((gas & (f == 0)).sum())) / n)
        last = share[-1]
        if last <= NO_FORCE_SHARE:
            return []
        k = len(share) - 1
        while k > 0 and share[k - 1] > NO_FORCE_SHARE:
            k -= 1
        since = f"since t = {run.time[k] * 1e6:.3g} us (frame {k})"
        count = f"{round(last * n)} of {n}"
    elif end is not None and end[1] and end[0] / end[1] > NO_FORCE_SHARE:
        count, since = f"{end[0]} of {end[1]}", "at the end of the run"
    else:
        return []
    return [{"kind": "gas without force",
             "message": f"most of the gas carries no force: {count} gas points {since} (no gas "
                        "neighbourhood, or a family collapsing in a step): the charge no "
                        "longer pushes on the rock through them",
             "fix": _wall_fix(model, _held_by(model), ", so that it keeps its neighbours")}]


def leaving(run, model, tube_result=None) -> list[dict]:
    out = []
    if not run.has_field("u") or not model.charges:
        return out
    tubed = [c for c in model.charges if c["tube"] is not None]
    holed = [c for c in model.charges if c["tube"] is None and c["center"] and c["radius"]]
    if tubed:
        res = tube_result
        if res is None or "not_available" in res:
            x, pid = run.geometry("x"), run.geometry("part")
            held = tb.Containment(run, model, x, pid) if model.tubes else None
            if held is not None:
                for k in range(run.frames):
                    held.frame(k, run.field("u", k))
                res = held.result()
        if res is not None and "max_outside" in res and res["max_outside"] > 0:
            f = res["first_outside"]
            mats = {t["name"]: model.part_material.get(t["part"]) for t in model.tubes}
            out.append({"kind": "gas leaves its tube",
                        "message": f"gas leaves its tube: {f['points']} gas points outside "
                                   f"the tube first at {f['t_us']:.3g} us, at most "
                                   f"{res['max_outside']}",
                        "fix": _wall_fix(model, sorted(set(mats.values()) - {None}))})
    if holed:
        x, pid = run.geometry("x"), run.geometry("part")
        r_dx = model.dx
        worst = {}                      # (charge, way) -> [first frame, first count, most]
        for k in range(run.frames):
            u = run.field("u", k)
            for c in holed:
                m = pid == c["part"]
                y = x[m] + u[m]
                r = np.hypot(y[:, 0] - c["center"][0], y[:, 1] - c["center"][1])
                inside = (y[:, 2] > model.z0) & (y[:, 2] < model.z1)
                ways = {"wall": (r > c["radius"] + r_dx) & inside,
                        "ends": (y[:, 2] < model.z0 - r_dx) | (y[:, 2] > model.z1 + r_dx)}
                for way, hit in ways.items():
                    cnt = run.sum_int(int(hit.sum()))
                    key = (c["name"], way)
                    if cnt and key not in worst:
                        worst[key] = [k, cnt, cnt]
                    if key in worst:
                        worst[key][2] = max(worst[key][2], cnt)
        for (name, way), (k, first, most) in worst.items():
            n = run.sum_int(int((pid == next(c["part"] for c in holed
                                             if c["name"] == name)).sum()))
            where = (f"more than one rock spacing ({r_dx * 1e3:.3g} mm) beyond the hole's wall, "
                     "inside the rock's thickness" if way == "wall" else
                     "more than one rock spacing beyond the rock's faces (out of the hole's "
                     "open ends)")
            fix = _wall_fix(model, [model.rock_material] if model.rock_material else [])
            if way == "ends":
                fix = ("the hole is open at its ends: a part over the charge's ends "
                       "(stemming) closes it; " + fix + " at the hole's wall")
            out.append({"kind": "gas leaves its hole",
                        "message": f"gas leaves its hole: {first} gas points of {name!r} lie "
                                   f"{where} first at {run.time[k] * 1e6:.3g} us (frame {k}), "
                                   f"at most {most} of its {n}",
                        "fix": fix})
    return out


def _held_by(model) -> list[str]:
    """The solid that should hold the gas: the tube's material, else the rock's."""
    tubes = [model.part_material.get(t["part"]) for t in model.tubes]
    return [m for m in tubes if m] or ([model.rock_material] if model.rock_material else [])


def _wall_fix(model, solids, why: str = "") -> str:
    mats = sorted({c["material"] for c in model.charges})
    solid = solids[0] if solids else "<solid>"
    wall = getattr(model.explosive, "wall", None)
    if wall is not None:            # held at the tube's face already: it leaves by its ends
        return (f"the gas is held at the surface of {wall.material!r} already "
                "(its `wall`); it leaves through the tube's open ends: a specimen as thin "
                "as its charge is long vents the charge within microseconds (a charge "
                "shorter than the rock, or a thicker specimen, keeps it longer)")
    return (" or ".join(f"`materials.{m}.wall = {{ material = \"{solid}\" }}`" for m in mats)
            + " holds the gas at that solid's surface (the solid must be in the explosive's "
            "`interacts_with`)" + why)


def lattice(run, model, measures=None) -> list[dict]:
    """``measures``: section name -> {charge or label: lattice_bias.measure block}; without
    it, the mid-height section of the rock at the last frame, per charge."""
    if measures is None:
        measures = {}
        if not model.charges or not (run.has_field("damage") or run.has_field("failure_mode")):
            return []
        named = ch.rock_levels(run, model)
        mid = {n: z for n, z in named.items() if n == ch.NAMES[1]} or named
        last = run.frames - 1
        got = secs.gather_sections(run, model, mid, [("damage", last), ("failure_mode", last)])
        if run.root:
            usable = [c for c in model.charges if c["center"] and c["radius"]]
            for name, sec in (got or {}).items():
                per = ch.measure(sec, usable, last)
                measures[name] = {c: v["lattice_bias"] for c, v in per.items()}
        measures = run.comm.bcast(measures, root=0)
    hits = []
    for sec_name, per in measures.items():
        for who, m in per.items():
            if not isinstance(m, dict) or "a4" not in m or not m["noise"] > 0:
                continue
            if m["a4"] >= LATTICE_A4 and m["a4"] >= LATTICE_NOISE * m["noise"]:
                hits.append(f"{who} on the {sec_name} section: a_4 {m['a4']:.2f} "
                            f"({m['a4'] / m['noise']:.1f} x noise, {m['n_failed']} failed points)")
    if not hits:
        return []
    k = model.scene_parts.index(model.rock_base) if model.rock_base in model.scene_parts else "N"
    rock_mat = model.rock_material or "<rock>"
    return [{"kind": "lattice bias",
             "message": "the failed points show the lattice's four-fold symmetry (cracks "
                        "along the lattice's axes or diagonals, not the rock's): "
                        + "; ".join(hits),
             "fix": f"`parts.{k}.jitter` (moves the points off the lattice) and "
                    f"`materials.{rock_mat}.heterogeneity` (a random strength field) make "
                    "the rock a rock mass"}]


def collect(run, model, lattice_measures=None, tube_result=None, end_no_force=None) -> list[dict]:
    """Every warning of the run (module docstring), in that order."""
    return (pressure(run, model) + no_force(run, model, end_no_force)
            + leaving(run, model, tube_result) + lattice(run, model, lattice_measures))


def lines(warnings) -> list[str]:
    """The block as text lines (empty without warnings)."""
    if not warnings:
        return []
    out = [f"WARNING: {len(warnings)} thing(s) in this run need your attention:"]
    for w in warnings:
        out.append(f"  - {w['message']}.")
        out.append(f"    Fix: {w['fix']}.")
    return out
